"""Each line's extremes over a run: the table an engineer reads first.

For every line of a scene, the largest and the smallest segment tension with the segment
and time of each, the largest tension at each end (a mooring's fairlead and anchor, a
riser's top and touchdown), and, where the line type gives its minimum breaking load
(MBL), the utilisation: the largest tension over the MBL. A line whose utilisation passes
1 / safety factor is warned of.

The default safety factor, 1.67, is API RP 2SK's for an intact mooring analysed
dynamically (the largest tension at most 60 % of the MBL); DNV-OS-E301 and ISO 19901-7
set others, and `--safety-factor` takes any factor of at least 1.
"""

from dataclasses import dataclass

import numpy as np

from .._names import DEFAULT_SAFETY_FACTOR
from ._columns import aligned
from ._scene import BuiltScene

TABLE_ROWS = 20
"""Lines shown in [`table`][]: the most utilised, or the most loaded where no MBL is given."""


@dataclass(frozen=True)
class LineExtremes:
    """One line's extremes over a run's output times.

    - `line`, `line_type`: the names the scene gives them.
    - `segments`: the line's number of segments.
    - `largest`, `largest_time`, `largest_segment`: the largest segment tension (N), when
        (s) and in which segment, numbered from end A from 1.
    - `smallest`, `smallest_time`, `smallest_segment`: the smallest, likewise; 0 where a
        segment went slack.
    - `end_a`, `end_b`: the largest tension (N) of the segment at end A and at end B.
    - `breaking_load`: the line type's minimum breaking load (N), or `None` where the
        scene gives none.
    """

    line: str
    line_type: str
    segments: int
    largest: float
    largest_time: float
    largest_segment: int
    smallest: float
    smallest_time: float
    smallest_segment: int
    end_a: float
    end_b: float
    breaking_load: float | None

    @property
    def utilisation(self) -> float | None:
        """The largest tension over the minimum breaking load (–), or `None` without one."""
        return None if self.breaking_load is None else self.largest / self.breaking_load


def line_extremes(built: BuiltScene, times: np.ndarray, tension: np.ndarray) -> tuple[LineExtremes, ...]:
    """Each line's [`LineExtremes`][] from segment tensions `tension` (N), shape
    `(times, segments)`, at `times` (s), shape `(times,)`."""
    breaking = {t.name: t.minimum_breaking_load for t in built.scene.line_types}
    rows = []
    for line, segments in zip(built.scene.lines, built.line_segments):
        history = np.asarray(tension)[:, segments] + 0.0  # + 0.0: a slack segment's −0.0 as 0
        t_max, s_max = np.unravel_index(np.argmax(history), history.shape)
        t_min, s_min = np.unravel_index(np.argmin(history), history.shape)
        rows.append(
            LineExtremes(
                line=line.name,
                line_type=line.line_type,
                segments=line.segments,
                largest=float(history[t_max, s_max]),
                largest_time=float(times[t_max]),
                largest_segment=int(s_max) + 1,
                smallest=float(history[t_min, s_min]),
                smallest_time=float(times[t_min]),
                smallest_segment=int(s_min) + 1,
                end_a=float(np.max(history[:, 0])),
                end_b=float(np.max(history[:, -1])),
                breaking_load=breaking[line.line_type],
            )
        )
    return tuple(rows)


def table(rows: tuple[LineExtremes, ...], limit: int = TABLE_ROWS) -> str:
    """`rows` as a text table in kN and s, a line each: all of them up to `limit`, else
    the `limit` most utilised (or most loaded) and a count of the rest."""
    shown = list(rows)
    if len(shown) > limit:
        shown.sort(key=lambda r: (r.utilisation is not None, r.utilisation or 0.0, r.largest), reverse=True)
        shown = shown[:limit]
    mbl = any(r.breaking_load is not None for r in rows)
    heading = ["line", "type", "largest kN", "t s", "segment", "smallest kN", "t s", "end A kN", "end B kN"]
    if mbl:
        heading += ["MBL kN", "utilisation"]
    body = []
    for r in shown:
        cells = [
            r.line,
            r.line_type,
            f"{r.largest / 1e3:.3f}",
            f"{r.largest_time:.3f}",
            f"{r.largest_segment}/{r.segments}",
            f"{r.smallest / 1e3:.3f}",
            f"{r.smallest_time:.3f}",
            f"{r.end_a / 1e3:.3f}",
            f"{r.end_b / 1e3:.3f}",
        ]
        if mbl:
            load, u = r.breaking_load, r.utilisation
            cells += ["-", "-"] if load is None or u is None else [f"{load / 1e3:.1f}", f"{u:.1%}"]
        body.append(cells)
    text = aligned(heading, body, left=2)
    if len(rows) > len(shown):
        text.append(f"... and {len(rows) - len(shown)} more lines (all in SceneRun.line_extremes())")
    return "\n".join(text)


def overloads(rows: tuple[LineExtremes, ...], safety_factor: float = DEFAULT_SAFETY_FACTOR) -> list[str]:
    """A warning for each line whose largest tension passes its minimum breaking load
    over `safety_factor`."""
    warnings = []
    for r in rows:
        load, u = r.breaking_load, r.utilisation
        if load is None or u is None or u <= 1 / safety_factor:
            continue
        what = (
            "beyond its minimum breaking load: the line would break"
            if u > 1
            else f"above 1/{safety_factor:g} = {1 / safety_factor:.1%} (safety factor {safety_factor:g})"
        )
        warnings.append(
            f"line {r.line} ({r.line_type}): largest tension {r.largest / 1e3:.3f} kN at t = {r.largest_time:.3f} s, "
            f"segment {r.largest_segment}/{r.segments}, is {u:.1%} of its minimum breaking load "
            f"{load / 1e3:.1f} kN, {what}"
        )
    return warnings
