"""Statistics of each output channel over a run: mean, standard deviation and extremes.

A run's channels (MoorDyn's names: `FairTen1`, `Con4Fx`, `L1N20PZ`, ...) are sampled at
the output times. Mean and standard deviation are time averages by the trapezoidal rule
over `[start, end]`, so a last output interval shorter than the others (a duration that
is not a multiple of the output step) weighs for its length; the extremes are the largest
and smallest samples, with their times. `start` leaves a start-up transient out, as
OrcaFlex's build-up stage or the first period of a MoorDyn run would be.
"""

from dataclasses import dataclass

import numpy as np

from ._columns import aligned

TABLE_ROWS = 20
"""Channels shown in [`table`][]; the rest are counted."""


@dataclass(frozen=True)
class ChannelStatistics:
    """One output channel's statistics over `[start, end]` (s).

    - `name`, `units`: the channel's MoorDyn name and its unit (`N`, `m`, `m/s`).
    - `mean`, `std`: its time average and standard deviation (in `units`).
    - `minimum`, `minimum_time`, `maximum`, `maximum_time`: its smallest and largest
        sample and when (s).
    - `start`, `end`: the interval (s).
    """

    name: str
    units: str
    mean: float
    std: float
    minimum: float
    minimum_time: float
    maximum: float
    maximum_time: float
    start: float
    end: float


def from_start(times: np.ndarray, start: float) -> np.ndarray:
    """Which output `times` (s) are counted from `start` (s) on: a boolean mask, an
    output time within rounding of `start` included."""
    times = np.asarray(times, dtype=float)
    return times >= start - 1e-9 * max(float(times[-1]), 1.0)


def channel_statistics(
    channels: dict[str, np.ndarray], units: dict[str, str], start: float = 0.0
) -> tuple[ChannelStatistics, ...]:
    """[`ChannelStatistics`][] of every channel but `Time`, from the samples at or after
    `start` (s).

    **Arguments:**

    - `channels`: `Time` (s), shape `(times,)`, then each channel's samples, the same
        shape, as [`jaxcable.io.SceneRun.channels`][] gives them.
    - `units`: each channel's unit.
    - `start`: the first time (s) counted.

    **Raises:**

    `ValueError` where `start` is not a number below the last output time.
    """
    times = np.asarray(channels["Time"], dtype=float)
    end = float(times[-1])
    if not np.isfinite(start) or start < 0 or (start >= end and times.size > 1):
        raise ValueError(f"statistics start at {start!r} s, but the outputs run from 0 to {end:g} s")
    kept = from_start(times, start)
    t = times[kept]
    span = t[-1] - t[0]
    rows = []
    for name, series in channels.items():
        if name == "Time":
            continue
        x = np.asarray(series, dtype=float)[kept] + 0.0  # + 0.0: a slack segment's −0.0 as 0
        if span > 0:
            mean = _integral(x, t) / span
            std = float(np.sqrt(max(_integral((x - mean) ** 2, t) / span, 0.0)))
        else:
            mean, std = float(x[0]), 0.0
        low, high = int(np.argmin(x)), int(np.argmax(x))
        rows.append(
            ChannelStatistics(
                name=name,
                units=units[name],
                mean=mean,
                std=std,
                minimum=float(x[low]),
                minimum_time=float(t[low]),
                maximum=float(x[high]),
                maximum_time=float(t[high]),
                start=float(t[0]),
                end=end,
            )
        )
    return tuple(rows)


def _integral(x: np.ndarray, t: np.ndarray) -> float:
    """∫ x dt by the trapezoidal rule (numpy's `trapezoid` is numpy 2's)."""
    return float(np.sum(0.5 * (x[1:] + x[:-1]) * np.diff(t)))


def table(rows: tuple[ChannelStatistics, ...], limit: int = TABLE_ROWS) -> str:
    """`rows` as a text table, a channel each in its own units, the first `limit` of them
    and a count of the rest."""
    if not rows:
        return ""
    shown = rows[:limit]
    heading = ["channel", "units", "mean", "std", "min", "t s", "max", "t s"]
    body = [
        [
            r.name,
            r.units,
            f"{r.mean:.6g}",
            f"{r.std:.4g}",
            f"{r.minimum:.6g}",
            f"{r.minimum_time:.3f}",
            f"{r.maximum:.6g}",
            f"{r.maximum_time:.3f}",
        ]
        for r in shown
    ]
    text = aligned(heading, body, left=2)
    first = rows[0]
    what = f"statistics over t = {first.start:g} to {first.end:g} s"
    if len(rows) > len(shown):
        text.append(f"... and {len(rows) - len(shown)} more channels (all in SceneRun.channel_statistics())")
    return f"{what}:\n" + "\n".join(text)
