"""Timing for benchmarks: warm-up, then the median of repeated runs (never used in tests)."""
import statistics
import time

__all__ = ["median_seconds", "alternating_medians"]


def median_seconds(run, repeats=7, warmup=2):
    """Median wall time of ``run()`` over ``repeats`` calls after ``warmup`` untimed calls [s]."""
    for _ in range(warmup):
        run()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def alternating_medians(runs, repeats=7, warmup=2):
    """Median wall time of each of several callables, timed in alternation so drift hits all alike.

    Parameters
    ----------
    runs : dict of str to callable
    repeats, warmup : int

    Returns
    -------
    dict of str to float
        Median seconds per name.
    """
    for run in runs.values():
        for _ in range(warmup):
            run()
    times = {name: [] for name in runs}
    for _ in range(repeats):
        for name, run in runs.items():
            start = time.perf_counter()
            run()
            times[name].append(time.perf_counter() - start)
    return {name: statistics.median(t) for name, t in times.items()}
