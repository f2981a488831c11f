"""Time integration with diffrax, and the result object users read tensions from."""

from typing import Any

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import optimistix as optx
from jaxtyping import Array, ArrayLike, Float

from . import _checks as checks, _lagrangian as lag
from ._environment import Environment
from ._jacobian import with_network_jacobian
from ._network import CableNetwork
from ._picard import PicardTrapezoid
from ._state import State


def default_solver() -> diffrax.AbstractSolver:
    """`diffrax.Dopri5()`: jaxcable's default, chosen from measurements.

    On seed 003's taut, snapping line (C_E = 3e7 N) the step size is limited by
    accuracy, not stability: slackening and snap loads need short steps whatever the
    method. With 10 segments over 10 s at rtol = atol = 1e-6, an explicit Runge–Kutta
    method took about as many steps as `Kvaerno5` (Tsit5 4,055; Kvaerno5 with Newton
    3,952) and ran 45× faster, since an implicit step must form and factor the Jacobian.
    Of the explicit methods, Dopri5 took 11–28 % fewer steps than Tsit5 (fewer rejected
    across snap loads) and ran as fast to 1.6× faster at 10–100 segments over 60 s.
    `benchmarks/seed003.py` measures it; `benchmarks/README.md` has the figures.
    Use [`jaxcable.stiff_solver`][] where stability, not accuracy, limits the step.
    """
    return diffrax.Dopri5()


def stiff_solver() -> diffrax.AbstractSolver:
    """`Kvaerno5` with a full Newton root finder, for stability-limited (stiff) runs.

    diffrax's default root finder for implicit solvers, `VeryChord`, reuses one
    Jacobian across iterations; as segments slacken and re-tension that Jacobian goes
    stale and steps are rejected. On seed 003's line (10 segments, 10 s) it took 8,277
    steps where Newton took 3,952, though each was cheaper.

    With lumped mass, [`jaxcable.simulate`][] gives the root finder
    [`jaxcable.NetworkJacobian`][], so that each Newton iteration costs O(N), not the
    O(N³) of a dense LU.
    """
    return diffrax.Kvaerno5(root_finder=diffrax.with_stepsize_controller_tols(optx.Newton)())


SOLVERS = {
    "dopri5": default_solver,
    "tsit5": diffrax.Tsit5,
    "dopri8": diffrax.Dopri8,
    "kvaerno5": stiff_solver,
    "kencarp4": diffrax.KenCarp4,
    "picard": PicardTrapezoid,
}
"""Solvers by the names scene files and the command line use: explicit Runge–Kutta
`dopri5` (the default), `tsit5` and `dopri8`, implicit `kvaerno5`
([`jaxcable.stiff_solver`][]), implicit–explicit `kencarp4` (the line's axial forces
implicit, the rest explicit), and `picard`, seed 001's Picard–trapezoid iteration
([`jaxcable.PicardTrapezoid`][]), the historical baseline. Each entry makes a fresh
diffrax solver."""


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


IMEX_SOLVERS = (diffrax.KenCarp3, diffrax.KenCarp4, diffrax.KenCarp5, diffrax.Sil3)
"""Implicit–explicit solvers, which [`jaxcable.simulate`][] gives the split
`MultiTerm(nonstiff_field, stiff_field)` rather than the whole vector field."""


def terms_for(solver: diffrax.AbstractSolver) -> diffrax.AbstractTerm:
    """The diffrax terms `solver` integrates: split for an implicit–explicit solver,
    whole otherwise."""
    if isinstance(solver, IMEX_SOLVERS):
        return diffrax.MultiTerm(diffrax.ODETerm(nonstiff_field), diffrax.ODETerm(stiff_field))
    return diffrax.ODETerm(vector_field)


