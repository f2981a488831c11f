"""The branched-systems paper's snap loads, closer: what a snap's peak is, whether it converges, and the
paper's two claims the first reproduction left untried (`studies.moored_net` and
`studies.towed_trawl` hold the rest).

**What the peak of a snap is.** When a slack segment of a Kelvin–Voigt line goes taut
while its ends still separate at a rate ε̇₀ L, its viscous term `C_v ε̇ H(ε)` switches
on across the slack band (w = 1e-5 of strain, a few tens of microseconds; the viscous
switch already has the elastic one's smoothed width): the tension jumps to about
C_v ε̇₀, then falls as the dashpot brings the segment's end nodes to one axial speed,
over about μ L / C_v (μ a node's mass: 0.2 ms on the full net's 5.6 m steel segments,
0.7 ms on the small net's 11 m ones). That spike is the lumped model's, not the cable's. By the law, its height
C_v ε̇₀ = C_v Δv / L grows as the segments shorten; and a continuous Kelvin–Voigt rod
struck by a speed step Δv has no finite peak at all: while t ≪ C_v / C_E its tension
at the struck end is Δv √(C_v m' / (π t)) (the diffusion limit of its wave equation,
m' the mass per length with added mass), singular at t = 0 though its impulse is
finite. What the cable's material carries, and what a load cell slower than the
dashpot reads, is

- the **elastic tension** `(C_E ε + C_E1 ε²) H(ε)`, continuous in time since the
  strain is, whose peak converges with the output interval and the tolerances; and
- the tension **averaged over the retardation time** C_v / C_E (20 ms here), to which
  the spike adds its impulse (about a node's mass times Δv) over that time, finite in
  the continuous rod too.

`resolve_snap` samples one snap at up to 1 MHz so that the resolved maximum of the
total tension is found too, and `convergence` takes the three measures as the output
interval and the tolerances are halved. Both converged measures are what the claims
below are graded on; the sampled maximum of the total tension is shown beside them,
so that the reader sees how far it is from both.

**Nonlinear elasticity (C_E1 > 0) lowers the snap loads.** The net's snap and the
trawl's jerk on a fall, with C_E1 = 0 and C_E1 = `QUADRATIC_RATIO` × C_E on every line.

**Viscoelasticity hardly matters in regular waves** (the paper's conclusions: "it has
practically no effect when towing in regular sea waves, i.e. when there are no
jerks"). The trawl in steady tow through the anchored-line paper's 5.6 s waves, with and without the
viscous term: the tension at the four points of `studies.towed_trawl.POINTS`.
"""

import dataclasses
import time

import numpy as np

from jaxcable import SolverConfig, State, simulate, solve_statics
from jaxcable.examples._anchored_line import AXIAL_STIFFNESS
from jaxcable.examples._moored_net import VISCOUS_RATIO, fig5_segments, moored_net

from . import moored_net as s2n
from . import towed_trawl as s2

# The interval of the finest output (s): 1 µs, a small share of the spike's 0.2 ms fall.
FINEST = 1e-6
# Output intervals, as powers of two times `FINEST`: 4.096 ms (244 Hz) down to 1 µs.
STRIDES = tuple(2**k for k in range(12, -1, -1))
# A measure has converged where halving the output interval, and halving the
# tolerances, each change it by less than this share.
CONVERGED = 0.01
# C_E1 / C_E of the nonlinear-elastic runs: the anchored-line paper's largest.
QUADRATIC_RATIO = 0.2
# Sizes. `net`: the net study's size for the run up to the snap; `search`: the span (s)
# whose largest tension near buoy 2's anchor is the snap resolved (its fourth wave
# period), where no net run is given to find it in; `rtols`: the tolerances (rtol =
# atol), each half the one before; `half_window`: the span (s) either side of the snap
# sampled every `FINEST`. `trawl`: the trawl study's size for the fall and the tow in
# waves; `tow_speeds`: the steady towing speeds (m/s) in waves; `tow_end`: the end of
# those runs (s), the last `tow_periods` wave periods measured, after the waves' two
# periods of ramp from `trawl["start"]`. SMALL resolves the snap at one tolerance only.
# FULL resolves it in the small net too: at the net's full segments each run up to the
# snap takes some 200,000 steps, and the evidence is in the sampling and the tolerances.
SMALL = dict(
    net=s2n.SMALL,
    search=(3 * s2n.WAVE_PERIOD, 4 * s2n.WAVE_PERIOD),
    rtols=(1e-6,),
    half_window=0.03,
    trawl=s2.SMALL,
    tow_speeds=(2.0,),
    tow_end=290.0,
    tow_periods=1,
)
FULL = dict(
    net=s2n.SMALL,
    search=(3 * s2n.WAVE_PERIOD, 4 * s2n.WAVE_PERIOD),
    rtols=(1e-6, 5e-7, 2.5e-7),
    half_window=0.03,
    trawl=s2.FULL,
    tow_speeds=(1.0, 2.0, 3.0),
    tow_end=298.0,
    tow_periods=3,
)


