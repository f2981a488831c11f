"""Airy waves, the current profile and the environment that carries them, each against a
closed form written out here or an independent numerical solve."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.optimize import brentq

import jaxcable as jc
from jaxcable import airy_wavenumber

G = 9.81


def reference_wavenumber(period, depth):
    """k from ω² = g k tanh(k d) by bracketing, independent of jaxcable's Newton."""
    omega = 2 * np.pi / period
    return brentq(
        lambda k: omega**2 - G * k * np.tanh(k * depth), 1e-9, 10 * omega**2 / G + 10 / depth, xtol=1e-15, rtol=1e-15
    )


def closed_form(height, period, depth, k, x, z, t, phase=0.0):
    """Airy's u, w, ∂u/∂t, ∂w/∂t with cosh and sinh as textbooks write them."""
    omega = 2 * np.pi / period
    theta = k * x - omega * t + phase
    a = 0.5 * height * omega / np.sinh(k * depth)
    u = a * np.cosh(k * (z + depth)) * np.cos(theta)
    w = a * np.sinh(k * (z + depth)) * np.sin(theta)
    return u, w, omega * u * np.tan(theta), -omega * a * np.sinh(k * (z + depth)) * np.cos(theta)


@pytest.mark.parametrize(
    "period, depth", [(2.0, 500.0), (8.0, 20.0), (12.0, 10.0), (30.0, 5.0), (60.0, 0.5), (5.6, 200.0)]
)
def test_dispersion_matches_an_independent_root(period, depth):
    assert float(airy_wavenumber(period, depth, G)) == pytest.approx(reference_wavenumber(period, depth), rel=1e-13)


def test_dispersion_limits():
    # Deep water: λ → g T² / 2π. Shallow: c → √(g d) (1 − (kd)²/6).
    deep = jc.Airy(1.0, 6.0, 2000.0)
    assert float(deep.wavelength) == pytest.approx(G * 36 / (2 * np.pi), rel=1e-12)
    shallow = jc.Airy(0.01, 100.0, 1.0)
    kd = float(shallow.wavenumber)
    celerity = float(shallow.wavelength) / 100.0
    assert celerity == pytest.approx(np.sqrt(G) * (1 - kd**2 / 6), rel=1e-5)
    assert celerity == pytest.approx(np.sqrt(G), rel=1e-3)


@pytest.fixture(scope="module")
def wave():
    return jc.Airy(2.0, 8.0, 20.0, phase=0.3)


def test_velocities_and_accelerations_match_the_closed_form(wave):
    k = reference_wavenumber(8.0, 20.0)
    x = np.array([0.0, 7.0, 31.0, 55.0])
    z = np.array([-0.5, -5.0, -12.0, -20.0])
    t = 1.7
    points = jnp.stack([x, jnp.zeros(4), z], axis=-1)
    u, w, du, dw = closed_form(2.0, 8.0, 20.0, k, x, z, t, phase=0.3)
    np.testing.assert_allclose(wave.velocity(points, t), np.stack([u, 0 * u, w], -1), atol=1e-12)
    np.testing.assert_allclose(wave.acceleration(points, t), np.stack([du, 0 * u, dw], -1), atol=1e-12)
    np.testing.assert_allclose(wave.elevation(x, 0.0 * x, t), np.cos(k * x - 2 * np.pi / 8.0 * t + 0.3), atol=1e-12)


def test_continuity_and_no_flow_through_the_bed(wave):
    def divergence(p):
        jac = jax.jacfwd(lambda q: wave.velocity(q, 0.9))(p)
        return jac[0, 0] + jac[1, 1] + jac[2, 2]

    for p in ([3.0, 0.0, -2.0], [40.0, 5.0, -15.0]):
        assert abs(float(divergence(jnp.array(p)))) < 1e-13
    assert float(wave.velocity(jnp.array([13.0, 0.0, -20.0]), 0.4)[2]) == pytest.approx(0.0, abs=1e-14)


def test_heading_rotates_the_wave():
    ahead = jc.Airy(1.0, 7.0, 30.0)
    turned = jc.Airy(1.0, 7.0, 30.0, heading=90.0)
    p = jnp.array([4.0, 0.0, -3.0])
    q = jnp.array([0.0, 4.0, -3.0])
    u, v = ahead.velocity(p, 1.1), turned.velocity(q, 1.1)
    np.testing.assert_allclose([v[0], v[1], v[2]], [0.0, u[0], u[2]], atol=1e-13)


