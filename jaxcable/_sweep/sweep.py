"""Sweeps: one compiled, vmapped simulation over a batch of parameter values.

A sweep builds the models of all cases at once: `build(**case)` is traced once under
an eager `jax.vmap`, so float leaves that depend on the swept parameters come out
batched while the topology (node and segment indices, motions' structure, static
options) stays a single, unbatched constant. Every case is one diffrax solve with
`throw=False` inside one compiled `vmap`; a case that fails keeps its own result code
and does not stop, or change, the others.

The case axis is split across devices by sharding: the batched inputs are placed with
`NamedSharding(Mesh(devices, ("cases",)), PartitionSpec("cases"))` and the compiler
partitions the vmapped solve to match. (Not `jax.shard_map`, which would let each
device run its own loop without the per-step agreement on whether any case is still
running: lineax, which the statics and implicit solvers use, rejects the
manual-axis shardings that values carry inside it, with JAX 0.10 and lineax 0.1.)
On one device no mesh is built: the sweep is a plain `jit(vmap(...))`.

On a CPU the batch is also split into chunks, run by the same compiled program on
threads, one a core. XLA's CPU backend ran a batched step's kernels on about one core
(128 cases of the anchored line: 32.7 s in one batch, 17.3 s in two chunks on two
cores), and JAX releases the GIL while a program runs, so the threads keep every core
busy without the process-wide `XLA_FLAGS` that would split the host into devices.

There, on one device, cases that choose their own adaptive steps are not batched at
all: each chunk's cases run one after another (`lax.map`), each chunk one case by
default. In lockstep under `vmap` every case waits for the slowest, and the while loop
selects every carried array between each case's old and new value at every step; on a
CPU that cost more than it saved (the anchored line, 20 segments, Dopri5 over 10 s: 28 µs
a case and step for 16 cases in lockstep, 21 µs for one case alone, and 32 cases over
60 s took 17,100 to 58,700 steps each). Fixed steps, shared steps and other devices keep
the batch.
"""

import functools
import itertools
import threading
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx
from jax.sharding import Mesh, NamedSharding, PartitionSpec

from .. import _checks as checks
from .._model.network import CableNetwork, unheld_nodes, without_absent_bodies
from .._model.state import State
from .._programs import RUN_ONCE, program
from .._progress import progress_bar
from .._sea.environment import Environment
from .._simulation.blocks import integrate_batch_in_blocks, prepare_batch, substeps_per_interval
from .._simulation.simulate import (
    IMEX_SOLVERS,
    INITIAL_STATES,
    SimulationResult,
    _simulate,
    as_config,
    for_model,
    result_codes,
    result_of,
    to_host,
    vector_field,
)
from .._solver.config import SolverConfig, describe_stepping
from .._solver.stability import STEP_FRACTION, fixed_steps
from .._statics.solution import StaticSolution
from .._statics.solve import failure_message, solve_statics
from .._typing import RealLike
from .cases import build_batch, build_first, check_keywords, check_parameters, each_case, invalid_cases, statics_differ
from .devices import CASES, available_cores, check_chunks, check_devices, place, split
from .result import SweepResult

STEPS = ("per_case", "shared")


# Step-size controllers whose steps do not depend on the state: every case of a batch
# takes the same steps.
_FIXED_STEPS = (diffrax.ConstantStepSize, diffrax.StepTo)


