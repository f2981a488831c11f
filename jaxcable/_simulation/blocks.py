"""Integration interval by interval between output times, in compiled blocks, for runs
whose programs must stay in JAX's persistent compilation cache.

[`jaxcable.simulate`][] hands its output times to diffrax (`SaveAt(ts=...)`), which
checks them with a host callback: diffrax 0.7.2's `diffeqsolve` is itself compiled
(`eqx.filter_jit`), so its `ts` are always traced and `eqx.error_if` always inserts the
callback. JAX keeps no program with a callback on disk, so every `jaxcable run` would
compile its solve again (about a quarter of a warm run of the Low & Langley file).

Here each output interval is a `diffeqsolve` of its own that saves only its end
(`SaveAt(t1=True)`, no callback), and carries diffrax's solver state (Dopri5's last
derivative), the step-size controller's error history and `made_jump` on to the next, so
the intervals continue one solve. They differ from one `simulate` call only in that every
output time ends a step, and each interval starts with diffrax's first-step estimate
(the controller keeps no step size between solves): on the Low & Langley file, with
adaptive Dopri5, 57,417 steps against 54,992, positions within 4.2e-8 m of `simulate`'s
and tensions within 3.3e-4 of the peak. The intervals run `BLOCK` at a
time in one compiled `lax.scan`, so the program depends on the model's structure and not
on the duration, and Python reports progress between blocks.

With a fixed step (`diffrax.ConstantStepSize`, as MoorDyn steps at its `dtM`) each
interval is `n` equal steps of the solver's own `step`, `n` the fewest that keep the
step at or below `dt0`: no step-size control to carry, and no interpolation, since
every output time ends a step. diffrax would check the given `dt0` with a callback, so
these steps are not taken through `diffeqsolve`.
"""

import functools
import math
from collections.abc import Callable
from typing import Any

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import ArrayLike, Bool, Float

from .. import _checks as checks
from .._interrupt import StopRequest
from .._model.network import CableNetwork, network_conditions, without_absent_bodies
from .._model.state import State
from .._programs import RUN_ONCE, Program, program
from .._sea.environment import Environment
from .._solver.config import SolverConfig
from .._solver.explicit import explicit_step
from .simulate import (
    SimulationResult,
    as_config,
    failure_message,
    for_model,
    integrated_state,
    public_state,
    result_codes,
    result_of,
    terms_for,
    to_host,
)

BLOCK = 64
"""Output intervals per compiled call: larger blocks make fewer calls from Python and a
coarser progress bar (the Low & Langley run, 2,140 intervals, makes 34 calls); the
compiled program is the same size either way."""


