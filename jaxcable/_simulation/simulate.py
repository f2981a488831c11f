"""Time integration with diffrax, and the result object users read tensions from."""

from typing import Any, Literal

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx
from jaxtyping import Array, Float

from .. import _checks as checks
from .._derivative_check import warn_of_slack
from .._equations import lagrangian as lag
from .._model.network import CableNetwork, network_conditions, unheld_nodes, without_absent_bodies
from .._model.state import State
from .._progress import SimulatedTime
from .._sea.environment import Environment
from .._solver.config import SolverConfig
from .._solver.jacobian import with_network_jacobian
from .._statics.solve import solve_statics
from .._typing import RealLike, RealScalarLike


class SimulationResult(eqx.Module):
    """What a simulation produced, at the output times.

    **Attributes:**

    - `times`: output times (s), shape `(times,)`.
    - `positions`, `velocities`: of every node (m, m/s), shape `(times, nodes, 3)`.
    - `strain`: ε (–), shape `(times, segments)`.
    - `tension`: T (N), shape `(times, segments)`.
    - `reactions`: force (N) of each constrained node's support on the network, in the
        order of `model.constrained_nodes`, shape `(times, constrained, 3)`.
    - `stats`: diffrax's statistics (`num_steps`, `num_accepted_steps`,
        `num_rejected_steps`).
    - `result`: diffrax's result code; see `success`. After a failure (with
        `throw=False`), times, positions and velocities past the failure time are
        `inf`, and the strains, tensions and reactions computed from them NaN.
    """

    times: Float[Array, " times"]
    positions: Float[Array, "times nodes 3"]
    velocities: Float[Array, "times nodes 3"]
    strain: Float[Array, "times segments"]
    tension: Float[Array, "times segments"]
    reactions: Float[Array, "times constrained 3"]
    stats: dict[str, Any]
    result: diffrax.RESULTS

    @property
    def success(self) -> Array:
        """`True` where the solve reached the final time."""
        return self.result == diffrax.RESULTS.successful


def vector_field(t, y, args):
    """`d(x_f, v_f)/dt = (v_f, a_f)`, the first-order form of `M_ff a_f = Q_f − M_fc a_c`."""
    model, env = args
    free_positions, free_velocities = y
    a_free, *_ = lag.free_accelerations(model, env, t, free_positions, free_velocities)
    return free_velocities, a_free


def stiff_field(t, y, args):
    """The implicit part of an implicit–explicit split: `(v_f, M⁻¹ Q_internal)`, the
    line's axial forces, whose stiffness ω_n = 2 (N/L) √(EA/m) limits explicit steps."""
    model, env = args
    free_positions, free_velocities = y
    a_free, *_ = lag.free_accelerations(model, env, t, free_positions, free_velocities, part="internal")
    return free_velocities, a_free


def nonstiff_field(t, y, args):
    """The explicit part: `(0, M⁻¹ (Q − Q_internal − M_fc a_c))`, weight, buoyancy,
    drag, fluid inertia, bodies and the seabed."""
    model, env = args
    free_positions, free_velocities = y
    a_free, *_ = lag.free_accelerations(model, env, t, free_positions, free_velocities, part="external")
    return jnp.zeros_like(free_velocities), a_free


INITIAL_STATES = ("statics", "rest")
"""The named starts of `simulate` and `sweep`, besides a `State`."""

IMEX_SOLVERS = (diffrax.KenCarp3, diffrax.KenCarp4, diffrax.KenCarp5, diffrax.Sil3)
"""Implicit–explicit solvers, which [`jaxcable.simulate`][] gives the split
`MultiTerm(nonstiff_field, stiff_field)` rather than the whole vector field."""


def component_major_field(t, y, args):
    """[`vector_field`][] on the component-major state: `y = (x_f, v_f)`, each of shape
    `(3, free)`, the layout the equations compute in (`jaxcable._equations.lagrangian`), so that
    an evaluation transposes nothing. On the anchored line (20 segments) an RK4 step took
    12.8 µs against 19.9 µs on the public layout `(free, 3)`."""
    model, env = args
    free_positions, free_velocities = y
    a_free = lag._free_accelerations(model, env, t, free_positions, free_velocities, "all")[0]
    return free_velocities, a_free