@dataclasses.dataclass
class SnapWindow:
    """One snap near buoy 2's anchor, sampled every `FINEST` seconds over `times` (s):
    the segment's total tension `total` and elastic tension `elastic` (N) and its strain
    `strain` (–); `damping` its C_v (N·s) and `slack_width` its law's w (–); `rtol` the
    tolerances it was solved to, `steps` the solver's steps from t = 0."""

    rtol: float
    quadratic_ratio: float
    times: np.ndarray
    total: np.ndarray
    elastic: np.ndarray
    strain: np.ndarray
    damping: float
    slack_width: float
    steps: int
    wall_time: float  # s, compile included


@dataclasses.dataclass
class Peaks:
    """A snap's three measures (N) at one output interval `interval` (s): the largest
    sample of the total tension `sampled`, of the elastic tension `elastic`, and of the
    total tension's `s2n.SMOOTH`-second running mean `smoothed`."""

    interval: float
    sampled: float
    elastic: float
    smoothed: float


def find_snap(run: s2n.NetRun, start: float, end: float) -> float | None:
    """The time (s) of the largest sample of the tension near buoy 2's anchor over
    `[start, end]` (s) of `run`, if the run is sampled there at its dense rate
    (`run.config["dense"]`); `None` if not."""
    m = run.window(start, end)
    if m.sum() < 2 or np.max(np.diff(run.times[m])) > 1.01 / run.config["dense"]:
        return None
    return float(run.times[m][np.argmax(run.at("near anchor")[m])])


def locate_snap(config: dict, start: float, end: float) -> float:
    """The time (s) of the largest tension near buoy 2's anchor over `[start, end]` (s),
    sampled at `config["dense"]`, in a run of the net at size `config` from t = 0."""
    model, env = moored_net(segments=config["segments"], viscous=config["viscous"])
    statics = solve_statics(model, env.without_waves())
    ts = np.linspace(start, end, int(round((end - start) * config["dense"])) + 1)
    result = simulate(
        model,
        env,
        end,
        ts=ts,
        initial=statics.state,
        solver=SolverConfig(max_steps=config.get("max_steps", 1_000_000)),
    )
    return float(ts[np.argmax(np.asarray(result.tension)[:, fig5_segments(model, 2)["near anchor"]])])


def resolve_snap(
    config: dict, at: float, rtol: float = 1e-6, half_window: float = 0.03, quadratic_ratio: float = 0.0
) -> SnapWindow:
    """The net at size `config` (`studies.moored_net.SMALL` or `FULL`) from its still
    water equilibrium to `at + half_window` (s), solved to `rtol` = atol and sampled
    every `FINEST` seconds within `half_window` of `at`: the snap near buoy 2's anchor.
    `quadratic_ratio`: C_E1 / C_E on every line."""
    model, env = moored_net(segments=config["segments"], viscous=config["viscous"], quadratic_ratio=quadratic_ratio)
    statics = solve_statics(model, env.without_waves())
    start, end = at - half_window, at + half_window
    dense = np.linspace(start, end, int(round((end - start) / FINEST)) + 1)
    ts = np.concatenate([np.arange(0.0, start - 0.025, 0.05), dense])
    clock = time.perf_counter()
    result = simulate(
        model,
        env,
        end,
        ts=ts,
        initial=statics.state,
        solver=SolverConfig(rtol=rtol, atol=rtol, max_steps=config.get("max_steps", 1_000_000)),
    )
    wall = time.perf_counter() - clock
    segment = fig5_segments(model, 2)["near anchor"]
    window = slice(ts.size - dense.size, None)
    strain = np.asarray(result.strain)[window]
    law = model.line.tension_law
    return SnapWindow(
        rtol=rtol,
        quadratic_ratio=quadratic_ratio,
        times=dense,
        total=np.asarray(result.tension)[window, segment],
        elastic=np.asarray(law.elastic_tension(strain))[:, segment],
        strain=strain[:, segment],
        damping=float(np.asarray(law.damping())[segment]),
        slack_width=float(np.asarray(law.slack_width)[segment]),
        steps=int(result.stats["num_steps"]),
        wall_time=wall,
    )


