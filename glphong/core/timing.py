"""Timing for benchmarks: warm-up, then the median of repeated runs (never used in tests)."""
import statistics
import time

__all__ = ["median_seconds", "alternating_medians", "alternating_times", "quartiles_ms", "progress_bar"]


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


def alternating_times(runs, repeats=7, warmup=2):
    """Wall times of several callables, timed in alternation (one round calls each once) so drift hits
    all alike, after ``warmup`` untimed rounds.

    Returns
    -------
    dict of str to list of float
        ``repeats`` times [s] per name.
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
    return times


def alternating_medians(runs, repeats=7, warmup=2):
    """Median wall time [s] of each of several callables (`alternating_times`), dict of str to float."""
    return {name: statistics.median(t) for name, t in alternating_times(runs, repeats, warmup).items()}


def quartiles_ms(times):
    """``(q1, median, q3)`` [ms] of a list of wall times [s] (all three the one time where there is one)."""
    q = statistics.quantiles(times, n=4) if len(times) > 1 else [times[0]] * 3
    return tuple(1000.0 * v for v in (q[0], statistics.median(times), q[2]))


def progress_bar(total, enabled=True, unit="point"):
    """A tqdm progress bar of ``total`` steps, or None where disabled or tqdm is not installed."""
    if not enabled:
        return None
    try:
        from tqdm import tqdm
    except ImportError:
        return None
    return tqdm(total=total, unit=unit, leave=False)
