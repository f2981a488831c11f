"""Zhukov's plane problems as a study: the free element's drift, the tethered element's
impulses, and the map of where its tether goes slack; the thesis's two integrators side
by side (Simpson's rule against the trapezoid rule at a fifth of its step); and eq. 7's
similarity in α, ξ, ρ.

Used by `notebooks/growing_elements.ipynb`, `validation/growing_elements_reproduction.py`
and the tests. Each study is one [`jaxcable.sweep`][]: over k₀ for the free element, over
the weight characteristic ρ for the tethered one. See `jaxcable/examples/growing_elements.py` for the scenes and
the definitions of u₀ and ρ.
"""

import dataclasses
import time

import jax
import numpy as np

from jaxcable import Airy, SolverConfig, sweep
from jaxcable.examples._growing_element import (
    DEPTH,
    ELEMENT_MASS,
    FRAME_DEPTH,
    GRAVITY,
    ORGANISM_MASS,
    TETHER_LENGTH,
    TETHER_STIFFNESS,
    WAVE_PERIOD,
    element_depth,
    growing_element,
    growing_element_wave,
    orbital_speed,
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
    u0 = float(orbital_speed(growing_element_wave(), element_depth()))
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
    wave = growing_element_wave()
    t1 = periods * WAVE_PERIOD
    times = np.linspace(0.0, t1, periods * samples_per_period + 1)
    start = time.perf_counter()
    result = sweep(
        lambda specific_drag: growing_element(0.0, tethered=False, specific_drag=specific_drag),
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
    wave = growing_element_wave()
    z = element_depth()
    u0 = float(orbital_speed(wave, z))
    t1 = periods * WAVE_PERIOD
    times = np.linspace(0.0, t1, periods * samples_per_period + 1)
    start = time.perf_counter()
    result = sweep(
        lambda weight_characteristic: growing_element(weight_characteristic, specific_drag=specific_drag),
        {"weight_characteristic": weight_characteristics},
        t1,
        ts=times,
        solver=SolverConfig(rtol=1e-8, atol=1e-8),
    )
    tension = np.asarray(result.simulation.tension[:, :, 0])
    positions = np.asarray(result.simulation.positions[:, :, 1, :])
    run_s = time.perf_counter() - start
    keep = times >= settle_periods * WAVE_PERIOD
    model, env = growing_element(specific_drag=specific_drag)
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

    best_rms, best_sine = np.inf, (0.0, 0.0, 0.0)
    final_phases = np.linspace(np.pi / 2, np.pi, 91)
    for start in np.linspace(0.0, np.pi / 2, 91):
        basis = np.sin(start + (final_phases[:, None] - start) * s)
        amplitude = basis @ f / np.sum(basis**2, axis=1)
        residual = np.sqrt(np.mean((amplitude[:, None] * basis - f) ** 2, axis=1))
        k = int(np.argmin(residual))
        if residual[k] < best_rms:
            best_rms, best_sine = float(residual[k]), (float(amplitude[k]), float(start), float(final_phases[k]))
    coefficients = np.polyfit(s, f, 2)[::-1]
    parabola_rms = float(np.sqrt(np.mean((np.polyval(coefficients[::-1], s) - f) ** 2)))
    rectangle = np.where((s > 0) & (s < 1), np.mean(f[1:-1]), 0.0)
    return ImpulseFit(
        times=t,
        tension=f,
        sine=best_sine,
        parabola=(float(coefficients[0]), float(coefficients[1]), float(coefficients[2])),
        sine_rms=best_rms / peak,
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
    axes[0].set_title(
        f"tethered element, k₀ = {study.specific_drag:g} s²/m² "
        f"(St = {float(inertia_number(study.specific_drag)):.2g}): tether tension over the element's weight in water"
    )
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
    ax.set(
        xlabel="τ = ω t mod 2π (crest at the frame point at 0)",
        ylabel="weight characteristic ρ",
        title=f"the tether's shadow, k₀ = {study.specific_drag:g} s²/m² (St = "
        f"{float(inertia_number(study.specific_drag)):.2g})",
    )
    plt.colorbar(mesh, ax=ax, label="fraction of the time slack\n(1: shadow, 0: light)")
    return ax


def plot_impulse(fit: ImpulseFit, rho: float, specific_drag: float = TETHERED_SPECIFIC_DRAG, ax=None):
    """One impulse, of the element of weight characteristic `rho` and k₀ `specific_drag`
    (s²/m²), with its part-of-a-sine and parabola fits."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(5, 3))
    s = np.linspace(0, 1, 200)
    ax.plot(fit.s, fit.tension, "k.", ms=3, label="jaxcable")
    ax.plot(s, fit.sine_curve(s), label=f"part of a sine, RMS {100 * fit.sine_rms:.1f} %")
    ax.plot(s, fit.parabola_curve(s), "--", label=f"parabola, RMS {100 * fit.parabola_rms:.1f} %")
    ax.set(
        xlabel="(t − t_on) / (t_off − t_on)",
        ylabel="tether tension T (N)",
        title=f"one impulse, ρ = {rho:g}, k₀ = {specific_drag:g} s²/m²",
    )
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


# The drift verdict's tolerance: within this fraction of the Stokes drift.
DRIFT_TOLERANCE = 0.1
# "Shifted toward the surface": the element's mean height above its tether's arc, the
# z a taut tether allows at its x, at least this fraction of the orbit radius u₀/ω. A
# taut tether keeps it at or below 0 (stretch), whatever the swing; a mean depth above
# the static hanging one would not do, since any swing on the arc rises above it.
ARC_RISE_FRACTION = 0.1
# "Keeps its loops": the path over the last period encloses at least this fraction of
# the free element's orbit.
LOOP_FRACTION = 0.25
# The never-slack threshold is pinned by the ρ grid within this factor of the
# quasi-static, inertia-free bound: set by the weight against the water's vertical drag,
# not moved by a factor by the swing or the element's inertia.
THRESHOLD_FACTOR = 1.5


def orbit_radius() -> float:
    """u₀/ω (m): the radius of the water's orbit at the element's depth."""
    return float(orbital_speed(growing_element_wave(), element_depth())) / OMEGA


def quasi_static_threshold() -> float:
    """(w₀/u₀)² = tanh² k(z + d) (–): the ρ above which the largest upward drag on an
    element held still, k₀ m_o g w₀², cannot lift its weight. By the definition of ρ,
    the inertia-free element's tether never slackens above it."""
    wave = growing_element_wave()
    return float(np.tanh(float(wave.wavenumber) * (element_depth() + DEPTH)) ** 2)


def rise_above_arc(study: TetheredStudy) -> np.ndarray:
    """Per case, the element's mean height (m) above the lowest point a taut
    (unstretched) tether allows at its horizontal position, `z_f − √(l² − (x − x_f)²)`."""
    x = study.positions[:, :, 0]
    arc = -FRAME_DEPTH - np.sqrt(np.clip(TETHER_LENGTH**2 - x**2, 0.0, None))
    return np.mean(study.positions[:, :, 2] - arc, axis=1)


def threshold_bracket(study: TetheredStudy) -> tuple[float, float] | None:
    """`(last ρ that goes slack, first ρ from which none does)`, or `None` where the
    study has no never-slack region or no slack case below it."""
    taut_from = never_slack_from(study)
    slack = study.weight_characteristic[study.slack_fraction() > 0]
    if taut_from is None or slack.size == 0:
        return None
    return float(slack.max()), taut_from


def _loop_areas(path_times: np.ndarray, positions: np.ndarray) -> np.ndarray:
    # The area each path encloses over its last wave period: a loop has one, an arc swung
    # to and fro on a taut tether has none.
    n = int(round(WAVE_PERIOD / (path_times[1] - path_times[0])))
    return np.array([_enclosed_area(p[-n:]) for p in positions])


def drift_row(free: FreeStudy) -> tuple[str, str, str, str]:
    """The free element's drift, graded at every St of the study, not only the limit."""
    ratio, st = free.drift_ratio, free.inertia_number
    close = np.abs(ratio - 1) <= DRIFT_TOLERANCE
    limit, heaviest = int(np.argmin(st)), int(np.argmax(st))
    within = st[close].max() if close.any() else float("nan")
    agreement = "yes" if close.all() else ("partly" if close[limit] else "no")
    return (
        "A free body in a wave moves on looped orbits, carried along by the wave (Stokes drift), "
        "in good agreement with potential-wave theory",
        f"drift / Stokes drift {ratio[limit]:.4f} at St = {st[limit]:.1g}; within {100 * DRIFT_TOLERANCE:.0f} % "
        f"up to St = {within:.2g}; {ratio[heaviest]:.2f} at St = {st[heaviest]:.2g} (the scallop cage, the "
        "thesis's reference organism)",
        agreement,
        "without inertia the element is a water particle, whose drift is the Stokes drift by theory, so the "
        "limit checks the integration only; the test that could fail is finite St, where the element lags the "
        f"water, drifts less and sinks (mean depth {free.mean_depth[heaviest]:.2f} m against "
        f"{free.mean_depth[limit]:.2f} m)",
    )


def loops_row(free: FreeStudy, tethered: TetheredStudy) -> tuple[str, str, str, str]:
    """The tethered element's loops and their shift toward the surface, graded off the
    tether's arc (on which a taut swing already rises above the static depth)."""
    radius = orbit_radius()
    closest = int(np.argmin(free.inertia_number))
    rise = rise_above_arc(tethered) / radius
    area = _loop_areas(tethered.times, tethered.positions)
    free_area = _loop_areas(free.times, free.positions[closest : closest + 1])[0]
    both = (rise >= ARC_RISE_FRACTION) & (area >= LOOP_FRACTION * free_area)
    rho = tethered.weight_characteristic
    return (
        "Tethered, the body keeps its loops, shifted toward the surface, and settles on a closed path near the frame",
        f"mean height above the tether's arc {rise.max():.2f} u₀/ω (ρ = {rho[np.argmax(rise)]:g}) to "
        f"{rise.min():.3f} u₀/ω (ρ = {rho[np.argmin(rise)]:g}), u₀/ω = {radius:.3f} m; the path over a period "
        f"encloses {area.max():.3f} m² (ρ = {rho[np.argmax(area)]:g}) to {area.min():.4f} m², the free orbit "
        f"{free_area:.3f} m²; both at least {ARC_RISE_FRACTION:g} u₀/ω and {100 * LOOP_FRACTION:.0f} % "
        + (f"for ρ ≤ {rho[both].max():g}" if both.any() else "for no ρ"),
        "yes" if both[int(np.argmin(rho))] else ("partly" if both.any() else "no"),
        "where the tether is slack the rising water lifts the element off its arc and it loops; a heavy "
        "element stays taut and swings on the arc, which encloses almost nothing",
    )


def back_slope_row(tethered: TetheredStudy) -> tuple[str, str, str, str]:
    share = back_slope_share(tethered)
    rho = tethered.weight_characteristic
    impulsive = tethered.slack_fraction() > 0
    mostly = impulsive & (share >= 0.9)
    return (
        "The tether force comes as impulses, only on the wave's back slope (water moving down)",
        f"{100 * share[impulsive].min():.0f}–{100 * share[impulsive].max():.0f} % of ∫T dt on the back "
        f"slope where the tether goes slack (ρ ≤ {rho[impulsive].max():g}); at least 90 % for ρ ≤ "
        f"{rho[mostly].max() if mostly.any() else float('nan'):g}",
        "yes" if share[impulsive].min() >= 0.9 else "partly",
        "the lighter the element, the more of its impulse falls on the back slope; a heavier one is "
        "slack only briefly and pulls on both slopes. Snap loads open each impulse where the element "
        "has inertia",
    )


def never_slack_row(tethered: TetheredStudy, cage: TetheredStudy) -> tuple[str, str, str, str]:
    """The never-slack region: its existence follows from ρ's definition; graded by
    where it begins, at two St, against the quasi-static bound."""
    bound = quasi_static_threshold()
    studies = (tethered, cage)
    brackets = [threshold_bracket(study) for study in studies]

    def pinned(bracket):
        return bracket is not None and bracket[0] >= bound / THRESHOLD_FACTOR and bracket[1] <= bound * THRESHOLD_FACTOR

    def said(study, bracket):
        st = float(inertia_number(study.specific_drag))
        if bracket is None:
            return f"St = {st:.2g}: none in the study"
        above = (study.weight_characteristic > bound) & (study.slack_fraction() > 0)
        lifted = "".join(
            f", ρ = {r:g} slack {100 * f:.0f} % of the time"
            for r, f in zip(study.weight_characteristic[above], study.slack_fraction()[above])
        )
        return f"St = {st:.2g}: between ρ = {bracket[0]:g} and {bracket[1]:g}{lifted}"

    exists = all(b is not None for b in brackets)
    agreement = ("yes" if all(pinned(b) for b in brackets) else "partly") if exists else "no"
    return (
        "At high weight characteristic ρ there are regions where the tether never goes slack",
        "the tether stops going slack "
        + "; ".join(said(study, b) for study, b in zip(studies, brackets))
        + f"; the quasi-static, inertia-free bound (w₀/u₀)² = {bound:.3f}",
        agreement + " (its existence follows from ρ's definition; graded: the threshold within "
        f"{THRESHOLD_FACTOR:g}× of the bound at both St)",
        "ρ is defined here so that an element held still cannot be lifted above the bound; what could fail is "
        "the threshold of the moving, elastic element with inertia. The swing and the snaps lift it a little "
        "above the bound: an element just above it still goes slack",
    )


def impulse_row(tethered: TetheredStudy) -> tuple[str, str, str, str]:
    fits = impulse_fits(tethered)
    sine = np.array([f.sine_rms for f in fits.values()])
    parabola = np.array([f.parabola_rms for f in fits.values()])
    rectangle = np.array([f.rectangle_rms for f in fits.values()])
    rhos = list(fits)
    best, worst = int(np.argmin(sine)), int(np.argmax(sine))
    return (
        "The impulse is well fitted by part of a sine or a parabola (a rectangle in rough work)",
        f"RMS misfit over the peak, best (ρ = {rhos[best]:g}) and worst (ρ = {rhos[worst]:g}) of {len(fits)} "
        f"impulses: part of a sine {100 * sine[best]:.0f} and {100 * sine[worst]:.0f} %, parabola "
        f"{100 * parabola[best]:.0f} and {100 * parabola[worst]:.0f} %, rectangle {100 * rectangle[best]:.0f} "
        f"and {100 * rectangle[worst]:.0f} %",
        "yes" if max(sine[best], parabola[best]) < 0.1 and max(sine[worst], parabola[worst]) < 0.1 else "partly",
        "sine and parabola fit equally well, the rectangle worse; the snap that opens a light "
        "element's impulse is what neither smooth shape captures",
    )


def table_markdown(rows) -> str:
    """The closing table from `(claim, jaxcable, agreement, why)` rows."""
    lines = ["| thesis's claim | jaxcable | agreement | why |", "|---|---|---|---|"]
    lines += [f"| {a} | {b} | {c} | {d} |" for a, b, c, d in rows]
    return "\n".join(lines)


def verdict_markdown(free: FreeStudy, tethered: TetheredStudy, cage: TetheredStudy, extra_rows=()) -> str:
    """The closing table: the thesis's claim, jaxcable's result, agreement and why; every
    number taken from the studies given. `extra_rows` (the integrators', the
    similarity's) are appended."""
    rows = [
        drift_row(free),
        loops_row(free, tethered),
        back_slope_row(tethered),
        never_slack_row(tethered, cage),
        impulse_row(tethered),
        *extra_rows,
    ]
    return table_markdown(rows)


# --------------------------------------------------------------------------------------
# The integrators (the thesis, ch. 3): "a step five times smaller than Simpson's gives the
# method with the trapezoid rule an accuracy like Simpson's".

STEP_RATIO = 5
# "Like Simpson's": within this factor of Simpson's error, half an order of magnitude.
SIMILAR_FACTOR = 3.0
# Problem 1 of the thesis, pre-strained so that the string stays taut: the middle mass
# (10 kg between two 1 m pieces of EF = 1e4 N) given 0.1 m/s along the string is the
# oscillator x'' = −ω² x, ω² = 2 EF/(l M), with x = (v₀/ω) sin ωt exactly.
THREAD_OMEGA = float(np.sqrt(2 * 1.0e4 / (1.0 * 10.0)))  # rad/s
THREAD_SPEED = 0.1  # m/s
THREAD_SPAN = 0.64  # s, 4.6 periods
THREAD_STEPS = (0.04, 0.02, 0.01, 0.005, 0.0025, 0.00125, 0.000625)  # s, Simpson's
# Problem 3, the tethered element in the wave, from its static hanging over the two ramp
# periods and two more; output every 0.05 s, on both methods' step grids.
WAVE_SPAN = 4 * WAVE_PERIOD  # s
WAVE_OUTPUT = 0.05  # s
WAVE_STEPS = (0.05, 0.025, 0.01, 0.005, 0.0025, 0.001)  # s, Simpson's
WAVE_WEIGHTS = (0.5, 2.0)  # ρ: a tether that snaps, one that stays taut


def evaluations_per_step(solver) -> int:
    """Vector-field evaluations one step of a Picard solver costs: the Euler predictor's,
    and one (trapezoid) or two (Simpson) an iteration."""
    from jaxcable import PicardSimpson

    return 1 + (2 if isinstance(solver, PicardSimpson) else 1) * solver.iterations


@dataclasses.dataclass
class QuadratureStudy:
    """Simpson's rule at step h against the trapezoid rule at h/5, both by Picard
    iteration (3 iterations each), on one problem: per Simpson step `simpson_step` (s),
    each method's error (relative to the problem's scale, `inf` where the run failed) and
    the vector-field evaluations it took. For the wave problem, `case` names the rows
    (one per ρ) of the `(cases, steps)` error arrays."""

    problem: str
    case: list[str]
    simpson_step: np.ndarray
    simpson_error: np.ndarray
    trapezoid_error: np.ndarray
    simpson_evaluations: np.ndarray
    trapezoid_evaluations: np.ndarray

    @property
    def error_ratio(self) -> np.ndarray:
        """The trapezoid's error at h/5 over Simpson's at h: 1 where the claim holds."""
        return self.trapezoid_error / self.simpson_error

    @property
    def similar(self) -> np.ndarray:
        return (self.error_ratio <= SIMILAR_FACTOR) & (self.error_ratio >= 1 / SIMILAR_FACTOR)


def _picard_solvers():
    from jaxcable import PicardSimpson, PicardTrapezoid

    return PicardSimpson(), PicardTrapezoid()


def thread_quadrature_study(steps=THREAD_STEPS) -> QuadratureStudy:
    """The thesis's problem 1 (taut): the error is the largest distance from the exact
    x(t) at the output times (every largest step), over the amplitude v₀/ω."""
    import diffrax
    import jax.numpy as jnp

    omega, v0 = THREAD_OMEGA, THREAD_SPEED
    term = diffrax.ODETerm(lambda t, y, args: jnp.stack([y[1], -(omega**2) * y[0]]))
    ts = np.arange(1, round(THREAD_SPAN / max(steps)) + 1) * max(steps)
    exact = v0 / omega * np.sin(omega * ts)

    def error_and_evaluations(solver, h):
        solution = diffrax.diffeqsolve(
            term,
            solver,
            0.0,
            THREAD_SPAN,
            jnp.asarray(h),  # an array: one compile for every step
            jnp.array([0.0, v0]),
            saveat=diffrax.SaveAt(ts=jnp.asarray(ts)),
            stepsize_controller=diffrax.ConstantStepSize(),
            max_steps=100_000,
            throw=False,
        )
        assert solution.ys is not None
        error = np.max(np.abs(np.asarray(solution.ys[:, 0]) - exact)) / (v0 / omega)
        steps_taken = int(solution.stats["num_steps"])
        return (error if np.isfinite(error) else np.inf), steps_taken * evaluations_per_step(solver)

    simpson, trapezoid = _picard_solvers()
    s = [error_and_evaluations(simpson, h) for h in steps]
    t = [error_and_evaluations(trapezoid, h / STEP_RATIO) for h in steps]
    return QuadratureStudy(
        problem="problem 1: a mass on a taut string",
        case=["x"],
        simpson_step=np.asarray(steps, dtype=float),
        simpson_error=np.array([[e for e, _ in s]]),
        trapezoid_error=np.array([[e for e, _ in t]]),
        simpson_evaluations=np.array([n for _, n in s]),
        trapezoid_evaluations=np.array([n for _, n in t]),
    )


def wave_quadrature_study(steps=WAVE_STEPS, weight_characteristics=WAVE_WEIGHTS) -> QuadratureStudy:
    """The tethered element in the wave (k₀ = 5 s²/m²) at each ρ: the error is the
    largest difference in tether tension at the output times from Dopri5 at
    rtol = atol = 1e-12, over the reference's peak tension."""
    import diffrax

    ts = np.arange(1, round(WAVE_SPAN / WAVE_OUTPUT) + 1) * WAVE_OUTPUT

    def tension(config):
        result = sweep(
            lambda weight_characteristic: growing_element(weight_characteristic, specific_drag=TETHERED_SPECIFIC_DRAG),
            {"weight_characteristic": weight_characteristics},
            WAVE_SPAN,
            ts=ts,
            solver=config,
        )
        steps_taken = np.asarray(result.simulation.stats["num_steps"])
        values = np.asarray(result.simulation.tension[:, :, 0])
        return np.where(np.asarray(result.success)[:, None], values, np.nan), steps_taken

    reference, _ = tension(SolverConfig(rtol=1e-12, atol=1e-12))
    peak = reference.max(axis=1)

    def errors_and_evaluations(solver, h):
        config = SolverConfig(solver, dt0=h, stepsize_controller=diffrax.ConstantStepSize(), max_steps=200_000)
        values, steps_taken = tension(config)
        error = np.max(np.abs(values - reference), axis=1) / peak
        return np.where(np.isfinite(error), error, np.inf), int(steps_taken.max()) * evaluations_per_step(solver)

    simpson, trapezoid = _picard_solvers()
    s = [errors_and_evaluations(simpson, h) for h in steps]
    t = [errors_and_evaluations(trapezoid, h / STEP_RATIO) for h in steps]
    return QuadratureStudy(
        problem=f"problem 3: the tethered element in the wave (k₀ = {TETHERED_SPECIFIC_DRAG:g} s²/m²)",
        case=[f"ρ = {r:g}" for r in weight_characteristics],
        simpson_step=np.asarray(steps, dtype=float),
        simpson_error=np.stack([e for e, _ in s], axis=1),
        trapezoid_error=np.stack([e for e, _ in t], axis=1),
        simpson_evaluations=np.array([n for _, n in s]),
        trapezoid_evaluations=np.array([n for _, n in t]),
    )


# --------------------------------------------------------------------------------------
# The thesis's similarity (eq. 7): T = (EF/(l ω)) u₀ η(α, ξ, ρ, τ), x = (u₀/ω) χ(α, ξ, ρ, τ).
# The abstract does not define α. Written in the scales of eq. 7, the element's equation
# of motion, M ẍ = k₀ m_o g |u − ẋ|(u − ẋ) − W e_z − T e, divided by the drag at u₀,
# k₀ m_o g u₀², reads
#     St χ'' = |v − χ'|(v − χ') − ρ e_z − α η e,   α = EF / (l ω k₀ m_o g u₀),
# so the group left beside ξ and ρ is α, the tension scale of eq. 7 over the drag at u₀;
# it is taken as the thesis's α here. jaxcable's element keeps its inertia, St, which the
# thesis's model does not have; the wave adds k u₀/ω, k z and k d, the tether its mass
# over the element's. Scenes that share every group must give the same η and χ; the
# thesis's reduction to (α, ξ, ρ) holds only as far as St does not matter.

SIMILARITY_WEIGHT = 0.2  # ρ: light enough to go slack, possible up to k₀ = 50 s²/m²


@dataclasses.dataclass
class SimilarScene:
    """One scene of the similarity study: its dimensional choices (`units` (L, T, M)
    for [`jaxcable.examples.growing_element`][], EF (N) and k₀ (s²/m²) in the default
    scene's units), its groups α, ξ, ρ, St, and its response in the thesis's variables
    over τ = ω t: `eta` `(times,)` and `chi` `(times, 2)`, the element's x and z from
    the frame point over u₀/ω."""

    label: str
    units: tuple[float, float, float]
    tether_stiffness: float
    specific_drag: float
    alpha: float
    xi: float
    rho: float
    inertia: float
    tau: np.ndarray
    eta: np.ndarray
    chi: np.ndarray
    success: bool


def similar_scene(
    label: str,
    units=(1.0, 1.0, 1.0),
    *,
    tether_stiffness: float = 1.0e5,
    specific_drag: float = TETHERED_SPECIFIC_DRAG,
    weight_characteristic: float = SIMILARITY_WEIGHT,
    periods: int = 6,
    samples_per_period: int = 72,
) -> SimilarScene:
    """Run the tethered element from its static hanging for `periods` wave periods and
    return its response in eq. 7's variables, sampled at the same τ whatever its units."""
    length, time_unit, mass = units

    def build(weight_characteristic):
        return growing_element(
            weight_characteristic, specific_drag=specific_drag, tether_stiffness=tether_stiffness, units=units
        )

    model, env = build(weight_characteristic)
    (wave,) = env.waves
    assert isinstance(wave, Airy)
    omega = float(wave.angular_frequency)
    z = element_depth() * length
    u0 = float(orbital_speed(wave, z))
    tau = np.linspace(0.0, 2 * np.pi * periods, periods * samples_per_period + 1)
    result = sweep(
        build,
        {"weight_characteristic": [weight_characteristic]},
        float(tau[-1] / omega),
        ts=tau / omega,
        solver=SolverConfig(rtol=1e-10, atol=1e-10),
    )
    body = model.body
    stiffness = tether_stiffness * mass * length / time_unit**2
    drag = float(body.specific_drag[1]) * float(body.organism_mass[1]) * float(env.gravity)
    tether = TETHER_LENGTH * length
    frame = np.asarray(model.node_positions[0])
    positions = np.asarray(result.simulation.positions[0, :, 1, :]) - frame
    return SimilarScene(
        label=label,
        units=(float(length), float(time_unit), float(mass)),
        tether_stiffness=float(tether_stiffness),
        specific_drag=float(specific_drag),
        alpha=stiffness / (tether * omega * drag * u0),
        xi=tether * omega / u0,
        rho=float(weight_characteristic),
        inertia=float(body.mass[1]) * omega / (drag * u0),
        tau=tau,
        eta=np.asarray(result.simulation.tension[0, :, 0]) * tether * omega / (stiffness * u0),
        chi=positions[:, [0, 2]] * omega / u0,
        success=bool(result.success[0]),
    )


def response_difference(a: SimilarScene, b: SimilarScene, settle_periods: int = 2) -> float:
    """The largest difference of η, and of χ, between two scenes after the ramp, each
    over a's largest value of it (the larger of the two relative differences)."""
    keep = a.tau >= 2 * np.pi * settle_periods
    eta = np.max(np.abs(a.eta[keep] - b.eta[keep])) / np.max(np.abs(a.eta[keep]))
    chi = np.max(np.abs(a.chi[keep] - b.chi[keep])) / np.max(np.abs(a.chi[keep]))
    return float(max(eta, chi))


# Scenes that share every group agree to this fraction (the solver's rtol is 1e-10);
# a change of α must move the response by more than DIFFERENT.
SAME = 1e-4
DIFFERENT = 0.1


def similarity_study(periods: int = 6, samples_per_period: int = 72) -> list[SimilarScene]:
    """The default scene (ρ = 0.2, k₀ = 5 s²/m²); the same at Froude scale 4 (lengths ×4,
    times ×2, masses ×64: the same water and gravity); in arbitrary units (lengths ×0.5,
    times ×0.8, masses ×3: another gravity and water); with α doubled (EF ×2); and with
    St ten times smaller at the same α, ξ and ρ (k₀ and EF ×10)."""
    size = dict(periods=periods, samples_per_period=samples_per_period)
    return [
        similar_scene("the default scene", **size),
        similar_scene("Froude scale 4", (4.0, 2.0, 64.0), **size),
        similar_scene("arbitrary units", (0.5, 0.8, 3.0), **size),
        similar_scene("α × 2", tether_stiffness=2.0e5, **size),
        similar_scene("St / 10", tether_stiffness=1.0e6, specific_drag=10 * TETHERED_SPECIFIC_DRAG, **size),
    ]


def _groups(scene: SimilarScene) -> np.ndarray:
    return np.array([scene.alpha, scene.xi, scene.rho, scene.inertia])


def similarity_classes(scenes: list[SimilarScene]) -> dict[str, list[tuple[SimilarScene, float]]]:
    """Each scene after the first, with its response's difference from the first, sorted
    by how its groups differ: `"same"` (α, ξ, ρ and St equal to 1e-9), `"alpha"` (α
    differs), `"inertia"` (only St differs)."""
    base = _groups(scenes[0])
    classes = {"same": [], "alpha": [], "inertia": []}
    for scene in scenes[1:]:
        differs = ~np.isclose(_groups(scene), base, rtol=1e-9, atol=0.0)
        kind = "same" if not differs.any() else ("alpha" if differs[0] else "inertia")
        classes[kind].append((scene, response_difference(scenes[0], scene)))
    return classes


def similarity_row(scenes: list[SimilarScene]) -> tuple[str, str, str, str]:
    """The thesis's eq. 7 as a test that could fail both ways."""
    classes = similarity_classes(scenes)
    base = scenes[0]

    def listed(kind):
        return ", ".join(f"{scene.label} {d:.1e}" for scene, d in classes[kind])

    same = all(d <= SAME for _, d in classes["same"]) and bool(classes["same"])
    alpha = all(d >= DIFFERENT for _, d in classes["alpha"]) and bool(classes["alpha"])
    inertia = [d for _, d in classes["inertia"]]
    if same and alpha:
        agreement = "yes" if all(d < DIFFERENT for d in inertia) else "partly"
    else:
        agreement = "no"
    return (
        "In dimensionless form the tension and the position depend on α, ξ, ρ and τ alone (eq. 7)",
        f"at α = {base.alpha:.4g}, ξ = {base.xi:.4g}, ρ = {base.rho:g}, St = {base.inertia:.3g}, the largest "
        f"difference of η or χ from the default scene: same groups in other units {listed('same')} (at most "
        f"{SAME:g}); α changed: {listed('alpha')} (at least {DIFFERENT:g}); only St changed: {listed('inertia')}",
        agreement,
        "α is taken as EF/(l ω k₀ m_o g u₀), the group the equation of motion leaves beside ξ and ρ (the "
        "abstract names it only). The reduction holds with St as a fourth group: the element's inertia, "
        "which the thesis's element lacks, changes the response at the same α, ξ and ρ",
    )


def quadrature_row(*studies: QuadratureStudy) -> tuple[str, str, str, str]:
    """The thesis's claim that the trapezoid rule at a fifth of Simpson's step matches
    Simpson's accuracy, from each problem's errors and costs."""
    parts, similar = [], []
    for study in studies:
        for case, ratio, ok in zip(study.case, study.error_ratio, study.similar):
            similar.append(ok)
            held = study.simpson_step[ok]
            where = f"at h = {', '.join(f'{h:g}' for h in held)} s" if held.size else "at no step"
            parts.append(
                f"{study.problem}, {case}: trapezoid/Simpson error {ratio.min():.2g}–{ratio.max():.3g} over "
                f"h = {study.simpson_step.max():g}–{study.simpson_step.min():g} s, within {SIMILAR_FACTOR:g}× {where}"
            )
    cost = studies[0].trapezoid_evaluations / studies[0].simpson_evaluations
    similar = np.concatenate(similar)
    agreement = "yes" if similar.all() else ("partly" if similar.any() else "no")
    return (
        "The trapezoid rule with a step five times smaller gives the Picard method an accuracy like Simpson's",
        "; ".join(parts) + f"; the trapezoid run takes {cost.mean():.2f}× Simpson's evaluations (3 iterations each)",
        agreement,
        "second order against fourth: the error ratio grows as 1/h² and the two meet at one step only, where the "
        "error is coarse; a slack tether's kink costs Simpson its order, and there the trapezoid holds its own. "
        "At equal accuracy on smooth problems Simpson is the cheaper",
    )


def plot_quadrature(*studies: QuadratureStudy, axes=None):
    """Error against vector-field evaluations for Simpson at h and the trapezoid at h/5,
    one panel per problem, each pair joined by a thin line."""
    import matplotlib.pyplot as plt

    if axes is None:
        _, axes = plt.subplots(1, len(studies), figsize=(5.5 * len(studies), 3.8), squeeze=False)
        axes = axes[0]
    for ax, study in zip(axes, studies):
        for k, case in enumerate(study.case):
            line = ax.loglog(study.simpson_evaluations, study.simpson_error[k], "o-", label=f"Simpson at h, {case}")
            ax.loglog(
                study.trapezoid_evaluations,
                study.trapezoid_error[k],
                "s--",
                color=line[0].get_color(),
                label=f"trapezoid at h/5, {case}",
            )
            for pair in zip(
                study.simpson_evaluations, study.trapezoid_evaluations, study.simpson_error[k], study.trapezoid_error[k]
            ):
                ax.plot(pair[:2], pair[2:], color="0.8", lw=0.6, zorder=0)
        ax.set(
            xlabel="vector-field evaluations (3 Picard iterations a step)",
            ylabel="largest error / scale" + (" (x over v₀/ω)" if study.case == ["x"] else " (T over its peak)"),
            title=study.problem,
        )
        ax.legend(fontsize=7)
    return axes


def plot_similarity(scenes: list[SimilarScene], settle_periods: int = 4, axes=None):
    """η and the element's height χ_z over τ for each scene of the similarity study, over
    the last periods: similar scenes lie on one curve."""
    import matplotlib.pyplot as plt

    if axes is None:
        _, axes = plt.subplots(2, 1, figsize=(9, 5), sharex=True)
    styles = ["-", "--", ":", "-", "-"]
    for scene, style in zip(scenes, styles):
        keep = scene.tau >= 2 * np.pi * settle_periods
        label = f"{scene.label}: α = {scene.alpha:.3g}, St = {scene.inertia:.2g}"
        axes[0].plot(scene.tau[keep] / (2 * np.pi), scene.eta[keep], style, lw=1.2, label=label)
        axes[1].plot(scene.tau[keep] / (2 * np.pi), scene.chi[keep, 1], style, lw=1.2, label=label)
    base = scenes[0]
    axes[0].set(
        ylabel="η = T l ω / (EF u₀)",
        title=f"eq. 7's similarity: ξ = {base.xi:.3g}, ρ = {base.rho:g} in every scene",
    )
    axes[1].set(xlabel="τ / 2π = t / T_w (wave periods)", ylabel="χ_z = (z − z_f) ω / u₀")
    axes[0].legend(fontsize=7, loc="upper right")
    return axes
