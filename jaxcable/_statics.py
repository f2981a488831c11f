"""Static equilibrium under gravity, buoyancy and a steady current."""

import equinox as eqx
import jax
import jax.numpy as jnp
import optimistix as optx
from jaxtyping import Array, Float, Int

from . import _checks as checks
from . import _lagrangian as lag
from ._environment import Environment
from ._network import CableNetwork, check_held
from ._state import State
from ._typing import RealScalarLike


class StaticSolution(eqx.Module):
    """The equilibrium of a network.

    **Attributes:**

    - `state`: node positions (m) and zero velocities, usable as the initial state of
        [`jaxcable.simulate`][].
    - `strain`: ε (–), shape `(segments,)`.
    - `tension`: T (N), shape `(segments,)`.
    - `reactions`: force (N) of each support on the network, shape `(constrained, 3)`.
    - `residual`: the largest remaining force (N) on a free node.
    - `result`: optimistix's result code; `result == optimistix.RESULTS.successful` on
        success.
    - `steps`: iterations of the solver that finished (Levenberg–Marquardt, or the
        energy descent that goes first where there is a seabed).
    """

    state: State
    strain: Float[Array, " segments"]
    tension: Float[Array, " segments"]
    reactions: Float[Array, "constrained 3"]
    residual: Float[Array, ""]
    result: optx.RESULTS
    steps: Int[Array, ""]


def solve_statics(
    model: CableNetwork,
    env: Environment,
    *,
    t: RealScalarLike = 0.0,
    initial: State | None = None,
    rtol: float = 1e-10,
    atol: float = 1e-10,
    max_steps: int = 500,
    force_tolerance: float = 1e-6,
    throw: bool = True,
) -> StaticSolution:
    """Find the static equilibrium of `model` in `env`, with constrained nodes at their
    positions at time `t` (s).

    Solves `Q_f(x, 0) = 0` for the free node positions by Levenberg–Marquardt on the
    force residual, scaled by the line's weight so that the tolerances are relative.
    A current contributes steady drag. The elastic laws are tension-only, so the initial
    positions matter: a slack guess has no stiffness to move it. Start from a shape
    with every segment slightly stretched (as [`jaxcable.CableNetwork.from_branches`][]
    makes for a straight taut line), or from a sagged guess.

    If that solve leaves a large residual, the free nodes first descend the potential
    energy by BFGS from the initial positions, current drag aside, and
    Levenberg–Marquardt starts again from there. Energy descent always makes progress
    where a hanging part must swing or straighten a long way, as below a weight or a
    free end, which Levenberg–Marquardt on the forces was seen to stall on (MoorDyn's
    `lifting.txt` and `hanging_lines.txt` examples). With a seabed that the starting
    shape dips below, the descent goes first instead.

    These decisions are taken in the compiled solve (`jax.lax.cond` on the residual),
    so the same path runs eagerly, under `jit` and under `vmap`. Under `vmap` a `cond`
    runs both branches for every case; the fallback's objective is zero for a case that
    does not need it, so its loops stop at once unless some case does need it.

    **Arguments:**

    - `model`, `env`: the network and the water.
    - `t`: the time (s) at which constrained nodes are placed.
    - `initial`: a starting guess; `model.node_positions` by default.
    - `rtol`, `atol`: tolerances on the positions (m).
    - `max_steps`: solver iterations before giving up.
    - `force_tolerance`: the largest residual force on a free node that counts as
        equilibrium, relative to the heaviest segment's weight.
    - `throw`: raise if the solver fails; otherwise check `result`.

    **Returns:**

    A [`jaxcable.StaticSolution`][].

    **Raises:**

    `ValueError` if a part of the network has no constrained node (the topology is
    static, so under `jit` too), or naming the field and value of a bad input (a model
    edited with `eqx.tree_at`, say; `equinox.EquinoxRuntimeError` naming the field
    where the model is traced). With `throw=True`, `equinox.EquinoxRuntimeError` (a
    `RuntimeError`) if no equilibrium is found, eagerly and under `jit` alike.
    """
    check_held(model)
    start = model.node_positions if initial is None else initial.positions
    start = checks.check(start, model.conditions() + env.conditions())
    solution = _equilibrium(model, env, start, t, rtol, atol, max_steps, force_tolerance)
    if not throw:
        return solution
    residual = checks.raise_if(
        solution.residual,
        solution.result != optx.RESULTS.successful,
        f"solve_statics found no equilibrium: the largest force left on a free node is above "
        f"force_tolerance ({force_tolerance}) times the heaviest segment's weight after "
        f"max_steps ({max_steps}) iterations. Start from positions where every segment is "
        "taut, or raise max_steps; with throw=False the solution's `residual` reports the force.",
    )
    return eqx.tree_at(lambda s: s.residual, solution, residual)


