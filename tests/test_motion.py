"""Prescribed motions against closed-form kinematics."""

import warnings

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.interpolate import CubicSpline, PchipInterpolator

import jaxcable as jc
from jaxcable._model.motion import AbstractMotion, _natural_spline_slopes


def test_harmonic_kinematics():
    # r = A sin(ωt + φ) e, v = Aω cos(ωt + φ) e, a = −Aω² sin(ωt + φ) e.
    amplitude, period, phase = 1.3, 5.6, 0.4
    direction = np.array([3.0, 0.0, 4.0]) / 5.0
    motion = jc.Harmonic(amplitude, period, direction=(3.0, 0.0, 4.0), phase=phase)
    omega = 2 * np.pi / period
    for t in np.linspace(0.0, 7.0, 9):
        r, v, a = (np.asarray(k) for k in motion.kinematics(t))
        arg = omega * t + phase
        np.testing.assert_allclose(r, amplitude * np.sin(arg) * direction, atol=1e-14)
        np.testing.assert_allclose(v, amplitude * omega * np.cos(arg) * direction, atol=1e-13)
        np.testing.assert_allclose(a, -amplitude * omega**2 * np.sin(arg) * direction, atol=1e-13)


def test_sampled_kinematics_converge_to_the_sampled_function():
    # A sampled sine: the spline is exact at the samples, and its velocity and
    # acceleration, which enter the equations, converge to the sine's at second order or
    # better as the sampling refines (4× finer, at least 16× smaller error).
    omega = 2 * np.pi / 5.6
    checks = np.linspace(0.3, 9.7, 37)

    def errors(samples):
        times = np.linspace(0.0, 10.0, samples)
        motion = jc.Sampled(
            times, np.stack([np.sin(omega * times), np.zeros_like(times), np.cos(omega * times)], axis=1)
        )
        assert np.allclose(
            np.asarray(motion.displacement(times[7]))[[0, 2]],
            [np.sin(omega * times[7]), np.cos(omega * times[7])],
            atol=1e-14,
        )
        err = np.zeros(3)
        for t in checks:
            r, v, a = (np.asarray(k)[0] for k in motion.kinematics(t))
            err = np.maximum(
                err, np.abs([r - np.sin(omega * t), v - omega * np.cos(omega * t), a + omega**2 * np.sin(omega * t)])
            )
        return err

    coarse, fine = errors(101), errors(401)
    assert np.all(fine < coarse / 16), (coarse, fine)
    assert fine[0] < 1e-8 and fine[1] < 1e-6 and fine[2] < 1e-3


def test_sampled_holds_its_end_values():
    motion = jc.Sampled([0.0, 1.0, 2.0], [[0.0, 0, 0], [1.0, 0, 0], [3.0, 0, 0]])
    r, v, _ = (np.asarray(k) for k in motion.kinematics(5.0))
    np.testing.assert_allclose(r, [3.0, 0.0, 0.0])
    np.testing.assert_allclose(v, 0.0)


def test_sampled_velocity_at_the_end_samples_is_the_one_sided_derivative():
    # At the first and last sample the velocity must be the spline's own slope there
    # (a backward or forward difference), not half of it, as a clipped time would give.
    t = np.linspace(0.0, 10.0, 101)
    motion = jc.Sampled(t, np.stack([np.sin(t), np.zeros_like(t), np.zeros_like(t)], axis=1))
    h = 1e-6
    for end, inside in ((10.0, 10.0 - h), (0.0, h)):
        _, velocity, _ = motion.kinematics(end)
        slope = (motion.displacement(end)[0] - motion.displacement(inside)[0]) / (end - inside)
        np.testing.assert_allclose(velocity[0], slope, rtol=1e-5)


def test_ramped_harmonic_starts_at_rest_and_matches_its_closed_form():
    # f(u) = u³(6u² − 15u + 10), u = t / ramp: r = f A sin(ωt + φ) e, and its
    # derivatives by the product rule, against the motion's forward-mode kinematics.
    amplitude, period, phase, ramp = 2.0, 7.0, 0.7, 5.0
    motion = jc.Harmonic(amplitude, period, direction=(0.0, 0.0, 1.0), phase=phase, ramp=ramp)
    omega = 2 * np.pi / period
    for t in (0.0, 1.3, 4.9, 5.0, 11.0):
        u = min(t / ramp, 1.0)
        f = u**3 * (6 * u**2 - 15 * u + 10)
        df = 30 * u**2 * (u - 1) ** 2 / ramp if t < ramp else 0.0
        ddf = 60 * u * (u - 1) * (2 * u - 1) / ramp**2 if t < ramp else 0.0
        s, c = np.sin(omega * t + phase), np.cos(omega * t + phase)
        r, v, a = motion.kinematics(t)
        np.testing.assert_allclose(r[2], f * amplitude * s, atol=1e-12)
        np.testing.assert_allclose(v[2], amplitude * (df * s + f * omega * c), atol=1e-12)
        np.testing.assert_allclose(a[2], amplitude * (ddf * s + 2 * df * omega * c - f * omega**2 * s), atol=1e-12)
    _, v0, a0 = motion.kinematics(0.0)
    assert np.all(v0 == 0) and np.all(a0 == 0)