def sweep(
    build: Callable[..., tuple[CableNetwork, Environment]],
    parameters: Mapping[str, RealLike],
    t1: float,
    *,
    t0: float = 0.0,
    ts: RealLike | None = None,
    initial: str | State = "statics",
    solver: SolverConfig | None = None,
    steps: str = "per_case",
    chunks: int | None = None,
    devices: Sequence[jax.Device] | None = None,  # pyright: ignore[reportInvalidTypeForm]  (jax.Device is an alias of jaxlib's class)
    progress: bool = False,
) -> SweepResult:
    """Simulate one model over a batch of parameter values, in one compiled solve.

    `build` is called once on concrete values (the first case, so that constructors'
    checks run with real values and name any bad field), then once under an eager
    `jax.vmap` over all cases, with one scalar per parameter. Not under `jit`: what
    does not depend on the parameters stays concrete, so `build` may use numpy on its
    fixed inputs. Everything it derives from the parameters comes out batched; its
    topology must not depend on them. Each case is then integrated as
    [`jaxcable.simulate`][] would with the same solver, with `throw=False`, so a case
    that fails is reported in its `status` and leaves the others' results untouched.

    Told no solver, a sweep takes fixed RK4 steps at 0.7 of their stability limit at
    the fastest mode of its stiffest case ([`jaxcable.fixed_steps`][]), shortened so
    that each interval between output times is a whole number of steps: every case
    takes the same steps, the batch runs in lockstep, and each output time ends a
    step. `SweepResult.stepping` says which. On the anchored line (20 segments, lumped,
    60 s at 100 Hz) that is 5 ms steps, 12,000 a case, where the adaptive Dopri5 of
    `simulate` took 17,100–58,700, and the peak tension over the first snap lies
    within 0.5 % of a converged run's (MoorDyn's midpoint steps of 1 ms: 0.2–0.4 %;
    `benchmarks/default_stepping.py`). Pass `solver=SolverConfig()` for
    `simulate`'s adaptive steps.

    Every case's model and water are checked as their constructors check concrete
    values (the traced build cannot), by the same conditions. A case that breaks one (a
    negative stiffness, say) is not integrated: it reports `"invalid input: case i:
    <field> must be ..., got <value>"` in its `status`, `inf` outputs and
    `diffrax.RESULTS.nonfinite_input`. So that the batch computes only with valid
    values, its leaves are replaced by those of the first valid case before the
    batch runs; the other cases are unchanged and equal their single runs.

    The cases are split across `devices` by sharding. When their number is not
    a multiple of the device count the batch is padded by repeating the last case, and
    the padding is dropped from the result. The returned arrays stay split by case
    across the devices, except after padding was dropped: JAX cannot split an array
    unevenly, so those are gathered onto every device. On one device nothing is
    padded or sharded.

    Compiles once per model structure (topology, static options, which leaves are
    swept), batch size, device set and options. Later calls with new values reuse it,
    even through a new `build` function that makes the same structure: the models
    enter the compiled solve as data.

    With fixed steps each case equals its single run with them to rounding. With
    adaptive steps each case matches its single [`jaxcable.simulate`][] run to rounding
    at first (1e-11 of the peak tension over the anchored-line paper's first second). Batched and
    single compiled code round differently, though, and over long snapping histories
    that can change the adaptive steps: over 4 s, step counts differed by up to 4 % and
    tensions at a given time by up to 3 % of the peak, the same order as the solver's
    own error at `rtol = 1e-6`. Tighten `rtol` when histories must agree pointwise.
    On a CPU with one device, cases with their own adaptive steps are not batched
    but integrated one at a time (see `chunks`), and each equals its single run
    bitwise, steps included.

    !!! note

        Where the batch integrates in lockstep (on other devices, or on several
        CPU devices), a vmapped while loop runs until its slowest case finishes, and
        finished cases wait. So a case that runs out of `max_steps` costs every case
        on its device `max_steps` steps. Set the configuration's `max_steps` to a few
        times what a good case needs, rather than leaving it at a million.

    **Arguments:**

    - `build`: a function `build(**case) -> (model, env)` returning a
        [`jaxcable.CableNetwork`][] and an [`jaxcable.Environment`][]. It receives one
        scalar per parameter, by name; use JAX operations on them (not `float()`,
        `if`, or numpy), or replace float leaves of a prebuilt model with
        `eqx.tree_at`.
    - `parameters`: a mapping from each of `build`'s keyword names to its values, a
        1-D array of shape `(cases,)`; every parameter has the same number of cases.
        [`jaxcable.sweep_grid`][] makes a Cartesian product.
    - `t1`, `t0`: end and start time (s), shared by all cases.
    - `ts`: output times (s), shape `(times,)`, shared; 201 evenly spaced times from
        `t0` to `t1` by default.
    - `initial`: where each case starts. `"statics"` (default): its own static
        equilibrium, solved inside the batch by [`jaxcable.solve_statics`][] with
        constrained nodes at their positions at `t0` (with the same fallbacks as a
        single call); a case whose statics fails is reported as failed and not
        integrated. Where the swept parameters cannot change that equilibrium, it is
        solved once instead, for more than one case, by an eager `solve_statics`
        call (whose program is kept on disk, or the discrete catenary that needs
        none), and shared by every case: so when, the valid cases' values being
        compared exactly, no float leaf of the model or the water differs between
        cases except in the motions, and the motions put every constrained node at
        the same position at `t0` (a harmonic amplitude with zero phase, say; not a
        phase, a current, a length or a stiffness, and not the waves, whose loads
        at `t0` statics includes). The batch's program then compiles without
        statics: the first call of a 32-case, 60 s RK4 sweep of the anchored line took
        10.3 s instead of 19.6 s. `SweepResult.statics_shared` and the summary say
        so. A shared equilibrium agrees with the per-case ones to the statics'
        tolerance, not to rounding.
        A network with a part that nothing holds has no equilibrium and starts at
        rest, as in [`jaxcable.simulate`][]. `"rest"`: `model.node_positions` at rest.
        A [`jaxcable.State`][]: positions and velocities of shape `(nodes, 3)` shared by
        all cases, or `(cases, nodes, 3)`, one per case.
    - `solver`: a [`jaxcable.SolverConfig`][], as for [`jaxcable.simulate`][], shared
        by all cases; its `max_steps` counts each case's own steps. By default, fixed
        RK4 steps chosen for the cases' fastest modes (above). With fixed steps
        (`diffrax.ConstantStepSize` with `dt0`) every case takes the same steps, in
        blocks of output intervals whose compiled programs are kept on disk
        (`jaxcable._simulation.blocks`): each interval between output times (and from `t0` to the
        first) is `n` equal steps of at most `dt0`, with no interpolation, and the
        outputs are computed in one vectorised pass a block. A case whose state
        becomes non-finite (its step beyond the stability limit) fails with
        `diffrax.RESULTS.nonfinite`; the others run on.
    - `steps`: `"per_case"` (default): each case chooses its own steps, and matches
        its single run to rounding at first. `"shared"`: the batch is one system with
        one adaptive step, the smallest any case needs, so each case is integrated at
        least as finely as alone but with different steps (its results agree with its
        single run to the tolerance, not to rounding), and `stats` counts the shared
        steps. Faster on a CPU, where the per-case loop's masking of every carried
        array at every step costs more than the evaluations
        (`benchmarks/sweep_throughput.py`). One case that fails (too many steps, a collapsing step) fails the
        others of its chunk; explicit solvers only. With `chunks`, each chunk has its
        own shared step.
    - `chunks`: how many groups of consecutive cases to run, on threads through the
        same compiled program. By default, on CPU devices, two per core this process
        may use, over the number of devices, where each keeps at least 16 cases (4 on
        a 2-core machine with one device from 64 cases), else one per core; 1 on other
        devices. Each chunk equals what a sweep of its cases alone would give. On a
        CPU with one device and `steps="per_case"` with an adaptive controller, the
        cases of a chunk run one after another, not batched, and the default is one
        case a chunk, on as many threads as cores: each thread takes the next case
        when it finishes one. 1 (and only 1) where the devices span processes.
    - `devices`: the JAX devices to split the cases (of each chunk) across;
        `jax.devices()` by default. Across processes and hosts (JAX's multi-controller
        runtime: `jax.distributed.initialize()` in every process, which then all call
        `sweep` alike), `jax.devices()` are every process's devices: the batch is one
        global batch split across them, and each process's `SweepResult` holds every
        case once its arrays are gathered (`jax.experimental.multihost_utils`).
    - `progress`: show a progress bar on stderr in simulated seconds, summed over the
        cases (`sweep: |███   | 480.0/1920.0 s simulated` for 32 cases of 60 s), as
        [`jaxcable.simulate`][]'s; with fixed steps it moves after each block of 64
        output intervals, otherwise as each chunk finishes (each case, with the CPU's
        default chunks for adaptive steps).

    **Returns:**

    A [`jaxcable.SweepResult`][].

    **Raises:**

    `ValueError` naming the parameter and value if `parameters` is empty, a parameter
    is not 1-D, empty, not finite, of a different length from the others, or not a
    keyword `build` takes; if `build` does not return `(CableNetwork, Environment)`,
    uses a parameter's value in Python, returns a topology that depends on the
    parameters, or returns nothing that depends on them; if every case's values are
    invalid (naming the first); and for bad times, `initial`, `solver` or `devices`.
    Errors raised by `build` on the first case propagate, with a note naming the case.
    """
    values = check_parameters(parameters)
    n_cases = len(next(iter(values.values())))
    check_keywords(build, values)
    if not t1 > t0:
        raise ValueError(f"sweep: t1 must be greater than t0, got t0={t0}, t1={t1}")
    ts = np.linspace(t0, t1, 201) if ts is None else np.asarray(ts, dtype=float)
    if ts.ndim != 1 or ts.size == 0:
        raise ValueError(f"sweep: ts must be a non-empty 1-D array, got shape {ts.shape}")
    if not (ts[0] >= t0 and ts[-1] <= t1 and np.all(np.diff(ts) >= 0)):
        raise ValueError(
            f"sweep: ts must be increasing and lie within [t0, t1] = [{t0}, {t1}], got [{ts[0]}, {ts[-1]}]"
        )
    if isinstance(initial, str):
        checks.option("sweep: initial", initial, INITIAL_STATES)
    elif not isinstance(initial, State):
        raise ValueError(f"sweep: initial must be 'statics', 'rest' or a jaxcable.State, got {initial!r}")
    checks.option("sweep: steps", steps, STEPS)
    config = None if solver is None else as_config("sweep", solver)
    devices = check_devices(devices)
    # On one CPU device, cases with their own adaptive steps run one at a time (see the
    # module's notes): a chunk a case unless told otherwise.
    if steps == "shared":
        if config is None:
            raise ValueError("sweep: steps='shared' shares an adaptive step; give its solver, such as SolverConfig()")
        if isinstance(config.solver, IMEX_SOLVERS) or isinstance(config.solver, diffrax.AbstractImplicitSolver):
            raise ValueError(f"sweep: steps='shared' takes an explicit solver, got {type(config.solver).__name__}")

    reference = build_first(build, values)
    batched, unbatched = build_batch(build, values, reference)
    if not jax.tree.leaves(batched):
        raise ValueError(
            f"sweep: build returned the same model and water for every case: nothing it returns depends on "
            f"{', '.join(map(repr, values))}, so the cases would not differ. Use the parameters in build "
            "(jax.numpy on them, or eqx.tree_at on a prebuilt model's float leaves)"
        )
    invalid = invalid_cases(batched, unbatched, reference)
    if len(invalid) == n_cases:
        raise ValueError(f"sweep: every case is invalid; {invalid[0]}")
    if invalid:
        bad = np.asarray(sorted(invalid))
        good = next(i for i in range(n_cases) if i not in invalid)
        batched = jax.tree.map(lambda x: x.at[bad].set(x[good]), batched)
    if config is None:
        config = fixed_steps(each_case(batched, unbatched), duration=t1 - t0)
    # With fixed steps every case takes the same steps: the batch runs in lockstep, in
    # blocks of output intervals whose programs are kept on disk (`jaxcable._simulation.blocks`).
    in_blocks = (
        steps == "per_case"
        and isinstance(config.stepsize_controller, diffrax.ConstantStepSize)
        and config.dt0 is not None
    )
    # On one CPU device, cases with their own adaptive steps run one at a time (see the
    # module's notes): a chunk a case unless told otherwise.
    in_turn = (
        steps == "per_case"
        and len(devices) == 1
        and devices[0].platform == "cpu"
        and not isinstance(config.stepsize_controller, _FIXED_STEPS)
    )
    if any(d.process_index != jax.process_index() for d in devices):
        # Across processes (`jax.distributed`) every process must launch the programs it
        # shares with the others in the same order, which chunks on threads would not.
        if chunks not in (None, 1):
            raise ValueError(f"sweep: chunks must be 1 where the devices span processes, got {chunks!r}")
        chunks = 1
    chunks = n_cases if in_turn and chunks is None else min(check_chunks(chunks, devices, n_cases), n_cases)

    # Per-case inputs carry the case axis and are split across devices; shared inputs
    # (the topology among them) are replicated.
    per_case = {"model": batched, "valid": np.asarray([i not in invalid for i in range(n_cases)])}
    shared = {
        "model": unbatched,
        "t0": np.asarray(t0, dtype=float),
        "t1": np.asarray(t1, dtype=float),
        "ts": ts,
        "solver": for_model(config, reference[0]),
    }
    mode = initial if isinstance(initial, str) else "state"
    if mode == "statics" and unheld_nodes(reference[0]) is not None:
        mode = "rest"  # a part that nothing holds has no equilibrium, as in `simulate`
    if mode == "statics" and n_cases > 1 and not statics_differ(batched, unbatched, t0):
        good = next(i for i in range(n_cases) if i not in invalid)
        # Indexed on the host: a JAX array's index is a program of its own, eagerly.
        model, env = eqx.combine(jax.tree.map(lambda x: jax.device_put(np.asarray(x)[good]), batched), unbatched)
        try:
            shared["statics"] = solve_statics(model, env, t=t0, throw=False)
            mode = "shared statics"
        except ValueError:
            # Refused before solving (a line far too short for its ends, say): each
            # case solved in the batch reports that as its own failed statics, as
            # where the cases differ.
            pass
    if isinstance(initial, State):
        shape = reference[0].node_positions.shape
        start = (np.asarray(initial.positions, dtype=float), np.asarray(initial.velocities, dtype=float))
        if start[0].shape != start[1].shape or start[0].shape not in (shape, (n_cases, *shape)):
            raise ValueError(
                f"sweep: initial.positions and initial.velocities must have shape {shape} (shared) "
                f"or {(n_cases, *shape)} (one per case), got {start[0].shape} and {start[1].shape}"
            )
        if not (np.all(np.isfinite(start[0])) and np.all(np.isfinite(start[1]))):
            raise ValueError("sweep: initial.positions and initial.velocities must be finite")
        (per_case if start[0].ndim == 3 else shared)["initial"] = start

    n_devices = len(devices)
    padding = -n_cases % (n_devices * chunks)
    if padding:
        # Repeat the last case rather than pad with zeros (a zero stiffness, say),
        # which could fail or take longer than every real case; it is dropped below.
        per_case = jax.tree.map(lambda x: jnp.concatenate([x, jnp.repeat(x[-1:], padding, axis=0)]), per_case)
    if n_devices == 1:
        mesh = None
        parts = place(split(per_case, chunks), devices[0])
        shared = place(shared, devices[0])
    else:
        mesh = Mesh(np.asarray(devices), (CASES,))
        parts = place(split(per_case, chunks), NamedSharding(mesh, PartitionSpec(CASES)))
        shared = place(shared, NamedSharding(mesh, PartitionSpec()))

    stepping = describe_stepping(config)
    if in_blocks:
        # The steps taken: each interval between output times in equal steps of at most dt0.
        grid, _ = _grid(t0, t1, ts)
        dt = float(np.max(np.diff(grid))) / substeps_per_interval(grid, float(np.asarray(config.dt0)))
        stepping = f"{type(config.solver).__name__}, fixed steps of {dt:.4g} s"
    if solver is None:
        stepping += (
            f" ({STEP_FRACTION:g} of its stability limit at the fastest modes, or less to end at the output times)"
        )
    with progress_bar(n_cases * (t1 - t0), progress, "sweep") as reached:
        done = _Done(reached, n_cases, t1 - t0)
        if in_blocks:
            simulation, statics, success = _run_in_blocks(parts, shared, mode, done)
        elif chunks == 1:
            simulation, statics, success = done(_run(parts[0], shared, mode, steps, mesh, in_turn), n_cases)
        else:
            # Compiled ahead of the threads: called first through `jit`, the chunks of a
            # first call ran one after the other, taking twice as long as warm.
            compiled = _run.lower(parts[0], shared, mode, steps, mesh, in_turn).compile()
            # Chunks run in turn take a core each; batched chunks each take a thread, two
            # a core by default (`check_chunks` says why).
            threads = min(chunks, available_cores()) if in_turn else chunks

            def run(part):
                return done(compiled(part, shared, mode, steps, mesh, in_turn), len(part["valid"]))

            with ThreadPoolExecutor(threads) as pool:
                outputs = list(pool.map(run, parts))
            simulation, statics, success = jax.tree.map(lambda *x: jnp.concatenate(x), *outputs)
        if mesh is not None:
            simulation, statics, success = place(
                (simulation, statics, success), NamedSharding(mesh, PartitionSpec(CASES))
            )
    if padding:
        simulation, statics, success = jax.tree.map(lambda x: x[:n_cases], (simulation, statics, success))
    return SweepResult(
        parameters={k: jax.device_put(np.asarray(v)) for k, v in values.items()},
        simulation=simulation,
        statics=statics,
        success=success,
        status=_status(simulation, statics, invalid),
        statics_shared=mode == "shared statics",
        stepping=stepping,
    )


