"""Zhukov's plane problems (Zhukov 2005, ch. 4–5): the Stokes drift, the free growing
element's drift, and the tethered element's impulses and slack "shadows".

The references are independent of jaxcable's integrator: the Stokes drift is checked
against a water particle integrated by scipy through the same linear velocity field, and
the drift measurement and impulse fits against curves with known answers.
"""

import jax
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import jaxcable as jc
from jaxcable.examples import _growing_element as scene
from studies import growing_elements as study


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


@pytest.mark.slow
def test_tethered_light_element_loads_its_tether_on_the_back_slope(tethered):
    assert tethered.success.all()
    slack = tethered.slack_fraction()
    share = study.back_slope_share(tethered)
    assert slack[0] > 0.3
    assert share[0] > 0.9
    _, shadow = study.shadow_map(tethered)
    assert shadow[0].max() == 1.0  # some phase of the wave is always in shadow


@pytest.mark.slow
def test_tethered_heavy_element_never_goes_slack(tethered):
    assert tethered.slack_fraction()[1] == 0.0
    # Taut throughout, it pulls on the tether with at least its weight less the drag the
    # rising water can exert, and at most its weight plus that drag: ρ = 2 gives
    # T/W within 1 ± 1/2 in the quasi-static limit; inertia widens it a little.
    ratio = tethered.tension[1] / tethered.weight[1]
    assert 0.3 < ratio.min() < 1.0 < ratio.max() < 1.7


@pytest.mark.slow
def test_tethered_light_element_rises_off_its_arc_and_the_heavy_one_does_not(tethered):
    # A taut tether keeps the element on its arc, below it by the stretch, whatever it
    # swings; only a slack one lets the water lift it off. So the light element's rise is
    # physics, and the heavy element sits its mean stretch T l / EF (3 mm) below the arc;
    # 10 %: the stretch acts along the tether, which tilts by up to 8° here.
    rise = study.rise_above_arc(tethered)
    assert rise[0] > study.ARC_RISE_FRACTION * study.orbit_radius()
    stretch = np.mean(tethered.tension[1]) * scene.TETHER_LENGTH / scene.TETHER_STIFFNESS
    assert rise[1] == pytest.approx(-stretch, rel=0.1)


def test_quasi_static_threshold_is_the_waters_velocity_ratio():
    # (w₀/u₀)² from the wave's own velocity field over a period, against tanh² k(z + d).
    wave = scene.growing_element_wave()
    t = np.linspace(0.0, scene.WAVE_PERIOD, 721)
    points = np.tile([0.0, 0.0, scene.element_depth()], (t.size, 1))
    velocity = np.asarray(jax.vmap(wave.velocity)(points, t))
    ratio = np.max(np.abs(velocity[:, 2])) / np.max(np.abs(velocity[:, 0]))
    assert study.quasi_static_threshold() == pytest.approx(ratio**2, rel=1e-4)


@pytest.fixture(scope="module")
def thread():
    return study.thread_quadrature_study()


def test_thread_quadrature_orders_and_the_five_times_claim(thread):
    # Problem 1 (taut) against its closed form: Simpson by 3 Picard iterations is fourth
    # order and the trapezoid second, so halving h divides their errors by 16 and 4 on
    # the finest steps, and the trapezoid's error at h/5 over Simpson's at h grows by 4.
    simpson, trapezoid = thread.simpson_error[0], thread.trapezoid_error[0]
    np.testing.assert_allclose(simpson[-3:-1] / simpson[-2:], 16.0, rtol=0.05)
    np.testing.assert_allclose(trapezoid[-3:-1] / trapezoid[-2:], 4.0, rtol=0.02)
    ratio = thread.error_ratio[0]
    np.testing.assert_allclose(ratio[-2:] / ratio[-3:-1], 4.0, rtol=0.05)
    # So "like Simpson's" holds near one step only, and the row says so from the numbers.
    assert thread.similar.any() and not thread.similar.all()
    assert study.quadrature_row(thread)[2] == "partly"
    # Three iterations a step: Simpson 7 evaluations, the trapezoid 4 at five times the steps.
    np.testing.assert_array_equal(thread.trapezoid_evaluations * 7, thread.simpson_evaluations * 20)


@pytest.mark.slow
def test_wave_quadrature_runs_and_keeps_its_references():
    # The tethered element: Simpson at 10 ms and the trapezoid at 2 ms against Dopri5 at
    # 1e-12. Both converge (errors well under 1 % of the peak tension), and halving h
    # lowers both on the taut element.
    wave = study.wave_quadrature_study(steps=(0.01, 0.005))
    assert np.all(wave.simpson_error < 1e-2) and np.all(wave.trapezoid_error < 1e-2)
    taut = wave.case.index("ρ = 2")
    assert wave.simpson_error[taut, 1] < wave.simpson_error[taut, 0] / 8
    assert wave.trapezoid_error[taut, 1] < wave.trapezoid_error[taut, 0] / 3


@pytest.fixture(scope="module")
def similar():
    return study.similarity_study(periods=4)


@pytest.mark.slow
def test_similar_scenes_share_their_dimensionless_response(similar):
    # Eq. 7 both ways: scenes in other units with every group the same agree to the
    # solver's tolerance (rtol = 1e-10 gives 1e-6 here, limit 1e-4); doubling α moves η
    # or χ by more than 10 %, and so does St at the same α, ξ and ρ.
    assert all(scene.success for scene in similar)
    classes = study.similarity_classes(similar)
    assert len(classes["same"]) == 2 and len(classes["alpha"]) == 1 and len(classes["inertia"]) == 1
    assert all(d < study.SAME for _, d in classes["same"])
    assert all(d > study.DIFFERENT for _, d in classes["alpha"])
    base = similar[0]
    for other, _ in classes["same"]:
        # the scene really is in other units, with the same α
        assert other.units != base.units and other.alpha == pytest.approx(base.alpha, rel=1e-12)
    assert study.similarity_row(similar)[2] in ("yes", "partly")