def peaks(window: SnapWindow, stride: int = 1) -> Peaks:
    """The snap's [`Peaks`][] from every `stride`-th sample of `window`."""
    total, elastic = window.total[::stride], window.elastic[::stride]
    interval = stride * FINEST
    n = max(int(round(s2n.SMOOTH / interval)), 1)
    smoothed = _running_mean(total, n).max()
    return Peaks(interval, float(total.max()), float(elastic.max()), float(smoothed))


def _running_mean(values: np.ndarray, n: int) -> np.ndarray:
    """The means of every `n` consecutive `values`, by a running sum: `np.convolve`
    takes seconds over 20,000-sample windows at 1 µs."""
    running = np.concatenate([[0.0], np.cumsum(values)])
    return (running[n:] - running[:-n]) / n


def convergence(windows: list[SnapWindow], strides=STRIDES) -> list[list[Peaks]]:
    """The [`Peaks`][] of each window (tolerances halving) at each output interval of
    `strides` (halving): one row per window, one entry per stride."""
    return [[peaks(w, s) for s in strides] for w in windows]


def converged(table: list[list[Peaks]], measure: str, share: float = CONVERGED) -> float | None:
    """The value of `measure` ("sampled", "elastic" or "smoothed") at the finest
    interval and tightest tolerance of `table` (from [`convergence`][]), if halving the
    interval and halving the tolerances there each change it by less than `share`;
    `None` if not. A table of one tolerance is judged on the interval alone."""
    finest = [getattr(row[-1], measure) for row in table]
    value = finest[-1]
    by_interval = abs(getattr(table[-1][-2], measure) - value)
    # A table of one tolerance is judged on the interval alone.
    by_tolerance = abs(finest[-2] - value) if len(finest) > 1 else 0.0
    return value if max(by_interval, by_tolerance) < share * abs(value) else None


def converged_interval(table: list[list[Peaks]], measure: str, share: float = CONVERGED) -> float | None:
    """The longest output interval (s) from which every shorter one, at the tightest
    tolerance, gives `measure` within `share` of its finest value; `None` if not even
    the finest two agree."""
    row = table[-1]
    final = getattr(row[-1], measure)
    good = [abs(getattr(p, measure) - final) < share * abs(final) for p in row]
    if not good[-2]:
        return None
    k = len(good) - 1
    while k > 0 and good[k - 1]:
        k -= 1
    return row[k].interval


def spike_model(window: SnapWindow) -> float:
    """The tension (N) the law gives as the segment's strain leaves the slack band
    (its first sample at or past w), `(C_E ε + C_E1 ε²) + C_v ε̇`, with ε̇ taken by
    central differences of the strain samples: the viscous jump the spike starts
    from, on the segment's own strain, not its reported tension."""
    taut = np.flatnonzero(window.strain >= window.slack_width)
    if taut.size == 0 or taut[0] == 0 or taut[0] + 1 >= window.strain.size:
        raise ValueError("the window holds no snap: the strain never leaves the slack band inside it")
    j = taut[0]
    rate = (window.strain[j + 1] - window.strain[j - 1]) / (window.times[j + 1] - window.times[j - 1])
    return float(window.elastic[j] + window.damping * rate)


# --- the claims ------------------------------------------------------------------------


def nonlinear_fall(config: dict, quadratic_ratio: float, guess: State | None = None) -> s2.TrawlRun:
    """The trawl's 3 → 1 m/s fall (viscoelastic, calm) at size `config`, with C_E1 =
    `quadratic_ratio` × C_E; `guess` a steady tow at 3 m/s to start statics from."""
    return s2.run_trawl(
        f"fall 3→1, C_E1 = {quadratic_ratio:g} C_E",
        config,
        guess=guess,
        case=((3.0, 1.0), True, False, "short"),
        quadratic_ratio=quadratic_ratio,
    )


def elastic_jerk(run: s2.TrawlRun, point: str = "tow point") -> float:
    """The largest elastic tension (N) at `point` over the jerk's span of
    [`studies.towed_trawl.jerk`][]: from the lowest tension in the first second after the
    step to 2 s after it."""
    tension = run.at(point)
    first = run.window(s2.STEP_TIME, s2.STEP_TIME + 1.0)
    since = run.times[first][np.argmin(tension[first])]
    return float(run.elastic_at(point)[run.window(since, s2.STEP_TIME + 2.0)].max())


