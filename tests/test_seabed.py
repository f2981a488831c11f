"""The seabed: a chain resting on the bottom against the elastic catenary with seabed
contact, and friction against Coulomb's law."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.optimize import brentq

import jaxcable as jc
from jaxcable._equations import lagrangian as _lagrangian

RHO, G = 1025.0, 9.81
DEPTH, LENGTH, SPAN = 50.0, 300.0, 280.0
DIAMETER, MASS, EA = 0.1, 40.0, 5e8
WET_WEIGHT = (MASS - RHO * np.pi * DIAMETER**2 / 4) * G  # w (N/m)


def catenary_with_seabed():
    """Horizontal tension H, fairlead vertical force V_F (N) and touchdown distance (m)
    of an elastic catenary from an anchor on a frictionless bed (Irvine; the form
    MoorPy and MAP use): the unstretched length L_B = L − V_F/w lies on the bed."""

    def height(h, v):
        return h / WET_WEIGHT * (np.sqrt(1 + (v / h) ** 2) - 1) + v**2 / (2 * EA * WET_WEIGHT)

    def fairlead_vertical(h):
        # The height rises monotonically with V_F: one root for the depth.
        return brentq(lambda v: height(h, v) - DEPTH, 0.0, WET_WEIGHT * LENGTH, xtol=1e-12)

    def span(h):
        v = fairlead_vertical(h)
        return LENGTH - v / WET_WEIGHT + h / WET_WEIGHT * np.arcsinh(v / h) + h * LENGTH / EA - SPAN

    # Above this H even the whole chain hanging cannot reach the fairlead's height.
    lifted = brentq(lambda h: height(h, WET_WEIGHT * LENGTH) - DEPTH, 1.0, 1e9, xtol=1e-10)
    h = brentq(span, 1.0, lifted * (1 - 1e-9), xtol=1e-10)
    v = fairlead_vertical(h)
    return h, v, (LENGTH - v / WET_WEIGHT) * (1 + h / EA)


@pytest.fixture(scope="module")
def resting_chain():
    line = jc.LineType(mass_per_length=MASS, diameter=DIAMETER, tension_law=jc.LinearElastic(EA, 1e-6))
    model = jc.CableNetwork.from_branches(
        junctions=np.array([[0.0, 0.0, -DEPTH], [SPAN, 0.0, 0.0]]),
        branches=[jc.Branch(0, 1, line, LENGTH, 60)],
        constraints={0: jc.Fixed(), 1: jc.Fixed()},
    )
    env = jc.Environment(RHO, G, depth=DEPTH, seabed=jc.Seabed())
    return model, env, jc.solve_statics(model, env)


def test_chain_on_the_seabed_matches_the_analytic_catenary(resting_chain):
    model, env, static = resting_chain
    h, v, touchdown = catenary_with_seabed()
    assert 0.2 * LENGTH < touchdown < 0.8 * LENGTH  # a real touchdown, not a degenerate case
    fairlead = np.asarray(static.reactions[1])
    assert fairlead[0] == pytest.approx(h, rel=2e-3)
    assert fairlead[2] == pytest.approx(v, rel=2e-3)
    assert np.linalg.norm(fairlead) == pytest.approx(np.hypot(h, v), rel=2e-3)
    # The top segment's tension is the catenary's half a segment below the fairlead.
    assert float(static.tension[-1]) == pytest.approx(np.hypot(h, v - WET_WEIGHT * LENGTH / 120), rel=2e-3)
    # Frictionless: the anchor carries the horizontal tension, and vertically only the
    # half of the first segment that the bed does not (the anchor sits on the bed).
    anchor = np.asarray(static.reactions[0])
    assert anchor[0] == pytest.approx(-h, rel=2e-3)
    assert anchor[2] == pytest.approx(WET_WEIGHT * LENGTH / 120, rel=1e-2)

    positions = np.asarray(static.state.positions)
    order = np.argsort(positions[:, 0])
    x, z = positions[order, 0], positions[order, 2]
    # Nodes on the bed sink by w l / (k d l) = w / (k d); lifted ones are clear of it.
    sink = WET_WEIGHT / (3e6 * DIAMETER)
    lifted = z > -DEPTH + 10 * sink
    first_lifted = int(np.argmax(lifted))
    assert not lifted[:first_lifted].any() and lifted[first_lifted:].all()
    spacing = LENGTH / 60
    assert x[first_lifted - 1] - spacing < touchdown < x[first_lifted] + spacing
    np.testing.assert_allclose(z[1 : first_lifted - 1], -DEPTH - sink, rtol=0, atol=0.2 * sink)


@pytest.mark.slow
def test_friction_holds_a_dragged_chain_at_mu_times_its_weight():
    """A chain lying on the bed, pulled along it at a steady speed much faster than the
    friction speed: the pull equals μ times the wet weight on the bed (drag is off)."""
    mu, speed, length, n = 0.6, 0.2, 20.0, 10
    # Critically damped axially (C_v = (L/N) √(EA m)), so that the chain slides
    # steadily instead of ringing.
    damping = length / n * np.sqrt(EA * MASS)
    law = jc.KelvinVoigt(EA, 0.0, damping, 1e-6)
    line = jc.LineType(mass_per_length=MASS, diameter=DIAMETER, tension_law=law, normal_drag=0.0, tangential_drag=0.0)
    start = np.array([0.0, 0.0, -DEPTH - WET_WEIGHT / (3e6 * DIAMETER)])

    class Towed(jc.AbstractMotion):
        """Along +x, accelerating smoothly to `speed` over the first second."""

        def displacement(self, t):
            distance = speed * jnp.where(t < 1.0, t**3 - 0.5 * t**4, t - 0.5)
            return jnp.stack([distance, 0.0 * t, 0.0 * t])

    model = jc.CableNetwork.from_branches(
        junctions=np.stack([start, start + [length * 1.0001, 0.0, 0.0]]),
        branches=[jc.Branch(0, 1, line, length, n)],
        constraints={1: Towed()},
    )
    env = jc.Environment(RHO, G, depth=DEPTH, seabed=jc.Seabed(friction=mu, friction_speed=0.002))
    result = jc.simulate(
        model, env, 8.0, ts=np.linspace(6.0, 8.0, 11), initial="rest", solver=jc.SolverConfig(rtol=1e-7, atol=1e-7)
    )
    pull = np.asarray(result.reactions[:, 0, 0])
    regularised = speed / np.hypot(speed, 0.002)  # 0.99995: sliding far above v_s
    np.testing.assert_allclose(pull, mu * WET_WEIGHT * length * regularised, rtol=1e-3)


def test_bed_force_is_moordyns_per_node():
    """MoorDyn's `Line::getStateDeriv` pushes a node below the bed up by `(kBot δ − cBot ż)
    d (l₋ + l₊)/2`, l± the unstretched lengths of the segments either side (one at an
    end), vertically, whether the node moves into the bed or out of it. jaxcable's
    spring (the gradient of its penalty energy) plus its damper is that, node by node."""
    segments, length, depth, k, c = 4, 20.0, 30.0, 2.0e6, 4.0e5
    line = jc.LineType(mass_per_length=MASS, diameter=DIAMETER, tension_law=jc.LinearElastic(EA))
    model = jc.CableNetwork.from_branches(
        junctions=np.array([[0.0, 0.0, -depth], [length, 0.0, -depth]]),
        branches=[jc.Branch(0, 1, line, length, segments)],
        constraints={},
    )
    bed = jc.Environment(RHO, G, depth=depth, seabed=jc.Seabed(k, c))
    bare = jc.Environment(RHO, G, depth=depth)
    x = np.linspace(0.0, length, segments + 1)
    z = -depth + np.array([-0.02, 0.01, -0.005, -0.03, 0.0])  # two above or on the bed
    positions = np.stack([x, np.zeros_like(x), z], axis=1)
    velocities = np.array([[0.1, 0.0, -0.3], [0.0, 0.2, 0.1], [0.0, 0.0, 0.4], [0.5, 0.0, -0.2], [0.0, 0.0, 0.7]])

    def spring(env):
        return -np.asarray(jax.grad(lambda p: _lagrangian.potential_energy(model, env, p))(jnp.asarray(positions)))

    got = spring(bed) - spring(bare) + np.asarray(_lagrangian.seabed_forces(model, bed, positions, velocities))
    share = length / segments * np.array([0.5, 1.0, 1.0, 1.0, 0.5])
    below = z < -depth
    expected = np.zeros_like(positions)
    expected[:, 2] = np.where(below, ((-depth - z) * k - velocities[:, 2] * c) * DIAMETER * share, 0.0)
    np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-6)
    assert np.sum(below) == 3 and expected[3, 2] > 0 > expected[2, 2]  # out of the bed fast: pulled down


def test_moordyn_friction_is_its_saturated_ramp():
    """With `friction_damping` c_f, friction is MoorDyn's (Line.cpp): μ c_f |v| per node
    against the horizontal velocity v until that exceeds μ N, then μ N, N = |k δ − c ż| A
    the whole bed reaction; none at rest or off the bed."""
    segments, length, depth, k, c, mu, c_f = 4, 20.0, 30.0, 2.0e6, 4.0e5, 0.7, 5.0e4
    line = jc.LineType(mass_per_length=MASS, diameter=DIAMETER, tension_law=jc.LinearElastic(EA))
    model = jc.CableNetwork.from_branches(
        junctions=np.array([[0.0, 0.0, -depth], [length, 0.0, -depth]]),
        branches=[jc.Branch(0, 1, line, length, segments)],
        constraints={},
    )
    env = jc.Environment(RHO, G, depth=depth, seabed=jc.Seabed(k, c, mu, friction_damping=c_f))
    x = np.linspace(0.0, length, segments + 1)
    z = -depth + np.array([-0.02, -0.01, -0.005, -0.03, 0.01])
    positions = np.stack([x, np.zeros_like(x), z], axis=1)
    # Sliding fast (capped), slowly (on the ramp), at rest, rising fast, and off the bed.
    velocities = np.array([[3.0, -4.0, 0.0], [1e-3, 2e-3, 0.0], [0.0, 0.0, 0.0], [0.5, 0.0, 0.4], [2.0, 0.0, 0.0]])
    got = np.asarray(_lagrangian.seabed_forces(model, env, positions, velocities))
    share = length / segments * np.array([0.5, 1.0, 1.0, 1.0, 0.5])
    normal = np.where(z < -depth, ((-depth - z) * k - velocities[:, 2] * c) * DIAMETER * share, 0.0)
    speed = np.linalg.norm(velocities[:, :2], axis=1)
    ramp, cap = mu * c_f * speed, mu * np.abs(normal)
    magnitude = np.where(ramp > cap, cap, ramp)
    direction = np.divide(velocities[:, :2], speed[:, None], out=np.zeros((5, 2)), where=speed[:, None] > 0)
    np.testing.assert_allclose(got[:, :2], -magnitude[:, None] * direction, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(got[:, 2], np.where(z < -depth, -velocities[:, 2] * c * DIAMETER * share, 0.0))
    assert ramp[0] > cap[0] > 0 and 0 < ramp[1] < cap[1] and magnitude[4] == 0
    assert normal[3] < 0  # rising out of the bed faster than the spring pushes: N = |that|
    # Differentiable at rest: the ramp's slope, μ c_f, not a NaN.
    slope = jax.jacfwd(lambda v: _lagrangian.seabed_forces(model, env, positions, v)[2, 0])(jnp.asarray(velocities))
    assert float(slope[2, 0]) == pytest.approx(-mu * c_f)