def _component_major(solver: diffrax.AbstractSolver) -> bool:
    """Whether `solver` integrates the component-major state: an explicit Runge–Kutta
    method, which only evaluates the field. Implicit and implicit–explicit methods keep
    the public layout, in which [`jaxcable.NetworkJacobian`][] structures their
    Jacobian."""
    return isinstance(solver, diffrax.AbstractERK)


def terms_for(solver: diffrax.AbstractSolver) -> diffrax.AbstractTerm:
    """The diffrax terms `solver` integrates: split for an implicit–explicit solver,
    component-major for an explicit Runge–Kutta method ([`component_major_field`][]),
    whole otherwise. [`integrated_state`][] and [`public_state`][] convert its states."""
    if isinstance(solver, IMEX_SOLVERS):
        return diffrax.MultiTerm(diffrax.ODETerm(nonstiff_field), diffrax.ODETerm(stiff_field))
    if _component_major(solver):
        return diffrax.ODETerm(component_major_field)
    return diffrax.ODETerm(vector_field)


def integrated_state(solver: diffrax.AbstractSolver, model: CableNetwork, positions, velocities):
    """The state `solver` integrates ([`terms_for`][]) from every node's positions (m)
    and velocities (m/s), shape `(nodes, 3)`: the free nodes' `(x_f, v_f)`, shape
    `(3, free)` each for an explicit Runge–Kutta method, `(free, 3)` otherwise."""
    free = model.free_nodes
    y = (positions[free], velocities[free])
    return (y[0].T, y[1].T) if _component_major(solver) else y


def public_state(solver: diffrax.AbstractSolver, y):
    """[`integrated_state`][]'s state back in the public layout, `(..., free, 3)` each,
    with any leading axes (saved times) kept."""
    return tuple(jnp.swapaxes(x, -1, -2) for x in y) if _component_major(solver) else y


def _undamped(model: CableNetwork) -> bool:
    """Whether the line has no axial damping: a law without it, or one whose damping is
    zero everywhere (known only where it is not traced)."""
    law = model.line.tension_law
    if not law.damped:
        return True
    damping = law.damping()
    return not checks.traced(damping) and not np.any(np.asarray(damping))