@eqx.filter_jit
def _run(per_case, shared, mode, steps, mesh, in_turn):
    """The compiled batch: `vmap` over cases, split across the devices of `mesh` (if
    given) by the sharding of the inputs; or, `in_turn`, each case's statics and
    solve one after another (`lax.map`), each with its own adaptive steps. Returns the
    batched `SimulationResult`, `StaticSolution` (or `None`) and success flags.

    Compiled once per model structure (topology, static options), batch size, mesh
    and options: the model arrives as data, not through the user's `build`, so a new
    `build` function does not recompile.
    """
    # vmap maps arrays only; the rest of the shared tree (the solver's functions, say)
    # is closed over.
    shared, shared_static = eqx.partition(shared, eqx.is_array)

    def own_steps(case_system, start, shared, t1, ts):
        shared = eqx.combine(shared, shared_static)
        model, env = case_system
        return _simulate(model, env, start, shared["t0"], t1, ts, shared["solver"], diffrax.NoProgressMeter(), False)

    def prepare(case, shared):
        return _prepare(case, eqx.combine(shared, shared_static), mode)

    if in_turn:
        systems, starts, statics, valid, ok = jax.lax.map(lambda case: prepare(case, shared), per_case)
    else:
        systems, starts, statics, valid, ok = jax.vmap(prepare, in_axes=(0, None))(per_case, shared)
    if steps == "shared":
        simulation = _shared_steps(systems, starts, ok, eqx.combine(shared, shared_static))
    else:
        t0, t1, ts = shared["t0"], shared["t1"], shared["ts"]
        if isinstance(shared_static["solver"].stepsize_controller, _FIXED_STEPS):
            # Every case takes the same steps. Given the same times too, the loops'
            # conditions (diffrax's over steps and, within each step, over the output
            # times it passes) are the batch's, not each case's, so `vmap` masks
            # nothing. With a condition per case, saving 6,001 output times of 16
            # cases over 7,200 RK4 steps of the anchored line cost 0.64 s of CPU time
            # beside the steps' 1.02 s; with the batch's, 0.01 s. A case not to be
            # integrated runs a copy of one that is (`finish` replaces its outputs),
            # and none runs when none is to.
            donor = jnp.argmax(ok)
            arrays, rest = eqx.partition((systems, starts), eqx.is_array)
            arrays = jax.tree.map(lambda x: jnp.where(ok.reshape(-1, *[1] * (x.ndim - 1)), x, x[donor]), arrays)
            systems, starts = eqx.combine(arrays, rest)
            t1, ts, axis = jnp.where(jnp.any(ok), t1, t0), jnp.where(jnp.any(ok), ts, t0), None
        else:
            # A case that is invalid or without equilibrium is not integrated: with
            # t1 = t0 diffrax takes no step, so it cannot hold the batch's loop (or its
            # max_steps) hostage.
            t1, ts, axis = jnp.where(ok, t1, t0), jnp.where(ok[:, None], ts, t0), 0
        if in_turn:
            simulation = jax.lax.map(
                lambda case: own_steps(case[0], case[1], shared, case[2], case[3]), (systems, starts, t1, ts)
            )
        else:
            simulation = jax.vmap(own_steps, in_axes=(0, 0, None, axis, axis))(systems, starts, shared, t1, ts)
    outputs = jax.vmap(_finish)(simulation, statics, valid, ok)
    if mesh is not None:
        # Keep every output split by case, as the inputs are, so that no device
        # gathers the whole batch.
        outputs = jax.lax.with_sharding_constraint(outputs, NamedSharding(mesh, PartitionSpec(CASES)))
    return outputs


