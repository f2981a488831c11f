"""The moored net as a study: the buoys' heave and drift, and the tension along
the vertical branch under buoy 2 (the paper's Figs. 4–5).

Used by `validation/branched_systems_reproduction.py` and the tests. One run of
[`jaxcable.simulate`][] from the still-water equilibrium, the 6.4 s waves ramping in
over the first two periods (`jaxcable.examples._moored_net.moored_net`, which states the scene and the
choices the paper leaves open). Everything is measured over the run's last whole wave
periods, `config["periods"]` of them, once the ramp is long past.

Sizes: `FULL` is the scene's default segments, to 120 s (Fig. 5's time axis starts at
120 s). `SMALL` is for the tests and a quick look, well under a minute: one segment in
each upper part and diagonal branch, two in each lower part and side of the row, seven
periods. Both keep the lines' viscous term, whose stiffness sets the explicit solver's
step (as the shortest steel segment squared: 0.17 ms on 5 m segments); SMALL's single
10.5 m upper parts are what make it fast, and they make Fig. 5's first two places one
segment. Dropping the viscous term instead would not do: the elastic net chatters
(hundreds of slack spells in four periods, snaps of 50 kN, measured) and amplifies
rounding until buoys 2 and 4 part from each other's mirror image by millimetres.

Where tension is read: Fig. 5's four places on buoy 2's vertical branch, by the segment
that touches them (`jaxcable.examples._moored_net.fig5_segments`). A segment counts as slack at or below
`studies.towed_trawl.SLACK_TENSION` (0 N): Kelvin–Voigt's viscous term takes a stretched
segment briefly below zero when it unloads fast, and that counts too.
"""

import dataclasses
import time

import numpy as np

from jaxcable import SolverConfig, airy_wavenumber, simulate, solve_statics
from jaxcable.examples import floater_amplitude
from jaxcable.examples._moored_net import (
    GRAVITY,
    HUB,
    N_BUOYS,
    PRETENSION,
    VISCOUS_RATIO,
    WATER_DEPTH,
    WAVE_PERIOD,
    anchor_node,
    branch_segments,
    buoy_node,
    corner_node,
    fig5_segments,
    moored_net,
)

from .towed_trawl import SLACK_TENSION, Snap, series_snaps

# Study sizes. `segments`: upper, lower, row side, diagonal (`moored_net`); `end`: the
# run's last time (s), from t = 0; `periods`: the whole wave periods at the end over which
# everything is measured; `rate` and `dense`: output samples a second before and within
# them. A snap's spike lasts a few milliseconds (it decays to a third in 5 ms, measured),
# so the measured periods are sampled at 2 kHz: at 200 Hz the largest sample of a spike
# was whichever sample happened to fall on it.
SMALL = dict(segments=(1, 2, 2, 1), viscous=True, end=7 * WAVE_PERIOD, periods=4, rate=20.0, dense=2000.0)
FULL = dict(segments=(2, 4, 4, 3), viscous=True, end=120.0, periods=5, rate=20.0, dense=2000.0, max_steps=4_000_000)
BUOYS = tuple(range(1, N_BUOYS + 1))
PLACES = ("under buoy", "above junction", "below junction", "near anchor")
# A slack spell ends in a snap where the tension then peaks (within
# `studies.towed_trawl.SNAP_WINDOW`) above this many times the segment's mean: a spike, not
# the tension merely coming back.
SNAP_RATIO = 1.5
# s, the span of the running mean whose largest value is a place's `max_smoothed`: the
# lines' retardation time C_v / C_E.
SMOOTH = VISCOUS_RATIO