def simulate(
    model: CableNetwork,
    env: Environment,
    t1: RealScalarLike,
    *,
    t0: RealScalarLike = 0.0,
    ts: RealLike | None = None,
    initial: State | Literal["statics", "rest"] = "statics",
    solver: SolverConfig | None = None,
    progress: bool = False,
    throw: bool = True,
) -> SimulationResult:
    """Integrate the motion of `model` in `env` from `t0` to `t1`.

    The unknowns are the free nodes' positions and velocities; constrained nodes follow
    their motions. Compiles on the first call for a given network topology and options;
    later calls with new float values (stiffness, drag, amplitude, ...) reuse it.

    **Arguments:**

    - `model`, `env`: the network and the water.
    - `t1`, `t0`: end and start time (s); traced values are allowed (records of
        different spans in one `vmap`).
    - `ts`: output times (s); 201 evenly spaced times from `t0` to `t1` by default.
    - `initial`: where to start. `"statics"` (default): the static equilibrium with
        constrained nodes at their positions at `t0`, from
        [`jaxcable.solve_statics`][] (solved inside the caller's `jit`, `vmap` or
        derivative, where there is one, so that a derivative includes the
        equilibrium's); a network with a part that nothing holds has none and
        starts at rest. `"rest"`: `model.node_positions` at rest (a drop test).
        A [`jaxcable.State`][]: as given (`solve_statics(...).state`, say, solved
        once for many runs).
    - `solver`: how to integrate, a [`jaxcable.SolverConfig`][]: the diffrax solver,
        step-size controller, tolerances, first step, step limit and adjoint.
        `SolverConfig()` by default: Dopri5 with a PIDController at rtol = atol = 1e-6
        and at most 1,000,000 steps. A new tolerance or first step reuses the
        compiled solve.
    - `progress`: show a progress bar on stderr in simulated seconds
        (`simulate: |███   | 12.3/60.0 s simulated`); where stderr is not a terminal
        (a log), a line at most every 20 s of wall time and the last.
    - `throw`: raise on solver failure (default). Set `False` inside `vmap` sweeps and
        read `result.success` per case instead.

    **Returns:**

    A [`jaxcable.SimulationResult`][].

    **Raises:**

    `ValueError` naming the field and value for a bad input (a model's field edited
    with `eqx.tree_at`, say, a non-finite time, t1 ≤ t0, `ts` outside [t0, t1] or not
    increasing, a non-finite initial state, a support below the seabed, or a model,
    water or initial state of the wrong type), or a `solver` that is not a
    [`jaxcable.SolverConfig`][]; with a traced model or
    times (inside `jit`), `equinox.EquinoxRuntimeError` naming the field instead.
    With `throw=True`, an error carrying diffrax's message when the solve fails (too
    many steps, step size collapse). `TypeError` saying what to pass for
    forward-mode differentiation (`jax.jacfwd`) without `diffrax.ForwardMode()`.
    Non-finite states are rejected steps, not output;
    with a fixed step, which cannot reject, a state that goes non-finite fails the
    solve (`diffrax.RESULTS.nonfinite`).

    **Warns:**

    [`jaxcable.DerivativeWarning`][], once a process, where `simulate` is
    differentiated (`jax.grad`, `jax.jvp`, ... of a function that calls it) and a
    segment goes slack in the run: through slack and snap loads the derivative can be
    exact and of no use (see [`jaxcable.check_derivative`][]).
    """
    for name, value, kind in (("model", model, CableNetwork), ("env", env, Environment)):
        if not isinstance(value, kind):
            raise ValueError(f"simulate: {name} must be a jaxcable.{kind.__name__}, got {type(value).__name__}")
    if isinstance(initial, str):
        checks.option("simulate: initial", initial, INITIAL_STATES)
    elif not isinstance(initial, State):
        raise ValueError(
            f"simulate: initial must be 'statics', 'rest' or a jaxcable.State, got {type(initial).__name__}"
        )
    t0, t1 = jnp.asarray(t0, dtype=float), jnp.asarray(t1, dtype=float)
    # An infinite t1 would step until `max_steps`.
    t0, t1 = checks.check((t0, t1), [checks.finite("simulate: t0", t0), checks.finite("simulate: t1", t1)])
    later = checks.Condition(
        "simulate: t1",
        ~(t1 > t0),
        t1,
        "must be greater than t0",
        lambda: f"simulate: t1 must be greater than t0, got t0={float(t0)}, t1={float(t1)}",
    )
    t1 = checks.check(t1, [later])
    ts = jnp.linspace(t0, t1, 201) if ts is None else jnp.asarray(ts, dtype=float)
    if ts.ndim != 1 or ts.size == 0:
        raise ValueError(f"simulate: ts must be a non-empty 1-D array, got shape {ts.shape}")
    ts = checks.check(
        ts,
        [
            checks.finite("simulate: ts", ts),
            checks.Condition("simulate: ts", (ts < t0) | (ts > t1), ts, "must lie within [t0, t1]"),
            checks.increasing("simulate: ts", ts),
        ],
    )
    given = isinstance(initial, State)
    initial_positions = initial.positions if given else model.node_positions
    initial_velocities = initial.velocities if given else jnp.zeros_like(initial_positions)
    if initial_positions.shape != model.node_positions.shape:
        raise ValueError(
            f"simulate: initial.positions must have shape {model.node_positions.shape}, got {initial_positions.shape}"
        )
    # Constructors checked concrete inputs; a model built or edited (`eqx.tree_at`)
    # with other values, or traced, is checked here, so that a bad value is named
    # rather than turning into NaNs mid-solve.
    initial_positions = checks.check(
        initial_positions,
        network_conditions(model, env)
        + [
            # A NaN start with `throw=False` would otherwise run on to `max_steps`, every
            # step rejected.
            checks.finite("simulate: initial.positions", initial_positions),
            checks.finite("simulate: initial.velocities", initial_velocities),
        ],
    )
    statics_result = None
    if initial == "statics" and unheld_nodes(model) is None:
        try:
            statics = solve_statics(model, env, t=t0, throw=throw)
        except RuntimeError as error:
            raise type(error)(
                f"simulate: the start, initial='statics', failed: {error}\n(initial='rest' starts at rest, "
                "initial=State(...) where given)"
            ) from None
        initial_positions, initial_velocities = statics.state.positions, statics.state.velocities
        statics_result = statics.result
    start = (initial_positions, initial_velocities)
    # Called eagerly, the solve is compiled without error checks, which are raised here
    # after it returns (`checks.raise_if`): a program with them could not be kept in
    # JAX's persistent cache. Under the caller's `jit` they go inside, as they must.
    inside = throw and checks.traced((model, env, start, t0, t1, ts))
    config = for_model(as_config("simulate", solver), model)
    try:
        result = _simulate(
            without_absent_bodies(model),  # a bare line's program computes no body terms
            env,
            start,
            t0,
            t1,
            ts,
            config,
            SimulatedTime(jnp.asarray(t0, dtype=float), jnp.asarray(t1, dtype=float))
            if progress
            else diffrax.NoProgressMeter(),
            inside,
        )
    except TypeError as error:
        # The default adjoint is a custom VJP, which JAX cannot push tangents through.
        # It is not chosen for the caller: a tangent (`jax.jvp`) and a linearisation
        # for `jax.grad` are told apart only by JAX's private tracer classes, and
        # `ForwardMode` would break `jax.grad`.
        if "forward-mode autodiff" not in str(error) or isinstance(config.adjoint, diffrax.ForwardMode):
            raise
        raise TypeError(
            "simulate: forward-mode differentiation (jax.jacfwd, jax.jvp) needs "
            "solver=SolverConfig(adjoint=diffrax.ForwardMode()); the default adjoint, "
            f"{type(config.adjoint).__name__}, supports reverse mode (jax.grad, jax.jacrev) only"
        ) from None
    if statics_result is not None:
        # A start that is not an equilibrium fails the run, as a failed case of a sweep
        # does (reachable with `throw=False` only: otherwise statics raised).
        # Concrete codes are compared on the host, which compiles nothing.
        failed = (
            statics_result != optx.RESULTS.successful
            if checks.traced(statics_result)
            else bool(np.any(result_codes(statics_result) != result_codes(optx.RESULTS.successful)))
        )
        if failed is not False:
            result = eqx.tree_at(
                lambda r: r.result,
                result,
                diffrax.RESULTS.where(failed, diffrax.RESULTS.promote(statics_result), result.result),
            )
    if throw and not inside and np.any(result_codes(result.result) != result_codes(diffrax.RESULTS.successful)):
        raise eqx.EquinoxRuntimeError(failure_message(result.result) + _where_failed(result, ts))
    if checks.differentiated((model, env, start, t0, t1, ts)):
        warn_of_slack(result.times, result.strain, undamped=_undamped(model))
    return result


