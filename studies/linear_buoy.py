"""A linear system in an irregular sea, and its closed form (issue 21): a submerged buoy
on a vertical tether of one segment, without drag.

It heaves as a linear oscillator: mass M = M_b + C_a ρ V + m L₀/3 (the buoy, its added
mass and the tether's share of the consistent mass matrix), stiffness k = EA/L₀, damping
c = C_v/L₀ (the Kelvin–Voigt tether), forced by Froude–Krylov and added mass on the
water's vertical acceleration at the buoy, (1 + C_a) ρ V ∂w/∂t, with
∂w/∂t = −ω² sinh k(z + d)/sinh kd · η per component. The tether's tension moves by
T' = k x + c ẋ, so per unit wave amplitude

    H_T(ω) = (k + icω) (1 + C_a) ρ V ω² sinh k(z + d)/sinh kd / (k − M ω² + icω),

and its variance in a sea of spectrum S is ∫ |H_T|² S dω. The closed form here is numpy
and scipy only: DNV-RP-C205's JONSWAP normalised by scipy's quadrature, the dispersion
relation by Brent's method. The buoy's sway on the tether is a pendulum of stiffness T₀/S (the
static tension over the stretched length), which couples to the tension at second order.

The sea's components sit on multiples of Δω = 2π/256 s, so over exactly one repeat
period, 256 s, the cross terms of the variance vanish: the record's variance is the
discrete sum Σ |H_T(ω_i)|² a_i²/2 with no sampling scatter, which differs from the
integral by the band's truncation and the midpoint rule's O(Δω²) error. The start's
transient decays as e^(−ζω_n t), e^(−5.8) by `START`.

Used by `tests/test_irregular_response.py` and `validation/irregular_response.py`.
"""

import numpy as np
from scipy import integrate, optimize

import jaxcable as jc

RHO, G, DEPTH = 1025.0, 9.81, 50.0
VOLUME, BUOY_MASS, ADDED_MASS = 2.0, 1000.0, 1.0
LINE_MASS, LENGTH = 2.0, 38.0
NATURAL, DAMPING_RATIO = 1.2, 0.08  # rad/s, –
MASS = BUOY_MASS + ADDED_MASS * RHO * VOLUME + LINE_MASS * LENGTH / 3
STIFFNESS = MASS * NATURAL**2  # N/m
DAMPING = 2 * DAMPING_RATIO * MASS * NATURAL  # N·s/m
REPEAT = 256.0  # s
STEP = 2 * np.pi / REPEAT  # rad/s
COMPONENTS, BAND = 120, (24.5 * STEP, 144.5 * STEP)  # multiples of Δω, 0.60 to 3.55 rad/s
TP, GAMMA = 6.0, 3.3
START = 60.0  # s: the ramp (20 s) and the transient over
DT_OUT = 0.25  # s


def tethered_buoy() -> jc.CableNetwork:
    """The buoy at z = −10 m on 38 m of tether from an anchor on the bed at 50 m."""
    line = jc.LineType(
        LINE_MASS,
        0.01,
        jc.KelvinVoigt(STIFFNESS * LENGTH, 0.0, DAMPING * LENGTH),
        area=1e-6,  # the tether's own Froude–Krylov force: 1e-5 of the buoy's
        normal_drag=0.0,
        tangential_drag=0.0,
        normal_added_mass=0.0,
    )
    return jc.CableNetwork.from_branches(
        np.array([[0.0, 0.0, -DEPTH], [0.0, 0.0, -10.0]]),
        [jc.Branch(0, 1, line, LENGTH, 1)],
        constraints={0: jc.Fixed()},
        bodies={1: jc.Body(mass=BUOY_MASS, volume=VOLUME, added_mass=ADDED_MASS)},
    )


def still_water() -> jc.Environment:
    return jc.Environment(RHO, G, depth=DEPTH)


def sea(seed, significant_height: float) -> jc.WaveComponents:
    """The JONSWAP sea (T_p = 6 s, γ = 3.3) of `significant_height` (m), from `seed`."""
    return jc.WaveComponents.from_spectrum(
        jc.Jonswap(significant_height, TP, GAMMA), DEPTH, seed=seed, components=COMPONENTS, frequencies=BAND
    )


def sweep_seeds(significant_height: float, seeds: int, static: jc.StaticSolution) -> tuple[jc.SweepResult, np.ndarray]:
    """Tension histories of `seeds` seeds from one compiled sweep, from the still-water
    `static` equilibrium, the sea ramped on over 20 s, over `START` plus one repeat
    period; and the output times (s)."""
    model = tethered_buoy()

    def build(seed):
        return model, jc.Environment(RHO, G, depth=DEPTH, waves=sea(seed, significant_height), wave_ramp=20.0)

    ts = np.arange(0.0, START + REPEAT + 1e-9, DT_OUT)
    result = jc.sweep(
        build,
        {"seed": np.arange(float(seeds))},
        ts[-1],
        ts=ts,
        initial=static.state,
        solver=jc.SolverConfig(rtol=1e-8, atol=1e-8),
    )
    return result, ts


def wavenumber(omega: float) -> float:
    def residual(k):
        return k * np.tanh(k * DEPTH) - omega**2 / G

    return float(optimize.root_scalar(residual, bracket=(1e-9, 2 * omega**2 / G + 1.0), xtol=1e-14).root)