@eqx.filter_jit
def _equilibrium(model, env, start, t, rtol, atol, max_steps, force_tolerance) -> StaticSolution:
    """The whole solve, compiled once per topology and option set, its fallbacks decided
    by `jax.lax.cond` on traced residuals."""
    if env.seabed is None:
        descended = jnp.asarray(False)
        found = _solve(model, env, start, t, rtol, atol, max_steps, True)
    else:
        # Where the starting shape dips below the bed, the bed lifts it and its
        # segments go slack, and contact kinks the forces: Levenberg–Marquardt crawled
        # there (955 iterations for a 60-segment chain lying on the bottom, against 56
        # for the same chain hanging free, measured). Energy descent minds neither, so
        # it goes first, and often finishes the job.
        descended = jnp.min(start[model.free_nodes, 2], initial=jnp.inf) < -env.depth
        start, descent_steps = jax.lax.cond(
            descended,
            lambda x: _descend(model, env, x, t, 40 * max_steps, descended),
            lambda x: (x, jnp.asarray(0, jnp.int32)),
            start,
        )
        remaining, _ = _remaining(model, env, start, t)
        done = descended & (remaining <= force_tolerance)
        found = jax.lax.cond(
            done,
            lambda: (start, remaining, descent_steps),
            lambda: _solve(model, env, start, t, rtol, atol, max_steps, ~done),
        )
    retry = (found[1] > force_tolerance) & ~descended

    def again():
        moved, _ = _descend(model, env, start, t, 10 * max_steps, retry)
        second = _solve(model, env, moved, t, rtol, atol, max_steps, retry)
        return jax.tree.map(lambda a, b: jnp.where(second[1] < found[1], a, b), second, found)

    positions, remaining, steps = jax.lax.cond(retry, again, lambda: found)
    # Levenberg–Marquardt stops when its steps vanish, which also happens on a slack
    # guess with no stiffness at all; only a small force residual means equilibrium.
    # Conversely a small residual is equilibrium even where contact's kinks kept its
    # steps from vanishing.
    result = optx.RESULTS.where(
        remaining <= force_tolerance, optx.RESULTS.successful, optx.RESULTS.nonlinear_divergence
    )
    return _solution(model, env, t, positions, remaining, _force_scale(model, env), result, steps)


@eqx.filter_jit
def _solution(model, env, t, positions, remaining, scale, result, steps) -> StaticSolution:
    """The solution's outputs, compiled whole: run op by op, its gradients and scatters
    took 20–30 s on a first call, measured."""
    velocities = jnp.zeros_like(positions)
    _, _, strain = lag.segment_geometry(model, positions)
    return StaticSolution(
        state=State(positions, velocities),
        strain=strain,
        tension=lag.tension(model, positions, velocities),
        reactions=lag.reactions(model, env, t, positions, velocities, jnp.zeros_like(positions)),
        residual=remaining * scale,
        result=result,
        steps=steps,
    )


def _force_scale(model, env):
    """The heaviest segment's dry weight (N), which residual forces are relative to."""
    return jnp.maximum(jnp.max(model.line.mass_per_length * env.gravity * model.segment_length), 1e-12)