@dataclasses.dataclass
class NetRun:
    """One run: the junctions' positions `junctions` (m), shape `(times, 13, 3)`, node
    order as in `jaxcable.examples._moored_net` (buoys, corners, anchors, hub), and the tension `tension`
    (N) of every segment, shape `(times, segments)`, at `times` (s); `still` and
    `still_tension` the same in the still-water equilibrium the run starts from.
    `places` maps each of `PLACES` to its segment; `branches` each buoy to its vertical
    branch's segments, from the buoy down to the anchor."""

    config: dict
    pretension: float
    times: np.ndarray
    junctions: np.ndarray
    tension: np.ndarray
    still: np.ndarray
    still_tension: np.ndarray
    places: dict[str, int]
    branches: dict[int, np.ndarray]
    steps: int
    statics_time: float  # s, compile included
    wall_time: float  # s, simulate's, compile included

    @property
    def period(self) -> float:
        return WAVE_PERIOD

    def buoy(self, buoy: int) -> np.ndarray:
        """Buoy `buoy`'s position (m), shape `(times, 3)`."""
        return self.junctions[:, buoy_node(buoy)]

    def at(self, place: str) -> np.ndarray:
        """The tension (N) at one of `PLACES`, shape `(times,)`."""
        return self.tension[:, self.places[place]]

    def window(self, t0: float, t1: float = np.inf) -> np.ndarray:
        return (self.times >= t0) & (self.times <= t1)

    def measured_from(self, periods: int | None = None) -> float:
        """The start (s) of the last `periods` whole wave periods (`config["periods"]`
        by default)."""
        periods = self.config["periods"] if periods is None else periods
        return float(self.times[-1] - periods * self.period)

    def last_periods(self, periods: int | None = None) -> np.ndarray:
        """The samples of the last `periods` whole wave periods, the first sample of
        the span left out so that every phase is counted once."""
        return self.times > self.measured_from(periods) + 1e-9


def run_net(config: dict = SMALL, pretension: float = PRETENSION, progress: bool = False) -> NetRun:
    """The net at size `config` (`SMALL` or `FULL`) from its still-water equilibrium
    into the waves, to `config["end"]`."""
    model, env = moored_net(segments=config["segments"], viscous=config["viscous"], pretension=pretension)
    clock = time.perf_counter()
    statics = solve_statics(model, env.without_waves())
    statics_time = time.perf_counter() - clock
    end = float(config["end"])
    start = end - config["periods"] * WAVE_PERIOD
    ts = np.concatenate(
        [
            np.arange(0.0, start - 0.5 / config["rate"], 1.0 / config["rate"]),
            np.linspace(start, end, int(round((end - start) * config["dense"])) + 1),
        ]
    )
    clock = time.perf_counter()
    result = simulate(
        model,
        env,
        end,
        ts=ts,
        initial=statics.state,
        solver=SolverConfig(max_steps=config.get("max_steps", 1_000_000)),
        progress=progress,
    )
    wall = time.perf_counter() - clock
    junctions = slice(0, HUB + 1)
    return NetRun(
        config=dict(config),
        pretension=pretension,
        times=ts,
        junctions=np.asarray(result.positions)[:, junctions],
        tension=np.asarray(result.tension),
        still=np.asarray(statics.state.positions)[junctions],
        still_tension=np.asarray(statics.tension),
        places=fig5_segments(model, 2),
        branches={
            b: np.concatenate(
                [
                    branch_segments(model, buoy_node(b), corner_node(b)),
                    branch_segments(model, corner_node(b), anchor_node(b)),
                ]
            )
            for b in BUOYS
        },
        steps=int(result.stats["num_steps"]),
        statics_time=statics_time,
        wall_time=wall,
    )


# --- measures --------------------------------------------------------------------------


@dataclasses.dataclass
class Harmonic:
    """A series fitted as `mean + slope (t − t_mid) + amplitude cos(ω t − lag)`, plus
    its second and third harmonics, over a span of whole periods 2π/ω, t_mid its middle:
    `mean` the value there, `slope` per second, `lag` (rad) in (−π, π]. Fitting the
    higher harmonics alongside keeps them out of the trend and the first harmonic,
    which a span's ends would otherwise mix."""

    mean: float
    slope: float
    amplitude: float
    lag: float


