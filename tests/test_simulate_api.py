"""The simulation's contract: shapes, failure reporting, progress, solver choice."""

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import compilations

import jaxcable as jc
from jaxcable._solver.explicit import explicit_step, unrolls
from jaxcable._solver.stability import stability_function
from jaxcable.examples import anchored_line


def test_result_shapes_and_constrained_nodes(driven_line):
    model, env, static = driven_line
    ts = np.linspace(0.0, 1.0, 11)
    result = jc.simulate(model, env, 1.0, ts=ts, initial=static.state)
    assert bool(result.success)
    n_t, n_n, n_s = 11, model.n_nodes, model.n_segments
    assert result.times.shape == (n_t,)
    assert result.positions.shape == result.velocities.shape == (n_t, n_n, 3)
    assert result.strain.shape == result.tension.shape == (n_t, n_s)
    assert result.reactions.shape == (n_t, 2, 3)
    # The driven node is exactly where its motion puts it: x = X + A sin(2πt/T).
    expected = 30.0 + 0.5 * np.sin(2 * np.pi * ts / 4.0)
    np.testing.assert_allclose(result.positions[:, 1, 0], expected, rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        result.velocities[:, 1, 0], 0.5 * 2 * np.pi / 4.0 * np.cos(2 * np.pi * ts / 4.0), atol=1e-12
    )
    np.testing.assert_allclose(result.positions[:, 0], np.broadcast_to([0.0, 0.0, -30.0], (n_t, 3)), atol=0)
    assert {"num_steps", "num_accepted_steps", "num_rejected_steps"} <= set(result.stats)


def test_failure_raises_by_default(driven_line):
    model, env, static = driven_line
    with pytest.raises(eqx.EquinoxRuntimeError, match="maximum number of solver steps"):
        jc.simulate(model, env, 1.0, initial=static.state, solver=jc.SolverConfig(max_steps=5))


def test_failure_is_reported_without_throw(driven_line):
    model, env, static = driven_line
    result = jc.simulate(model, env, 1.0, initial=static.state, solver=jc.SolverConfig(max_steps=5), throw=False)
    assert not bool(result.success)
    assert result.result == diffrax.RESULTS.max_steps_reached


@pytest.mark.slow  # 34 s of the default suite
def test_the_default_start_is_statics_as_in_a_sweep(driven_line):
    """`simulate` without `initial` starts where `sweep` does: from statics, solved at
    `t0` (here 1 s, where the top's harmonic motion has moved it); `"rest"` is the drop
    test."""
    model, env, _ = driven_line
    ts = np.linspace(1.0, 1.5, 3)
    default = jc.simulate(model, env, 1.5, t0=1.0, ts=ts)
    given = jc.simulate(model, env, 1.5, t0=1.0, ts=ts, initial=jc.solve_statics(model, env, t=1.0).state)
    # `simulate` passes t0 as an array, the call above a Python float: two compiled
    # statics programs, equal to rounding.
    np.testing.assert_allclose(default.tension, given.tension, rtol=1e-9, atol=1e-9)

    def current(c):
        return model, jc.Environment(current=(c, 0.0, 0.0))

    swept = jc.sweep(current, {"c": [0.3]}, 1.5, t0=1.0, ts=ts, solver=jc.SolverConfig())
    np.testing.assert_allclose(swept.tension[0], default.tension, rtol=1e-9)
    rest = jc.simulate(model, env, 1.5, t0=1.0, ts=ts, initial="rest")
    assert np.abs(np.asarray(rest.tension - default.tension)).max() > 1.0  # N: a different start


@pytest.mark.slow
def test_the_default_start_is_statics_inside_a_derivative(driven_line):
    """A derivative through `simulate` without `initial` includes the equilibrium's
    dependence on the parameter, as central differences of whole runs do."""
    model, env, _ = driven_line

    def top_tension(scale):
        scaled = eqx.tree_at(lambda m: m.line.normal_drag, model, scale * model.line.normal_drag)
        tight = jc.SolverConfig(rtol=1e-10, atol=1e-10)  # at 1e-6 the two differ by 0.3 %
        return jc.simulate(scaled, env, 1.5, t0=1.0, ts=[1.5], solver=tight).tension[-1, -1]

    # The derivative includes the equilibrium's dependence on the drag (whose own
    # derivative, 87 N, is the larger part and of the other sign).
    central = (top_tension(1.001) - top_tension(0.999)) / 0.002
    assert float(jax.grad(top_tension)(1.0)) == pytest.approx(float(central), rel=1e-4)


