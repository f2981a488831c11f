"""Integration interval by interval (`jaxcable._simulation.blocks`), which the scene runner and the
command line use so that their compiled solve can stay in JAX's persistent cache."""

import diffrax
import jax
import numpy as np
import pytest
from helpers import compilations

import jaxcable as jc
from jaxcable import examples
from jaxcable._interrupt import StopRequest
from jaxcable._simulation import blocks as _blocks
from jaxcable._simulation.simulate import as_config, for_model

# Three blocks, the last padded: 150 intervals of 0.04 s.
TS = np.linspace(0.0, 6.0, 151)


@pytest.mark.slow  # against a tight reference: 20 s of the default suite
def test_blocks_are_as_accurate_as_one_simulate_call(driven_line):
    """Against a reference at rtol = atol = 1e-10, the blocks' positions are about as
    close as one `simulate` call's at the same tolerance, 1e-6 (4.7e-3 m against 2.5e-3 m,
    measured), though every output time now ends a step; the step counts differ by a
    few percent."""
    model, env, static = driven_line
    config = jc.SolverConfig(rtol=1e-6, atol=1e-6)
    reference = jc.simulate(
        model, env, TS[-1], ts=TS, initial=static.state, solver=jc.SolverConfig(rtol=1e-10, atol=1e-10)
    )
    whole = jc.simulate(model, env, TS[-1], ts=TS, initial=static.state, solver=config)
    blocks = _blocks.simulate_in_blocks(model, env, TS, static.state, config)
    np.testing.assert_array_equal(blocks.times, TS)
    np.testing.assert_array_equal(blocks.positions[0], static.state.positions)
    error_whole = np.max(np.abs(whole.positions - reference.positions))
    error_blocks = np.max(np.abs(blocks.positions - reference.positions))
    assert error_blocks <= 3 * error_whole, (error_blocks, error_whole)  # measured 1.9×
    steps, whole_steps = blocks.stats["num_steps"], int(whole.stats["num_steps"])
    assert steps == blocks.stats["num_accepted_steps"] + blocks.stats["num_rejected_steps"]
    assert abs(steps - whole_steps) <= 0.1 * whole_steps, (steps, whole_steps)


def test_the_block_has_no_host_callback_and_compiles_once(driven_line):
    """JAX keeps no program with a host callback in its persistent cache: `simulate`'s
    has diffrax's (its output times are checked by one); a block's has none, and one
    program serves every block, the first and the padded last included."""
    model, env, static = driven_line
    config = for_model(as_config("test", None), model)
    carry = _blocks._start(model, env, (static.state.positions, static.state.velocities), 0.0, 0.04, config)
    block = TS[: _blocks.BLOCK]
    lowered = _blocks._block.lower(model, env, carry, block, block + 0.04, block < 1.0, config)
    assert "callback" not in lowered.as_text()
    start = (static.state.positions, static.state.velocities)
    args = (model, env, start, jax.numpy.asarray(0.0), jax.numpy.asarray(1.0), jax.numpy.asarray(TS[:5]))
    with_ts = jc._simulation.simulate._simulate.lower(*args, config, diffrax.NoProgressMeter(), False)
    assert "callback" in with_ts.as_text()

    reached = []
    with compilations("_block") as compiled:
        _blocks.simulate_in_blocks(
            model, env, TS, static.state, jc.SolverConfig(rtol=1e-7, atol=1e-7), on_block=reached.append
        )
    assert len(compiled) <= 1  # none where an earlier test compiled it
    assert reached == pytest.approx([TS[63], TS[127], TS[150]])  # the first block begins with t = 0 itself


def test_a_failed_run_keeps_what_it_computed(driven_line):
    """Past `max_steps`, the blocks before the failing one are kept, bitwise the full
    run's; a state gone non-finite (RK4 at 0.02 s, beyond its stability limit here) keeps
    the outputs before it. Each message says between which output times it failed."""
    model, env, static = driven_line
    config = jc.SolverConfig(rtol=1e-6, atol=1e-6)
    full = _blocks.simulate_in_blocks(model, env, TS, static.state, config)
    limit = int(0.5 * full.stats["num_steps"])  # reached in the second block (measured)
    with pytest.raises(jc.SimulationFailed, match="The maximum number of solver steps was reached") as caught:
        _blocks.simulate_in_blocks(model, env, TS, static.state, jc.SolverConfig(rtol=1e-6, atol=1e-6, max_steps=limit))
    partial, block = caught.value.partial, _blocks.BLOCK
    assert str(caught.value).startswith(f"simulate failed between t = {TS[block - 1]:g} s and t = {TS[block]:g} s:")
    assert caught.value.time == TS[block - 1] and partial is not None
    np.testing.assert_array_equal(partial.times, TS[:block])
    for name in ("positions", "velocities", "tension", "reactions"):
        np.testing.assert_array_equal(getattr(partial, name), getattr(full, name)[:block], err_msg=name)
    assert partial.stats["num_steps"] <= limit

    rk4 = jc.SOLVERS["rk4"]()
    unstable = jc.SolverConfig(rk4.solver, stepsize_controller=diffrax.ConstantStepSize(), dt0=0.02)
    with pytest.raises(jc.SimulationFailed, match="the state became non-finite") as caught:
        _blocks.simulate_in_blocks(model, env, TS, static.state, unstable)
    partial = caught.value.partial
    assert partial is not None and 1 < partial.times.size < block  # measured: 4 of them
    first_bad = TS[partial.times.size]
    assert f"between t = {partial.times[-1]:g} s and t = {first_bad:g} s" in str(caught.value)
    assert np.all(np.isfinite(partial.positions)) and np.all(np.isfinite(partial.tension))


