"""glphong's version (one place; ``glphong.__version__``)."""
__version__ = "0.1.0"