def test_a_network_that_nothing_holds_starts_at_rest():
    """A free line has no equilibrium: `"statics"` starts it at rest, as `sweep` does."""

    def free_line(mass_per_length):
        line = jc.LineType(mass_per_length=mass_per_length, diameter=0.03, tension_law=jc.LinearElastic(2e6))
        return jc.CableNetwork([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]], [[0, 1]], [10.0], line, {}), jc.Environment()

    model, env = free_line(2.0)
    ts = np.linspace(0.0, 0.5, 3)
    np.testing.assert_array_equal(
        jc.simulate(model, env, 0.5, ts=ts).positions, jc.simulate(model, env, 0.5, ts=ts, initial="rest").positions
    )
    swept = jc.sweep(free_line, {"mass_per_length": [2.0]}, 0.5, ts=ts, solver=jc.SolverConfig())
    # To the rounding of the line's 10 m coordinates (a coordinate that stays near zero
    # is rounding noise of about 1e-19 m, and differs between the two programs).
    expected = jc.simulate(model, env, 0.5, ts=ts).positions
    np.testing.assert_allclose(swept.positions[0], expected, rtol=1e-12, atol=1e-14)


@pytest.mark.unchecked  # jaxtyping's checker would refuse the word first, by annotation
def test_an_unknown_start_is_refused_by_name(driven_line):
    model, env, _ = driven_line
    with pytest.raises(ValueError, match=r"simulate: initial must be one of \('statics', 'rest'\), got 'equilibrium'"):
        jc.simulate(model, env, 1.0, initial="equilibrium")  # pyright: ignore[reportArgumentType]


@pytest.mark.slow
def test_any_diffrax_solver_and_progress(driven_line, capsys):
    model, env, static = driven_line
    # Two different solvers integrating the same equations must agree (independent
    # discretisations of the same ODE), and the progress meter must print.
    dopri8 = jc.SolverConfig(diffrax.Dopri8(), rtol=1e-10, atol=1e-10)
    kvaerno5 = jc.SolverConfig(jc.stiff_solver(), rtol=1e-8, atol=1e-8)
    a = jc.simulate(model, env, 0.5, initial=static.state, solver=dopri8)
    b = jc.simulate(model, env, 0.5, initial=static.state, solver=kvaerno5, progress=True)
    np.testing.assert_allclose(a.tension, b.tension, rtol=1e-5, atol=1e-3)
    assert "simulate: 0.5/0.5 s simulated" in capsys.readouterr().err


def test_statics_state_is_at_rest(driven_line):
    # With both ends held where statics put them, the equilibrium must stay put: tension
    # constant and velocities zero. Position errors of the integrator's tolerance times
    # the segment stiffness (~2e5 N/m) show up in the tension, hence the tight rtol.
    model, env, static = driven_line
    still = jc.Environment(current=(0.3, 0.0, 0.0))
    frozen = jc.CableNetwork(
        model.node_positions,
        model.segment_nodes,
        model.segment_length,
        model.line,
        {0: jc.Fixed(), 1: jc.Fixed()},
        bodies={1: jc.Body(mass=5.0)},
    )
    tight = jc.SolverConfig(rtol=1e-10, atol=1e-10)
    result = jc.simulate(frozen, still, 2.0, initial=static.state, ts=np.linspace(0, 2.0, 5), solver=tight)
    np.testing.assert_allclose(result.tension, np.broadcast_to(static.tension, result.tension.shape), rtol=1e-6)
    np.testing.assert_allclose(result.velocities, 0.0, atol=1e-6)


@pytest.mark.slow
def test_fixed_step_blow_up_is_a_failure_not_output():
    """Heun at 20× its stable step on the anchored line goes non-finite; the result says
    so (and raises with `throw=True`) rather than passing the NaNs on as a success."""
    model, env = anchored_line(6, mass_matrix="lumped")
    static = jc.solve_statics(model, env)

    def heun(dt0):
        return jc.SolverConfig(diffrax.Heun(), dt0=dt0, stepsize_controller=diffrax.ConstantStepSize())

    run = jc.simulate(model, env, 5.0, initial=static.state, solver=heun(0.05), throw=False)
    assert not bool(run.success)
    assert run.result == diffrax.RESULTS.nonfinite
    # The error names the output times the failure lies between, as the outputs show it.
    finite = np.isfinite(np.asarray(run.positions)).all(axis=(1, 2))
    last = int(np.argmin(finite)) - 1
    assert last >= 0 and finite[: last + 1].all()
    between = rf"after the output at t = {float(run.times[last]):g} s and before t = {float(run.times[last + 1]):g} s"
    with pytest.raises(eqx.EquinoxRuntimeError, match=r"simulate: the state became non-finite.*" + between):
        jc.simulate(model, env, 5.0, initial=static.state, solver=heun(0.05))
    stable = jc.simulate(model, env, 0.5, initial=static.state, solver=heun(1e-3), throw=False)
    assert bool(stable.success)