def test_a_run_asked_to_stop_ends_its_block_and_keeps_it(driven_line):
    """A stop asked for from another thread (Ctrl-C in `jaxcable run`) ends the run at
    the end of the block it is in, with that block's results; until a block has ended,
    `ask` says there is nothing to keep."""
    model, env, static = driven_line
    config = jc.SolverConfig(rtol=1e-6, atol=1e-6)
    stop, said = StopRequest(), []
    with pytest.raises(jc.SimulationInterrupted, match=f"interrupted at t = {TS[_blocks.BLOCK - 1]:g} s") as caught:
        _blocks.simulate_in_blocks(
            model, env, TS, static.state, config, on_block=lambda _: said.append(stop.ask()), stop=stop
        )
    assert said == [False]  # asked during the first block's callback, before it was kept
    assert stop.ask()  # after it, a stop keeps results
    partial = caught.value.partial
    np.testing.assert_array_equal(partial.times, TS[: _blocks.BLOCK])
    full = _blocks.simulate_in_blocks(model, env, TS, static.state, config, stop=StopRequest())
    np.testing.assert_array_equal(partial.tension, full.tension[: _blocks.BLOCK])


def test_bad_times_and_a_first_step_are_refused(driven_line):
    model, env, static = driven_line
    with pytest.raises(ValueError, match="simulate_in_blocks: ts must be strictly increasing"):
        _blocks.simulate_in_blocks(model, env, np.array([0.0, 0.2, 0.1]), static.state)
    with pytest.raises(ValueError, match="an adaptive solver.s dt0 must be None"):
        _blocks.simulate_in_blocks(model, env, TS, static.state, jc.SolverConfig(dt0=1e-3))


def test_the_progress_bar_changes_no_answer(capsys):
    """`run_scene`'s bar is drawn from Python between blocks: the same arrays with it or
    without it."""
    scene = jc.read_scene(examples.scene_path("anchored_line"))
    quiet = jc.run_scene(scene, duration=0.2, dt_out=0.05)
    assert "simulated" not in capsys.readouterr().err
    shown = jc.run_scene(scene, duration=0.2, dt_out=0.05, progress=True)
    assert "0.2/0.2 s simulated" in capsys.readouterr().err
    np.testing.assert_array_equal(shown.tension, quiet.tension)
    assert shown.steps == quiet.steps


# Fixed steps: 40 midpoint steps of 1 ms in each 0.04 s interval.
FIXED = jc.SolverConfig(diffrax.Midpoint(), dt0=1e-3, stepsize_controller=diffrax.ConstantStepSize())


def test_fixed_steps_are_one_simulate_call_with_the_same_steps(driven_line):
    """Every output time ends a step of 1 ms, as in one `simulate` call with the same
    constant step: the same arithmetic, so the same answers but for rounding (the step
    times are summed differently), which the snapping line grows to 1e-7 m by 5.7 s."""
    model, env, static = driven_line
    whole = jc.simulate(model, env, TS[-1], ts=TS, initial=static.state, solver=FIXED)
    blocks = _blocks.simulate_in_blocks(model, env, TS, static.state, FIXED)
    np.testing.assert_allclose(blocks.positions, whole.positions, rtol=0, atol=1e-6)
    np.testing.assert_allclose(blocks.tension, whole.tension, rtol=0, atol=1e-4 * np.max(whole.tension))
    assert blocks.stats == {"num_steps": 6000, "num_accepted_steps": 6000, "num_rejected_steps": 0}
    assert int(whole.stats["num_steps"]) == 6000


def test_a_fixed_block_has_no_host_callback_and_compiles_once(driven_line):
    model, env, static = driven_line
    config = for_model(FIXED, model)
    carry = _blocks._fixed_start(model, env, (static.state.positions, static.state.velocities), 0.0, 0.04, config)
    block = TS[: _blocks.BLOCK]
    lowered = _blocks._fixed_block.lower(model, env, carry, block, block + 0.04, block < 1.0, config, 40)
    assert "callback" not in lowered.as_text()
    fine = jc.SolverConfig(diffrax.Midpoint(), dt0=5e-4, stepsize_controller=diffrax.ConstantStepSize())
    with compilations("_fixed_block") as compiled:
        _blocks.simulate_in_blocks(model, env, TS, static.state, fine)
    assert len(compiled) <= 1


@pytest.mark.parametrize(
    "ts, dt, substeps",
    [
        (np.arange(0.0, 1.0001, 0.05), 1e-3, 50),  # MoorDyn's dtM into its dtOut: exact
        (np.arange(0.0, 1.0001, 0.05), 0.03, 2),  # 0.025 s steps, the fewest within 0.03
        (np.array([0.0, 0.1, 0.2, 0.21]), 0.01, 10),  # the longest interval decides
        (np.array([0.0, 0.1]), 1.0, 1),
    ],
)
def test_substeps_per_interval(ts, dt, substeps):
    assert _blocks.substeps_per_interval(ts, dt) == substeps


def test_fixed_steps_past_max_steps_are_refused_before_running(driven_line):
    model, env, static = driven_line
    config = jc.SolverConfig(
        diffrax.Midpoint(), dt0=1e-3, stepsize_controller=diffrax.ConstantStepSize(), max_steps=5999
    )
    with pytest.raises(ValueError, match="takes 6000 steps from 0 to 6 s, more than the solver's max_steps = 5999"):
        _blocks.simulate_in_blocks(model, env, TS, static.state, config)
    with pytest.raises(ValueError, match="needs the solver's dt0"):
        _blocks.simulate_in_blocks(
            model,
            env,
            TS,
            static.state,
            jc.SolverConfig(diffrax.Midpoint(), stepsize_controller=diffrax.ConstantStepSize()),
        )