def _prepare(case, shared, mode: str):
    """A case's model and water, start, statics (or `None`) and flags: `valid` input,
    and `ok` to integrate. `mode` is `"statics"` (its own equilibrium), `"shared
    statics"` (the one solved before the batch, in `shared["statics"]`, which `vmap`
    hands every case a copy of), `"rest"` or `"state"` (given, per case or shared)."""
    model, env = eqx.combine(case["model"], shared["model"])
    valid = case["valid"]
    statics = None
    ok = valid
    if mode in ("statics", "shared statics"):
        statics = solve_statics(model, env, t=shared["t0"], throw=False) if mode == "statics" else shared["statics"]
        start = (statics.state.positions, statics.state.velocities)
        ok = valid & (statics.result == optx.RESULTS.successful)
    elif mode == "rest":
        start = (model.node_positions, jnp.zeros_like(model.node_positions))
    else:
        start = case["initial"] if "initial" in case else shared["initial"]
    return (model, env), start, statics, valid, ok


def _finish(simulation, statics, valid, ok):
    """One case's outputs as the sweep reports them: those of a case that was not
    integrated (invalid, or without equilibrium) `inf`, its code its statics' (or
    `nonfinite_input`); and whether the case succeeded."""
    # No state was integrated: inf throughout, as diffrax marks outputs past a
    # failure, and the statics' code promoted to diffrax's enumeration (or, for an
    # invalid case, `nonfinite_input`) so that `simulation.success` is False too.
    # And no steps counted: with fixed steps such a case ran a valid case's copy.
    arrays = ("times", "positions", "velocities", "strain", "tension", "reactions")
    simulation = eqx.tree_at(
        lambda s: [*(getattr(s, a) for a in arrays), s.stats],
        simulation,
        [
            *(jnp.where(ok, getattr(simulation, a), jnp.inf) for a in arrays),
            {k: jnp.where(ok, v, 0) for k, v in simulation.stats.items()},
        ],
    )
    # pyright takes an equinox Enumeration's members for literals, not for instances of it.
    failure: diffrax.RESULTS = diffrax.RESULTS.nonfinite_input  # pyright: ignore[reportAssignmentType]
    if statics is not None:
        failure = diffrax.RESULTS.where(valid, diffrax.RESULTS.promote(statics.result), failure)
        # An invalid case's statics are its substitute's: not to be read as its own.
        floats, rest = eqx.partition(statics, eqx.is_inexact_array)
        statics = eqx.combine(jax.tree.map(lambda x: jnp.where(valid, x, jnp.inf), floats), rest)
        invalid: optx.RESULTS = optx.RESULTS.nonfinite_input  # pyright: ignore[reportAssignmentType]  (as above)
        statics = eqx.tree_at(lambda s: s.result, statics, optx.RESULTS.where(valid, statics.result, invalid))
    result = diffrax.RESULTS.where(ok, simulation.result, failure)
    simulation = eqx.tree_at(lambda s: s.result, simulation, result)
    return simulation, statics, simulation.result == diffrax.RESULTS.successful