def test_a_new_tolerance_reuses_the_compiled_solve(driven_line):
    """Tolerances are array leaves of the configuration, not static fields: after the
    first run, two more tolerances compile nothing (counted from JAX's compile log),
    yet each changes the steps taken. A static change (`max_steps`) does recompile,
    which shows that the count sees compilations."""
    model, env, static = driven_line
    steps = []
    with compilations("_simulate") as compiled:
        for tol in (1e-6, 1e-8, 1e-7):
            config = jc.SolverConfig(rtol=tol, atol=tol)
            result = jc.simulate(model, env, 1.0, ts=np.linspace(0.0, 1.0, 7), initial=static.state, solver=config)
            steps.append(int(result.stats["num_steps"]))
            if tol == 1e-6:
                first, compiled[:] = len(compiled), []
        after_tolerances = list(compiled)
        config = jc.SolverConfig(max_steps=500_000)
        jc.simulate(model, env, 1.0, ts=np.linspace(0.0, 1.0, 7), initial=static.state, solver=config)
    assert first <= 1  # once, or already compiled by an earlier test
    assert after_tolerances == []
    assert len(set(steps)) == 3, steps
    assert len(compiled) == 1


@pytest.mark.unchecked
def test_solver_config_errors_name_the_field():
    with pytest.raises(ValueError, match=r"solver must be one of \('dopri5'.*'picard'\), got 'dopri'"):
        jc.SOLVERS["dopri"]()
    with pytest.raises(ValueError, match="SolverConfig.rtol must be positive, got 0.0"):
        jc.SolverConfig(rtol=0.0)
    with pytest.raises(ValueError, match="SolverConfig.max_steps must be a positive integer, got 1.5"):
        jc.SolverConfig(max_steps=1.5)
    with pytest.raises(ValueError, match="SolverConfig.solver must be a diffrax.AbstractSolver"):
        jc.SolverConfig("tsit5")
    with pytest.raises(ValueError, match="rtol and atol set the default PIDController"):
        jc.SolverConfig(rtol=1e-8, stepsize_controller=diffrax.ConstantStepSize())


@pytest.mark.unchecked
def test_simulate_takes_a_configuration_not_a_bare_solver(driven_line):
    model, env, static = driven_line
    with pytest.raises(ValueError, match=r"simulate: solver must be a jaxcable.SolverConfig.*SolverConfig\(diffrax"):
        jc.simulate(model, env, 1.0, initial=static.state, solver=diffrax.Tsit5())


def test_presets_are_configurations():
    """`SOLVERS` names make configurations whose solver is the named one and whose
    tolerances are those given."""
    config = jc.SOLVERS["kvaerno5"](rtol=1e-7)
    assert isinstance(config, jc.SolverConfig) and isinstance(config.solver, diffrax.Kvaerno5)
    assert float(config.stepsize_controller.rtol) == 1e-7 and float(config.stepsize_controller.atol) == 1e-6
    assert isinstance(jc.SOLVERS["picard"]().solver, jc.PicardTrapezoid)
    assert jc.SolverConfig().max_steps == 1_000_000


def test_bad_values_are_named_eagerly_and_under_jit(driven_line):
    """A stiffness made negative after construction, or bad times, are refused naming
    the field: with the value eagerly, by `eqx.error_if` when traced."""
    model, env, static = driven_line
    law = model.line.tension_law
    bad = eqx.tree_at(lambda m: m.line.tension_law.axial_stiffness, model, -law.axial_stiffness)
    with pytest.raises(ValueError, match="LineType.tension_law.axial_stiffness must be positive, got -"):
        jc.simulate(bad, env, 1.0, initial=static.state)
    with pytest.raises(eqx.EquinoxRuntimeError, match="LineType.tension_law.axial_stiffness must be positive"):
        eqx.filter_jit(lambda m: jc.simulate(m, env, 1.0, initial=static.state))(bad)
    with pytest.raises(ValueError, match="simulate: t1 must be greater than t0, got t0=0.0, t1=0.0"):
        jc.simulate(model, env, 0.0, initial=static.state)
    with pytest.raises(eqx.EquinoxRuntimeError, match="simulate: t1 must be greater than t0"):
        eqx.filter_jit(lambda t1: jc.simulate(model, env, t1, ts=[0.0], initial=static.state))(0.0)
    with pytest.raises(ValueError, match=r"simulate: ts must lie within \[t0, t1\], got 2.0 at index 1"):
        jc.simulate(model, env, 1.0, ts=[0.0, 2.0], initial=static.state)