def simulate_in_blocks(
    model: CableNetwork,
    env: Environment,
    ts: Float[np.ndarray, " times"],
    initial: State,
    solver: SolverConfig | None = None,
    on_block: Callable[[float], None] | None = None,
    stop: StopRequest | None = None,
) -> SimulationResult:
    """Integrate from `ts[0]` to `ts[-1]` (s), saving at `ts`, as [`jaxcable.simulate`][]
    does with `t0=ts[0]` and `throw=True`, but interval by interval (see the module's
    notes for how the two differ).

    **Arguments:**

    - `model`, `env`: the network and the water, concrete (not traced).
    - `ts`: output times (s), concrete, strictly increasing, at least two.
    - `initial`: the state at `ts[0]`.
    - `solver`: a [`jaxcable.SolverConfig`][]: adaptive with `dt0` `None` (diffrax would
        check a first step with a callback), or a fixed step
        (`stepsize_controller=diffrax.ConstantStepSize()` with `dt0`); `SolverConfig()`
        by default.
    - `on_block`: called after each block with the simulated time (s) it reached.
    - `stop`: a request, from another thread, to stop at the end of a block
        (`jaxcable._interrupt.StopRequest`), raising [`jaxcable.SimulationInterrupted`][]
        with the results so far.

    **Returns:**

    A [`jaxcable.SimulationResult`][]; `stats` holds the step counts summed over the
    intervals.

    **Raises:**

    `ValueError` for bad times or a `solver` with `dt0`, and for a bad model field as
    `simulate` does; [`jaxcable.SimulationFailed`][] (a `RuntimeError`) with diffrax's
    message and the output times it fell between if the solve fails, or if the
    intervals together take more than the configuration's `max_steps`, holding the
    results before the failure.
    """
    config = for_model(as_config("simulate_in_blocks", solver), model)
    ts = np.asarray(ts, dtype=float)
    if ts.ndim != 1 or ts.size < 2:
        raise ValueError(f"simulate_in_blocks: ts must be 1-D with at least 2 times, got shape {ts.shape}")
    checks.enforce([checks.finite("simulate_in_blocks: ts", ts), checks.increasing("simulate_in_blocks: ts", ts)])
    checks.enforce(
        network_conditions(model, env)
        + [
            checks.finite("simulate_in_blocks: initial.positions", initial.positions),
            checks.finite("simulate_in_blocks: initial.velocities", initial.velocities),
        ]
    )
    start, block, options = _programs_for(config, ts)
    model = without_absent_bodies(model)  # a bare line's program computes no body terms
    carry = start(model, env, (initial.positions, initial.velocities), ts[0], ts[1], config)
    starts, ends, active = _intervals(ts)
    blocks, steps = [], np.zeros(3, dtype=np.int64)
    for k in range(0, len(starts), BLOCK):
        part = slice(k, k + BLOCK)
        carry, ys, counts, failure = block(model, env, carry, starts[part], ends[part], active[part], config, **options)
        saved, result = _outputs(model, env, ends[part], ys, failure)
        saved = [np.asarray(x) for x in saved]
        before, steps = steps, steps + np.asarray(counts)
        # `max_steps` bounds each interval's solve; the run as a whole is held to it here.
        code = diffrax.RESULTS.where(steps[0] > config.max_steps, diffrax.RESULTS.max_steps_reached, result)
        if code != diffrax.RESULTS.successful:
            raise _failed(ts, blocks, saved, k, steps if code == diffrax.RESULTS.nonfinite else before, code)
        blocks.append(saved)
        reached = float(ends[part][active[part]][-1])
        if on_block is not None:
            on_block(reached)
        if stop is not None:
            stop.keeping()
            if stop.asked and reached < ts[-1]:
                kept = ts[: min(k + BLOCK, len(ts))]
                partial = _result(kept, blocks, steps, diffrax.RESULTS.successful)
                raise SimulationInterrupted(f"interrupted at t = {reached:g} s", partial, reached)
    return _result(ts, blocks, steps, diffrax.RESULTS.successful)


class SimulationFailed(RuntimeError):
    """A run that failed part-way, with what it computed before the failure.

    **Attributes:**

    - `partial`: the run's results at the output times before the failure: a
        [`jaxcable.SimulationResult`][] from the engine, a [`jaxcable.io.SceneRun`][]
        from [`jaxcable.run_scene`][]; `None` where nothing but the start was computed.
    - `time`: the last output time (s) that was computed, the start where none was.
    """

    def __init__(self, message: str, partial: Any, time: float):
        super().__init__(message)
        self.partial = partial
        self.time = time


class SimulationInterrupted(SimulationFailed):
    """A run stopped part-way when asked (Ctrl-C in `jaxcable run`), with what it computed
    (`partial`, up to `time`)."""


def _failed(
    ts: np.ndarray, blocks: list, saved: list, k: int, steps: np.ndarray, code: diffrax.RESULTS
) -> SimulationFailed:
    """The failure of the block from interval `k`, keeping the blocks before it and,
    where its state became non-finite, the block's outputs before that: a stable run's
    history up to the step that diverged. After a solve's failure or `max_steps` the
    block's outputs are not kept (its later intervals ran on from the failed one).
    `steps`: the step counts of what is kept (the failed block's too where its outputs
    are)."""
    end = min(k + BLOCK, len(ts))
    if code == diffrax.RESULTS.nonfinite:
        positions, velocities = saved[0][: end - k], saved[1][: end - k]
        finite = np.all(np.isfinite(positions), axis=(1, 2)) & np.all(np.isfinite(velocities), axis=(1, 2))
        kept = int(np.argmin(finite)) if not np.all(finite) else end - k
        blocks = [*blocks, [x[:kept] for x in saved]]
    computed = sum(len(b[0]) for b in blocks)
    last = float(ts[computed - 1]) if computed else float(ts[0])
    if computed < len(ts):
        where = f"between t = {last:g} s and t = {float(ts[computed]):g} s"
    else:
        where = f"by t = {last:g} s"
    message = f"simulate failed {where}: {failure_message(code).removeprefix('simulate: ')}"
    partial = _result(ts[:computed], blocks, steps, code) if computed > 1 else None
    return SimulationFailed(message, partial, last)