def tow_in_waves(config: dict, speed: float, viscous: bool, end: float, guess: State | None = None) -> s2.TrawlRun:
    """The trawl towed steadily at `speed` (m/s) through the 5.6 s waves, which ramp in
    over two periods from `config["start"]`, to `end` (s); with or without the viscous
    term; `guess` a steady tow at `speed` to start statics from."""
    case = ((speed, speed), viscous, True, "short")
    name = f"{speed:g} m/s in waves, {'viscoelastic' if viscous else 'elastic'}"
    return s2.run_trawl(name, dict(config, end=dict(short=end), dense=0.0), guess=guess, case=case)


@dataclasses.dataclass
class WaveTension:
    """The tension (N) at one point over the measured periods: `mean`, `range`
    (max − min), `max`, `min`."""

    mean: float
    range: float
    max: float
    min: float


def wave_tensions(run: s2.TrawlRun, periods: int) -> dict[str, WaveTension]:
    """Each of `studies.towed_trawl.POINTS`'s [`WaveTension`][] over the run's last `periods`
    wave periods."""
    m = run.window(run.times[-1] - periods * s2.WAVE_PERIOD + 1e-9)
    out = {}
    for point in s2.POINTS:
        x = run.at(point)[m]
        out[point] = WaveTension(float(x.mean()), float(np.ptp(x)), float(x.max()), float(x.min()))
    return out


def wave_difference(elastic: dict[str, WaveTension], viscous: dict[str, WaveTension]) -> dict[str, float]:
    """By measure (mean, range, max), the largest change over the points, viscoelastic
    against elastic, as a share of the elastic value."""
    return {
        key: max(
            abs(getattr(viscous[p], key) - getattr(elastic[p], key)) / abs(getattr(elastic[p], key)) for p in elastic
        )
        for key in ("mean", "range", "max")
    }


# --- the study -------------------------------------------------------------------------


@dataclasses.dataclass
class SnapStudy:
    """Everything the verdicts need: the net's snap at `at` (s), resolved at each
    tolerance (`windows`) and with C_E1 = `QUADRATIC_RATIO` C_E (`nonlinear`); the
    trawl's fall by C_E1 / C_E (`falls`); its steady tows in waves by `(speed,
    viscous)` (`tows`); and the size `config`."""

    config: dict
    at: float
    windows: list[SnapWindow]
    nonlinear: SnapWindow
    falls: dict[float, s2.TrawlRun]
    tows: dict[tuple[float, bool], s2.TrawlRun]

    @property
    def table(self) -> list[list[Peaks]]:
        return convergence(self.windows)


def run_study(config: dict = SMALL, net: s2n.NetRun | None = None) -> SnapStudy:
    """The study at size `config`. The snap resolved is the largest near buoy 2's
    anchor over `config["search"]`: found in `net`, a run of the net at
    `config["net"]`'s size, where that run is sampled densely there
    ([`find_snap`][]); otherwise located by one more run ([`locate_snap`][])."""
    at = find_snap(net, *config["search"]) if net is not None else None
    at = locate_snap(config["net"], *config["search"]) if at is None else at
    half = config["half_window"]
    windows = [resolve_snap(config["net"], at, rtol, half) for rtol in config["rtols"]]
    nonlinear = resolve_snap(config["net"], at, config["rtols"][0], half, QUADRATIC_RATIO)
    # Runs at one first speed share their steady tow: statics at 20 segments is dear.
    falls = {0.0: nonlinear_fall(config["trawl"], 0.0)}
    falls[QUADRATIC_RATIO] = nonlinear_fall(config["trawl"], QUADRATIC_RATIO, falls[0.0].steady)
    tows = {}
    for v in config["tow_speeds"]:
        tows[(v, False)] = tow_in_waves(config["trawl"], v, False, config["tow_end"])
        tows[(v, True)] = tow_in_waves(config["trawl"], v, True, config["tow_end"], tows[(v, False)].steady)
    return SnapStudy(dict(config), at, windows, nonlinear, falls, tows)


# --- tables and plots ------------------------------------------------------------------

_MEASURES = dict(
    sampled="largest sample of the total tension",
    elastic="largest elastic tension (C_E ε + C_E1 ε²)",
    smoothed=f"largest {1e3 * s2n.SMOOTH:.0f} ms mean of the total tension",
)