def tension_response(omega: float, z: float) -> complex:
    """H_T(ω) (N/m) at the buoy's depth z (m) (module docstring)."""
    k = wavenumber(omega)
    force = (1 + ADDED_MASS) * RHO * VOLUME * omega**2 * np.sinh(k * (z + DEPTH)) / np.sinh(k * DEPTH)
    return (STIFFNESS + 1j * DAMPING * omega) * force / (STIFFNESS - MASS * omega**2 + 1j * DAMPING * omega)


def jonswap(omega, significant_height: float):
    """DNV-RP-C205's JONSWAP (m²·s/rad), normalised to H_s²/16 by quadrature."""
    wp = 2 * np.pi / TP

    def shape(w):
        sigma = np.where(w <= wp, 0.07, 0.09)
        return w**-5 * np.exp(-1.25 * (wp / w) ** 4) * GAMMA ** np.exp(-((w - wp) ** 2) / (2 * sigma**2 * wp**2))

    total = integrate.quad(shape, 0, wp, limit=400)[0] + integrate.quad(shape, wp, np.inf, limit=400)[0]
    return significant_height**2 / 16 * shape(omega) / total


def response_moment(order: int, z: float, significant_height: float) -> float:
    """∫ ω^n |H_T|² S dω (N²·(rad/s)^n): n = 0 the tension's variance, n = 2 its rate's."""

    def f(w):
        return w**order * abs(tension_response(w, z)) ** 2 * jonswap(w, significant_height)

    return integrate.quad(f, 0.05, 10.0, limit=400, points=[2 * np.pi / TP, NATURAL])[0]


def linear_tension(seed, z: float, ts, significant_height: float) -> tuple[np.ndarray, float]:
    """The closed form's tension change (N) at `ts` for one seed's components,
    T'(t) = −Σ Re[H_T(ω_i) a_i e^{−iθ₀_i} e^{iω_i t}] (the sign of ∂w/∂t = −ω² ... η),
    and its discrete variance Σ |H_T(ω_i)|² a_i²/2 (N²)."""
    one = sea(seed, significant_height)
    omega = 2 * np.pi / np.asarray(one.periods)
    gain = np.array([tension_response(w, z) for w in omega])
    phasors = gain * np.asarray(one.amplitudes) * np.exp(-1j * np.asarray(one.phases))
    return -np.real(np.exp(1j * np.outer(ts, omega)) @ phasors), float(np.sum(np.abs(phasors) ** 2 / 2))


def compare(result: jc.SweepResult, ts, static: jc.StaticSolution, significant_height: float) -> dict:
    """The sweep against the closed form, seed by seed, over one repeat period after
    `START`: the tension's variance against ∫ |H_T|² S dω and the discrete sum, its mean
    against the rest tension, the RMS of the pointwise difference, each seed's maximum,
    and the extremes' statistics of both; and the buoy's largest heave and sway (m) from
    its rest. Tensions in N."""
    z, rest = float(static.state.positions[1, 2]), float(static.tension[0])
    variance = response_moment(0, z, significant_height)
    rate = response_moment(2, z, significant_height)
    period = (ts >= START) & (ts < START + REPEAT)
    keep = ts >= START
    seeds = int(result.n_cases)
    rows, linear = [], []
    for seed in range(seeds):
        tension = np.asarray(result.simulation.tension[seed, :, 0])
        closed, discrete = linear_tension(seed, z, ts, significant_height)
        linear.append(rest + closed)
        error = tension[period] - rest - closed[period]
        rows.append(
            {
                "variance_over_integral": float(np.var(tension[period]) / variance),
                "discrete_over_integral": discrete / variance,
                "mean_offset_over_sigma": float((np.mean(tension[period]) - rest) / np.sqrt(variance)),
                "rms_error_over_sigma": float(np.sqrt(np.mean(error**2) / variance)),
                "max_error_over_sigma": float(np.max(np.abs(error)) / np.sqrt(variance)),
            }
        )
    buoy = np.asarray(result.simulation.positions[:, :, 1]) - np.asarray(static.state.positions[1])
    simulated = result.tension_extremes(START)
    reference = jc.extreme_statistics(np.stack(linear)[:, keep], ts[keep])
    duration = ts[-1] - START
    return {
        "significant_height": significant_height,
        "seeds": seeds,
        "rest_tension": rest,
        "sigma": float(np.sqrt(variance)),
        "rice_mpm": rest + np.sqrt(variance) * np.sqrt(2 * np.log(np.sqrt(rate / variance) / (2 * np.pi) * duration)),
        "per_seed": rows,
        "maxima": np.asarray(simulated.maxima).tolist(),
        "linear_maxima": np.asarray(reference.maxima).tolist(),
        "mpm": float(simulated.most_probable_maximum),
        "linear_mpm": float(reference.most_probable_maximum),
        "spread": float(simulated.spread),
        "linear_spread": float(reference.spread),
        "standard_error": float(simulated.standard_error),
        "rayleigh_mpm": float(simulated.rayleigh_mpm),
        "largest_heave": float(np.abs(buoy[..., 2]).max()),
        "largest_sway": float(np.linalg.norm(buoy[..., :2], axis=-1).max()),
    }