def _result(ts: np.ndarray, blocks: list, steps: np.ndarray, code: diffrax.RESULTS) -> SimulationResult:
    """The outputs of `blocks` at `ts`, joined (the last block's padding left off)."""
    columns = [np.concatenate([b[i] for b in blocks])[: len(ts)] for i in range(len(blocks[0]))]
    stats: dict[str, Any] = dict(zip(("num_steps", "num_accepted_steps", "num_rejected_steps"), map(int, steps)))
    # `device_put`, not `jnp.asarray`, which compiles a program of its own for each shape.
    positions, velocities, strain, tension, reactions = map(jax.device_put, columns)
    return SimulationResult(checks.on_device(ts), positions, velocities, strain, tension, reactions, stats, code)


def prepare(
    model: CableNetwork, env: Environment, ts: Float[np.ndarray, " times"], solver: SolverConfig | None = None
) -> None:
    """Start compiling the programs that [`simulate_in_blocks`][] will run with these
    arguments (and an initial state of `model.node_positions`' shape), in a background
    thread, where the command line keeps programs (`jaxcable._programs`): they compile
    while the caller does other work (traces statics, say). Nothing otherwise."""
    config = for_model(as_config("simulate_in_blocks", solver), model)
    ts = np.asarray(ts, dtype=float)
    start, block, options = _programs_for(config, ts)
    model = without_absent_bodies(model)  # as `simulate_in_blocks` runs it
    initial = (model.node_positions, checks.on_device(np.zeros(model.node_positions.shape)))
    _prepare_programs((start, block, _outputs), (model, env), initial, ts, config, options)


def _prepare_programs(programs: tuple[Program, Program, Program], system: tuple, initial, ts, config, options) -> None:
    """`Program.prepare` of a run's start, block and outputs `programs`, each for the
    arguments the one before it gives: `system` (the model and water, or a batch's
    leaves split as `integrate_batch_in_blocks` takes them) first."""
    start, block, outputs = programs
    start.prepare(*system, initial, ts[0], ts[1], config)
    carry = start.output_shapes(*system, initial, ts[0], ts[1], config)
    starts, ends, active = (x[:BLOCK] for x in _intervals(ts))
    block.prepare(*system, carry, starts, ends, active, config, **options)
    _, ys, _, failure = block.output_shapes(*system, carry, starts, ends, active, config, **options)
    outputs.prepare(*system, ends, ys, failure)


def _programs_for(
    config: SolverConfig, ts: np.ndarray, where: str = "simulate_in_blocks"
) -> tuple[Program, Program, dict[str, int]]:
    """The start and block programs for `config`, and the block's options: a fixed
    step's, with the number of substeps an interval takes, or an adaptive solve's.
    `ValueError`, naming `where`, for a configuration they cannot take."""
    fixed = isinstance(config.stepsize_controller, diffrax.ConstantStepSize)
    if fixed and config.dt0 is None:
        raise ValueError(f"{where}: a fixed step (diffrax.ConstantStepSize) needs the solver's dt0")
    if not fixed and config.dt0 is not None:
        raise ValueError(
            f"{where}: an adaptive solver's dt0 must be None (diffrax checks a first step with a callback)"
        )
    if not fixed:
        return _start, _block, {}
    substeps = substeps_per_interval(ts, float(np.asarray(config.dt0)))
    if substeps * (ts.size - 1) > config.max_steps:
        raise ValueError(
            f"{where}: a fixed step of {float(np.asarray(config.dt0)):g} s takes "
            f"{substeps * (ts.size - 1)} steps from {ts[0]:g} to {ts[-1]:g} s, more than the solver's "
            f"max_steps = {config.max_steps}"
        )
    return _fixed_start, _fixed_block, {"substeps": substeps}


