"""Seed 001's plane problems as a study: the free element's drift, the tethered element's
impulses, and the map of where its tether goes slack.

Used by `notebooks/seed001_growing_elements.ipynb`, `benchmarks/seed001_reproduction.py`
and the tests. Each study is one [`jaxcable.sweep`][]: over k₀ for the free element, over
the weight characteristic ρ for the tethered one. See `jaxcable/examples/seed001.py` for the scenes and
the definitions of u₀ and ρ.
"""

import dataclasses
import time

import jax
import numpy as np

from jaxcable import SolverConfig, sweep
from jaxcable.examples.seed001 import (
    ELEMENT_MASS,
    GRAVITY,
    ORGANISM_MASS,
    TETHER_LENGTH,
    TETHER_STIFFNESS,
    WAVE_PERIOD,
    element_depth,
    orbital_speed,
    seed001_element,
    seed001_wave,
)

OMEGA = 2 * np.pi / WAVE_PERIOD
# Study sizes: the notebook's default and the tests run SMALL, the benchmark FULL.
SMALL = dict(periods=20, samples_per_period=72, settle_periods=8)
FULL = dict(periods=60, samples_per_period=144, settle_periods=20)
FREE_SPECIFIC_DRAGS = (0.5, 5.0, 50.0, 500.0, 5000.0)  # s²/m²
# The tethered studies' k₀: ten times the scallop cage's, for an element with much drag for
# its mass (St = 0.12), nearer the thesis's inertia-free model; the cage itself (St = 1.2)
# is run beside it.
TETHERED_SPECIFIC_DRAG = 5.0  # s²/m²
WEIGHT_CHARACTERISTICS = (0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.25, 1.5, 2.0)
# A tether counts as slack where its tension is below this fraction of its element's
# weight in water (the tension law's slack switch is smoothed, so it is never exactly 0).
SLACK_FRACTION = 1e-3


def inertia_number(specific_drag) -> np.ndarray:
    """St = ω M / (k₀ m_o g u₀) (–): the element's inertia against its drag at the water's
    speed u₀. The thesis's model has none (St = 0); a relative speed of order √St · u₀
    is what it takes for drag to move the element with the water."""
    u0 = float(orbital_speed(seed001_wave(), element_depth()))
    return OMEGA * ELEMENT_MASS / (np.asarray(specific_drag) * ORGANISM_MASS * GRAVITY * u0)


def phase_locked_drift(t: np.ndarray, x: np.ndarray, z: np.ndarray) -> tuple[float, float]:
    """`(drift, mean depth)`: the mean horizontal speed (m/s) of a body moving on looped
    orbits, between the first and last times it rises through its mean depth, and that
    mean depth (m).

    Between two such times the body has made whole orbits, so its orbital motion cancels.
    Over a fixed number of *wave* periods it would not: the body's orbit period is
    Doppler-shifted by its drift, and the leftover part of an orbit biases the drift by
    several per cent over 20 periods.
    """
    mean = float(np.mean(z))
    s = z - mean
    k = np.flatnonzero((s[:-1] < 0) & (s[1:] >= 0))
    if k.size < 2:
        raise ValueError("phase_locked_drift: the body did not complete an orbit")
    crossings = t[k] - s[k] * (t[k + 1] - t[k]) / (s[k + 1] - s[k])
    xc = np.interp(crossings, t, x)
    return float((xc[-1] - xc[0]) / (crossings[-1] - crossings[0])), mean


@dataclasses.dataclass
class FreeStudy:
    """The free element over k₀: per case, St, the drift (m/s), the mean depth (m), the
    Stokes drift at that depth (m/s), and the path `positions` of shape
    `(cases, times, 3)` over `times` (s)."""

    specific_drag: np.ndarray
    inertia_number: np.ndarray
    drift: np.ndarray
    mean_depth: np.ndarray
    stokes_drift: np.ndarray
    times: np.ndarray
    positions: np.ndarray
    success: np.ndarray
    run_s: float

    @property
    def drift_ratio(self) -> np.ndarray:
        return self.drift / self.stokes_drift


