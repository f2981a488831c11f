"""Zhukov's Picard integrators against closed forms: the trapezoid rule's own recursion
on a linear equation, diffrax's Heun for one iteration, and second-order convergence to an
exact solution; for Simpson's rule, the (2, 2) Padé recursion of the Lobatto IIIA method
it converges to, and fourth-order convergence."""

import diffrax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcable as jc


def solve(solver, vector_field, y0, t1, steps=None, rtol=None):
    controller = diffrax.ConstantStepSize() if rtol is None else diffrax.PIDController(rtol=rtol, atol=rtol)
    solution = diffrax.diffeqsolve(
        diffrax.ODETerm(vector_field),
        solver,
        0.0,
        t1,
        # An array, not a float: equinox's jit would compile anew for each step size.
        None if steps is None else jnp.asarray(t1 / steps),
        y0,
        stepsize_controller=controller,
        saveat=diffrax.SaveAt(t1=True),
        max_steps=100_000,
    )
    return solution


def end(solution):
    """The solution at t1 (diffrax types `ys` as optional)."""
    ys = solution.ys
    assert ys is not None
    return ys[0]


def test_many_iterations_give_the_trapezoid_rule():
    # y' = λ y: the trapezoid rule multiplies by (1 + hλ/2)/(1 − hλ/2) each step; the
    # iteration contracts by |hλ/2| = 0.25, so 60 iterations converge to rounding.
    lam, h, steps = -5.0, 0.1, 20
    solution = solve(jc.PicardTrapezoid(iterations=60), lambda t, y, a: lam * y, jnp.array(1.0), h * steps, steps)
    factor = (1 + h * lam / 2) / (1 - h * lam / 2)
    np.testing.assert_allclose(float(end(solution)), factor**steps, rtol=1e-13)


def test_one_iteration_is_heun():
    def field(t, y, args):
        return jnp.stack([y[1], -y[0] - 0.3 * y[1] + jnp.sin(2 * t)])

    y0 = jnp.array([1.0, 0.0])
    ours = end(solve(jc.PicardTrapezoid(iterations=1), field, y0, 3.0, steps=60))
    heun = end(solve(diffrax.Heun(), field, y0, 3.0, steps=60))
    np.testing.assert_allclose(np.asarray(ours), np.asarray(heun), rtol=1e-14, atol=1e-14)


@pytest.mark.parametrize("iterations", [1, 3])
def test_second_order_convergence(iterations):
    # y'' = −y, exact (cos t, −sin t): halving the step quarters the error.
    def field(t, y, args):
        return jnp.stack([y[1], -y[0]])

    errors = []
    for steps in (100, 200, 400):
        y = end(solve(jc.PicardTrapezoid(iterations=iterations), field, jnp.array([1.0, 0.0]), 5.0, steps))
        errors.append(float(jnp.max(jnp.abs(y - jnp.array([jnp.cos(5.0), -jnp.sin(5.0)])))))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    np.testing.assert_allclose(ratios, 4.0, rtol=0.05)


def test_adaptive_steps_reach_the_tolerance():
    def field(t, y, args):
        return jnp.stack([y[1], -y[0]])

    loose = solve(jc.PicardTrapezoid(), field, jnp.array([1.0, 0.0]), 5.0, rtol=1e-4)
    tight = solve(jc.PicardTrapezoid(), field, jnp.array([1.0, 0.0]), 5.0, rtol=1e-7)
    exact = jnp.array([jnp.cos(5.0), -jnp.sin(5.0)])
    loose_error = float(jnp.max(jnp.abs(end(loose) - exact)))
    tight_error = float(jnp.max(jnp.abs(end(tight) - exact)))
    assert tight_error < 1e-5 and tight_error < loose_error / 30
    assert int(tight.stats["num_steps"]) > int(loose.stats["num_steps"])


@pytest.mark.slow
def test_simulates_a_cable_like_dopri5():
    # Zhukov's thread, as jaxcable's own simulation: a stretched two-segment string
    # whose middle mass is let go; the baseline must agree with Dopri5.
    line = jc.LineType(
        mass_per_length=0.5,
        diameter=0.01,
        tension_law=jc.LinearElastic(1e3),
        normal_drag=0.0,
        tangential_drag=0.0,
        normal_added_mass=0.0,
        area=0.5 / 1000.0,
    )
    model = jc.CableNetwork(
        [[0.0, 0, 0], [1.1, 0.05, 0], [2.0, 0, 0]],
        [[0, 1], [1, 2]],
        [0.99, 0.99],
        line,
        {0: jc.Fixed(), 2: jc.Fixed()},
        bodies={1: jc.Body(mass=1.0, volume=0.001)},
    )
    env = jc.Environment(water_density=1000.0)
    ts = jnp.linspace(0.0, 1.0, 11)
    ours = jc.simulate(
        model, env, 1.0, ts=ts, initial="rest", solver=jc.SolverConfig(jc.PicardTrapezoid(), rtol=1e-8, atol=1e-8)
    )
    reference = jc.simulate(model, env, 1.0, ts=ts, initial="rest", solver=jc.SolverConfig(rtol=1e-11, atol=1e-11))
    moved = float(np.max(np.abs(np.asarray(reference.positions[-1] - reference.positions[0]))))
    assert moved > 0.01  # the mass swings: the comparison is not of two resting states
    np.testing.assert_allclose(np.asarray(ours.positions), np.asarray(reference.positions), atol=1e-5)


def test_many_simpson_iterations_give_lobatto_iiia():
    # y' = λ y: the converged iteration is the three-stage Lobatto IIIA collocation, whose
    # stability function is the (2, 2) Padé approximant of e^z, z = hλ.
    lam, h, steps = -5.0, 0.1, 20
    solution = solve(jc.PicardSimpson(iterations=60), lambda t, y, a: lam * y, jnp.array(1.0), h * steps, steps)
    z = h * lam
    factor = (1 + z / 2 + z**2 / 12) / (1 - z / 2 + z**2 / 12)
    np.testing.assert_allclose(float(end(solution)), factor**steps, rtol=1e-13)


@pytest.mark.parametrize("iterations, order", [(1, 2), (2, 3), (3, 4)])
def test_simpson_gains_an_order_an_iteration(iterations, order):
    # y'' = −y over 5 s: from the Euler predictor each iteration adds one order, up to
    # Simpson's four. The error ratio on halving the step is 2^order.
    def field(t, y, args):
        return jnp.stack([y[1], -y[0]])

    errors = []
    for steps in (40, 80, 160):
        y = end(solve(jc.PicardSimpson(iterations=iterations), field, jnp.array([1.0, 0.0]), 5.0, steps))
        errors.append(float(jnp.max(jnp.abs(y - jnp.array([jnp.cos(5.0), -jnp.sin(5.0)])))))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    np.testing.assert_allclose(np.log2(ratios), order, atol=0.15)


def test_simpson_adaptive_steps_reach_the_tolerance():
    def field(t, y, args):
        return jnp.stack([y[1], -y[0]])

    solution = solve(jc.PicardSimpson(), field, jnp.array([1.0, 0.0]), 5.0, rtol=1e-8)
    exact = jnp.array([jnp.cos(5.0), -jnp.sin(5.0)])
    assert float(jnp.max(jnp.abs(end(solution) - exact))) < 1e-6


@pytest.mark.parametrize("solver", [jc.PicardTrapezoid, jc.PicardSimpson])
def test_bad_iterations(solver):
    with pytest.raises(ValueError, match=f"{solver.__name__}.iterations must be a positive integer, got 0"):
        solver(iterations=0)
