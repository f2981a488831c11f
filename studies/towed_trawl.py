"""The towed trawl as a study: the speed steps, their tensions, the buoy's depth,
the diverters' paths, and the snap loads.

Used by `notebooks/branched_systems.ipynb`, `validation/branched_systems_reproduction.py`
and the tests. Each case is one run of [`jaxcable.simulate`][] from the steady tow at the
first speed (`jaxcable.examples._towed_trawl.steady_tow`), stepping to the second at t = 300 s. See
`jaxcable/examples/towed_trawl.py` for the scene and the choices the paper leaves open.

Where tension is read (the paper's Figs. 7–8), by the segment that touches the point:

- the tow point: the tow cable's first segment;
- the branch point: the tow cable's last segment;
- the diverter attachment: the +y sweep branch's last segment;
- the buoy attachment: the support branch's last segment.
"""

import dataclasses
import time
from typing import Any

import numpy as np

from jaxcable import State, simulate
from jaxcable.examples import floater_amplitude
from jaxcable.examples._anchored_line import ADDED_MASS, AXIAL_STIFFNESS, MASS_PER_LENGTH
from jaxcable.examples._towed_trawl import (
    STEP_DURATION,
    STEP_TIME,
    TOW_LENGTH,
    WAVE_PERIOD,
    start_tow,
    steady_tow,
    towed_trawl,
)

# Study sizes: the notebook's default and the tests run SMALL, the benchmark FULL. `end`
# is each case's last time (s); `dense` the span (s) after the step sampled at 1 kHz.
SMALL = dict(segments=(6, 3), start=270.0, end=dict(long=320.0, short=306.0), dense=2.0)
FULL = dict(segments=(20, 10), start=270.0, end=dict(long=400.0, short=330.0), dense=6.0)
# The cases: name → (speeds (m/s), viscous, waves, length). 1 → 3 calm is the paper's
# Fig. 7, 1 → 4 in waves its Fig. 8 and 10, 1 → 2 with and without waves its Fig. 9; the
# falls are the decreases it mentions without a figure.
CASES = {
    "rise 1→3": ((1.0, 3.0), True, False, "long"),
    "rise 1→3, elastic": ((1.0, 3.0), False, False, "short"),
    "fall 3→1": ((3.0, 1.0), True, False, "short"),
    "fall 3→1, elastic": ((3.0, 1.0), False, False, "short"),
    "rise 1→4, waves": ((1.0, 4.0), True, True, "long"),
    "rise 1→2": ((1.0, 2.0), True, False, "long"),
    "rise 1→2, waves": ((1.0, 2.0), True, True, "long"),
}
POINTS = ("tow point", "branch point", "diverter", "buoy")
JUNCTIONS = dict(tow=0, branch=1, diverter=2, diverter_minus=3, buoy=4)
# A segment counts as slack where its tension is at or below zero: Kelvin–Voigt's
# viscous term can push a stretched segment briefly below zero when it unloads fast.
SLACK_TENSION = 0.0  # N
# A snap's peak is looked for within this time (s) after its slack spell ends.
SNAP_WINDOW = 1.0


@dataclasses.dataclass
class TrawlRun:
    """One speed step: the tension `tension` (N) of every segment, shape
    `(times, segments)`, and the junctions' positions `junctions` (m), shape
    `(times, 5, 3)`, at `times` (s); `points` maps each of `POINTS` to its segment."""

    name: str
    speeds: tuple[float, float]
    viscous: bool
    waves: bool
    times: np.ndarray
    tension: np.ndarray
    junctions: np.ndarray
    points: dict[str, int]
    steady: State  # the steady tow the run starts from
    front_angle: float  # rad, the tow cable's first segment below the tow, before the step
    steps: int
    wall_time: float  # s, compile included
    # N, the elastic part `(C_E ε + C_E1 ε²) H(ε)` of `tension`, same shape; `None` for
    # a run built by hand.
    elastic: np.ndarray | None = None

    def at(self, point: str) -> np.ndarray:
        """The tension (N) at one of `POINTS`, shape `(times,)`."""
        return self.tension[:, self.points[point]]

    def elastic_at(self, point: str) -> np.ndarray:
        """The elastic part of the tension (N) at one of `POINTS`, shape `(times,)`."""
        if self.elastic is None:
            raise ValueError(f"run {self.name!r} has no elastic tension (a run built by hand)")
        return self.elastic[:, self.points[point]]

    def window(self, t0: float, t1: float = np.inf) -> np.ndarray:
        return (self.times >= t0) & (self.times <= t1)