HARMONICS = 3


def harmonic_fit(
    times: np.ndarray, values: np.ndarray, period: float = WAVE_PERIOD, mid: float | None = None
) -> Harmonic:
    """The least-squares [`Harmonic`][] of `values` at `times` (s); `mid` (s) the time
    its `mean` is at, the middle of `times` by default."""
    omega = 2 * np.pi / period
    mid = 0.5 * (times[0] + times[-1]) if mid is None else mid
    waves = [f(n * omega * times) for n in range(1, HARMONICS + 1) for f in (np.cos, np.sin)]
    basis = np.stack([np.ones_like(times), times - mid, *waves], axis=1)
    (mean, slope, a, b, *_), *_ = np.linalg.lstsq(basis, values, rcond=None)
    return Harmonic(float(mean), float(slope), float(np.hypot(a, b)), float(np.arctan2(b, a)))


def wave_phase(buoy: int, still: np.ndarray) -> float:
    """The phase (degrees) of the wave at buoy `buoy`'s still position relative to buoy
    1's, −k Δx: negative where it arrives later."""
    k = float(airy_wavenumber(WAVE_PERIOD, WATER_DEPTH, GRAVITY))
    dx = still[buoy_node(buoy), 0] - still[buoy_node(1), 0]
    return float(np.degrees(_wrap(-k * dx)))


def _wrap(angle):
    """An angle (rad) wrapped into (−π, π]."""
    return -((np.pi - angle) % (2 * np.pi) - np.pi)


@dataclasses.dataclass
class Heave:
    """A buoy's vertical motion over the last whole periods: `amplitude` (m) and
    `phase` (degrees, relative to buoy 1's, negative when it lags) of its first harmonic
    at the wave period; `half_range` (m), half of max − min; `mean_z` (m), its mean
    height; `sink` (m), that less its still-water height."""

    amplitude: float
    phase: float
    half_range: float
    mean_z: float
    sink: float


def heave(run: NetRun, periods: int | None = None) -> dict[int, Heave]:
    """Each buoy's [`Heave`][], by buoy number."""
    m = run.last_periods(periods)
    fits = {b: harmonic_fit(run.times[m], run.buoy(b)[m, 2], run.period) for b in BUOYS}
    out = {}
    for b, fit in fits.items():
        z = run.buoy(b)[m, 2]
        out[b] = Heave(
            amplitude=fit.amplitude,
            phase=float(np.degrees(_wrap(fits[1].lag - fit.lag))),
            half_range=float(np.ptp(z) / 2),
            mean_z=float(z.mean()),
            sink=float(z.mean() - run.still[buoy_node(b), 2]),
        )
    return out


@dataclasses.dataclass
class Drift:
    """A buoy's mean horizontal offset (m) from its still-water position over the last
    whole periods: `along` the wave (+x), `across` it (+y), and `inward`, toward the
    net's centre; `rate` (m per wave period), how fast `along` still changes."""

    along: float
    across: float
    inward: float
    rate: float


def drift(run: NetRun, periods: int | None = None) -> dict[int, Drift]:
    """Each buoy's [`Drift`][], by buoy number. The offsets are the fitted means: the
    values at the middle of the last whole periods, a linear trend and the wave-period
    motion taken out."""
    m = run.last_periods(periods)
    mid = 0.5 * (run.measured_from(periods) + run.times[-1])
    out = {}
    for b in BUOYS:
        still = run.still[buoy_node(b), :2]
        x = harmonic_fit(run.times[m], run.buoy(b)[m, 0], run.period, mid)
        y = harmonic_fit(run.times[m], run.buoy(b)[m, 1], run.period, mid)
        offset = np.array([x.mean, y.mean]) - still
        outward = still / np.linalg.norm(still)
        out[b] = Drift(float(offset[0]), float(offset[1]), float(-offset @ outward), x.slope * run.period)
    return out