def convergence_markdown(study: SnapStudy) -> str:
    """The convergence table: each measure (kN) at each output interval, one column per
    tolerance."""
    table = study.table
    rtols = [w.rtol for w in study.windows]
    head = "| output interval | " + " | ".join(
        f"{name} (kN), rtol {r:g}" for name in ("sampled", "elastic", f"{1e3 * s2n.SMOOTH:.0f} ms mean") for r in rtols
    )
    lines = [head + " |", "|---" * (1 + 3 * len(rtols)) + "|"]
    for k in range(len(table[0])):
        cells = [f"{table[0][k].interval * 1e3:g} ms"]
        for measure in _MEASURES:
            cells += [f"{getattr(row[k], measure) / 1e3:.2f}" for row in table]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def plot_convergence(study: SnapStudy, axes=None):
    """Left: the three measures (kN) against the output interval, one line per measure
    and tolerance, with the net study's 2 kHz marked. Right: the resolved snap, total
    and elastic tension against time."""
    import matplotlib.pyplot as plt

    if axes is None:
        _, axes = plt.subplots(1, 2, figsize=(13, 4.2))
    left, right = axes
    styles = ("-", "--", ":")
    for k, (w, row) in enumerate(zip(study.windows, study.table)):
        intervals = [p.interval * 1e3 for p in row]
        for colour, (measure, name) in zip(("C0", "C1", "k"), _MEASURES.items()):
            left.semilogx(
                intervals,
                [getattr(p, measure) / 1e3 for p in row],
                styles[k % len(styles)],
                marker="o",
                ms=3,
                color=colour,
                label=f"{name}, rtol = atol = {w.rtol:g}",
            )
    left.axvline(1e3 / study.config["net"]["dense"], color="0.6", ls=":", label="the net study's 2 kHz samples")
    left.set_yscale("log")
    left.set_xlabel("output interval (ms)")
    left.set_ylabel("snap near buoy 2's anchor (kN)")
    left.set_title(f"the moored net ({_size(study)}), the snap at t ≈ {study.at:.2f} s", fontsize="small")
    left.legend(fontsize="x-small")
    w = study.windows[-1]
    t = (w.times - study.at) * 1e3
    right.plot(t, w.total / 1e3, lw=0.8, color="C0", label="total tension (elastic + C_v ε̇), 1 µs samples")
    right.plot(t, w.elastic / 1e3, lw=0.8, color="C1", label="elastic tension C_E ε + C_E1 ε²")
    n = int(round(s2n.SMOOTH / FINEST))
    mean = _running_mean(w.total, n)
    right.plot(
        t[n // 2 : n // 2 + mean.size],
        mean / 1e3,
        lw=0.9,
        color="k",
        label=f"{1e3 * s2n.SMOOTH:.0f} ms mean of the total, at its window's centre",
    )
    right.set_title(f"the resolved snap, rtol = atol = {w.rtol:g}", fontsize="small")
    right.set_xlabel(f"t − {study.at:.3f} s (ms)")
    right.set_ylabel("near buoy 2's anchor, T (kN)")
    right.set_yscale("symlog", linthresh=10.0)
    right.legend(fontsize="x-small")
    return axes


def _size(study: SnapStudy) -> str:
    upper, lower, row, diagonal = study.config["net"]["segments"]
    return f"segments {upper}, {lower}, {row}, {diagonal}"


# --- verdict ---------------------------------------------------------------------------


def _change(new: float, old: float) -> float:
    return new / old - 1


def verdict_rows(study: SnapStudy) -> list[tuple[str, str, str, str]]:
    """The two claims' rows of the closing table, `(paper's claim, jaxcable's result,
    agreement, why)`, every number measured on `study`."""
    rows = []
    linear, nonlinear = peaks(study.windows[0]), peaks(study.nonlinear)
    fall, fall_q = study.falls[0.0], study.falls[QUADRATIC_RATIO]
    jerk, jerk_q = s2.jerk(fall)[0], s2.jerk(fall_q)[0]
    elastic_jerk_0, elastic_jerk_q = elastic_jerk(fall), elastic_jerk(fall_q)
    changes = [
        _change(nonlinear.elastic, linear.elastic),
        _change(nonlinear.smoothed, linear.smoothed),
        _change(elastic_jerk_q, elastic_jerk_0),
        _change(jerk_q, jerk),
    ]
    strain = float(study.windows[0].strain.max())
    strain_fall = float(fall.elastic_at("tow point").max()) / AXIAL_STIFFNESS
    lowest = min(changes)
    rows.append(
        (
            f"Nonlinear elasticity (C_E1 > 0) lowers the snap loads (C_E1 = {QUADRATIC_RATIO:g} C_E here)",
            f"the net's snap near buoy 2's anchor: elastic peak {linear.elastic / 1e3:.3f} → "
            f"{nonlinear.elastic / 1e3:.3f} kN ({100 * changes[0]:+.3f} %), {1e3 * s2n.SMOOTH:.0f} ms mean "
            f"{linear.smoothed / 1e3:.3f} → {nonlinear.smoothed / 1e3:.3f} kN ({100 * changes[1]:+.3f} %); "
            "the trawl's 3 → 1 m/s fall, jerk at the tow point: elastic "
            f"{elastic_jerk_0 / 1e3:.3f} → {elastic_jerk_q / 1e3:.3f} kN "
            f"({100 * changes[2]:+.3f} %), total {jerk / 1e3:.3f} → {jerk_q / 1e3:.3f} kN ({100 * changes[3]:+.3f} %)",
            "yes" if lowest < -0.05 else ("partly" if lowest < -0.01 else "no"),
            f"the strains at these snaps stay under {max(strain, strain_fall):.1e} on the steel cable (C_E = "
            f"{AXIAL_STIFFNESS:.0e} N), where C_E1 ε² is at most C_E1 ε / C_E = "
            f"{100 * QUADRATIC_RATIO * max(strain, strain_fall):.2f} % of C_E ε: a hardening term that small moves the "
            "peaks by about as much, and up; criterion: lower by more than 5 % (yes), 1 % (partly)",
        )
    )

    speeds = study.config["tow_speeds"]
    periods = study.config["tow_periods"]
    differences = {
        v: wave_difference(
            wave_tensions(study.tows[(v, False)], periods), wave_tensions(study.tows[(v, True)], periods)
        )
        for v in speeds
    }
    spells = {
        (v, viscous): len(s2.series_snaps(run.times, run.tension, after=run.times[-1] - periods * s2.WAVE_PERIOD))
        for (v, viscous), run in study.tows.items()
    }
    worst = max(max(d.values()) for d in differences.values())
    rows.append(
        (
            "Viscoelasticity has practically no effect when towing in regular waves, where there are no jerks",
            f"steady tow through the 5.6 s waves, {periods} period{'s' if periods > 1 else ''} measured, viscoelastic "
            "against elastic, the largest change over the tow point, branch point, diverter and buoy: "
            + "; ".join(
                f"{v:g} m/s: mean {100 * d['mean']:.2f} %, range {100 * d['range']:.2f} %, max {100 * d['max']:.2f} %"
                for v, d in differences.items()
            )
            + "; slack spells (elastic, viscoelastic): "
            + ", ".join(f"{spells[(v, False)]}, {spells[(v, True)]}" for v in speeds),
            "yes" if worst < 0.05 else ("partly" if worst < 0.15 else "no"),
            "the waves load the trawl at 0.18 Hz, where the dashpot's share of the tension, ω C_v / C_E = "
            f"{2 * np.pi / s2.WAVE_PERIOD * VISCOUS_RATIO:.3f}, is small, and no segment goes slack to make a jerk "
            "for it to act on; criterion: every change under 5 % (yes), 15 % (partly)",
        )
    )
    return rows


def record(study: SnapStudy) -> dict:
    """The study's numbers, for the benchmark's JSON."""
    return {
        "snap_time_s": study.at,
        "convergence": [
            {"rtol": w.rtol, "steps": w.steps, "wall_s": w.wall_time, "peaks_N": [vars(p) for p in row]}
            for w, row in zip(study.windows, study.table)
        ],
        "spike_model_N": spike_model(study.windows[-1]),
        "converged_N": {m: converged(study.table, m) for m in _MEASURES},
        "converged_from_interval_s": {m: converged_interval(study.table, m) for m in _MEASURES},
        "nonlinear_peaks_N": vars(peaks(study.nonlinear)),
        "falls": {
            str(q): {"jerk_N": s2.jerk(run)[0], "elastic_jerk_N": elastic_jerk(run), "steps": run.steps}
            for q, run in study.falls.items()
        },
        "tows": {
            f"{v:g} m/s, {'viscoelastic' if viscous else 'elastic'}": {
                "steps": run.steps,
                "wall_s": run.wall_time,
                "tension_N": {p: vars(x) for p, x in wave_tensions(run, study.config["tow_periods"]).items()},
            }
            for (v, viscous), run in study.tows.items()
        },
    }