def test_kinematics_above_the_mean_level():
    plain = jc.Airy(2.0, 8.0, 20.0)
    stretched = jc.Airy(2.0, 8.0, 20.0, wheeler=True)
    crest = jnp.array([0.0, 0.0, 1.0])  # η = H/2 = 1 at x = 0, t = 0
    np.testing.assert_allclose(plain.velocity(crest, 0.0), plain.velocity(jnp.array([0.0, 0.0, 0.0]), 0.0), atol=1e-14)
    # Wheeler maps the surface to z = 0 and the bed to itself ...
    np.testing.assert_allclose(
        stretched.velocity(crest, 0.0), plain.velocity(jnp.array([0.0, 0.0, 0.0]), 0.0), atol=1e-13
    )
    bed = jnp.array([0.0, 0.0, -20.0])
    np.testing.assert_allclose(stretched.velocity(bed, 0.0), plain.velocity(bed, 0.0), atol=1e-13)
    # ... and a point between to z' = d (z − η) / (d + η).
    k = reference_wavenumber(8.0, 20.0)
    u, *_ = closed_form(2.0, 8.0, 20.0, k, 0.0, 20.0 * (-5.0 - 1.0) / 21.0, 0.0)
    assert float(stretched.velocity(jnp.array([0.0, 0.0, -5.0]), 0.0)[0]) == pytest.approx(u, rel=1e-12)
    # The stretched acceleration is the time derivative at a fixed point.
    p, h = jnp.array([10.0, 0.0, -3.0]), 1e-5
    fd = (stretched.velocity(p, 0.7 + h) - stretched.velocity(p, 0.7 - h)) / (2 * h)
    np.testing.assert_allclose(stretched.acceleration(p, 0.7), fd, atol=1e-8)


def test_steepness_and_gradients():
    wave = jc.Airy.from_steepness(0.05, 6.0, 40.0)
    assert float(wave.steepness) == pytest.approx(0.05, rel=1e-13)
    assert float(wave.height) == pytest.approx(0.05 * 2 * np.pi / reference_wavenumber(6.0, 40.0), rel=1e-12)

    def horizontal(period, depth):
        return jc.Airy(1.0, period, depth).velocity(jnp.array([5.0, 0.0, -4.0]), 0.3)[0]

    for argnum, base in ((0, (7.0, 15.0)), (1, (7.0, 15.0))):
        grad = float(jax.grad(horizontal, argnums=argnum)(*base))
        h = 1e-5
        up, down = list(base), list(base)
        up[argnum] += h
        down[argnum] -= h
        fd = (float(horizontal(*up)) - float(horizontal(*down))) / (2 * h)
        assert grad == pytest.approx(fd, rel=1e-6)


def test_floater_amplitude():
    # 0.085 (9.81 · 5.6² / 2π)^0.75, by hand: 48.963^0.75 = 18.51.
    assert float(jc.examples.floater_amplitude(5.6)) == pytest.approx(1.5733, abs=1e-3)


def test_wave_input_errors():
    with pytest.raises(ValueError, match="Airy.height must be positive, got -1"):
        jc.Airy(-1.0, 8.0, 20.0)
    with pytest.raises(ValueError, match="Airy.period must be finite"):
        jc.Airy(1.0, np.nan, 20.0)
    with pytest.raises(ValueError, match="give Environment.depth"):
        jc.Environment(waves=jc.Airy(1.0, 8.0, 20.0))
    with pytest.raises(ValueError, match=r"Environment.waves\[0\].depth must equal Environment.depth, got 20.0"):
        jc.Environment(depth=30.0, waves=[jc.Airy(1.0, 8.0, 20.0)])
    with pytest.raises(ValueError, match="Environment.seabed needs the water depth"):
        jc.Environment(seabed=jc.Seabed())
    with pytest.raises(ValueError, match="Seabed.stiffness must be positive"):
        jc.Seabed(stiffness=0.0)
    with pytest.raises(ValueError, match="CurrentProfile.heights must be strictly increasing"):
        jc.CurrentProfile([-10.0, -20.0], [0.5, 0.2])


def test_current_profile_interpolates_along_its_heading():
    profile = jc.CurrentProfile([-100.0, -20.0, 0.0], [0.1, 0.5, 1.0], heading=30.0)
    env = jc.Environment(current=profile)
    points = jnp.array([[0.0, 0.0, -150.0], [0.0, 0.0, -60.0], [0.0, 0.0, -10.0], [0.0, 0.0, 2.0]])
    speeds = np.array([0.1, 0.3, 0.75, 1.0])
    direction = np.array([np.cos(np.pi / 6), np.sin(np.pi / 6), 0.0])
    np.testing.assert_allclose(env.water_velocity(points, 0.0), speeds[:, None] * direction, atol=1e-14)


# A sloping two-segment line with a buoy at its middle node, in a wave, at rest: the
# non-conservative forces are Morison's inertia on the water's acceleration (drag is
# switched off by zero coefficients).
RHO = 1025.0


def sloped_line(drag=0.0):
    line = jc.LineType(
        mass_per_length=5.0,
        diameter=0.08,
        tension_law=jc.LinearElastic(1e7),
        normal_drag=drag,
        tangential_drag=drag,
        normal_added_mass=0.8,
        tangential_added_mass=0.3,
    )
    positions = np.array([[0.0, 0.0, -18.0], [6.0, 1.0, -10.0], [14.0, 3.0, -2.0]])
    body = jc.Body(mass=50.0, volume=0.2, added_mass=0.6)
    model = jc.CableNetwork(
        node_positions=positions,
        segment_nodes=np.array([[0, 1], [1, 2]]),
        segment_length=np.linalg.norm(np.diff(positions, axis=0), axis=1),
        line=line,
        constraints={0: jc.Fixed(), 2: jc.Fixed()},
        bodies={1: body},
        drag_points=8,
    )
    return model, positions