@dataclasses.dataclass
class Place:
    """The tension at one place over the last whole periods: `still` (N) in still
    water; `min`, `max`, `mean` (N), and `max_time` (s) when it peaked; `max_smoothed`
    (N), the largest of its `SMOOTH`-second running mean, which a spike of a few
    samples barely moves; `spells`, the slack spells that ended within the span, with
    their snaps; `slack_fraction`, the share of the span spent slack."""

    still: float
    min: float
    max: float
    max_time: float
    max_smoothed: float
    mean: float
    spells: list[Snap]
    slack_fraction: float

    @property
    def snaps(self) -> list[Snap]:
        """The spells that end in a snap: a peak above `SNAP_RATIO` times the mean."""
        return [s for s in self.spells if s.peak > SNAP_RATIO * self.mean]

    @property
    def longest(self) -> float:
        """The longest slack spell (s), 0 if none."""
        return max((s.slack_to - s.slack_from for s in self.spells), default=0.0)

    @property
    def peak(self) -> float:
        """The largest snap (N), NaN if the place never went slack."""
        return max((s.peak for s in self.spells), default=float("nan"))


def places(run: NetRun, periods: int | None = None) -> dict[str, Place]:
    """Each of Fig. 5's `PLACES`, by name."""
    m = run.last_periods(periods)
    n = max(int(round(SMOOTH / np.median(np.diff(run.times[m])))), 1)
    out = {}
    for name, segment in run.places.items():
        series = run.tension[:, segment]
        out[name] = Place(
            still=float(run.still_tension[segment]),
            min=float(series[m].min()),
            max=float(series[m].max()),
            max_time=float(run.times[m][np.argmax(series[m])]),
            max_smoothed=float(np.convolve(series[m], np.ones(n) / n, mode="valid").max()),
            mean=float(series[m].mean()),
            spells=series_snaps(run.times, run.tension, [segment], after=run.measured_from(periods)),
            slack_fraction=float(np.mean(series[m] <= SLACK_TENSION)),
        )
    return out


def branch_spells(run: NetRun, periods: int | None = None) -> dict[int, list[Snap]]:
    """The slack spells, with their snaps, on each buoy's vertical branch (any
    segment) over the last whole periods, by buoy number."""
    after = run.measured_from(periods)
    return {b: series_snaps(run.times, run.tension, run.branches[b], after=after) for b in BUOYS}


# --- plots -----------------------------------------------------------------------------


def plot_heave(run: NetRun, window=None, ax=None):
    """Each buoy's height z (m) against time (the paper's Fig. 4, vertical)."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(8, 3))
    m = run.window(*(window or (run.times[0], run.times[-1])))
    for b in BUOYS:
        ax.plot(run.times[m], run.buoy(b)[m, 2], lw=0.8, label=f"buoy {b}")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("buoy z (m)")
    ax.legend(ncol=4, fontsize="small")
    return ax


def plot_paths(run: NetRun, ax=None):
    """Each buoy's path in the horizontal plane, as offsets from its still position,
    drawn about that position scaled down so that all four fit (the paper's Fig. 4,
    horizontal); the waves run along +x."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(5, 5))
    offsets = np.stack([run.buoy(b)[:, :2] - run.still[buoy_node(b), :2] for b in BUOYS])
    reach = max(np.abs(offsets).max(), 1e-3)
    spacing = np.linalg.norm(run.still[buoy_node(1), :2])
    scale = 0.4 * spacing / reach
    for b, offset in zip(BUOYS, offsets):
        still = run.still[buoy_node(b), :2]
        path = still + scale * offset
        ax.plot(path[:, 0], path[:, 1], lw=0.7, label=f"buoy {b}")
        ax.plot(*still, "ko", ms=3)
    ax.annotate("", xy=(0.5 * spacing, 0), xytext=(-0.5 * spacing, 0), arrowprops=dict(arrowstyle="->", color="0.6"))
    ax.set_title(f"offsets × {scale:.1f} about the still positions; waves → +x", fontsize="small")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    ax.legend(fontsize="small")
    return ax