def free_study(
    specific_drags=FREE_SPECIFIC_DRAGS, *, periods: int, samples_per_period: int, settle_periods: int
) -> FreeStudy:
    """Run the free element for `periods` wave periods at each k₀, from rest, and measure
    its drift after `settle_periods` (the waves ramp up over the first two)."""
    wave = seed001_wave()
    t1 = periods * WAVE_PERIOD
    times = np.linspace(0.0, t1, periods * samples_per_period + 1)
    start = time.perf_counter()
    result = sweep(
        lambda specific_drag: seed001_element(0.0, tethered=False, specific_drag=specific_drag),
        {"specific_drag": specific_drags},
        t1,
        ts=times,
        initial="rest",
        solver=SolverConfig(rtol=1e-8, atol=1e-8),
    )
    positions = np.asarray(result.simulation.positions[:, :, 1, :])
    run_s = time.perf_counter() - start
    after = times >= settle_periods * WAVE_PERIOD
    drift, depth = zip(*(phase_locked_drift(times[after], p[after, 0], p[after, 2]) for p in positions))
    depth = np.array(depth)
    return FreeStudy(
        specific_drag=np.asarray(specific_drags, dtype=float),
        inertia_number=inertia_number(specific_drags),
        drift=np.array(drift),
        mean_depth=depth,
        stokes_drift=np.asarray(wave.stokes_drift(depth)),
        times=times,
        positions=positions,
        success=np.asarray(result.success),
        run_s=run_s,
    )


@dataclasses.dataclass
class TetheredStudy:
    """The tethered element over ρ, after the settling periods: `times` (s), the tether
    tension `tension` (N) and its dimensionless form `eta` = T l ω / (EF u₀), both of
    shape `(cases, times)`, the element's `positions` `(cases, times, 3)`, the water's
    vertical velocity at the element `vertical_water` (m/s), and the phase
    τ = ω t mod 2π, 0 where a crest passes the frame point. Per case: the element's
    weight in water `weight` (N) and its depth in static equilibrium `static_depth` (m).
    `specific_drag` is the elements' k₀ (s²/m²)."""

    weight_characteristic: np.ndarray
    specific_drag: float
    weight: np.ndarray
    static_depth: np.ndarray
    times: np.ndarray
    tension: np.ndarray
    eta: np.ndarray
    positions: np.ndarray
    vertical_water: np.ndarray
    success: np.ndarray
    run_s: float

    @property
    def phase(self) -> np.ndarray:
        return np.mod(OMEGA * self.times, 2 * np.pi)

    @property
    def slack(self) -> np.ndarray:
        """`(cases, times)`: where the tether carries (almost) nothing."""
        return self.tension < SLACK_FRACTION * self.weight[:, None]

    def slack_fraction(self) -> np.ndarray:
        """The fraction of the time each case's tether is slack."""
        return self.slack.mean(axis=1)


def tethered_study(
    weight_characteristics=WEIGHT_CHARACTERISTICS,
    *,
    specific_drag: float = TETHERED_SPECIFIC_DRAG,
    periods: int,
    samples_per_period: int,
    settle_periods: int,
) -> TetheredStudy:
    """Run the tethered element at each weight characteristic ρ, from its static
    equilibrium in still water, and keep what follows the settling periods."""
    wave = seed001_wave()
    z = element_depth()
    u0 = float(orbital_speed(wave, z))
    t1 = periods * WAVE_PERIOD
    times = np.linspace(0.0, t1, periods * samples_per_period + 1)
    start = time.perf_counter()
    result = sweep(
        lambda weight_characteristic: seed001_element(weight_characteristic, specific_drag=specific_drag),
        {"weight_characteristic": weight_characteristics},
        t1,
        ts=times,
        solver=SolverConfig(rtol=1e-8, atol=1e-8),
    )
    tension = np.asarray(result.simulation.tension[:, :, 0])
    positions = np.asarray(result.simulation.positions[:, :, 1, :])
    run_s = time.perf_counter() - start
    keep = times >= settle_periods * WAVE_PERIOD
    model, env = seed001_element(specific_drag=specific_drag)
    velocity = jax.vmap(env.water_velocity)
    vertical = np.stack([np.asarray(velocity(p[keep], times[keep])[:, 2]) for p in positions])
    rho = np.asarray(weight_characteristics, dtype=float)
    return TetheredStudy(
        weight_characteristic=rho,
        specific_drag=float(specific_drag),
        static_depth=positions[:, 0, 2],
        weight=rho * float(model.body.specific_drag[1]) * ORGANISM_MASS * GRAVITY * u0**2,
        times=times[keep],
        tension=tension[:, keep],
        eta=tension[:, keep] * TETHER_LENGTH * OMEGA / (TETHER_STIFFNESS * u0),
        positions=positions[:, keep],
        vertical_water=vertical,
        success=np.asarray(result.success),
        run_s=run_s,
    )