def _points(model) -> dict[str, int]:
    ends = np.asarray(model.segment_nodes)

    def ending_at(node):
        return int(np.flatnonzero(ends[:, 1] == node)[0])

    return {
        "tow point": int(np.flatnonzero(ends[:, 0] == JUNCTIONS["tow"])[0]),
        "branch point": ending_at(JUNCTIONS["branch"]),
        "diverter": ending_at(JUNCTIONS["diverter"]),
        "buoy": ending_at(JUNCTIONS["buoy"]),
    }


def run_trawl(
    name: str,
    config: dict = SMALL,
    progress: bool = False,
    guess: State | None = None,
    case: tuple | None = None,
    quadratic_ratio: float = 0.0,
) -> TrawlRun:
    """Run case `name` of `CASES` at size `config` (`SMALL` or `FULL`). `guess`: the
    steady tow at the case's first speed from another case, to start statics from.
    `case`: `(speeds, viscous, waves, length)` as in `CASES`, for a case not in it.
    `quadratic_ratio`: C_E1 / C_E of the cable (0, Hooke's, by default)."""
    speeds, viscous, waves, length = CASES[name] if case is None else case
    start, end = config["start"], config["end"][length]
    options: dict[str, Any] = dict(
        viscous=viscous, waves=waves, start=start, segments=config["segments"], quadratic_ratio=quadratic_ratio
    )
    if guess is None:
        model, env, state, _ = start_tow(speeds, **options)
    else:
        model, env = towed_trawl(speeds, **options)
        state, _ = steady_tow(model, env, speeds[0], start, initial=guess)
    # 20 Hz resolves the 5.6 s waves; 1 kHz over the step resolves its stages (0.13 s
    # apart) and the elastic cable's ringing.
    dense_end = STEP_TIME + config["dense"]
    ts = np.unique(
        np.concatenate(
            [
                np.arange(start, STEP_TIME, 0.05),
                np.arange(STEP_TIME, dense_end, 1e-3),
                np.arange(dense_end, end, 0.05),
                [end],
            ]
        )
    )
    ts = ts[ts <= end]  # a run that ends before the step
    clock = time.perf_counter()
    result = simulate(model, env, end, t0=start, ts=ts, initial=state, progress=progress)
    wall = time.perf_counter() - clock
    p = np.asarray(state.positions)
    points = _points(model)
    first = p[np.asarray(model.segment_nodes)[points["tow point"], 1]] - p[0]
    return TrawlRun(
        name=name,
        speeds=speeds,
        viscous=viscous,
        waves=waves,
        times=ts,
        tension=np.asarray(result.tension),
        junctions=np.asarray(result.positions)[:, :5],
        points=points,
        steady=state,
        front_angle=float(np.arccos(-first[0] / np.linalg.norm(first))),
        steps=int(result.stats["num_steps"]),
        wall_time=wall,
        elastic=np.asarray(model.line.tension_law.elastic_tension(result.strain)),
    )


def run_study(config: dict = SMALL, cases=tuple(CASES), progress: bool = False) -> dict[str, TrawlRun]:
    """Every case in `cases`, by name. Cases that start at the same speed share their
    steady tow: statics at 20 segments a branch is dear (`start_tow`)."""
    runs, steady = {}, {}
    for name in cases:
        first = CASES[name][0][0]
        runs[name] = run_trawl(name, config, progress, guess=steady.get(first))
        steady[first] = runs[name].steady
    return runs