def _free_forces(model, env, t, free_positions):
    positions, _ = lag.full_state(model, t, free_positions, jnp.zeros_like(free_positions))
    velocities = jnp.zeros_like(positions)  # at rest, constrained nodes included
    return lag.generalised_forces(model, env, t, positions, velocities)[model.free_nodes]


@eqx.filter_jit
def _remaining(model, env, positions, t):
    """The largest force on a free node at `positions`, relative to the scale, and the
    scale (N)."""
    scale = _force_scale(model, env)
    return jnp.max(jnp.abs(_free_forces(model, env, t, positions[model.free_nodes])), initial=0.0) / scale, scale


# Compiled on its own so that `_equilibrium`'s second call (the retry) reuses the first
# call's trace: tracing Levenberg–Marquardt and its Jacobian took 1.1 s of the 3.5 s
# that tracing and lowering `_equilibrium` took on the Low & Langley file, every run,
# whether or not the compiled program then came from the persistent cache (measured,
# quiet). The compiled program computes the same numbers.
@eqx.filter_jit
def _solve(model, env, start, t, rtol, atol, max_steps, active):
    """The Levenberg–Marquardt solve.

    Returns the node positions, the largest residual force on a free node relative to
    the heaviest segment's dry weight, and the iterations taken. Where `active` is
    false (a case of a `vmap` that runs this branch only because another case needs
    it) the problem is `x − start = 0` instead, solved where it starts, so the loop
    stops at once. Not a zero residual: its Jacobian would be singular, and the
    implicit derivative's linear solve, which runs for every case under `vmap`,
    would raise.
    """
    zeros_free = jnp.zeros((model.free_nodes.shape[0], 3))
    scale = _force_scale(model, env)
    x0 = start[model.free_nodes]

    def residual(free_positions, _):
        return _free_forces(model, env, t, free_positions) / scale

    def problem(free_positions, args):
        return jnp.where(active, residual(free_positions, args), free_positions - x0)

    solver = optx.LevenbergMarquardt(rtol=rtol, atol=atol)
    solution = optx.least_squares(problem, solver, x0, max_steps=max_steps, throw=False)
    positions, _ = lag.full_state(model, t, solution.value, zeros_free)
    remaining = jnp.max(jnp.abs(residual(solution.value, None)), initial=0.0)
    return positions, remaining, jnp.asarray(solution.stats["num_steps"], jnp.int32)


def _descend(model, env, start, t, max_steps, active):
    """Node positions after descending the potential energy Π (BFGS) from `start`, and
    the steps taken.

    Only a starting point for `_solve`, so it stops at `max_steps` without complaint.
    Π is scaled by the heaviest segment's dry weight times the network's length, so
    that the tolerances are relative. Where `active` is false, the objective is
    `½ |x − start|²` instead, whose minimum is the start, so the loop stops at once
    (and, as in `_solve`, its implicit derivative stays well posed).
    """
    free = model.free_nodes
    zeros_free = jnp.zeros((free.shape[0], 3))
    weight = jnp.max(model.line.mass_per_length * env.gravity * model.segment_length)
    scale = jnp.maximum(weight * jnp.sum(model.segment_length), 1e-12)
    x0 = start[free]

    def energy(free_positions, _):
        positions, _ = lag.full_state(model, t, free_positions, zeros_free)
        return lag.potential_energy(model, env, positions) / scale

    def objective(free_positions, args):
        return jnp.where(active, energy(free_positions, args), 0.5 * jnp.sum((free_positions - x0) ** 2))

    solver = optx.BFGS(rtol=1e-10, atol=1e-10)
    solution = optx.minimise(objective, solver, x0, max_steps=max_steps, throw=False)
    positions, _ = lag.full_state(model, t, solution.value, zeros_free)
    return positions, jnp.asarray(solution.stats["num_steps"], jnp.int32)
