"""How the built-in definitions are found: every module of a package of definitions is imported (which registers
the models or kinds it defines), and the classes its ``__all__`` names become the package's, so a new model or
light kind is one module in `glphong.materials` or `glphong.lights`, with nothing to list by hand."""
import importlib
import pkgutil

__all__ = ["import_definitions"]


def import_definitions(package, path, namespace, public):
    """Import every module of ``package`` (its ``__path__``: ``path``) in name order, putting each class its
    ``__all__`` names into ``namespace`` (the package's globals) and its name on ``public`` (the package's
    ``__all__``)."""
    for info in sorted(pkgutil.iter_modules(path), key=lambda info: info.name):
        module = importlib.import_module(f"{package}.{info.name}")
        for name in module.__all__:
            if isinstance(getattr(module, name), type):
                namespace[name] = getattr(module, name)
                public.append(name)