def result_codes(result) -> np.ndarray:
    """The integer codes of a diffrax or optimistix result (an enumeration item, of one
    case or of many), on the host: compared as integers, they compile nothing, where
    an enumeration's comparison is a JAX program of its own, eagerly."""
    return to_host(jax.tree.leaves(result)[0])


def to_host(tree):
    """The arrays of `tree` as numpy arrays. An array split across the devices of
    several processes (JAX's multi-controller runtime, `jax.distributed`) is gathered
    from all of them, so that each process holds the whole of it; every process must
    then make the same call at the same point, as for any program they share."""
    from jax.experimental import multihost_utils

    def one(x):
        if isinstance(x, jax.Array) and not x.is_fully_addressable:
            return np.asarray(multihost_utils.process_allgather(x, tiled=True))
        return np.asarray(x)

    return jax.tree.map(one, tree)


def _where_failed(result: SimulationResult, requested) -> str:
    """Between which of the `requested` output times a failed run stopped (the last with
    a finite time and state, and the next), and how to keep the run up to then; empty
    where the outputs do not say (none finite, or all)."""
    state = np.concatenate([np.asarray(result.positions), np.asarray(result.velocities)], axis=-1)
    finite = np.isfinite(np.asarray(result.times)) & np.isfinite(state).all(axis=(1, 2))
    requested = np.asarray(requested)
    if finite.all() or not finite[0]:
        return ""
    last = int(np.argmin(finite)) - 1  # the output before the first that is not finite
    return (
        f", after the output at t = {requested[last]:g} s and before t = {requested[last + 1]:g} s; "
        "simulate(..., throw=False) returns the run up to then, its later outputs inf or NaN"
    )