def shadow_map(study: TetheredStudy, bins: int = 72) -> tuple[np.ndarray, np.ndarray]:
    """`(phase_edges, slack)`: the fraction of the time the tether is slack in each phase
    bin of the wave, shape `(cases, bins)`, with the bins' edges in τ (rad). 1 is the
    thesis's "shadow", where the tether never carries load at that phase; 0 is "light"."""
    edges = np.linspace(0.0, 2 * np.pi, bins + 1)
    which = np.clip(np.digitize(study.phase, edges) - 1, 0, bins - 1)
    slack = np.array([[case[which == b].mean() for b in range(bins)] for case in study.slack])
    return edges, slack


@dataclasses.dataclass
class ImpulseFit:
    """One tension impulse of the tethered element and two fits of its shape over
    s = (t − t_on)/(t_off − t_on) ∈ [0, 1]: part of a sine, `A sin(φ₀ + (φ₁ − φ₀) s)`,
    and a parabola, `c₀ + c₁ s + c₂ s²`. Each `*_rms` is the fit's RMS residual over
    the impulse's peak."""

    times: np.ndarray
    tension: np.ndarray
    sine: tuple[float, float, float]
    parabola: tuple[float, float, float]
    sine_rms: float
    parabola_rms: float
    rectangle_rms: float

    @property
    def s(self) -> np.ndarray:
        return (self.times - self.times[0]) / (self.times[-1] - self.times[0])

    def sine_curve(self, s):
        amplitude, start, end = self.sine
        return amplitude * np.sin(start + (end - start) * s)

    def parabola_curve(self, s):
        return np.polyval(self.parabola[::-1], s)


def fit_impulse(times: np.ndarray, tension: np.ndarray, slack: np.ndarray) -> ImpulseFit:
    """Fit the longest complete impulse of one tension history: the longest run of taut
    samples with slack samples on both sides (a short one can be a rebound after a snap).

    The sine's phases are found on a grid (φ₀ over [0, π/2], φ₁ over [π/2, π], 91 points
    each), its amplitude by least squares for each pair; the parabola by least squares.
    The rectangle is the impulse's mean over its duration.
    """
    taut = ~slack
    starts = np.flatnonzero(~taut[:-1] & taut[1:]) + 1
    ends = np.flatnonzero(taut[:-1] & ~taut[1:]) + 1
    pairs = [(a, b) for a in starts for b in ends[ends > a][:1]]
    if not pairs:
        raise ValueError("fit_impulse: no complete impulse (the tether never goes slack, or never taut)")
    a, b = max(pairs, key=lambda pair: pair[1] - pair[0])
    # Include the slack samples on each side: the impulse starts and ends at zero.
    t, f = times[a - 1 : b + 1], tension[a - 1 : b + 1]
    s = (t - t[0]) / (t[-1] - t[0])
    peak = float(np.max(f))

    best = (np.inf, None)
    final_phases = np.linspace(np.pi / 2, np.pi, 91)
    for start in np.linspace(0.0, np.pi / 2, 91):
        basis = np.sin(start + (final_phases[:, None] - start) * s)
        amplitude = basis @ f / np.sum(basis**2, axis=1)
        residual = np.sqrt(np.mean((amplitude[:, None] * basis - f) ** 2, axis=1))
        k = int(np.argmin(residual))
        if residual[k] < best[0]:
            best = (residual[k], (float(amplitude[k]), float(start), float(final_phases[k])))
    coefficients = np.polyfit(s, f, 2)[::-1]
    parabola_rms = float(np.sqrt(np.mean((np.polyval(coefficients[::-1], s) - f) ** 2)))
    rectangle = np.where((s > 0) & (s < 1), np.mean(f[1:-1]), 0.0)
    return ImpulseFit(
        times=t,
        tension=f,
        sine=best[1],
        parabola=tuple(float(c) for c in coefficients),
        sine_rms=float(best[0]) / peak,
        parabola_rms=parabola_rms / peak,
        rectangle_rms=float(np.sqrt(np.mean((rectangle - f) ** 2))) / peak,
    )