def _intervals(ts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each interval's start and end time and whether it is one: a zero-length one at
    `ts[0]` first, which the blocks skip but whose outputs are the initial state's (so
    that no program of its own computes them), then those between output times, padded
    to whole blocks with zero-length intervals at the end."""
    starts, ends = np.append(ts[0], ts[:-1]), ts
    pad = -len(starts) % BLOCK
    starts, ends = np.append(starts, np.full(pad, ts[-1])), np.append(ends, np.full(pad, ts[-1]))
    index = np.arange(len(starts))
    return starts, ends, (index > 0) & (index < len(ts))


@program
def _start(model, env, initial, t0, t1, config: SolverConfig):
    """The carry at `t0`: the free state, diffrax's solver state, the controller's state
    and `made_jump`, as `diffeqsolve` makes them for a solve from `t0` towards `t1`.
    (The outputs at `t0` are the first block's, from its leading zero-length interval.)"""
    terms, solver = terms_for(config.solver), config.solver
    y0 = integrated_state(solver, model, *initial)
    args = (model, env)
    error_order = solver.error_order(terms)
    _, controller_state = config.stepsize_controller.init(terms, t0, t1, y0, None, args, solver.func, error_order)
    carry = (y0, solver.init(terms, t0, t1, y0, args), controller_state, False)
    # As arrays, the types `_block` returns: the controller's initial state holds a
    # Python bool, which `eqx.filter_jit` would take for a static argument and compile
    # the first block apart from the rest.
    return jax.tree.map(lambda x: jnp.asarray(x, dtype=jnp.result_type(x)), carry)


@program
def _block(
    model,
    env,
    carry,
    starts: Float[ArrayLike, " block"],
    ends: Float[ArrayLike, " block"],
    active: Bool[ArrayLike, " block"],
    config: SolverConfig,
):
    """`BLOCK` intervals, each one `diffeqsolve` continuing the last: the carry after
    them, the free state `(positions, velocities)` at their ends (each with a leading
    axis of the block's intervals), the step counts `(steps, accepted, rejected)`
    summed, and the first failure's result code (successful if none)."""
    terms, solver = terms_for(config.solver), config.solver
    saveat = diffrax.SaveAt(t1=True, solver_state=True, controller_state=True, made_jump=True)

    def interval(carry, piece):
        t0, t1, on = piece

        def solve(carry):
            y, solver_state, controller_state, made_jump = carry
            solution = diffrax.diffeqsolve(
                terms,
                solver,
                t0,
                t1,
                None,
                y,
                args=(model, env),
                saveat=saveat,
                stepsize_controller=config.stepsize_controller,
                max_steps=config.max_steps,
                adjoint=config.adjoint,
                solver_state=solver_state,
                controller_state=controller_state,
                made_jump=made_jump,
                throw=False,
            )
            assert solution.ys is not None
            y = jax.tree.map(lambda x: x[-1], solution.ys)
            counts = jnp.stack(
                [solution.stats[k] for k in ("num_steps", "num_accepted_steps", "num_rejected_steps")]
            ).astype(jnp.int64)
            after = (y, solution.solver_state, solution.controller_state, solution.made_jump)
            return after, counts, solution.result

        def skip(carry):
            return carry, jnp.zeros(3, jnp.int64), diffrax.RESULTS.successful

        carry, first_failure = carry
        carry, counts, result = jax.lax.cond(on, solve, skip, carry)
        first_failure = diffrax.RESULTS.where(first_failure == diffrax.RESULTS.successful, result, first_failure)
        return (carry, first_failure), (public_state(solver, carry[0]), counts)

    (carry, failure), (ys, counts) = jax.lax.scan(interval, (carry, diffrax.RESULTS.successful), (starts, ends, active))
    return carry, ys, jnp.sum(counts, axis=0), failure


# Not in the blocks' programs, whose compile they nearly doubled (the Low & Langley file's
# block), and compiled as a program that runs once a block (`RUN_ONCE`).
@functools.partial(program, compiler_options=RUN_ONCE)
def _outputs(model, env, ends: Float[ArrayLike, " block"], ys, failure):
    """The outputs `(positions, velocities, strain, tension, reactions)` at a block's
    interval ends from its free states `ys`, and the block's result: its first failure,
    or `nonfinite` where a state is not finite though no solve failed."""
    outputs = result_of(model, env, ends, ys, {}, failure)
    return (outputs.positions, outputs.velocities, outputs.strain, outputs.tension, outputs.reactions), outputs.result


def substeps_per_interval(ts: Float[np.ndarray, " times"], dt: float) -> int:
    """The fewest equal steps that cover the longest interval between output times
    `ts` (s) with steps of at most `dt` (s). A step that divides the interval to
    rounding (MoorDyn's dtM = 1 ms into 0.05 s, say) gives the exact quotient."""
    longest = float(np.max(np.diff(ts)))
    return max(1, math.ceil(longest / dt * (1 - 1e-9)))


def _fixed_start_body(model, env, initial, t0, t1, config: SolverConfig):
    """As `_start`, for a fixed step: the carry is the free state, the solver's state
    and `made_jump`."""
    terms, solver = terms_for(config.solver), config.solver
    y0 = integrated_state(solver, model, *initial)
    carry = (y0, solver.init(terms, t0, t1, y0, (model, env)), False)
    return jax.tree.map(lambda x: jnp.asarray(x, dtype=jnp.result_type(x)), carry)


@program
def _fixed_start(model, env, initial, t0, t1, config: SolverConfig):
    """`_fixed_start_body`, compiled."""
    return _fixed_start_body(model, env, initial, t0, t1, config)


def _fixed_block_body(
    model,
    env,
    carry,
    starts: Float[ArrayLike, " block"],
    ends: Float[ArrayLike, " block"],
    active: Bool[ArrayLike, " block"],
    config: SolverConfig,
    substeps: int,
):
    """`BLOCK` intervals of `substeps` equal steps each, with `_block`'s returns. An
    explicit method's step cannot fail; an implicit one's root finder can, and the
    first failure is kept."""
    terms, solver = terms_for(config.solver), config.solver
    args = (model, env)

    def interval(carry, piece):
        t0, t1, on = piece
        dt = (t1 - t0) / substeps

        def step(inner, k):
            (y, solver_state, made_jump), failure = inner
            a = t0 + k * dt
            b = jnp.where(k == substeps - 1, t1, a + dt)
            y, _, _, solver_state, result = explicit_step(solver, terms, a, b, y, args, solver_state, made_jump)
            failure = diffrax.RESULTS.where(failure == diffrax.RESULTS.successful, result, failure)
            return ((y, solver_state, jnp.asarray(False)), failure), None

        def solve(inner):
            inner, _ = jax.lax.scan(step, inner, jnp.arange(substeps))
            return inner

        carry, failure = jax.lax.cond(on, solve, lambda inner: inner, carry)
        counts = jnp.where(on, substeps, 0).astype(jnp.int64) * jnp.ones(2, jnp.int64)
        return (carry, failure), (public_state(solver, carry[0]), counts)

    (carry, failure), (ys, counts) = jax.lax.scan(interval, (carry, diffrax.RESULTS.successful), (starts, ends, active))
    steps = jnp.sum(counts, axis=0)
    return carry, ys, jnp.concatenate([steps, jnp.zeros(1, jnp.int64)]), failure


@program
def _fixed_block(model, env, carry, starts, ends, active, config: SolverConfig, substeps: int):
    """`_fixed_block_body`, compiled."""
    return _fixed_block_body(model, env, carry, starts, ends, active, config, substeps)


# A batch of cases, in lockstep: `cases` holds the leaves that differ between cases
# (with a leading case axis) and `system` the shared ones, as `eqx.partition` splits
# `(model, env)`; the carry and the states have the case axis too. One program per
# structure and batch size, kept on disk as the single run's are.
@program
def _batch_fixed_start(cases, system, initial, t0, t1, config: SolverConfig):
    """`_fixed_start` of every case."""

    def one(case, initial):
        model, env = eqx.combine(case, system)
        return _fixed_start_body(model, env, initial, t0, t1, config)

    return jax.vmap(one)(cases, initial)


@program
def _batch_fixed_block(cases, system, carry, starts, ends, active, config: SolverConfig, substeps: int):
    """`_fixed_block` of every case, each with its own failure and step counts."""

    def one(case, carry):
        model, env = eqx.combine(case, system)
        return _fixed_block_body(model, env, carry, starts, ends, active, config, substeps)

    return jax.vmap(one)(cases, carry)


@program
def _batch_outputs(cases, system, ends, ys, failure):
    """`_outputs` of every case. Compiled as XLA compiles by default, not as a program
    that runs once (`RUN_ONCE`): over a sweep's blocks it runs as many field
    evaluations as there are output times, which the kernels of `RUN_ONCE` took
    three times as long over (32 cases of the anchored line, 6,001 output times: 1.9 s
    of CPU against 0.6 s)."""

    def one(case, ys, failure):
        model, env = eqx.combine(case, system)
        out = result_of(model, env, ends, ys, {}, failure)
        return (out.positions, out.velocities, out.strain, out.tension, out.reactions), out.result

    return jax.vmap(one)(cases, ys, failure)


def prepare_batch(
    cases, system, ts: Float[np.ndarray, " times"], initial, solver: SolverConfig, where: str = "sweep"
) -> None:
    """Start compiling the programs that [`integrate_batch_in_blocks`][] will run with
    these arguments (`initial` may be `jax.ShapeDtypeStruct`s), in a background thread,
    where programs are kept (`jaxcable._programs`); a later call waits for them. So
    threads that each run a chunk of a batch do not each compile them.

    **Raises:**

    `ValueError`, naming `where`, for a solver without a fixed step or one that would
    take more than its `max_steps` steps."""
    ts = np.asarray(ts, dtype=float)
    _, _, options = _programs_for(solver, ts, where)
    programs = (_batch_fixed_start, _batch_fixed_block, _batch_outputs)
    _prepare_programs(programs, (cases, system), initial, ts, solver, options)


def integrate_batch_in_blocks(
    cases,
    system,
    ts: Float[np.ndarray, " times"],
    initial: tuple,
    solver: SolverConfig,
    out: list[np.ndarray],
    on_block: Callable[[float], None] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Integrate a batch of cases in lockstep with fixed steps, saving at `ts`, as
    [`simulate_in_blocks`][] integrates one: each output interval is `n` equal steps of
    the solver's own `step`, and the intervals run `BLOCK` at a time in one compiled
    `lax.scan` over the batch, whose program is kept on disk.

    **Arguments:**

    - `cases`, `system`: `(model, env)` split as `eqx.partition` splits it: the leaves
        that differ between cases, each with a leading case axis, and the shared ones
        (the topology among them), each tree with `None` in the other's places.
    - `ts`: output times (s), concrete, strictly increasing, at least two.
    - `initial`: each case's `(positions, velocities)` at `ts[0]`, each of shape
        `(cases, nodes, 3)`.
    - `solver`: a fixed step (`stepsize_controller=diffrax.ConstantStepSize()` with
        `dt0`), the same for every case.
    - `out`: numpy arrays that the outputs at `ts` are written into, block by block:
        positions and velocities (m, m/s) of shape `(cases, times, nodes, 3)`, strain
        (–) and tension (N) `(cases, times, segments)` and reactions (N) `(cases,
        times, constrained, 3)` (views of a larger batch's arrays, say).
    - `on_block`: called after each block with the simulated time (s) it reached.

    **Returns:**

    Each case's diffrax result code (as the integers of `diffrax.RESULTS`), shape
    `(cases,)`: `nonfinite` where its state became non-finite (its step beyond the
    stability limit), or its implicit solver's first failure, the others running on
    to `ts[-1]`; and its step counts (steps, accepted, rejected), shape `(cases, 3)`.

    **Raises:**

    `ValueError` for bad times, a solver without a fixed step, or more steps than the
    solver's `max_steps`.
    """
    if not isinstance(solver.stepsize_controller, diffrax.ConstantStepSize) or solver.dt0 is None:
        raise ValueError(
            "integrate_batch_in_blocks: the solver must take fixed steps (diffrax.ConstantStepSize with dt0)"
        )
    ts = np.asarray(ts, dtype=float)
    if ts.ndim != 1 or ts.size < 2:
        raise ValueError(f"integrate_batch_in_blocks: ts must be 1-D with at least 2 times, got shape {ts.shape}")
    checks.enforce(
        [checks.finite("integrate_batch_in_blocks: ts", ts), checks.increasing("integrate_batch_in_blocks: ts", ts)]
    )
    _, _, options = _programs_for(solver, ts)
    carry = _batch_fixed_start(cases, system, initial, ts[0], ts[1], solver)
    starts, ends, active = _intervals(ts)
    codes, steps = [], 0
    for k in range(0, len(starts), BLOCK):
        part = slice(k, k + BLOCK)
        carry, ys, counts, failure = _batch_fixed_block(
            cases, system, carry, starts[part], ends[part], active[part], solver, **options
        )
        saved, result = _batch_outputs(cases, system, ends[part], ys, failure)
        written = slice(k, min(k + BLOCK, len(ts)))  # the last block's padding is not
        for column, x in zip(out, to_host(saved)):
            column[:, written] = x[:, : written.stop - written.start]
        # (An enumeration's item is a pytree of its code, read through `jax.tree`.)
        codes.append(result_codes(result))
        steps = steps + to_host(counts)
        if on_block is not None:
            on_block(float(ends[part][active[part]][-1]))
    # Each case's first failure over the blocks (a block's result is its own first).
    codes = np.stack(codes)
    failed = codes != result_codes(diffrax.RESULTS.successful)
    return codes[np.argmax(failed, axis=0), np.arange(codes.shape[1])], np.asarray(steps)
