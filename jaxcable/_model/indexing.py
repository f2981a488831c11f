"""Indexing with static indices, as slices where the indices run in order.

The network's topology is static ([`jaxcable._model.network.Topology`][]), so every index
array the equations use — each segment's end nodes, the free nodes, the segments that
meet at a node — is known when tracing. A chain's indices are mostly runs of
consecutive integers, and a run is a slice. XLA fuses slices, pads and concatenations
with the arithmetic around them into one loop, where a gather or a scatter is a kernel
of its own: on the anchored line, the scatters and gathers of the old formulation were
about a third of an evaluation's kernels. Indices with many short runs (a net numbered
in no useful order) fall back to one gather, so the program stays small.
"""

import functools

import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

# Above this many runs, one gather is cheaper to compile than a concatenation of slices.
_MAX_RUNS = 16


@functools.lru_cache(maxsize=4096)
def _runs(key: bytes, size: int) -> tuple[tuple[int, int], ...]:
    """`(start, length)` of each maximal run of consecutive indices; a start of −1 marks
    a run of −1s (zeros)."""
    indices = np.frombuffer(key, dtype=np.int64, count=size)
    runs: list[list[int]] = []
    for i in indices.tolist():
        if runs:
            start, length = runs[-1]
            if (start < 0 and i < 0) or (start >= 0 and i == start + length):
                runs[-1][1] += 1
                continue
        runs.append([i if i >= 0 else -1, 1])
    return tuple((start, length) for start, length in runs)


def take(array: Array, indices: np.ndarray) -> Array:
    """`array[..., indices]`, along the last axis, for static integer `indices` (numpy,
    1-D); an index of −1 gives zeros.

    Compiles to slices and one concatenation where `indices` has at most 16 runs of
    consecutive integers, and to one gather otherwise. Exact either way: it only moves
    values.
    """
    indices = np.asarray(indices, dtype=np.int64)
    runs = _runs(indices.tobytes(), indices.size)
    leading = array.shape[:-1]
    if len(runs) > _MAX_RUNS:
        padded = jnp.concatenate([array, jnp.zeros((*leading, 1), array.dtype)], axis=-1)
        return padded[..., np.where(indices < 0, array.shape[-1], indices)]
    pieces = [
        jnp.zeros((*leading, length), array.dtype) if start < 0 else array[..., start : start + length]
        for start, length in runs
    ]
    if not pieces:
        return jnp.zeros((*leading, 0), array.dtype)
    return pieces[0] if len(pieces) == 1 else jnp.concatenate(pieces, axis=-1)


def incidence(targets: np.ndarray, n_targets: int) -> np.ndarray:
    """The static plan of a sum onto `n_targets` bins: `plan[t, k]` is the position in
    `targets` of the k-th entry that lands on bin `t`, or −1, shape `(n_targets, most)`.

    `sum(take(values, plan[:, k]) for k)` is then `segment_sum(values, targets)`, made
    of slices and adds, which fuse, where a scatter-add would not.
    """
    targets = np.asarray(targets)
    most = int(np.bincount(targets, minlength=n_targets).max()) if targets.size else 0
    plan = np.full((n_targets, most), -1, dtype=np.int64)
    filled = np.zeros(n_targets, dtype=np.int64)
    for position, target in enumerate(targets.tolist()):
        plan[target, filled[target]] = position
        filled[target] += 1
    return plan


def sum_into(values: Array, plan: np.ndarray) -> Array:
    """`segment_sum` of `values` along their last axis, by a plan from [`incidence`][]."""
    if plan.shape[1] == 0:
        return jnp.zeros((*values.shape[:-1], plan.shape[0]), values.dtype)
    total = take(values, plan[:, 0])
    for k in range(1, plan.shape[1]):
        total = total + take(values, plan[:, k])
    return total