def back_slope_share(study: TetheredStudy) -> np.ndarray:
    """Per case, the share of the tether's impulse ∫T dt delivered while the water at the
    element moves down (w < 0): on the wave's back slope, the thesis says, all of it."""
    down = study.vertical_water < 0
    return np.sum(study.tension * down, axis=1) / np.sum(study.tension, axis=1)


def plot_free(study: FreeStudy, cases=(0, 2, 4), axes=None):
    """The free element's paths relative to their start (left), and its drift over the
    Stokes drift against St (right)."""
    import matplotlib.pyplot as plt

    if axes is None:
        _, axes = plt.subplots(1, 2, figsize=(11, 3.5), gridspec_kw={"width_ratios": [2, 1]})
    for i in cases:
        path = study.positions[i] - study.positions[i, 0]
        axes[0].plot(
            path[:, 0],
            path[:, 2],
            lw=0.8,
            label=f"k₀ = {study.specific_drag[i]:g} s²/m², St = {study.inertia_number[i]:.2g}",
        )
    axes[0].set(xlabel="x − x₀ (m), the wave travels →", ylabel="z − z₀ (m)", title="free element, from rest")
    axes[0].set_aspect("equal")
    axes[0].legend(fontsize=7, loc="lower right")
    axes[1].semilogx(study.inertia_number, study.drift_ratio, "o-")
    axes[1].axhline(1.0, color="k", lw=0.5)
    axes[1].set(xlabel="St = ω M / (k₀ m_o g u₀)", ylabel="drift / Stokes drift", title="drift against inertia")
    return axes


def plot_tethered(study: TetheredStudy, cases, periods: float = 3.0, axes=None):
    """Tension histories over `periods` wave periods for the given cases, with the back
    slope (water moving down at the element) shaded."""
    import matplotlib.pyplot as plt

    if axes is None:
        _, axes = plt.subplots(len(cases), 1, figsize=(9, 1.7 * len(cases)), sharex=True, squeeze=False)
        axes = axes[:, 0]
    window = study.times <= study.times[0] + periods * WAVE_PERIOD
    t = study.times[window]
    for ax, i in zip(axes, cases):
        down = study.vertical_water[i, window] < 0
        ax.fill_between(t, 0, 1, where=down, transform=ax.get_xaxis_transform(), color="0.9", lw=0)
        ax.plot(t, study.tension[i, window] / study.weight[i], "k", lw=0.9)
        ax.set_ylabel(f"T / W\nρ = {study.weight_characteristic[i]:g}")
    axes[-1].set_xlabel("t (s); shaded: water moving down at the element (the back slope)")
    return axes