def test_towing_follows_its_speed_history():
    # The branched-systems paper's step, 1 -> 3 m/s over 2 s: distance by hand, piece by piece.
    motion = jc.Towing([0.0, 10.0, 12.0, 20.0], [1.0, 1.0, 3.0, 3.0], direction=(0.0, 2.0, 0.0))
    for t, distance, speed, acceleration in [
        (-1.0, -1.0, 1.0, 0.0),  # before the record: the first speed, held
        (5.0, 5.0, 1.0, 0.0),
        (11.0, 10.0 + 1.0 + 0.5 * 1.0 * 1.0**2, 2.0, 1.0),  # mid-ramp: 1 m/s² over 1 s
        (12.0, 10.0 + 2.0 + 0.5 * 1.0 * 2.0**2, 3.0, 0.0),
        (15.0, 14.0 + 9.0, 3.0, 0.0),
        (25.0, 14.0 + 24.0 + 15.0, 3.0, 0.0),  # after the record: the last speed, held
    ]:
        r, v, a = motion.kinematics(t)
        np.testing.assert_allclose(np.asarray(r), [0.0, distance, 0.0], rtol=1e-14, atol=1e-14)
        np.testing.assert_allclose(np.asarray(v), [0.0, speed, 0.0], rtol=1e-14, atol=1e-14)
        np.testing.assert_allclose(np.asarray(a), [0.0, acceleration, 0.0], rtol=1e-14, atol=1e-14)


def test_towing_rejects_bad_input():
    with pytest.raises(ValueError, match="Towing.times must be strictly increasing"):
        jc.Towing([0.0, 1.0, 1.0], [1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match=r"Towing.speeds must have shape \(3,\)"):
        jc.Towing([0.0, 1.0, 2.0], [1.0, 1.0])
    with pytest.raises(ValueError, match="Towing.speeds must be finite, got nan"):
        jc.Towing([0.0, 1.0], [1.0, float("nan")])


# --------------------------------------------------------------------------------------
# Interpolating a table: the natural spline, the monotone (PCHIP) one and straight lines,
# against SciPy's independent implementations and closed forms.

STEP_TIMES = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0])
STEP = np.array([0.0, 0.0, 0.0, 100.0, 100.0, 100.0])  # m, along x


def along_x(values):
    return np.stack([values, np.zeros_like(values), np.zeros_like(values)], axis=1)


def test_cubic_is_scipys_natural_spline_and_warns_where_it_overshoots_a_step():
    spline = CubicSpline(STEP_TIMES, STEP, bc_type="natural")
    with pytest.warns(UserWarning, match="strays") as caught:
        motion = jc.Sampled(STEP_TIMES, along_x(STEP))
    t = np.linspace(0.0, 5.0, 251)
    got = np.array([np.asarray(motion.kinematics(s)[0])[0] for s in t])
    np.testing.assert_allclose(got, spline(t), atol=1e-12)
    # The warning's undershoot is the spline's own least value between t = 1 and 2 s,
    # at the root of its derivative there.
    roots = [r for r in spline.derivative().roots() if 1.0 < r < 2.0]
    (message,) = [str(w.message) for w in caught]
    assert f"strays from {float(spline(roots[0])):.4g} to 0 m in x between t = 1 and 2 s" in message
    assert "interpolation='pchip'" in message


def test_cubic_is_scipys_natural_spline_on_uneven_samples_and_its_derivative_is_exact():
    """The spline's slopes come from the Thomas algorithm (`_tridiagonal_solve`, two
    scans): SciPy's natural spline through 200 unevenly spaced random samples, and,
    the slopes being linear in the values, their forward-mode derivative in any
    direction is the slopes of that direction."""
    rng = np.random.default_rng(3)
    times = np.cumsum(rng.uniform(0.01, 1.0, 200))
    values = rng.normal(size=(200, 3))
    slopes = _natural_spline_slopes(jnp.asarray(times), jnp.asarray(values))
    expected = CubicSpline(times, values, bc_type="natural").derivative()(times)
    np.testing.assert_allclose(slopes, expected, rtol=0, atol=1e-11 * float(np.max(np.abs(expected))))
    direction = rng.normal(size=values.shape)
    _, tangent = jax.jvp(lambda v: _natural_spline_slopes(jnp.asarray(times), v), (values,), (direction,))
    np.testing.assert_allclose(tangent, _natural_spline_slopes(jnp.asarray(times), jnp.asarray(direction)), atol=1e-12)