class _Done:
    """Moves the sweep's bar (if any) to the simulated seconds done, summed over the
    cases; called from the chunks' threads, as each finishes or each block of it."""

    def __init__(self, reached, n_cases: int, duration: float):
        self.reached, self.n_cases, self.duration = reached, n_cases, duration
        self.seconds: dict[int, float] = {}  # each chunk's cases × simulated seconds
        self.chunks = itertools.count()
        self.lock = threading.Lock()

    def __call__(self, outputs, cases: int):
        """A chunk of `cases` cases finished with `outputs`."""
        outputs = jax.block_until_ready(outputs)
        self.reach(next(self.chunks), cases * self.duration)
        return outputs

    def reach(self, chunk: int, seconds: float) -> None:
        """Chunk `chunk` has simulated `seconds` (s), summed over its cases."""
        if self.reached is None:
            return
        with self.lock:
            self.seconds[chunk] = seconds
            # A chunk's padding (repeats of the last case) is not counted.
            self.reached(min(sum(self.seconds.values()), self.n_cases * self.duration))


def _run_in_blocks(parts, shared, mode: str, done: _Done):
    """The batch with fixed steps: each chunk's starts (`_starts`), then its cases in
    lockstep, block by block of output intervals (`integrate_batch_in_blocks`), each
    chunk on a thread of its own, writing into the batch's outputs; the cases not
    integrated (`ok` false) then reported as `_finish` reports them. Returns the
    batched `SimulationResult`, `StaticSolution` (or `None`) and success flags, as
    `_run` does.

    The blocks integrate from `t0` through the output times, on `_grid`'s times,
    whose outputs are then read at `ts`.
    """
    t0, ts = float(shared["t0"]), np.asarray(shared["ts"])
    grid, at = _grid(t0, float(shared["t1"]), ts)
    config: SolverConfig = shared["solver"]
    inputs = {k: v for k, v in shared.items() if k not in ("solver", "ts", "t1")}
    system = shared["model"]
    sizes = [len(part["valid"]) for part in parts]
    offsets = np.cumsum([0, *sizes])
    with ThreadPoolExecutor(len(parts)) as pool:
        starts = list(pool.map(lambda part: _starts(part, inputs, mode), parts))
    statics, valid, ok = (
        jax.tree.map(lambda *x: np.concatenate(to_host(list(x))), *[s[i] for s in starts]) for i in range(1, 4)
    )
    model = eqx.combine(parts[0]["model"], system)[0]
    nodes, constrained = model.node_positions.shape[-2], len(model.constrained_nodes)
    shapes = [(nodes, 3), (nodes, 3), (model.n_segments,), (model.n_segments,), (constrained, 3)]
    # Written block by block; a case not integrated is `inf` once `_finish`ed.
    outputs = [np.empty((offsets[-1], grid.size, *shape)) for shape in shapes]
    codes, steps = np.zeros(offsets[-1], np.int32), np.zeros((offsets[-1], 3), np.int64)

    cases, lean = _without_absent_bodies([part["model"] for part in parts], system)

    def run(chunk: int):
        here = slice(offsets[chunk], offsets[chunk + 1])
        codes[here], steps[here] = integrate_batch_in_blocks(
            cases[chunk],
            lean,
            grid,
            starts[chunk][0],
            config,
            [x[here] for x in outputs],
            on_block=lambda t: done.reach(chunk, sizes[chunk] * (t - t0)),
        )

    if ok.any():  # else none is integrated
        # Compiled (or loaded) before the threads start, so that they do not each compile it.
        prepare_batch(cases[0], lean, grid, starts[0][0], config)
        with ThreadPoolExecutor(len(parts)) as pool:
            list(pool.map(run, range(len(parts))))
    if not np.array_equal(at, np.arange(grid.size)):
        outputs = [x[:, at] for x in outputs]
    stats = {k: steps[:, i] for i, k in enumerate(("num_steps", "num_accepted_steps", "num_rejected_steps"))}
    fields = (np.broadcast_to(ts, (len(codes), ts.size)), *outputs, stats, codes)
    # Built as one case (whose shapes its annotations check), then given the batch's
    # arrays, as `vmap` builds it in `_run`. `device_put`, not `jnp.asarray`, which
    # compiles a program of its own for each shape.
    times, positions, velocities, strain, tension, reactions, counts, code = jax.device_put(
        [jax.tree.map(lambda x: x[0], field) for field in fields]
    )
    result = jax.tree.map(lambda _: code, diffrax.RESULTS.successful)
    case = SimulationResult(times, positions, velocities, strain, tension, reactions, counts, result)
    simulation = eqx.tree_at(
        lambda s: (s.times, s.positions, s.velocities, s.strain, s.tension, s.reactions, s.stats, s.result),
        case,
        (*jax.device_put(fields[:-1]), jax.tree.map(lambda _: jax.device_put(codes), case.result)),
    )
    if not ok.all():
        return _finish_batch(simulation, statics, valid, ok)
    return simulation, statics, jax.device_put(codes == result_codes(diffrax.RESULTS.successful))


