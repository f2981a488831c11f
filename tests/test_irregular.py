"""Irregular seas as sums of Airy components, against closed forms: one component is an
Airy wave, the surface's variance is Σ a²/2 (Parseval), the field is divergence-free
and meets the linearised kinematic surface condition, and a record's components pass
through its samples."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcable as jc
from jaxcable._irregular import WaveComponents

DEPTH = 40.0
POINTS = jnp.array([[0.0, 0.0, -1.0], [13.0, -4.0, -20.0], [-7.0, 30.0, -39.0], [2.0, 1.0, 0.6]])


@pytest.fixture(scope="module")
def sea():
    rng = np.random.default_rng(3)
    periods = np.linspace(5.0, 14.0, 12)
    return WaveComponents(
        rng.uniform(0.05, 0.4, 12), periods, DEPTH, headings=rng.uniform(-40, 40, 12), phases=rng.uniform(0, 6.28, 12)
    )


@pytest.mark.parametrize("wheeler", [False, True])
def test_one_component_is_an_airy_wave(wheeler):
    airy = jc.Airy(1.6, 9.0, DEPTH, heading=25.0, phase=0.7, wheeler=wheeler)
    one = WaveComponents([0.8], [9.0], DEPTH, headings=25.0, phases=0.7, wheeler=wheeler)
    for t in (0.0, 3.3, 11.1):
        np.testing.assert_allclose(one.velocity(POINTS, t), airy.velocity(POINTS, t), rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(one.acceleration(POINTS, t), airy.acceleration(POINTS, t), rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(
            one.elevation(POINTS[:, 0], POINTS[:, 1], t), airy.elevation(POINTS[:, 0], POINTS[:, 1], t), atol=1e-14
        )
    assert float(one.height) == pytest.approx(1.6 * np.sqrt(2), rel=1e-12)  # H_s = 4 √(a²/2) = √2 H


def test_surface_variance_is_half_the_sum_of_squared_amplitudes(sea):
    # Over a long record the time average of η² tends to m₀ = Σ a²/2 (the cross terms
    # average out as 1/(Δω t)).
    times = jnp.linspace(0.0, 20000.0, 400001)
    eta = jax.vmap(lambda t: sea.elevation(3.0, -2.0, t))(times)
    assert float(jnp.mean(eta**2)) == pytest.approx(float(sea.variance), rel=5e-3)
    assert float(sea.variance) == pytest.approx(0.5 * float(jnp.sum(sea.amplitudes**2)), rel=1e-14)


def test_the_field_is_divergence_free_and_meets_the_surface_condition(sea):
    inside = jnp.array([[1.0, 2.0, -5.0], [40.0, -8.0, -30.0]])
    for t in (0.0, 4.2):
        jacobian = jax.vmap(jax.jacfwd(sea.velocity), in_axes=(0, None))(inside, t)
        divergence = jnp.trace(jacobian, axis1=1, axis2=2)
        assert float(jnp.max(jnp.abs(divergence))) < 1e-12
    # Linearised kinematic condition: w(z = 0) = ∂η/∂t.
    for t in (1.0, 7.5):
        w = sea.velocity(jnp.array([5.0, 3.0, 0.0]), t)[2]
        deta = jax.grad(lambda s: sea.elevation(5.0, 3.0, s))(t)
        assert float(w) == pytest.approx(float(deta), rel=1e-12)
    # No flow through the bed.
    assert abs(float(sea.velocity(jnp.array([5.0, 3.0, -DEPTH]), 2.0)[2])) < 1e-14


def test_components_of_a_record_pass_through_its_samples():
    rng = np.random.default_rng(0)
    times = 10.0 + 0.25 * np.arange(64)
    record = rng.normal(size=64)
    record -= record.mean()
    sea = WaveComponents.from_elevation(times, record, DEPTH)
    eta = jax.vmap(lambda t: sea.elevation(0.0, 0.0, t))(jnp.asarray(times))
    np.testing.assert_allclose(eta, record, atol=1e-12)
    # A sine record gives one component of its amplitude and period.
    times = 0.15 * np.arange(100)
    sine = WaveComponents.from_elevation(times, np.sin(2 * np.pi * times / 3.75), DEPTH)
    peak = int(np.argmax(sine.amplitudes))
    assert float(sine.amplitudes[peak]) == pytest.approx(1.0, rel=1e-12)
    assert float(sine.period) == pytest.approx(3.75, rel=1e-12)
    assert float(jnp.sum(sine.amplitudes) - sine.amplitudes[peak]) < 1e-12


def test_gradients_match_finite_differences(sea):
    def speed(amplitudes):
        wave = WaveComponents(amplitudes, sea.periods, DEPTH, headings=sea.headings, phases=sea.phases)
        return jnp.sum(wave.velocity(POINTS[:3], 2.0) ** 2)

    grad = jax.grad(speed)(sea.amplitudes)
    h = 1e-6
    step = jnp.zeros_like(sea.amplitudes).at[4].set(h)
    fd = (speed(sea.amplitudes + step) - speed(sea.amplitudes - step)) / (2 * h)
    assert float(grad[4]) == pytest.approx(float(fd), rel=1e-7)


def test_it_loads_an_environment_and_vmaps(sea):
    env = jc.Environment(depth=DEPTH, waves=sea)
    u = env.water_velocity(POINTS[:3], 1.0)
    np.testing.assert_allclose(u, sea.velocity(POINTS[:3], 1.0), rtol=1e-14)
    scaled = jax.vmap(
        lambda s: jnp.sum(WaveComponents(s * sea.amplitudes, sea.periods, DEPTH).velocity(POINTS[0], 0.0))
    )(jnp.array([1.0, 2.0]))
    assert float(scaled[1]) == pytest.approx(2 * float(scaled[0]), rel=1e-12)


def test_bad_components_are_named():
    with pytest.raises(ValueError, match="WaveComponents.amplitudes"):
        WaveComponents([-0.1], [5.0], DEPTH)
    with pytest.raises(ValueError, match="WaveComponents.periods"):
        WaveComponents([0.1, 0.2], [5.0, 0.0], DEPTH)
    with pytest.raises(ValueError, match="WaveComponents.headings must be a scalar or have shape"):
        WaveComponents([0.1, 0.2], [5.0, 6.0], DEPTH, headings=[0.0, 1.0, 2.0])
    with pytest.raises(ValueError, match="breaking"):
        WaveComponents([30.0], [5.0], DEPTH)