def failure_message(result: diffrax.RESULTS) -> str:
    if result == diffrax.RESULTS.nonfinite:
        return _NONFINITE
    return f"simulate: {diffrax.RESULTS[result]}"


_NONFINITE = (
    "simulate: the state became non-finite (with a fixed step, the step is beyond the method's stability limit)"
)


def as_config(where: str, solver: SolverConfig | None) -> SolverConfig:
    """`solver`, or `SolverConfig()` for `None`; `ValueError` for anything else, such as
    a bare diffrax solver (which the configuration wraps)."""
    if solver is None:
        return SolverConfig()
    if not isinstance(solver, SolverConfig):
        raise ValueError(
            f"{where}: solver must be a jaxcable.SolverConfig, got {solver!r}; wrap a diffrax solver "
            "as SolverConfig(diffrax.Tsit5()), or name a preset with jaxcable.SOLVERS['tsit5']()"
        )
    return solver


def for_model(config: SolverConfig, model: CableNetwork) -> SolverConfig:
    """`config` with [`jaxcable.NetworkJacobian`][] in its implicit solver's root finder
    where that replaces lineax's automatic choice (see
    `jaxcable._solver.jacobian.with_network_jacobian`)."""
    return eqx.tree_at(lambda c: c.solver, config, with_network_jacobian(config.solver, model))


@eqx.filter_jit
def _simulate(model, env, initial, t0, t1, ts, config: SolverConfig, meter, throw):
    y0 = integrated_state(config.solver, model, *initial)
    solution = diffrax.diffeqsolve(
        terms_for(config.solver),
        config.solver,
        t0,
        t1,
        config.dt0,
        y0,
        args=(model, env),
        saveat=diffrax.SaveAt(ts=ts),
        stepsize_controller=config.stepsize_controller,
        max_steps=config.max_steps,
        adjoint=config.adjoint,
        progress_meter=meter,
        throw=throw,
    )

    # The solve saves at `ts` (SaveAt(ts=...)), so diffrax returns both.
    assert solution.ts is not None and solution.ys is not None
    stats = {k: solution.stats[k] for k in ("num_steps", "num_accepted_steps", "num_rejected_steps")}
    return result_of(model, env, solution.ts, public_state(config.solver, solution.ys), stats, solution.result, throw)


def result_of(model, env, ts, ys, stats, result, throw: bool = False) -> SimulationResult:
    """The [`SimulationResult`][] of a solve that saved the free nodes' `ys = (positions,
    velocities)`, each of shape `(times, free, 3)`, at times `ts`, with diffrax's `stats`
    and `result`: the outputs at each time, and `result` made `nonfinite` where the
    state is not finite though the solve reported success."""

    def outputs(t, free_positions, free_velocities):
        _, positions, velocities, accelerations = lag.free_accelerations(model, env, t, free_positions, free_velocities)
        _, _, strain = lag.segment_geometry(model, positions)
        return (
            positions,
            velocities,
            strain,
            lag.tension(model, positions, velocities),
            lag.reactions(model, env, t, positions, velocities, accelerations),
        )

    positions, velocities, strain, tension, reactions = jax.vmap(outputs)(ts, *ys)
    # An adaptive controller rejects non-finite steps, but a fixed step (beyond the
    # method's stability limit) carries them to the end as a "successful" solve.
    finite = jnp.all(jnp.isfinite(positions)) & jnp.all(jnp.isfinite(velocities))
    result = diffrax.RESULTS.where(
        finite | (result != diffrax.RESULTS.successful),
        result,
        # pyright takes an equinox Enumeration's members for literals, not for instances of it.
        diffrax.RESULTS.nonfinite,  # pyright: ignore[reportArgumentType]
    )
    if throw:
        tension = eqx.error_if(tension, result == diffrax.RESULTS.nonfinite, _NONFINITE)
    return SimulationResult(ts, positions, velocities, strain, tension, reactions, stats, result)
