"""Derivatives through `jc.simulate` and `jc.solve_statics` against central finite
differences, and `jit` / `vmap` against plain calls.

The scene: a 5-segment line from an anchor at 30 m depth to a fairlead driven along x by
`jc.Harmonic`, in a 0.5 m/s current, with a body carrying Zhukov's specific-weight drag
k₀ at a free node. Six parameters are traced at once, through a single compiled
gradient: K_n, K_τ, k₀, C_E, C_E1 and the fairlead amplitude A.

The reference is a central difference of the same simulation, so the comparison tests
the reverse-mode derivative (diffrax's `RecursiveCheckpointAdjoint`, lineax's solve of
the consistent mass matrix, optimistix's implicit adjoint) against the function it
differentiates. At rtol = atol = 1e-10 (Tsit5), measured relative differences are
2e-8 to 3e-7 for K_τ, k₀, C_E, C_E1 and A, and 3e-6 to 5e-6 for K_n, whose effect on
the mean tension is the smallest (0.02 N for a 1 % change), so that the difference
quotient itself is only good to a few 1e-6 (its two steps differ by 2e-6). Hence
GRADIENT_RTOL = 5e-5 (four to five digits) for the simulation, and 1e-7 for statics
(measured 2.5e-10).

The consistent mass solve runs a fixed number of CG iterations, so its reverse mode does
not depend on the loss's scale (test_acceleration_gradient_independent_of_loss_scale);
with a tolerance it did, and position gradients were then good to only ~1e-4.
"""

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcable as jc
from jaxcable._equations import lagrangian as _lagrangian

N_SEGMENTS = 5
BODY_NODE = 3  # a free node (junctions are 0 and 1; interior nodes are 2..5)
NAMES = ("K_n", "K_tau", "k0", "C_E", "C_E1", "amplitude")
P0 = np.array([1.2, 0.01, 0.05, 2.0e4, 4.0e3, 1.0])  # –, –, s²/m², N, N, m
T1 = 2.0  # s
TS = np.linspace(0.0, T1, 41)
TOL = 1e-10
GRADIENT_RTOL = 5e-5
STATICS_RTOL = 1e-7


def base_model():
    line = jc.LineType(
        mass_per_length=1.0,
        diameter=0.03,
        tension_law=jc.NonlinearElastic(P0[3], P0[4]),
        normal_drag=P0[0],
        tangential_drag=P0[1],
    )
    return jc.CableNetwork.from_branches(
        junctions=[[0.0, 0.0, -30.0], [28.0, 0.0, 0.0]],  # chord 41.0 m > 40 m: taut start
        branches=[jc.Branch(0, 1, line, length=40.0, segments=N_SEGMENTS)],
        constraints={0: jc.Fixed(), 1: jc.Harmonic(amplitude=P0[5], period=2.0)},
        bodies={BODY_NODE: jc.Body(mass=20.0, volume=0.01, specific_drag=P0[2])},
    )


MODEL = base_model()
ENV = jc.Environment(water_density=1025.0, current=(0.5, 0.0, 0.0))


def with_parameters(p):
    """The model with the six parameters replaced by (possibly traced) entries of `p`."""
    n = MODEL.n_segments
    return eqx.tree_at(
        lambda m: (
            m.line.normal_drag,
            m.line.tangential_drag,
            m.body.specific_drag,
            m.line.tension_law.axial_stiffness,
            m.line.tension_law.quadratic_coefficient,
            m.motions[1].amplitude,
        ),
        MODEL,
        (
            jnp.full(n, p[0]),
            jnp.full(n, p[1]),
            MODEL.body.specific_drag.at[BODY_NODE].set(p[2]),
            jnp.full(n, p[3]),
            jnp.full(n, p[4]),
            jnp.asarray(p[5], dtype=float),
        ),
    )


def simulate_with(p, throw=True):
    return jc.simulate(
        with_parameters(p),
        ENV,
        T1,
        ts=TS,
        initial="rest",
        solver=jc.SolverConfig(diffrax.Tsit5(), rtol=TOL, atol=TOL),
        throw=throw,
    )


def mean_top_tension(p):
    """The scalar: the fairlead segment's tension (N), averaged over the output times."""
    return jnp.mean(simulate_with(p).tension[:, -1])


def central_differences(f, p, relative_step):
    p = np.asarray(p, dtype=float)
    out = []
    for i in range(p.size):
        h = relative_step * abs(p[i])
        up, down = p.copy(), p.copy()
        up[i] += h
        down[i] -= h
        out.append((float(f(up)) - float(f(down))) / (2 * h))
    return np.array(out)


@pytest.fixture(scope="module")
def simulate_gradients():
    """One compiled gradient of the scalar with respect to all six parameters, and its
    central differences at two relative steps (each forward call reuses one compiled
    simulation)."""
    gradient = np.asarray(jax.jit(jax.grad(mean_top_tension))(jnp.asarray(P0)))
    differences = {step: central_differences(mean_top_tension, P0, step) for step in (1e-3, 1e-4)}
    return gradient, differences