def plot_shadow_map(study: TetheredStudy, bins: int = 72, ax=None):
    """Where the tether is slack over the phase τ and ρ: dark is the "shadow"."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(7, 3.5))
    edges, slack = shadow_map(study, bins)
    rows = np.arange(study.weight_characteristic.size + 1) - 0.5
    mesh = ax.pcolormesh(edges, rows, slack, cmap="Greys", vmin=0, vmax=1, shading="flat")
    ax.set_yticks(np.arange(study.weight_characteristic.size), [f"{r:g}" for r in study.weight_characteristic])
    ax.set(xlabel="τ = ω t mod 2π (crest at the frame point at 0)", ylabel="ρ", title="fraction of the time slack")
    plt.colorbar(mesh, ax=ax)
    return ax


def plot_impulse(fit: ImpulseFit, ax=None):
    """One impulse with its part-of-a-sine and parabola fits."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(5, 3))
    s = np.linspace(0, 1, 200)
    ax.plot(fit.s, fit.tension, "k.", ms=3, label="jaxcable")
    ax.plot(s, fit.sine_curve(s), label=f"part of a sine, RMS {100 * fit.sine_rms:.1f} %")
    ax.plot(s, fit.parabola_curve(s), "--", label=f"parabola, RMS {100 * fit.parabola_rms:.1f} %")
    ax.set(xlabel="(t − t_on) / (t_off − t_on)", ylabel="T (N)")
    ax.legend(fontsize=7)
    return ax


def never_slack_from(study: TetheredStudy) -> float | None:
    """The least ρ from which on every larger ρ of the study keeps its tether taut
    throughout, or `None`."""
    taut = study.slack_fraction() == 0
    if not taut[-1]:
        return None
    k = len(taut) - 1
    while k > 0 and taut[k - 1]:
        k -= 1
    return float(study.weight_characteristic[k])


def impulse_fits(study: TetheredStudy) -> dict[float, ImpulseFit]:
    """The longest complete impulse of every case that has one, fitted, by ρ."""
    fits = {}
    for rho, tension, slack in zip(study.weight_characteristic, study.tension, study.slack):
        try:
            fits[float(rho)] = fit_impulse(study.times, tension, slack)
        except ValueError:
            continue
    return fits


def _enclosed_area(path: np.ndarray) -> float:
    """The area (m²) of the x–z polygon that `path` (points, 3) traces, closed from its
    last point back to its first (the shoelace formula)."""
    x, z = path[:, 0] - path[:, 0].mean(), path[:, 2] - path[:, 2].mean()
    return 0.5 * abs(float(np.sum(x * np.roll(z, -1) - np.roll(x, -1) * z)))