def _without_absent_bodies(cases: list, system) -> tuple[list, object]:
    """The chunks' batched `(model, env)` leaves and the shared ones with the model's
    `body` None where no case carries a body ([`jaxcable._model.network.without_absent_bodies`][]
    on the shared leaves, where no body leaf is swept), so that the batch's programs
    compute no body terms; otherwise as given."""
    model, env = system
    swept = any(jax.tree.leaves(case[0].body) for case in cases)
    if swept or without_absent_bodies(model) is model:
        return cases, system
    return [(eqx.tree_at(lambda m: m.body, case[0], None), case[1]) for case in cases], (
        eqx.tree_at(lambda m: m.body, model, None),
        env,
    )


def _grid(t0: float, t1: float, ts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The times the blocks integrate through, and where the output times `ts` lie
    among them (indices): `t0` and the distinct output times, with an interval longer
    than the outputs' median spacing (from `t0` to a first output time well after it)
    cut into pieces no longer than that. Every interval is then integrated in the same
    number of equal steps, set by the longest (`jaxcable._simulation.blocks`)."""
    times = np.unique(np.append(t0, ts))
    if times.size == 1:  # every output at t0: an interval to t1, never saved
        times = np.array([t0, t1])
    gaps = np.diff(times)
    pieces = np.maximum(1, np.ceil(gaps / np.median(gaps) * (1 - 1e-9))).astype(int)
    if np.all(pieces == 1):
        return times, np.searchsorted(times, ts)
    # Interval k's pieces end at times[k] + j (times[k+1] − times[k]) / pieces[k], j = 1 … pieces[k].
    interval = np.repeat(np.arange(gaps.size), pieces)
    j = np.arange(interval.size) - np.repeat(np.cumsum(pieces) - pieces, pieces) + 1
    grid = np.append(times[0], times[interval] + gaps[interval] * j / pieces[interval])
    grid[np.cumsum(pieces)] = times[1:]  # each given time exactly as given
    return grid, np.searchsorted(grid, ts)


@program
def _starts(per_case, shared, mode: str):
    """Each case's start `(positions, velocities)`, statics (or `None`), and `valid`
    and `ok` flags (`_prepare`), with a leading case axis."""

    def one(case):
        _, start, statics, valid, ok = _prepare(case, shared, mode)
        return start, statics, valid, ok

    return jax.vmap(one)(per_case)


@functools.partial(program, compiler_options=RUN_ONCE)
def _finish_batch(simulation, statics, valid, ok):
    """`_finish` of every case."""
    return jax.vmap(_finish)(simulation, statics, valid, ok)


def _shared_steps(systems, starts, ok, shared) -> SimulationResult:
    """The whole batch as one system, integrated with one step size: the largest that
    every case's error estimate allows (the controller's norm is the worst case's).

    Each case is integrated at least as finely as its own solve would be, and no case
    waits on a masked loop: under `vmap`, diffrax's while loop selects every carried
    array, its output buffers included, between each case's old and new value at every
    step, which on a CPU cost more than the evaluations. A case that is not to be
    integrated (invalid, or without equilibrium) has its derivative held at zero, so
    that it neither moves nor limits the step.
    """
    config: SolverConfig = shared["solver"]
    free = _free_nodes(systems)
    y0 = (starts[0][:, free], starts[1][:, free])

    def field(t, y, args):
        def one(system, y):
            return vector_field(t, y, system)

        derivative = jax.vmap(one)(args, y)
        return jax.tree.map(lambda d: jnp.where(ok[:, None, None], d, 0.0), derivative)

    controller = config.stepsize_controller
    if isinstance(controller, diffrax.PIDController):
        norm = controller.norm
        controller = eqx.tree_at(lambda c: c.norm, controller, lambda y: jnp.max(jax.vmap(norm)(y)))
    solution = diffrax.diffeqsolve(
        diffrax.ODETerm(field),
        config.solver,
        shared["t0"],
        shared["t1"],
        config.dt0,
        y0,
        args=systems,
        saveat=diffrax.SaveAt(ts=shared["ts"]),
        stepsize_controller=controller,
        max_steps=config.max_steps,
        adjoint=config.adjoint,
        throw=False,
    )
    assert solution.ts is not None and solution.ys is not None
    stats = {k: solution.stats[k] for k in ("num_steps", "num_accepted_steps", "num_rejected_steps")}

    def one_result(system, positions, velocities):
        model, env = system
        return result_of(model, env, solution.ts, (positions, velocities), stats, solution.result)

    # diffrax saves the batch with times first: (times, cases, free, 3).
    return jax.vmap(one_result, in_axes=(0, 1, 1))(systems, *solution.ys)


def _free_nodes(systems):
    model, _ = systems
    return model.free_nodes


def _status(simulation: SimulationResult, statics: StaticSolution | None, invalid: dict[int, str]) -> tuple[str, ...]:
    """One line per case, from the result codes fetched to the host once."""
    host = to_host((simulation.result, simulation.stats, statics))
    result, stats, statics = host
    codes, solved = result_codes(result), result_codes(diffrax.RESULTS.successful)
    lines = []
    for i in range(len(np.asarray(stats["num_steps"]))):
        if i in invalid:
            lines.append(invalid[i])
            continue
        if statics is not None and result_codes(statics.result)[i] != result_codes(optx.RESULTS.successful):
            lines.append("statics failed: " + failure_message(jax.tree.map(lambda x: x[i], statics)))  # noqa: B023
            continue
        if codes[i] == solved:
            lines.append("successful")
        else:
            case_result = jax.tree.map(lambda x: np.asarray(x[i]), result)  # noqa: B023 (called within this iteration)
            lines.append(
                f"{diffrax.RESULTS[case_result]} (stopped after {stats['num_steps'][i]} steps, "
                f"{stats['num_rejected_steps'][i]} rejected)"
            )
    return tuple(lines)
