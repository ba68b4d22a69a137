"""The command line (`cli`, `expressions`) and the benchmarks (`bench`, `speed`): glphong's users, not
its core.
"""