def plot_fig5(run: NetRun, window=None, axes=None):
    """Tension histories (kN) at Fig. 5's four places on buoy 2's vertical branch, one
    panel each, over `window` (s; the last whole periods by default), with their
    `SMOOTH`-second running mean where the samples are dense enough to take one."""
    import matplotlib.pyplot as plt

    if axes is None:
        _, axes = plt.subplots(len(PLACES), 1, figsize=(8, 2 * len(PLACES)), sharex=True)
    m = run.window(*(window or (run.measured_from(), run.times[-1])))
    t = run.times[m]
    n = int(round(SMOOTH / np.median(np.diff(t))))
    for ax, place in zip(np.atleast_1d(axes), PLACES):
        ax.plot(t, run.at(place)[m] / 1e3, lw=0.7, label="samples")
        if n > 1:
            mean = np.convolve(run.at(place)[m], np.ones(n) / n, mode="valid")
            ax.plot(t[n // 2 : n // 2 + mean.size], mean / 1e3, lw=0.9, color="k", label=f"{1e3 * SMOOTH:.0f} ms mean")
        ax.axhline(0.0, color="0.7", lw=0.5)
        ax.set_ylabel(f"{place}\nT (kN)")
    np.atleast_1d(axes)[0].legend(fontsize="small", loc="upper right")
    np.atleast_1d(axes)[-1].set_xlabel("t (s)")
    return axes


# --- verdict ---------------------------------------------------------------------------


def _grade(passed: int, of: int) -> str:
    return "yes" if passed == of else ("partly" if passed else "no")


def verdict_rows(run: NetRun) -> list[tuple[str, str, str, str]]:
    """The net's rows of the closing table, `(paper's claim, jaxcable's result,
    agreement, why)`, every number measured on `run` (the `FULL` run) over its last
    whole periods."""
    span = f"t = {run.measured_from():.0f}–{run.times[-1]:.0f} s"
    h, d, p = heave(run), drift(run), places(run)
    rows = []

    amplitudes = [h[b].amplitude for b in BUOYS]
    phases = [h[b].phase for b in BUOYS]
    waves = [wave_phase(b, run.still) for b in BUOYS]
    behind = max(abs(np.degrees(_wrap(np.radians(x - w)))) for x, w in zip(phases, waves))
    differ = [max(amplitudes) > 1.2 * min(amplitudes), max(abs(x) for x in phases) > 30.0]
    rows.append(
        (
            "The buoys heave with different amplitudes and phases (Fig. 4)",
            f"over {span}: heave amplitude " + ", ".join(f"{a:.2f}" for a in amplitudes) + " m (buoys 1–4; "
            f"the wave's {_wave_amplitude():.2f} m), phase from buoy 1 "
            + ", ".join(_degrees(x) for x in phases)
            + "; mean height "
            + ", ".join(f"{h[b].sink:+.2f}" for b in BUOYS)
            + " m from still water",
            _grade(sum(differ), 2),
            "the phases follow the wave's own at each buoy, −k Δx = "
            + ", ".join(_degrees(w) for w in waves)
            + f", to within {behind:.0f}°; the amplitudes differ though the wave's is the same at all four",
        )
    )

    gap = abs(np.degrees(_wrap(np.radians(h[2].phase - h[4].phase))))
    spread = abs(h[2].amplitude - h[4].amplitude) / max(h[2].amplitude, h[4].amplitude)
    rows.append(
        (
            "Buoys 2 and 4 heave in phase",
            f"amplitudes {h[2].amplitude:.3f} and {h[4].amplitude:.3f} m, phases {h[2].phase:+.1f}° and "
            f"{h[4].phase:+.1f}° from buoy 1",
            "yes" if gap < 1.0 and spread < 0.01 else "no",
            "the scene is mirror-symmetric about the waves' vertical plane y = 0, in which they run",
        )
    )

    on_axis = all(abs(d[b].across) < 0.05 * max(abs(d[b].along), 0.01) for b in (1, 3))
    forward = all(d[b].along > 0.05 for b in (1, 3))
    most = all(abs(d[1].along) >= abs(d[b].along) for b in BUOYS)
    order = sorted(BUOYS, key=lambda b: -abs(d[b].along))
    rows.append(
        (
            "Buoys 1 and 3 drift only along the wave direction, buoy 1 the most",
            f"mean offsets along the waves (x) {d[1].along:+.2f} m (buoy 1) and {d[3].along:+.2f} m (buoy 3), "
            f"across {_signed(d[1].across)} and {_signed(d[3].across)} m; buoys 2 and 4 {d[2].along:+.2f} m along; "
            f"still changing by {max(abs(d[b].rate) for b in BUOYS):.3f} m a period or less",
            _grade(on_axis + forward + most, 3),
            "they stay on the x axis, by the mirror symmetry, and move "
            + ("downwave" if forward else "not both downwave")
            + (
                ""
                if most
                else "; but buoy 1 drifts the least of the four: largest to smallest, buoys "
                + ", ".join(map(str, order))
            ),
        )
    )

    along_24 = all(d[b].along > 0.05 for b in (2, 4))
    inward_24 = all(d[b].inward > max(0.05, 0.1 * abs(d[b].along)) for b in (2, 4))
    rows.append(
        (
            "Buoys 2 and 4 drift along the wave direction and are pulled toward the centre",
            f"mean offsets along the waves {d[2].along:+.2f} and {d[4].along:+.2f} m, toward the centre "
            f"{d[2].inward:+.3f} and {d[4].inward:+.3f} m",
            _grade(along_24 + inward_24, 2),
            ("downwave" if along_24 else "not downwave")
            + (
                ", and inward"
                if inward_24
                else ", and inward by less than a tenth of that (criterion: 5 cm and a tenth)"
            ),
        )
    )

    snapping = [name for name in PLACES if p[name].snaps]
    taut = [name for name in PLACES if not p[name].spells]

    def describe(name):
        place = p[name]
        text = f"{name} {place.min / 1e3:.2f}–{place.max / 1e3:.1f} kN (mean {place.mean / 1e3:.1f})"
        if place.spells:
            text += (
                f", slack {len(place.spells)}× in {run.config['periods']} periods for up to "
                f"{place.longest:.2f} s, snaps to {place.peak / 1e3:.1f} kN"
            )
        return text

    rows.append(
        (
            "Snap loads (slack, then a spike) on all parts of the vertical branch under buoy 2 (Fig. 5's four places)",
            f"over {span}: " + "; ".join(describe(name) for name in PLACES),
            _grade(len(snapping), len(PLACES)),
            f"slack, then a spike above {SNAP_RATIO}× the mean, at {len(snapping)} of the 4 places"
            + (
                f"; {', '.join(taut)}: never slack, the least tension "
                + ", ".join(f"{p[n].min / 1e3:.2f}" for n in taut)
                + " kN"
                if taut
                else ""
            ),
        )
    )

    upper = max(p[n].max_smoothed for n in PLACES[:2])
    lower = max(p[n].max_smoothed for n in PLACES[2:])
    ratio = upper / lower
    raw = max(p[n].max for n in PLACES[:2]) / max(p[n].max for n in PLACES[2:])
    # Where, near the anchor's largest sample, each place peaks: one spike along the branch?
    t0 = p["near anchor"].max_time
    near = run.window(t0 - 0.05, t0 + 0.05)
    lags = [run.times[near][np.argmax(run.at(n)[near])] - t0 for n in PLACES]
    together = all(run.at(n)[near].max() >= 0.99 * p[n].max for n in PLACES)
    j = int(np.flatnonzero(run.times == t0)[0])
    anchor = run.at("near anchor")
    drop = anchor[j] / max(anchor[min(j + 1, anchor.size - 1)], 1e-9)
    snaps_upper = all(p[n].snaps for n in PLACES[:2])
    dt = float(np.median(np.diff(run.times[run.last_periods()])))
    rows.append(
        (
            "The upper part's jerk is somewhat smaller than the lower part's (the weight of the freely hanging part)",
            f"largest tension over {1e3 * SMOOTH:.0f} ms, upper part {upper / 1e3:.1f} kN, lower {lower / 1e3:.1f} kN "
            f"({ratio:.2f}×); in single {1e3 * dt:.1f} ms samples "
            + ", ".join(f"{p[n].max / 1e3:.1f}" for n in PLACES)
            + f" kN from the buoy down ({raw:.2f}×)",
            "yes" if 0.6 <= ratio < 0.98 and snaps_upper else ("partly" if 0.6 <= ratio < 1.0 else "no"),
            (
                "somewhat smaller"
                if 0.6 <= ratio < 0.98
                else "about as large"
                if 0.98 <= ratio < 1.02
                else "much smaller (criterion for somewhat: 0.6–0.98×)"
                if ratio < 0.6
                else "larger"
            )
            + (
                f"; all four places peak within {1e3 * (max(lags) - min(lags)):.1f} ms of each other, as the "
                f"segment near the anchor snaps taut: one spike along the branch; near the anchor it falls "
                f"{drop:.1f}-fold from its highest sample to the next, so the samples' heights depend on the "
                "sampling"
                if together
                else ""
            )
            + ("" if snaps_upper else "; the upper part's peaks follow no slack spell of its own"),
        )
    )

    spells = branch_spells(run)
    window = run.last_periods()
    snapped = {}
    for b in BUOYS:
        means = dict(zip(run.branches[b], run.tension[window][:, run.branches[b]].mean(axis=0)))
        snapped[b] = [x for x in spells[b] if x.peak > SNAP_RATIO * means[x.segment]]
    slack_buoys = [b for b in BUOYS if spells[b]]
    rows.append(
        (
            "The same picture on every vertical branch whenever its tension drops to zero",
            "slack spells on the vertical branches under buoys 1–4: "
            + ", ".join(str(len(spells[b])) for b in BUOYS)
            + f"; of them ending in a spike above {SNAP_RATIO}× the segment's mean: "
            + ", ".join(str(len(snapped[b])) for b in BUOYS),
            _grade(sum(len(snapped[b]) == len(spells[b]) for b in slack_buoys), len(slack_buoys))
            if slack_buoys
            else "no",
            (
                "only the branches under buoys "
                + ", ".join(map(str, slack_buoys))
                + " go slack; spells under 10 ms: "
                + ", ".join(str(sum(x.slack_to - x.slack_from < 0.01 for x in spells[b])) for b in BUOYS)
            )
            if slack_buoys
            else "no vertical branch goes slack",
        )
    )
    return rows


def _signed(value: float, digits: int = 3) -> str:
    """A signed number to `digits` decimals, with no −0."""
    return f"{round(value, digits) + 0.0:+.{digits}f}"


def _degrees(angle: float) -> str:
    """An angle (degrees) to the nearest degree, signed, with no −0."""
    return f"{int(round(angle)):+d}°"


def _wave_amplitude() -> float:
    return float(floater_amplitude(WAVE_PERIOD))


def verdict_markdown(run: NetRun) -> str:
    """The net's rows as a markdown table."""
    lines = ["| paper's claim | jaxcable's result | agreement | why |", "|---|---|---|---|"]
    for row in verdict_rows(run):
        lines.append("| " + " | ".join(cell.replace("|", "/") for cell in row) + " |")
    return "\n".join(lines)