def verdict_markdown(free: FreeStudy, tethered: TetheredStudy, cage: TetheredStudy) -> str:
    """The closing table: the thesis's claim, jaxcable's result, agreement and why; every
    number taken from the studies given."""
    closest = int(np.argmin(free.inertia_number))
    heaviest = int(np.argmax(free.inertia_number))
    drift_error = abs(free.drift_ratio[closest] - 1)
    share = back_slope_share(tethered)
    rho = tethered.weight_characteristic
    impulsive = tethered.slack_fraction() > 0
    taut_from = never_slack_from(tethered)
    fits = impulse_fits(tethered)
    sine = np.array([f.sine_rms for f in fits.values()])
    parabola = np.array([f.parabola_rms for f in fits.values()])
    rectangle = np.array([f.rectangle_rms for f in fits.values()])
    rhos = list(fits)
    best, worst = int(np.argmin(sine)), int(np.argmax(sine))
    depth_t = tethered.positions[:, :, 2].mean(axis=1)
    lifted = depth_t - tethered.static_depth
    # The area the path encloses over the last period: a loop has one, an arc swung to
    # and fro on a taut tether has none.
    n = int(round(WAVE_PERIOD / (tethered.times[1] - tethered.times[0])))
    loop_area = np.array([_enclosed_area(p[-n:]) for p in tethered.positions])
    free_area = _enclosed_area(free.positions[closest, -n:])
    rows = [
        (
            "A free body in a wave moves on looped orbits, carried along by the wave (Stokes drift), "
            "in good agreement with potential-wave theory",
            f"looped orbits at every k₀; drift / Stokes drift {free.drift_ratio[closest]:.4f} at St = "
            f"{free.inertia_number[closest]:.1g}, {free.drift_ratio[heaviest]:.2f} at St = "
            f"{free.inertia_number[heaviest]:.2g} (the scallop cage)",
            "yes" if drift_error < 0.01 else "no",
            "in the thesis's inertia-free limit; an element with real inertia lags the water, "
            "drifts less and sinks (mean depth "
            f"{free.mean_depth[heaviest]:.2f} m against {free.mean_depth[closest]:.2f} m)",
        ),
        (
            "Tethered, the body keeps its loops, shifted toward the surface, and settles on a "
            "closed path near the frame",
            f"mean depth {1e2 * lifted.max():.0f} cm (ρ = {tethered.weight_characteristic[np.argmax(lifted)]:g}) to "
            f"{1e3 * lifted.min():.1f} mm (ρ = {tethered.weight_characteristic[np.argmin(lifted)]:g}) above the static "
            f"hanging depth; the path over a period encloses {loop_area.max():.3f} m² (ρ = "
            f"{tethered.weight_characteristic[np.argmax(loop_area)]:g}) to {loop_area.min():.4f} m² (ρ = "
            f"{tethered.weight_characteristic[np.argmin(loop_area)]:g}), the free element's orbit {free_area:.3f} m²",
            "yes" if lifted.min() >= 0 and loop_area.max() > 0.25 * free_area else "no",
            "where the tether is slack the rising water lifts the element toward the surface and it "
            "loops; a heavy element stays taut and swings on an arc, which encloses almost nothing",
        ),
        (
            "The tether force comes as impulses, only on the wave's back slope (water moving down)",
            f"{100 * share[impulsive].min():.0f}–{100 * share[impulsive].max():.0f} % of ∫T dt on the back "
            f"slope where the tether goes slack (ρ ≤ {rho[impulsive].max():g}); at least 90 % for ρ ≤ "
            f"{rho[impulsive & (share >= 0.9)].max() if (impulsive & (share >= 0.9)).any() else float('nan'):g}",
            "yes" if share[impulsive].min() >= 0.9 else "partly",
            "the lighter the element, the more of its impulse falls on the back slope; a heavier one is "
            "slack only briefly and pulls on both slopes. Snap loads open each impulse where the element "
            "has inertia",
        ),
        (
            "At high weight characteristic ρ there are regions where the tether never goes slack",
            "never slack for ρ ≥ "
            + (f"{taut_from:g}" if taut_from is not None else "(none in the study)")
            + f" at k₀ = {tethered.specific_drag:g} s²/m²; the cage (k₀ = {cage.specific_drag:g} s²/m²) "
            + "never slack for ρ ≥ "
            + (f"{never_slack_from(cage):g}" if never_slack_from(cage) is not None else "–"),
            "yes" if taut_from is not None else "no",
            "a heavy element's weight exceeds the drag the rising water can exert on it",
        ),
        (
            "The impulse is well fitted by part of a sine or a parabola (a rectangle in rough work)",
            f"RMS misfit over the peak, best (ρ = {rhos[best]:g}) and worst (ρ = {rhos[worst]:g}) of {len(fits)} "
            f"impulses: part of a sine {100 * sine[best]:.0f} and {100 * sine[worst]:.0f} %, parabola "
            f"{100 * parabola[best]:.0f} and {100 * parabola[worst]:.0f} %, rectangle {100 * rectangle[best]:.0f} "
            f"and {100 * rectangle[worst]:.0f} %",
            "yes" if max(sine[best], parabola[best]) < 0.1 and max(sine[worst], parabola[worst]) < 0.1 else "partly",
            "sine and parabola fit equally well, the rectangle worse; the snap that opens a light "
            "element's impulse is what neither smooth shape captures",
        ),
    ]
    lines = ["| thesis's claim | jaxcable | agreement | why |", "|---|---|---|---|"]
    lines += [f"| {a} | {b} | {c} | {d} |" for a, b, c, d in rows]
    return "\n".join(lines)