@pytest.mark.parametrize(
    "wave", [jc.Airy(2.0, 7.0, 25.0, heading=20.0), jc.Cnoidal(3.0, 15.0, 25.0, heading=20.0)], ids=["airy", "cnoidal"]
)
def test_fluid_inertia_is_morison_on_the_waters_acceleration(wave):
    from jaxcable._equations import lagrangian as lag

    model, positions = sloped_line()
    env = jc.Environment(RHO, G, depth=25.0, waves=wave)
    t = 0.8
    got = np.asarray(lag.nonconservative_forces(model, env, t, jnp.asarray(positions), jnp.zeros((3, 3))))

    # Reference: the line's load by a 4,000-point midpoint rule (error ~1e-8), shared to the ends by
    # the shape functions, and the body's ρ V (1 + C_a) a.
    expected = np.zeros((3, 3))
    area = np.pi * 0.08**2 / 4
    xi = (np.arange(4000) + 0.5) / 4000
    for i, j in [(0, 1), (1, 2)]:
        chord = positions[j] - positions[i]
        tangent = chord / np.linalg.norm(chord)
        points = positions[i] + xi[:, None] * chord
        a = np.asarray(wave.acceleration(jnp.asarray(points), t))
        a_t = (a @ tangent)[:, None] * tangent
        f = RHO * area * ((1 + 0.8) * (a - a_t) + (1 + 0.3) * a_t)
        expected[i] += np.linalg.norm(chord) * np.mean(f * (1 - xi)[:, None], axis=0)
        expected[j] += np.linalg.norm(chord) * np.mean(f * xi[:, None], axis=0)
    expected[1] += RHO * 0.2 * 1.6 * np.asarray(wave.acceleration(jnp.asarray(positions[1]), t))
    np.testing.assert_allclose(got, expected, rtol=1e-7, atol=1e-9)

    # Switched off, only drag is left: zero here.
    dry = jc.Environment(RHO, G, depth=25.0, waves=wave, fluid_inertia=False)
    assert (
        np.abs(np.asarray(lag.nonconservative_forces(model, dry, t, jnp.asarray(positions), jnp.zeros((3, 3))))).max()
        == 0.0
    )


def count_primitives(model, env, names):
    from jaxcable._equations import lagrangian as lag

    jaxpr = jax.make_jaxpr(lambda x, v: lag.generalised_forces(model, env, 0.3, x, v))(
        jnp.asarray(model.node_positions), jnp.zeros((model.n_nodes, 3))
    )
    count = 0

    def walk(jpr):
        nonlocal count
        for eqn in jpr.eqns:
            count += eqn.primitive.name in names
            for sub in jax.core.subjaxprs(eqn) if hasattr(jax.core, "subjaxprs") else []:
                walk(sub)
            for param in eqn.params.values():
                inner = getattr(param, "jaxpr", None)
                if inner is not None:
                    walk(getattr(inner, "jaxpr", inner))

    walk(jaxpr.jaxpr)
    return count


def test_absent_terms_are_not_compiled():
    model, _ = sloped_line(drag=1.2)
    wave = jc.Airy(2.0, 7.0, 25.0)
    still = count_primitives(model, jc.Environment(RHO, G), {"cos", "sin", "exp"})
    waves = count_primitives(model, jc.Environment(RHO, G, depth=25.0, waves=wave), {"cos", "sin", "exp"})
    drag_only = count_primitives(
        model, jc.Environment(RHO, G, depth=25.0, waves=wave, fluid_inertia=False), {"cos", "sin", "exp"}
    )
    assert still == 0
    assert waves > drag_only > 0
    assert count_primitives(model, jc.Environment(RHO, G, depth=25.0), {"max"}) < count_primitives(
        model, jc.Environment(RHO, G, depth=25.0, seabed=jc.Seabed()), {"max"}
    )


@pytest.mark.parametrize("start", [0.0, 280.0])
def test_wave_ramp_scales_the_waves_and_their_acceleration(start):
    wave = jc.Airy(1.5, 9.0, 40.0)
    env = jc.Environment(depth=40.0, waves=wave, wave_ramp=18.0, wave_start=start, current=(0.2, 0.0, 0.0))
    p = jnp.array([[3.0, 1.0, -6.0]])
    for t in start + np.array([-5.0, 0.0, 4.0, 11.0, 18.0, 25.0]):
        u = min(max((t - start) / 18.0, 0.0), 1.0)
        f = u**3 * (6 * u**2 - 15 * u + 10)
        np.testing.assert_allclose(
            env.water_velocity(p, t), f * wave.velocity(p, t) + np.array([0.2, 0.0, 0.0]), atol=1e-14
        )
        h = 1e-5
        fd = (env.water_velocity(p, t + h) - env.water_velocity(p, t - h)) / (2 * h)
        np.testing.assert_allclose(env.water_acceleration(p, t), fd, atol=1e-8)