def test_pchip_through_a_step_is_the_smoothstep_and_stays_within_the_samples():
    # Flat on either side, so the Fritsch–Carlson slopes at t = 2 and 3 s are zero and
    # the rising piece is the cubic Hermite with zero end slopes: 100 (3s² − 2s³).
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overshoot warning
        motion = jc.Sampled(STEP_TIMES, along_x(STEP), interpolation="pchip")
    for t in np.linspace(0.0, 5.0, 41):
        r, v, a = (float(np.asarray(k)[0]) for k in motion.kinematics(t))
        s = t - 2.0
        if 0.0 <= s < 1.0:  # a sample starts the piece on its right (the acceleration jumps there)
            expected = (100 * (3 * s**2 - 2 * s**3), 100 * (6 * s - 6 * s**2), 100 * (6 - 12 * s))
        else:
            expected = (0.0 if t <= 2.0 else 100.0, 0.0, 0.0)
        np.testing.assert_allclose((r, v, a), expected, atol=1e-10)


def test_pchip_is_scipys_on_uneven_samples():
    times = np.array([0.0, 0.7, 1.5, 3.2, 4.0, 4.1])
    values = np.array([[1.0, 1.0, 0.0], [-2.0, 4.0, 0.5], [5.0, 25.0, 0.5], [4.5, 20.0, 2.0], [9.0, 81.0, 2.0],
                       [9.5, 80.0, 1.0]])  # fmt: skip
    motion = jc.Sampled(times, values, interpolation="pchip")
    t = np.linspace(0.0, 4.1, 203)
    got = np.array([np.asarray(motion.displacement(s)) for s in t])
    np.testing.assert_allclose(got, PchipInterpolator(times, values, axis=0)(t), atol=1e-12)


def test_linear_is_straight_between_samples():
    motion = jc.Sampled([0.0, 2.0, 3.0], along_x(np.array([0.0, 4.0, 1.0])), interpolation="linear")
    for t, position, speed in ((0.5, 1.0, 2.0), (1.5, 3.0, 2.0), (2.5, 2.5, -3.0), (7.0, 1.0, 0.0)):
        r, v, a = (float(np.asarray(k)[0]) for k in motion.kinematics(t))
        np.testing.assert_allclose((r, v, a), (position, speed, 0.0), atol=1e-12)


@pytest.mark.parametrize("ramp", [0.0, 2.5])
@pytest.mark.parametrize("interpolation", ["cubic", "pchip", "linear"])
def test_sampled_closed_form_kinematics_equal_forward_mode_derivatives(interpolation, ramp):
    # `Sampled.kinematics` writes the pieces' derivatives out (with the ramp's product
    # rule); the generic path takes them by forward-mode differentiation of the
    # displacement. At random times, at every sample, and outside the table (held: zero
    # velocity and acceleration once the ramp is over).
    rng = np.random.default_rng(3)
    ts = np.cumsum(rng.uniform(0.05, 0.3, 40))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the random table's spline overshoots
        motion = jc.Sampled(ts, rng.normal(size=(40, 3)), interpolation, ramp=ramp)
    times = np.concatenate([np.linspace(ts[0] - 1, ts[-1] + 1, 301), ts])
    closed = jax.vmap(motion.kinematics)(times)
    generic = jax.vmap(lambda t: AbstractMotion.kinematics(motion, t))(times)
    for c, g in zip(closed, generic):
        np.testing.assert_allclose(c, g, rtol=0, atol=1e-13 * float(np.max(np.abs(g)) + 1))
    outside = ((times < ts[0]) | (times > ts[-1])) & (times >= ramp)  # held, the ramp over
    assert np.all(np.asarray(closed[1])[outside] == 0) and np.all(np.asarray(closed[2])[outside] == 0)


def test_a_ramp_starts_a_moving_table_from_rest():
    """With a ramp the support starts where the table's scene put it, at rest and
    without acceleration, and follows the table once the ramp is over; `start_velocity`
    is the table's own speed at its first time."""
    ts = np.linspace(0.0, 20.0, 401)
    table = np.stack([2.0 * np.sin(2 * np.pi * ts / 5.6), 0 * ts, 0 * ts], axis=1)
    plain, ramped = (jc.Sampled(ts, table, ramp=ramp) for ramp in (0.0, 5.0))
    np.testing.assert_allclose(plain.start_velocity(), [2.0 * 2 * np.pi / 5.6, 0, 0], rtol=2e-3)
    np.testing.assert_array_equal(ramped.start_velocity(), plain.start_velocity())
    for interpolation in ("cubic", "pchip", "linear"):  # the closed form is the interpolant's own
        motion = jc.Sampled(ts, table, interpolation)
        np.testing.assert_allclose(motion.start_velocity(), motion.kinematics(ts[0])[1], rtol=1e-14, atol=1e-15)
    r, v, a = ramped.kinematics(0.0)
    assert np.all(np.asarray(r) == 0) and np.all(np.asarray(v) == 0) and np.all(np.asarray(a) == 0)
    for t in (5.0, 7.3, 12.0):
        for got, want in zip(ramped.kinematics(t), plain.kinematics(t)):
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