def test_scene_is_taut_and_sensitive(simulate_gradients):
    """Guards on the scene: no segment goes slack (so the scalar is smooth in every
    parameter), and every parameter moves the scalar by a measurable amount."""
    result = simulate_with(P0)
    assert bool(result.success)
    assert float(jnp.min(result.strain)) > 1e-3  # far above the slack band (1e-5)
    gradient, _ = simulate_gradients
    mean = float(mean_top_tension(P0))
    # The change in mean tension (N) for a 1 % change of each parameter: all above 1e-5 of
    # the mean (the smallest, K_n's, is 3.6e-5 of it), far above the solver's noise.
    effect = np.abs(gradient * P0) * 0.01
    assert np.all(effect > 1e-5 * mean), dict(zip(NAMES, effect))


@pytest.mark.parametrize("index", range(len(NAMES)), ids=NAMES)
def test_simulate_gradient_matches_central_differences(simulate_gradients, index):
    """d(mean fairlead tension)/dθ by jax.grad through jc.simulate vs central
    differences, for θ = K_n, K_τ, k₀, C_E, C_E1, A (measured: see the module notes)."""
    gradient, differences = simulate_gradients
    fd_coarse, fd_fine = differences[1e-3][index], differences[1e-4][index]
    # The two steps agree with each other, so the difference quotient is converged...
    assert fd_fine == pytest.approx(fd_coarse, rel=GRADIENT_RTOL)
    # ...and with the reverse-mode derivative.
    assert gradient[index] == pytest.approx(fd_fine, rel=GRADIENT_RTOL)


# --------------------------------------------------------------------------------------
# Statics.


def fairlead_tension(axial_stiffness):
    """The fairlead segment's static tension (N) as a function of C_E."""
    model = eqx.tree_at(
        lambda m: m.line.tension_law.axial_stiffness, MODEL, jnp.full(MODEL.n_segments, axial_stiffness)
    )
    return jc.solve_statics(model, ENV).tension[-1]


def test_statics_gradient_matches_central_differences():
    """d(fairlead tension)/dC_E through solve_statics (implicit adjoint) vs central
    differences of the same compiled solve. Measured agreement 2.5e-10 relative."""
    value_and_grad = jax.jit(jax.value_and_grad(fairlead_tension))
    c_e = P0[3]
    value, gradient = value_and_grad(c_e)
    assert float(value) > 0
    fd = {}
    for step in (1e-3, 1e-4):
        h = step * c_e
        fd[step] = (float(value_and_grad(c_e + h)[0]) - float(value_and_grad(c_e - h)[0])) / (2 * h)
    assert fd[1e-4] == pytest.approx(fd[1e-3], rel=STATICS_RTOL)
    assert float(gradient) == pytest.approx(fd[1e-4], rel=STATICS_RTOL)
    # Guard: the tension really depends on C_E (a stiffer line sags less and pulls harder).
    assert abs(float(gradient)) * c_e > 1e-3 * float(value)


# --------------------------------------------------------------------------------------
# jit and vmap.
#
# Compiled differently (one XLA program for the user's function, or a batched one), the
# same arithmetic can round differently in the last bit. With an adaptive step-size
# controller such a difference can, rarely, add or remove a step (measured here: one
# vmapped case took 1046 steps against 1045 alone), after which the two solutions differ
# by the solver's tolerance, not by rounding. Rounding differences also grow along the
# run: the batched program fuses the arithmetic differently (measured: 2.8e-10 m on a
# 30 m scale after 40 output times, 1e-11 relative). So: identical step counts must give
# agreement to 1e-10 of the quantity's scale; a different step count only to 1e-9
# (10× the solver tolerance), and the step counts may differ by at most one.


def assert_same_solution(got, expected):
    """`got`, `expected`: (positions, tension, num_steps) of one simulation each.

    Positions must agree to 1e-10 of their scale (1e-9 after a different step count).
    Tension is C_E × strain, and strain is a difference of positions over a segment
    length: a position error δ moves it by C_E δ / L. So tensions must agree to the
    tension that the position tolerance makes, C_E × (1e-10 × scale) / L, not to 1e-10
    of the tension itself."""
    steps_got, steps_expected = int(got[2]), int(expected[2])
    assert abs(steps_got - steps_expected) <= 1
    tolerance = 1e-10 if steps_got == steps_expected else 1e-9
    positions_got, positions_expected = np.asarray(got[0]), np.asarray(expected[0])
    position_tolerance = tolerance * np.max(np.abs(positions_expected))
    np.testing.assert_allclose(positions_got, positions_expected, rtol=0, atol=position_tolerance)
    segment_length = float(MODEL.segment_length[0])
    tension_tolerance = P0[3] * position_tolerance / segment_length
    np.testing.assert_allclose(np.asarray(got[1]), np.asarray(expected[1]), rtol=0, atol=tension_tolerance)


def history(p, throw=True):
    result = simulate_with(p, throw=throw)
    return result.positions, result.tension, result.stats["num_steps"], result.success