def test_rk4_stability_function_is_the_taylor_polynomial():
    """RK4's stability function is the fourth-degree Taylor polynomial of exp, so its
    imaginary-axis interval reaches 2√2."""
    z = np.array([0.3 + 0.1j, -1.0, 2.0j])
    taylor = 1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24
    np.testing.assert_allclose(stability_function(jc.RK4(), z), taylor, rtol=1e-14)
    edge = stability_function(jc.RK4(), np.array([2.8j, 2.9j]))
    assert abs(edge[0]) <= 1.0 < abs(edge[1])


@pytest.mark.slow
def test_rk4_is_the_classical_method(driven_line):
    """`SOLVERS["rk4"]` (MoorDyn's `RK4`) at fixed steps: halving the step divides the
    error by about 2⁴ = 16; and adaptively its midpoint-rule estimate steers it to a
    requested tolerance."""
    model, env, static = driven_line
    ts = np.linspace(0.0, 0.5, 11)

    def top_tension(config):
        run = jc.simulate(model, env, 0.5, ts=ts, initial=static.state, solver=config)
        return np.asarray(run.tension[:, -1])

    reference = top_tension(jc.SOLVERS["dopri8"](rtol=1e-12, atol=1e-12))
    errors = []
    for dt in (4e-3, 2e-3, 1e-3):
        fixed = jc.SOLVERS["rk4"](dt0=dt, stepsize_controller=diffrax.ConstantStepSize())
        errors.append(np.max(np.abs(top_tension(fixed) - reference)))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    np.testing.assert_allclose(ratios, 16.0, rtol=0.25)

    scale = np.max(np.abs(reference))
    adaptive = top_tension(jc.SOLVERS["rk4"](rtol=1e-8, atol=1e-8))
    assert np.max(np.abs(adaptive - reference)) < 1e-6 * scale


@pytest.mark.parametrize(
    "solver", [diffrax.Midpoint(), diffrax.Heun(), diffrax.Ralston(), jc.RK4(), diffrax.Bosh3()], ids=type
)
def test_written_out_explicit_steps_are_diffrax_steps(solver):
    """`explicit_step` writes out the stages of an explicit tableau that is not
    first-same-as-last (midpoint, Heun, Ralston, RK4) and leaves the others (Bosh3) to
    their own `step`: its step, error estimate, dense output and both derivatives equal
    those of diffrax's general Runge–Kutta step to rounding, on a nonlinear,
    time-dependent system."""

    def field(t, y, k):
        x, v = y
        return v, -k * jnp.sin(x) * (1 + 0.1 * t) - 0.05 * v * jnp.abs(v)

    term = diffrax.ODETerm(field)
    y0 = (jnp.array([0.3, -1.2, 2.0]), jnp.array([0.5, 0.1, -0.4]))
    state = solver.init(term, 0.1, 0.15, y0, 2.0)
    assert unrolls(solver) == (not solver.tableau.fsal)

    def written(k):
        return explicit_step(solver, term, 0.1, 0.15, y0, k, state, False)[:3]

    def general(k):
        return diffrax.AbstractRungeKutta.step(solver, term, 0.1, 0.15, y0, k, state, False)[:3]

    for a, b in zip(jax.tree.leaves(written(2.0)), jax.tree.leaves(general(2.0)), strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-14, atol=1e-15)
    # diffrax's stage loop is reverse-mode only (a checkpointed loop); written-out
    # stages take both modes.
    reference = jax.jacrev(lambda k: general(k)[0])(2.0)
    for derivative in (jax.jacfwd, jax.jacrev) if unrolls(solver) else (jax.jacrev,):
        found = derivative(lambda k: written(k)[0])(2.0)
        for x, y in zip(jax.tree.leaves(found), jax.tree.leaves(reference), strict=True):
            np.testing.assert_allclose(x, y, rtol=1e-13, atol=1e-15)


@pytest.mark.slow
def test_bosh3_fixed_steps_converge_at_third_order(driven_line):
    """`SOLVERS["bosh3"]` at a fixed step, as the speed table's sweep runs it: on the
    driven line, halving the step divides the error (against a tight Dopri8 run) by
    about 2³ = 8, Bogacki–Shampine's third order."""
    model, env, static = driven_line
    ts = np.linspace(0.0, 0.5, 11)

    def top_tension(config):
        run = jc.simulate(model, env, 0.5, ts=ts, initial=static.state, solver=config)
        return np.asarray(run.tension[:, -1])

    reference = top_tension(jc.SOLVERS["dopri8"](rtol=1e-12, atol=1e-12))
    errors = []
    for dt in (2e-3, 1e-3, 5e-4):
        fixed = jc.SOLVERS["bosh3"](dt0=dt, stepsize_controller=diffrax.ConstantStepSize())
        errors.append(np.max(np.abs(top_tension(fixed) - reference)))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    np.testing.assert_allclose(ratios, 8.0, rtol=0.2)