def simulate(
    model: CableNetwork,
    env: Environment,
    t1: float,
    *,
    t0: float = 0.0,
    ts: ArrayLike | None = None,
    initial: State | None = None,
    solver: diffrax.AbstractSolver | None = None,
    rtol: float = 1e-6,
    atol: float = 1e-6,
    dt0: float | None = None,
    stepsize_controller: diffrax.AbstractStepSizeController | None = None,
    jacobian: str = "auto",
    max_steps: int = 1_000_000,
    adjoint: diffrax.AbstractAdjoint | None = None,
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
    - `initial`: the initial [`jaxcable.State`][]; `model.node_positions` at rest by
        default. Use `solve_statics(...).state` to start from equilibrium.
    - `solver`: any diffrax solver; [`jaxcable.default_solver`][] (Dopri5) by default,
        or [`jaxcable.stiff_solver`][] (Kvaerno5 with Newton) where stiffness, not
        accuracy, limits the step. Implicit–explicit solvers (`KenCarp3/4/5`,
        `Sil3`) get the line's axial forces implicitly and the rest explicitly.
    - `rtol`, `atol`: step-size controller tolerances, on positions (m) and velocities
        (m/s). A new tolerance reuses the compiled solve.
    - `dt0`: first step (s); chosen by diffrax by default. With a fixed step, the step.
    - `stepsize_controller`: any diffrax step-size controller;
        `diffrax.PIDController(rtol, atol)` by default. `diffrax.ConstantStepSize()`
        with `dt0` gives fixed steps (as MoorDyn takes); `rtol` and `atol` are then
        unused, except by an implicit solver's root finder, which needs its own
        tolerances.
    - `jacobian`: how an implicit solver's root finder solves its linear systems.
        `"auto"` (default): with [`jaxcable.NetworkJacobian`][] (coloured JVPs and a
        block-tridiagonal factorisation along the network, O(N) a step) for a
        lumped-mass model whose solver leaves the linear solver to lineax; otherwise
        as the solver says. `"structured"`: always, or a `ValueError` saying why it
        cannot. `"dense"`: never (diffrax's dense Jacobian and LU, O(N³)).
    - `max_steps`: the most steps before the solve is declared failed.
    - `adjoint`: diffrax's adjoint for reverse-mode gradients;
        `RecursiveCheckpointAdjoint` by default.
    - `progress`: show a tqdm progress bar over simulated time.
    - `throw`: raise on solver failure (default). Set `False` inside `vmap` sweeps and
        read `result.success` per case instead.

    **Returns:**

    A [`jaxcable.SimulationResult`][].

    **Raises:**

    `ValueError` naming the field and value for a bad input (a model's field edited
    with `eqx.tree_at`, say, t1 ≤ t0, or `ts` outside [t0, t1]); with a traced model or
    times (inside `jit`), `equinox.EquinoxRuntimeError` naming the field instead.
    With `throw=True`, an error carrying diffrax's message when the solve fails (too
    many steps, step size collapse). Non-finite states are rejected steps, not output;
    with a fixed step, which cannot reject, a state that goes non-finite fails the
    solve (`diffrax.RESULTS.nonfinite`).
    """
    t0, t1 = jnp.asarray(t0, dtype=float), jnp.asarray(t1, dtype=float)
    later = checks.Condition(
        "simulate: t1", ~(t1 > t0), t1, "must be greater than t0",
        lambda: f"simulate: t1 must be greater than t0, got t0={float(t0)}, t1={float(t1)}",
    )
    t1 = checks.check(t1, [later])
    ts = jnp.linspace(t0, t1, 201) if ts is None else jnp.asarray(ts, dtype=float)
    if ts.ndim != 1 or ts.size == 0:
        raise ValueError(f"simulate: ts must be a non-empty 1-D array, got shape {ts.shape}")
    ts = checks.check(ts, [checks.Condition("simulate: ts", (ts < t0) | (ts > t1), ts, "must lie within [t0, t1]")])
    initial_positions = model.node_positions if initial is None else initial.positions
    initial_velocities = jnp.zeros_like(initial_positions) if initial is None else initial.velocities
    if initial_positions.shape != model.node_positions.shape:
        raise ValueError(
            f"simulate: initial.positions must have shape {model.node_positions.shape}, "
            f"got {initial_positions.shape}"
        )
    # Constructors checked concrete inputs; a model built or edited (`eqx.tree_at`)
    # with other values, or traced, is checked here, so that a bad value is named
    # rather than turning into NaNs mid-solve.
    initial_positions = checks.check(initial_positions, model.conditions() + env.conditions())
    return _simulate(
        model,
        env,
        (initial_positions, initial_velocities),
        t0,
        t1,
        ts,
        with_network_jacobian(default_solver() if solver is None else solver, model, jacobian),
        step_controller(rtol, atol, stepsize_controller),
        None if dt0 is None else jnp.asarray(dt0, dtype=float),
        max_steps,
        diffrax.RecursiveCheckpointAdjoint() if adjoint is None else adjoint,
        diffrax.TqdmProgressMeter() if progress else diffrax.NoProgressMeter(),
        throw,
    )


def step_controller(
    rtol: float, atol: float, stepsize_controller: diffrax.AbstractStepSizeController | None
) -> diffrax.AbstractStepSizeController:
    """`stepsize_controller`, or by default `diffrax.PIDController(rtol, atol)` with the
    tolerances as arrays: a work-precision study then compiles once, not once per
    tolerance."""
    if stepsize_controller is not None:
        return stepsize_controller
    rtol, atol = (
        checks.check(value, [checks.sign(name, value)])
        for name, value in (("rtol", jnp.asarray(rtol, dtype=float)), ("atol", jnp.asarray(atol, dtype=float)))
    )
    return diffrax.PIDController(rtol=rtol, atol=atol)


@eqx.filter_jit
def _simulate(model, env, initial, t0, t1, ts, solver, controller, dt0, max_steps, adjoint, meter, throw):
    free = model.free_nodes
    y0 = (initial[0][free], initial[1][free])
    solution = diffrax.diffeqsolve(
        terms_for(solver),
        solver,
        t0,
        t1,
        dt0,
        y0,
        args=(model, env),
        saveat=diffrax.SaveAt(ts=ts),
        stepsize_controller=controller,
        max_steps=max_steps,
        adjoint=adjoint,
        progress_meter=meter,
        throw=throw,
    )

    def outputs(t, free_positions, free_velocities):
        _, positions, velocities, accelerations = lag.free_accelerations(
            model, env, t, free_positions, free_velocities
        )
        _, _, strain = lag.segment_geometry(model, positions)
        return (
            positions,
            velocities,
            strain,
            lag.tension(model, positions, velocities),
            lag.reactions(model, env, t, positions, velocities, accelerations),
        )

    positions, velocities, strain, tension, reactions = jax.vmap(outputs)(solution.ts, *solution.ys)
    # An adaptive controller rejects non-finite steps, but a fixed step (beyond the
    # method's stability limit) carries them to the end as a "successful" solve.
    finite = jnp.all(jnp.isfinite(positions)) & jnp.all(jnp.isfinite(velocities))
    result = diffrax.RESULTS.where(finite | (solution.result != diffrax.RESULTS.successful), solution.result, diffrax.RESULTS.nonfinite)
    if throw:
        tension = eqx.error_if(
            tension,
            result == diffrax.RESULTS.nonfinite,
            "simulate: the state became non-finite (with a fixed step, the step is beyond the method's stability limit)",
        )
    stats = {k: solution.stats[k] for k in ("num_steps", "num_accepted_steps", "num_rejected_steps")}
    return SimulationResult(solution.ts, positions, velocities, strain, tension, reactions, stats, result)