def test_jit_of_user_function_equals_eager_call():
    """A user function of a float parameter gives the same result under jax.jit as
    called directly (where jc.simulate compiles on its own). Measured: same step count,
    positions equal to 2e-12 m (6e-14 relative)."""

    def fairlead_history(amplitude):
        return history(jnp.asarray(P0).at[5].set(amplitude))

    eager = fairlead_history(1.3)
    jitted = jax.jit(fairlead_history)(1.3)
    assert_same_solution(jitted, eager)


@pytest.mark.slow
def test_filter_jit_of_user_function_equals_eager_call():
    """The same with eqx.filter_jit (one more compilation, hence slow)."""

    def fairlead_history(amplitude):
        return history(jnp.asarray(P0).at[5].set(amplitude))

    amplitude = jnp.asarray(0.7)
    assert_same_solution(eqx.filter_jit(fairlead_history)(amplitude), fairlead_history(amplitude))


def test_jit_with_jax_array_output_times():
    """As test_jit_of_user_function_equals_eager_call, with the output times given as a
    (closed-over) jax array instead of a numpy one."""
    ts = jnp.asarray(TS)

    def final_positions(amplitude):
        p = jnp.asarray(P0).at[5].set(amplitude)
        return jc.simulate(
            with_parameters(p),
            ENV,
            T1,
            ts=ts,
            initial="rest",
            solver=jc.SolverConfig(diffrax.Tsit5(), rtol=TOL, atol=TOL),
        ).positions[-1]

    np.testing.assert_allclose(np.asarray(jax.jit(final_positions)(1.3)), np.asarray(final_positions(1.3)), rtol=1e-12)


def test_vmap_equals_loop():
    """vmap over three parameter vectors (amplitude and K_n both varied; throw=False,
    per-case status) gives what three separate calls give."""
    factors = np.array([0.5, 1.0, 1.5])
    batch = np.tile(P0, (3, 1))
    batch[:, 5] *= factors  # amplitude
    batch[:, 0] *= factors[::-1]  # K_n
    batched = jax.vmap(lambda p: history(p, throw=False))(jnp.asarray(batch))
    assert np.all(np.asarray(batched[3]))
    for k in range(3):
        assert_same_solution([x[k] for x in batched[:3]], history(jnp.asarray(batch[k])))
    # Guard: the cases really differ.
    assert float(jnp.max(jnp.abs(batched[1][0] - batched[1][2]))) > 1.0


# --------------------------------------------------------------------------------------
# The consistent-mass solve's derivative.


def free_acceleration_component(k_n, factor):
    """factor × one free node's acceleration (m/s²), as a function of K_n, at a fixed
    state with random velocities."""
    rng = np.random.default_rng(0)
    positions = MODEL.node_positions[MODEL.free_nodes]
    velocities = jnp.asarray(rng.normal(size=positions.shape))
    model = eqx.tree_at(lambda m: m.line.normal_drag, MODEL, jnp.full(MODEL.n_segments, k_n))
    a = _lagrangian.free_accelerations(model, ENV, 0.0, positions, velocities)[0]
    return factor * a[1, 0]


@pytest.fixture(scope="module")
def acceleration_derivatives():
    value = jax.jit(free_acceleration_component)
    gradient = jax.jit(jax.grad(free_acceleration_component))
    h = 1e-5
    fd = (float(value(P0[0] + h, 1.0)) - float(value(P0[0] - h, 1.0))) / (2 * h)
    return gradient, fd


def test_acceleration_gradient(acceleration_derivatives):
    """One evaluation of the equations of motion (the consistent mass solve included):
    d a / dK_n by reverse mode vs central differences. Measured: 1e-11."""
    gradient, fd = acceleration_derivatives
    assert float(gradient(P0[0], 1.0)) == pytest.approx(fd, rel=1e-8)


def test_acceleration_gradient_independent_of_loss_scale(acceleration_derivatives):
    """d(s · a)/dK_n / s must not depend on the scale s of the quantity differentiated.
    With s = 1 reverse mode agrees with central differences to 4e-11; with s = 1e-9 it
    is off by 23 %. Through jc.simulate the cotangents that reach the solve are scaled by
    the step size and by the loss: see test_position_gradient_matches_central_differences.
    Running CG for a fixed 30 iterations, rtol = atol = 0, makes it scale-free (4e-11 at
    s = 1, 1e-9 and 1e-15)."""
    gradient, fd = acceleration_derivatives
    scale = 1e-9
    assert float(gradient(P0[0], scale)) / scale == pytest.approx(fd, rel=1e-8)


@pytest.mark.slow
def test_position_gradient_matches_central_differences():
    """d(final x of the body node)/dθ through jc.simulate vs central differences, for all
    six parameters. With a CG tolerance the relative differences were 5e-6 to 8e-5; with
    30 fixed iterations they are at most 3e-6, and with mass_matrix="lumped" at most
    4e-7 (both measured)."""

    def final_body_x(p):
        return simulate_with(p).positions[-1, BODY_NODE, 0]

    gradient = np.asarray(jax.jit(jax.grad(final_body_x))(jnp.asarray(P0)))
    fd = central_differences(final_body_x, P0, 1e-4)
    np.testing.assert_allclose(gradient, fd, rtol=1e-5)