# --- measures --------------------------------------------------------------------------


def front_jump(run: TrawlRun) -> tuple[float, float]:
    """`(measured, predicted)`: the tension's first stage at the tow point (N).

    The speed step sends an axial wave down the tow cable, which raises the tension by
    the cable's impedance times the step's component along the cable, Z Δv cos θ with
    Z = √(C_E (m + m_a)), until the wave comes back from the branch point 2 L / c later
    (c = √(C_E / (m + m_a)); 0.135 s). Measured: the mean over the second half of that
    interval, less the mean before the step.
    """
    mass = MASS_PER_LENGTH + ADDED_MASS
    speed = np.sqrt(AXIAL_STIFFNESS / mass)
    round_trip = 2 * TOW_LENGTH / speed
    t0 = STEP_TIME + STEP_DURATION
    tension = run.at("tow point")
    plateau = tension[run.window(t0 + 0.5 * round_trip, STEP_TIME + round_trip)].mean()
    before = tension[run.window(STEP_TIME - 5.0, STEP_TIME - 1e-9)].mean()
    dv = run.speeds[1] - run.speeds[0]
    return float(plateau - before), float(np.sqrt(AXIAL_STIFFNESS * mass) * dv * np.cos(run.front_angle))


def running_mean(run: TrawlRun, values: np.ndarray, period: float = WAVE_PERIOD) -> tuple[np.ndarray, np.ndarray]:
    """`(times, mean)`: `values` averaged over one wave period, on a uniform 20 Hz grid."""
    grid = np.arange(run.times[0], run.times[-1], 0.05)
    v = np.interp(grid, run.times, values)
    n = int(round(period / 0.05))
    mean = np.convolve(v, np.ones(n) / n, mode="valid")
    return grid[n // 2 : n // 2 + mean.size], mean


@dataclasses.dataclass
class Levels:
    """A quantity before and after a step: its mean and its range `max − min`, over the
    last `span` seconds before the step and the run's last `span` seconds; and the
    largest one-period mean in between (`peak_mean`)."""

    mean_before: float
    mean_after: float
    range_before: float
    range_after: float
    peak_mean: float


def levels(run: TrawlRun, values: np.ndarray, span: float = 15.0) -> Levels:
    before = values[run.window(STEP_TIME - span, STEP_TIME - 1e-9)]
    after = values[run.window(run.times[-1] - span)]
    t, mean = running_mean(run, values)
    return Levels(
        mean_before=float(before.mean()),
        mean_after=float(after.mean()),
        range_before=float(np.ptp(before)),
        range_after=float(np.ptp(after)),
        peak_mean=float(mean[t > STEP_TIME].max()),
    )


@dataclasses.dataclass
class Snap:
    """A slack spell on one segment and the load that ends it: slack from `slack_from`
    to `slack_to` (s), then the tension's peak `peak` (N) at `peak_time` within one
    second, and the run's final mean tension `settled` (N) on that segment."""

    segment: int
    slack_from: float
    slack_to: float
    peak: float
    peak_time: float
    settled: float


def series_snaps(
    times: np.ndarray,
    tension: np.ndarray,
    segments=None,
    after: float = -np.inf,
    within: float = SNAP_WINDOW,
    settle: float = 5.0,
) -> list[Snap]:
    """Every slack spell after `after` (s) on `segments` (columns of `tension`, shape
    `(times, segments)`; all by default), with its snap: the largest tension within
    `within` seconds after the spell ends. A segment is slack at or below
    `SLACK_TENSION`; a spell still going at the end is left out. `settled`
    is the segment's mean tension over the last `settle` seconds."""
    segments = range(tension.shape[1]) if segments is None else segments
    window = times >= after
    t = times[window]
    found = []
    for s in segments:
        series = tension[window, s]
        slack = series <= SLACK_TENSION
        starts = np.flatnonzero(slack[1:] & ~slack[:-1]) + 1
        if slack.size and slack[0]:
            starts = np.concatenate([[0], starts])
        settled = float(tension[times >= times[-1] - settle, s].mean())
        for k in starts:
            ends = np.flatnonzero(~slack[k:])
            if ends.size == 0:
                continue
            stop = k + ends[0]
            following = (t >= t[stop]) & (t <= t[stop] + within)
            j = np.flatnonzero(following)[np.argmax(series[following])]
            found.append(Snap(int(s), float(t[k]), float(t[stop]), float(series[j]), float(t[j]), settled))
    return found


def snaps(run: TrawlRun, segments=None, after: float = STEP_TIME) -> list[Snap]:
    """Every slack spell after `after` on `segments` (all by default), with its snap."""
    return series_snaps(run.times, run.tension, segments, after)


def jerk(run: TrawlRun, point: str = "tow point", span: float = 2.0) -> tuple[float, float]:
    """`(peak, level)` (N): the jerk at `point` and the level the tension goes on from.

    A rise overshoots at once: the peak is the largest tension within `span` seconds of
    the step. A fall first unloads the cable, then snaps it taut: the peak is the
    largest after the lowest tension in the first second. The level is the mean over
    the wave period after `span`; the ratio of the two is the jerk's size.
    """
    tension = run.at(point)
    since = STEP_TIME
    if run.speeds[1] < run.speeds[0]:
        first = run.window(STEP_TIME, STEP_TIME + 1.0)
        since = run.times[first][np.argmin(tension[first])]
    peak = tension[run.window(since, STEP_TIME + span)].max()
    level = tension[run.window(STEP_TIME + span, STEP_TIME + span + WAVE_PERIOD)].mean()
    return float(peak), float(level)


def settling_time(run: TrawlRun, point: str = "tow point", share: float = 0.9) -> float:
    """The time (s) after the step from which the one-period mean tension at `point`
    stays past `share` of its way from the level before the step to the final one."""
    t, mean = running_mean(run, run.at(point))
    lv = levels(run, run.at(point))
    reached = (mean - lv.mean_before) / (lv.mean_after - lv.mean_before) >= share
    later = t > STEP_TIME
    failing = np.flatnonzero(later & ~reached)
    return float(t[failing[-1] + 1] - STEP_TIME) if failing.size else 0.0


def ringing(run: TrawlRun, point: str, t0: float, t1: float, smooth: float = 0.1) -> float:
    """The rms (N) of the tension at `point` about its `smooth`-second running mean over
    [t0, t1]: the fast vibration that a viscoelastic cable damps."""
    m = run.window(t0, t1)
    t, v = run.times[m], run.at(point)[m]
    dt = float(np.median(np.diff(t)))
    n = max(int(round(smooth / dt)), 1)
    slow = np.convolve(v, np.ones(n) / n, mode="same")
    core = slice(n, -n)
    return float(np.sqrt(np.mean((v - slow)[core] ** 2)))


def sweep_width(run: TrawlRun, span: float = 15.0) -> tuple[float, float]:
    """`(before, after)`: the mean distance (m) between the two diverters across the
    tow, over the last `span` seconds before the step and of the run."""
    width = run.junctions[:, JUNCTIONS["diverter"], 1] - run.junctions[:, JUNCTIONS["diverter_minus"], 1]
    return (
        float(width[run.window(STEP_TIME - span, STEP_TIME - 1e-9)].mean()),
        float(width[run.window(run.times[-1] - span)].mean()),
    )


# --- plots -----------------------------------------------------------------------------


def plot_tensions(run: TrawlRun, points=POINTS, window=None, axes=None):
    """Tension histories (kN) at `points`, one panel each."""
    import matplotlib.pyplot as plt

    if axes is None:
        _, axes = plt.subplots(len(points), 1, figsize=(8, 2.2 * len(points)), sharex=True)
    m = run.window(*(window or (run.times[0], run.times[-1])))
    for ax, point in zip(np.atleast_1d(axes), points):
        ax.plot(run.times[m], run.at(point)[m] / 1e3, lw=0.7, label=_case_label(run))
        ax.set_ylabel(f"{point}\nT (kN)")
    # A legend naming every case drawn on these axes so far, so that the figure says
    # which run it shows.
    np.atleast_1d(axes)[0].legend(fontsize="small", loc="upper left")
    np.atleast_1d(axes)[-1].set_xlabel("t (s)")
    return axes


def _case_label(run: TrawlRun) -> str:
    """A legend entry naming the case: speeds, waves, cable."""
    before, after = run.speeds
    return (
        f"{before:g} → {after:g} m/s at t = {STEP_TIME:g} s, {'5.6 s waves' if run.waves else 'calm'}, "
        f"{'viscoelastic' if run.viscous else 'elastic'} cable"
    )


def plot_buoy_depth(runs, ax=None):
    """The buoy's z (m) against time for each run in `runs`."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(8, 3))
    for run in runs:
        ax.plot(run.times, run.junctions[:, JUNCTIONS["buoy"], 2], lw=0.7, label=run.name)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("buoy z (m)")
    ax.legend()
    return ax


def plot_diverter_paths(run: TrawlRun, ax=None):
    """Both diverters' paths in the horizontal plane, x taken from the tow point (the
    paper's Fig. 10)."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(5, 5))
    x_tow = run.junctions[:, JUNCTIONS["tow"], 0]
    for key, name in (("diverter", "diverter +y"), ("diverter_minus", "diverter −y")):
        p = run.junctions[:, JUNCTIONS[key]]
        ax.plot(p[:, 0] - x_tow, p[:, 1], lw=0.8, label=name)
        ax.plot(
            p[0, 0] - x_tow[0],
            p[0, 1],
            "ko",
            ms=3,
            label=f"start, t = {run.times[0]:g} s" if key == "diverter" else None,
        )
    ax.set_title(_case_label(run), fontsize="small")
    ax.set_xlabel("x − x_tow (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    ax.legend(fontsize="small")
    return ax


# --- verdict ---------------------------------------------------------------------------


def wave_height() -> float:
    """The trawl's wave height H (m), crest to trough."""
    return 2 * float(floater_amplitude(WAVE_PERIOD))


def depth(run: TrawlRun, junction: str = "buoy") -> Levels:
    """The levels of a junction's z (m) before and after the step."""
    return levels(run, run.junctions[:, JUNCTIONS[junction], 2])


def _spells(found: list[Snap]) -> str:
    return f"{len(found)} slack spell{'' if len(found) == 1 else 's'}"


def _first_snap(run: TrawlRun) -> Snap | None:
    found = snaps(run)
    return min(found, key=lambda s: s.slack_from) if found else None


def verdict_rows(runs: dict[str, TrawlRun]) -> list[tuple[str, str, str, str]]:
    """The trawl's rows of the closing table, `(paper's claim, jaxcable's result,
    agreement, why)`, every number measured on `runs` (all of `CASES`)."""
    rise, elastic = runs["rise 1→3"], runs["rise 1→3, elastic"]
    fall, fall_elastic = runs["fall 3→1"], runs["fall 3→1, elastic"]
    waves, slow, slow_waves = runs["rise 1→4, waves"], runs["rise 1→2"], runs["rise 1→2, waves"]
    rows = []

    jump, predicted = front_jump(rise)
    jump_e, predicted_e = front_jump(elastic)
    tow = levels(rise, rise.at("tow point"))
    share = jump / (tow.mean_after - tow.mean_before)
    settle = settling_time(rise)
    rows.append(
        (
            "After a speed step the tension rises in stages, then settles smoothly (Fig. 7, 1 → 3 m/s)",
            f"at the tow point a first stage of {jump / 1e3:.1f} kN within 0.13 s ({100 * share:.0f} % of the rise "
            f"{tow.mean_before / 1e3:.1f} → {tow.mean_after / 1e3:.1f} kN): the axial wave, whose height Z Δv cos θ = "
            f"{predicted_e / 1e3:.2f} kN the elastic cable matches ({jump_e / 1e3:.2f} kN); a damped swing, then a "
            "smooth "
            f"climb, 90 % of the way {settle:.0f} s after the step",
            "yes" if share > 0.3 and settle > 10 else "partly",
            "the stage is the elastic front of the step; the smooth part is the trawl speeding up against its drag",
        )
    )

    buoy = levels(waves, waves.at("buoy"))
    above = buoy.mean_after / buoy.mean_before
    rows.append(
        (
            "At the buoy attachment (1 → 4 m/s in waves) the mean first rises strongly, then settles slightly "
            "above its old level, with a much larger amplitude",
            f"one-period mean {buoy.mean_before / 1e3:.1f} → peak {buoy.peak_mean / 1e3:.1f} → "
            f"{buoy.mean_after / 1e3:.1f} kN "
            f"({above:.2f}× the old level); range {buoy.range_before / 1e3:.1f} → {buoy.range_after / 1e3:.1f} kN",
            "yes"
            if buoy.peak_mean > 1.2 * buoy.mean_before
            and 1 <= above < 1.3
            and buoy.range_after > 1.5 * buoy.range_before
            else "partly",
            f"measured: the branch point rises from z = {depth(waves, 'branch').mean_before:.0f} to "
            f"{depth(waves, 'branch').mean_after:.0f} m and the buoy's mean z goes "
            f"{depth(waves, 'buoy').mean_before:+.2f} → "
            f"{depth(waves, 'buoy').mean_after:+.2f} m; the paper's buoy and vehicle are not given, so the levels "
            "cannot be matched",
        )
    )

    t_tow, t_div = levels(waves, waves.at("tow point")), levels(waves, waves.at("diverter"))
    grows = [lv.mean_after > lv.mean_before and lv.range_after > lv.range_before for lv in (t_tow, t_div)]
    rows.append(
        (
            "At the tow point and at the diverter attachment both the mean tension and its range grow with speed",
            f"tow point: mean {t_tow.mean_before / 1e3:.1f} → {t_tow.mean_after / 1e3:.1f} kN, range "
            f"{t_tow.range_before / 1e3:.2f} → {t_tow.range_after / 1e3:.2f} kN; diverter: mean "
            f"{t_div.mean_before / 1e3:.1f} → "
            f"{t_div.mean_after / 1e3:.1f} kN, range {t_div.range_before / 1e3:.2f} → {t_div.range_after / 1e3:.2f} kN",
            "yes" if all(grows) else ("partly" if any(grows) else "no"),
            "the diverter's range does not grow, though the diverter rises from z = "
            f"{depth(waves, 'diverter').mean_before:.0f} to {depth(waves, 'diverter').mean_after:.0f} m, nearer the "
            "waves: "
            "measured, not explained here"
            if not grows[1]
            else "",
        )
    )

    width = {name: sweep_width(runs[name]) for name in ("rise 1→2", "rise 1→3", "rise 1→4, waves")}
    rows.append(
        (
            "The diverters' sweep narrows (Fig. 10, 1 → 4 m/s)",
            "distance between the diverters " + ", ".join(f"{b:.0f} → {a:.0f} m ({n})" for n, (b, a) in width.items()),
            "yes" if all(a < b for b, a in width.values()) else "no",
            "F₀ is fixed while the drag on the sweep branches grows as the speed squared",
        )
    )

    def jerk_text(run):
        peak, level = jerk(run)
        return f"{peak / 1e3:.1f} kN, {peak / level:.2f}× the level after"

    first_fall = _first_snap(fall)
    rows.append(
        (
            "Snap loads come both when the speed rises and when it falls",
            f"rise 1 → 3: the tow point jerks to {jerk_text(rise)}; 1 → 4 in waves {jerk_text(waves)}; "
            f"no segment goes slack (elastic cable: {_spells(snaps(elastic))} near the branch point). "
            f"Fall 3 → 1: the tow cable goes slack ({_spells(snaps(fall))}, from t = {first_fall.slack_from:.2f} s) "
            f"and snaps taut to {jerk_text(fall)}"
            if first_fall
            else "fall 3 → 1: no slack",
            "yes" if first_fall and jerk(rise)[0] > 1.2 * jerk(rise)[1] else "partly",
            "a rise loads the cable at once by its impedance times the step; a fall unloads it to slack, "
            "and the trawl's momentum snaps it taut",
        )
    )

    peaks = {n: jerk(runs[n])[0] for n in ("rise 1→3", "rise 1→3, elastic", "fall 3→1", "fall 3→1, elastic")}
    ring = [
        (ringing(e, "tow point", STEP_TIME + 1, STEP_TIME + 5), ringing(v, "tow point", STEP_TIME + 1, STEP_TIME + 5))
        for e, v in ((elastic, rise), (fall_elastic, fall))
    ]
    cut = [1 - peaks["rise 1→3"] / peaks["rise 1→3, elastic"], 1 - peaks["fall 3→1"] / peaks["fall 3→1, elastic"]]
    rows.append(
        (
            "Viscoelasticity (C_v = 0.02 C_E) barely changes the first snap but smooths the later ones",
            f"first peak at the tow point, elastic → viscoelastic: rise {peaks['rise 1→3, elastic'] / 1e3:.1f} → "
            f"{peaks['rise 1→3'] / 1e3:.1f} kN, fall {peaks['fall 3→1, elastic'] / 1e3:.1f} → "
            f"{peaks['fall 3→1'] / 1e3:.1f} kN "
            f"({100 * cut[0]:.0f} and {100 * cut[1]:.0f} % lower); the ringing 1–5 s after, rms "
            f"{ring[0][0] / 1e3:.2f} → {ring[0][1] / 1e3:.3f} kN (rise) and {ring[1][0] / 1e3:.2f} → "
            f"{ring[1][1] / 1e3:.3f} kN (fall)",
            "yes" if max(cut) < 0.1 and all(v < 0.2 * e for e, v in ring) else "partly",
            "the later vibrations are smoothed as the paper says; the first peak is cut by a quarter, not barely: "
            "the 0.02 s retardation time is as long as the step itself, so it damps the front's edge too",
        )
    )

    d2, d4 = depth(slow_waves), depth(waves)
    # Draw-down is how far the buoy is pulled under: its mean z falling.
    holds = [
        d2.range_after < d2.range_before,
        d2.mean_after > d2.mean_before,
        d4.range_after < d4.range_before,
        d4.mean_after < d4.mean_before,
    ]
    rows.append(
        (
            "The buoy's heave (Fig. 9, in waves): at 1 → 2 m/s its amplitude and its draw-down both decrease; "
            "at 1 → 4 m/s the amplitude decreases but the draw-down increases",
            f"heave range / mean z: 1 → 2 {d2.range_before:.2f} → {d2.range_after:.2f} m / {d2.mean_before:+.3f} → "
            f"{d2.mean_after:+.3f} m; 1 → 4 {d4.range_before:.2f} → {d4.range_after:.2f} m / {d4.mean_before:+.3f} → "
            f"{d4.mean_after:+.3f} m (wave height {wave_height():.2f} m); "
            f"calm 1 → 2: mean z {depth(slow).mean_before:+.3f} → {depth(slow).mean_after:+.3f} m",
            "yes" if all(holds) else ("partly" if any(holds) else "no"),
            f"{sum(holds)} of the 4 trends hold; wet up to the wave's surface, the buoy heaves "
            f"{d4.range_before / wave_height():.2f}× the wave height before the step",
        )
    )
    return rows


def verdict_markdown(runs: dict[str, TrawlRun], extra_rows=()) -> str:
    """The closing table as markdown: the trawl's rows, then `extra_rows`."""
    lines = ["| paper's claim | jaxcable's result | agreement | why |", "|---|---|---|---|"]
    for row in [*verdict_rows(runs), *extra_rows]:
        lines.append("| " + " | ".join(cell.replace("|", "/") for cell in row) + " |")
    return "\n".join(lines)
