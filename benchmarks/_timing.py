"""Timing shared by the benchmarks: compile time apart from run time."""

import statistics
import time


def timed(run, repeats):
    """Call `run()` once, then `repeats` more times.

    Returns `(result, compile, run)`: the first call's result, its time less the median
    warm call (s), and that median (s). jax is imported here, not at module level, so
    that a script can set `XLA_FLAGS` before JAX starts.
    """
    import jax

    start = time.perf_counter()
    result = jax.block_until_ready(run())
    first = time.perf_counter() - start
    warm = []
    for _ in range(repeats):
        start = time.perf_counter()
        jax.block_until_ready(run())
        warm.append(time.perf_counter() - start)
    run_time = statistics.median(warm)
    return result, max(first - run_time, 0.0), run_time
