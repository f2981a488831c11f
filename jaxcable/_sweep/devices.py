"""Where a sweep's cases run: the devices they are sharded across, and on a CPU the
chunks of cases that the same compiled program runs on threads, two a core."""

import os

import equinox as eqx
import jax
import numpy as np

# The mesh axis that cases are split along.
CASES = "cases"


def place(tree, where):
    """`jax.device_put` of the arrays in `tree`, leaving other leaves (a solver's
    functions, say) as they are."""
    arrays, rest = eqx.partition(tree, eqx.is_array)
    return eqx.combine(jax.device_put(arrays, where), rest)


def check_devices(devices) -> list:
    devices = jax.devices() if devices is None else list(devices)
    if not devices:
        raise ValueError("sweep: devices must not be empty")
    for d in devices:
        if not isinstance(d, jax.Device):
            raise ValueError(f"sweep: devices must be JAX devices (from jax.devices()), got {d!r}")
    if len(set(devices)) != len(devices):
        raise ValueError(f"sweep: devices must not repeat, got {devices}")
    return devices


# Cases a chunk keeps, at least, when the default gives each core two chunks.
_CASES_PER_CHUNK = 16


def check_chunks(chunks, devices, n_cases: int) -> int:
    if chunks is None:
        if devices[0].platform != "cpu":
            return 1
        cores = max(1, available_cores() // len(devices))
        # Two chunks a core finish sooner than one: a thread held up (by the Python
        # thread, or another process) leaves its core's second chunk to the other core.
        # For Bosh3 fixed steps on the anchored line that is 5–7 % sooner, and more
        # chunks gain no more (`benchmarks/sweep_throughput.py --chunks`). Not below 16
        # cases a chunk, where padding to a multiple of the chunks would cost more.
        return 2 * cores if n_cases >= 2 * cores * len(devices) * _CASES_PER_CHUNK else cores
    if not (isinstance(chunks, int) and not isinstance(chunks, bool) and chunks >= 1):
        raise ValueError(f"sweep: chunks must be a positive integer, got {chunks!r}")
    return chunks


def available_cores() -> int:
    """The CPU cores this process may run on (its affinity, where the OS has one)."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def split(per_case, chunks: int) -> list:
    """`per_case` cut into `chunks` equal runs of consecutive cases, as numpy arrays:
    JAX would compile a slicing program for each chunk's offset."""
    size = len(per_case["valid"]) // chunks
    per_case = jax.tree.map(np.asarray, per_case)

    def part(i):
        return jax.tree.map(lambda x: x[i * size : (i + 1) * size], per_case)

    return [part(i) for i in range(chunks)]
