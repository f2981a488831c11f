"""Seed 001's plane problems (Zhukov 2005, ch. 4–5): the Stokes drift, the free growing
element's drift, and the tethered element's impulses and slack "shadows".

The references are independent of jaxcable's integrator: the Stokes drift is checked
against a water particle integrated by scipy through the same linear velocity field, and
the drift measurement and impulse fits against curves with known answers.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import jaxcable as jc
from studies import seed001 as study


@pytest.mark.parametrize("height, depth, z0", [(0.5, 20.0, -3.5), (0.3, 5.0, -2.0)], ids=["deep", "intermediate"])
def test_stokes_drift_matches_a_water_particle(height, depth, z0):
    # A particle moved by the linear field itself drifts at the Stokes drift up to terms
    # of relative order (k a_x)², a_x its orbit's half-width: measured 1.00066 and 1.00053
    # here, with (k a_x)² = 6.5e-4 and 8.9e-4. Tolerance 2 (k a_x)².
    period = 4.0
    wave = jc.Airy(height, period, depth)
    k, a, omega = float(wave.wavenumber), height / 2, 2 * np.pi / period

    def velocity(t, y):
        x, z = y
        theta = k * x - omega * t
        return [
            a * omega * np.cosh(k * (z + depth)) / np.sinh(k * depth) * np.cos(theta),
            a * omega * np.sinh(k * (z + depth)) / np.sinh(k * depth) * np.sin(theta),
        ]

    solution = solve_ivp(velocity, [0, 30 * period], [0.0, z0], rtol=1e-11, atol=1e-12, dense_output=True)
    t = np.linspace(4 * period, 30 * period, 26 * 200 + 1)
    x, z = solution.sol(t)
    drift, mean_depth = study.phase_locked_drift(t, x, z)
    half_width = a * np.cosh(k * (mean_depth + depth)) / np.sinh(k * depth)
    assert drift / float(wave.stokes_drift(mean_depth)) == pytest.approx(1.0, abs=2 * (k * half_width) ** 2)


def test_phase_locked_drift_of_a_trochoid():
    # A looped path x = u t + r cos ω't, z = r sin ω't drifts at u exactly, whatever the
    # window; a fixed count of wave periods would not cancel the loop (ω' ≠ 2π/T).
    t = np.linspace(3.0, 83.0, 8001)
    omega = 2 * np.pi / 4.1
    x, z = 0.02 * t + 0.3 * np.cos(omega * t), -3.0 + 0.3 * np.sin(omega * t)
    drift, depth = study.phase_locked_drift(t, x, z)
    assert drift == pytest.approx(0.02, rel=1e-4)
    assert depth == pytest.approx(-3.0, abs=5e-3)


@pytest.mark.parametrize("shape", ["sine", "parabola"])
def test_fit_impulse_recovers_exact_shapes(shape):
    t = np.linspace(0.0, 4.0, 401)
    s = (t - 1.0) / 2.0
    inside = (s > 0) & (s < 1)
    if shape == "sine":
        tension = np.where(inside, 80.0 * np.sin(np.pi * s), 0.0)
    else:
        tension = np.where(inside, 200.0 * s * (1 - s), 0.0)
    fit = study.fit_impulse(t, tension, tension <= 0)
    # The impulse's window runs from the last slack sample before it to the first after,
    # here the exact ends, and the sine's phases 0 and π lie on its grid: both fits are
    # exact, and the rectangle is not.
    assert getattr(fit, f"{shape}_rms") < 1e-9
    assert fit.rectangle_rms > 0.15


@pytest.fixture(scope="module")
def free():
    # The thesis's inertia-free limit (St = 1.2e-4) and the scallop cage (St = 1.2).
    return study.free_study((0.5, 5000.0), **study.SMALL)


def test_free_element_drifts_at_the_stokes_drift_without_inertia(free):
    # Tolerance 1 %: Stokes' formula leaves out terms of relative order (k a_x)² = 0.25 %
    # at this depth (a water particle in this field drifts at 1.0027 of it), and the
    # element's inertia at St = 1.2e-4 leaves a slip of order √St ≈ 1 % of the water's
    # speed, whose effect on the drift measured under 0.1 % from St = 1.2e-3 down.
    assert free.success.all()
    assert free.inertia_number[1] == pytest.approx(1.2e-4, rel=0.05)
    assert free.drift_ratio[1] == pytest.approx(1.0, abs=0.01)


def test_free_cage_lags_the_water(free):
    # With inertia (St = 1.2) drag alone cannot keep the cage with the water: it drifts
    # at a third of the Stokes drift and sinks out of the orbits it started in.
    assert free.drift_ratio[0] < 0.5
    assert free.mean_depth[0] < free.mean_depth[1] - 0.2


@pytest.fixture(scope="module")
def tethered():
    return study.tethered_study((0.2, 2.0), **study.SMALL)


def test_tethered_light_element_loads_its_tether_on_the_back_slope(tethered):
    assert tethered.success.all()
    slack = tethered.slack_fraction()
    share = study.back_slope_share(tethered)
    assert slack[0] > 0.3
    assert share[0] > 0.9
    _, shadow = study.shadow_map(tethered)
    assert shadow[0].max() == 1.0  # some phase of the wave is always in shadow


def test_tethered_heavy_element_never_goes_slack(tethered):
    assert tethered.slack_fraction()[1] == 0.0
    # Taut throughout, it pulls on the tether with at least its weight less the drag the
    # rising water can exert, and at most its weight plus that drag: ρ = 2 gives
    # T/W within 1 ± 1/2 in the quasi-static limit; inertia widens it a little.
    ratio = tethered.tension[1] / tethered.weight[1]
    assert 0.3 < ratio.min() < 1.0 < ratio.max() < 1.7
