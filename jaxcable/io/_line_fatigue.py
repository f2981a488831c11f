"""Each line's fatigue damage over a run: the worst segment's Miner damage and life.

Where a line type names a T–N curve (`LineTypeSpec.fatigue_curve`), every segment of its
lines has its tension history counted by rainflow and summed by Miner's rule
([`jaxcable.fatigue_damage`][]); the line's row is its worst segment's. The damage is
that of the run's history from `start` on, and the life (years) its rate's: a single
run stands for one sea state, so a design's life sums the damage rates of its sea
states weighted by their probabilities (a campaign's work). Beside it, the worst
segment's damage-equivalent load at one cycle a second
([`jaxcable.damage_equivalent_load`][] at the curve's exponent): a tension range that
compares load cases without the curve's coefficient.
"""

from dataclasses import dataclass

import numpy as np

from .._campaign.fatigue import TN_CURVES, fatigue_damage
from ._columns import aligned
from ._scene import BuiltScene, SceneError
from ._statistics import from_start

TABLE_ROWS = 20
"""Lines shown in [`table`][]: the most damaged."""


@dataclass(frozen=True)
class LineFatigue:
    """One line's fatigue over a run, at its most damaged segment.

    - `line`, `line_type`, `curve`: the names the scene gives them and the T–N curve's.
    - `segments`: the line's number of segments.
    - `damage`: Miner's sum (–) of the worst segment over the counted history.
    - `segment`: that segment, numbered from end A from 1.
    - `annual_damage` (1/year) and `life` (years) at that rate.
    - `equivalent_load`: that segment's damage-equivalent load (N) at the curve's
        exponent m, one equivalent cycle a second of the counted interval (1 Hz):
        `(Σ n_i ΔT_i^m / (end − start))^(1/m)`.
    - `start`, `end`: the counted interval (s).
    """

    line: str
    line_type: str
    curve: str
    segments: int
    damage: float
    segment: int
    annual_damage: float
    life: float
    equivalent_load: float
    start: float
    end: float


def line_fatigue(
    built: BuiltScene, times: np.ndarray, tension: np.ndarray, start: float = 0.0
) -> tuple[LineFatigue, ...]:
    """Each line's [`LineFatigue`][] whose line type names a T–N curve, from segment
    tensions `tension` (N), shape `(times, segments)`, at `times` (s), counted from
    `start` (s).

    **Raises:**

    [`jaxcable.io.SceneError`][] for a line type whose curve needs a minimum breaking
    load it does not have."""
    types = {t.name: t for t in built.scene.line_types}
    kept = from_start(times, start)
    t = np.asarray(times)[kept]
    rows = []
    for line, segments in zip(built.scene.lines, built.line_segments):
        spec = types[line.line_type]
        if spec.fatigue_curve is None:
            continue
        if problem := spec.fatigue_problem():
            raise SceneError(problem)
        curve = TN_CURVES[spec.fatigue_curve]
        results = [
            fatigue_damage(
                np.asarray(tension)[kept, s], t, curve, area=spec.fatigue_area, breaking_load=spec.minimum_breaking_load
            )
            for s in np.asarray(segments)
        ]
        worst = int(np.argmax([r.damage for r in results]))
        r = results[worst]
        rows.append(
            LineFatigue(
                line=line.name,
                line_type=line.line_type,
                curve=spec.fatigue_curve,
                segments=line.segments,
                damage=r.damage,
                segment=worst + 1,
                annual_damage=r.annual_damage,
                life=r.life,
                equivalent_load=r.equivalent_load(curve.exponent, t[-1] - t[0]),
                start=float(t[0]),
                end=float(t[-1]),
            )
        )
    return tuple(rows)


def table(rows: tuple[LineFatigue, ...], limit: int = TABLE_ROWS) -> str:
    """`rows` as a text table, the `limit` most damaged lines and a count of the rest;
    empty without rows."""
    if not rows:
        return ""
    shown = sorted(rows, key=lambda r: r.damage, reverse=True)[:limit]
    heading = ["line", "type", "T–N curve", "damage", "segment", "per year", "life (years)", "DEL kN (1 Hz)"]
    body = [
        [
            r.line,
            r.line_type,
            r.curve,
            f"{r.damage:.3e}",
            f"{r.segment}/{r.segments}",
            f"{r.annual_damage:.3e}",
            "inf" if not np.isfinite(r.life) else f"{r.life:.4g}",
            f"{r.equivalent_load / 1e3:.4g}",
        ]
        for r in shown
    ]
    text = aligned(heading, body, left=3)
    if len(rows) > len(shown):
        text.append(f"... and {len(rows) - len(shown)} more lines (all in SceneRun.line_fatigue())")
    first = rows[0]
    return f"fatigue over t = {first.start:g} to {first.end:g} s (Miner's rule, rainflow counting):\n" + "\n".join(text)
