"""Static equilibrium under gravity, buoyancy and a steady current."""

import equinox as eqx
import jax.numpy as jnp
import optimistix as optx
from jaxtyping import Array, Float, Int

from . import _checks as checks, _lagrangian as lag
from ._environment import Environment
from ._network import CableNetwork, check_held
from ._state import State


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
    t: float = 0.0,
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

    If that solve leaves a large residual (outside `jit` and `vmap`, where the values
    can be inspected), the free nodes first descend the potential energy by BFGS from
    the initial positions, current drag aside, and Levenberg–Marquardt starts again
    from there. Energy descent always makes progress where a hanging part must swing
    or straighten a long way, as below a weight or a free end, which
    Levenberg–Marquardt on the forces was seen to stall on (MoorDyn's `lifting.txt`
    and `hanging_lines.txt` examples).

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

    `ValueError` if a part of the network has no constrained node; with `throw=True`,
    `RuntimeError` if no equilibrium is found.
    """
    check_held(model)
    start = model.node_positions if initial is None else initial.positions
    descended = False
    if env.seabed is not None and _reaches_bed(model, env, start):
        # Where the starting shape dips below the bed, the bed lifts it and its
        # segments go slack, and contact kinks the forces: Levenberg–Marquardt crawled
        # there (955 iterations for a 60-segment chain lying on the bottom, against 56
        # for the same chain hanging free, measured). Energy descent minds neither, so
        # it goes first, and often finishes the job.
        start, descent_steps = _descend(model, env, start, t, 40 * max_steps)
        descended = True
        remaining, scale = _remaining(model, env, start, t)
        if checks.is_concrete(remaining) and remaining <= force_tolerance:
            return _solution(model, env, t, start, remaining, scale, optx.RESULTS.successful, descent_steps)
    solution, positions, remaining, scale = _solve(model, env, start, t, rtol, atol, max_steps)
    if checks.is_concrete(remaining) and remaining > force_tolerance and not descended:
        retry = _solve(model, env, _descend(model, env, start, t, 10 * max_steps)[0], t, rtol, atol, max_steps)
        if retry[2] < remaining:
            solution, positions, remaining, scale = retry
    # Levenberg–Marquardt stops when its steps vanish, which also happens on a slack
    # guess with no stiffness at all; only a small force residual means equilibrium.
    # Conversely a small residual is equilibrium even where contact's kinks kept its
    # steps from vanishing.
    result = optx.RESULTS.where(remaining <= force_tolerance, optx.RESULTS.successful, optx.RESULTS.nonlinear_divergence)
    if throw:
        failed = result != optx.RESULTS.successful
        message = (
            "solve_statics found no equilibrium: the largest force left on a free node is "
            "{} N after {} iterations. Start from positions where every segment is taut, "
            "or raise max_steps."
        )
        if checks.is_concrete(failed):
            if bool(failed):
                raise RuntimeError(message.format(float(remaining * scale), int(solution.stats["num_steps"])))
        else:
            remaining = eqx.error_if(remaining, failed, message.format("a large", "its"))
    return _solution(model, env, t, positions, remaining, scale, result, solution.stats["num_steps"])


def _reaches_bed(model, env, positions) -> bool:
    """Whether any free node starts below the seabed; `True` when that cannot be known
    (traced positions), so that the robust path is taken."""
    lowest = jnp.min(positions[model.free_nodes, 2], initial=jnp.inf)
    if not (checks.is_concrete(lowest) and checks.is_concrete(env.depth)):
        return True
    return bool(lowest < -env.depth)


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


@eqx.filter_jit
def _solve(model, env, start, t, rtol, atol, max_steps):
    """The Levenberg–Marquardt solve, compiled once per topology and option set.

    Returns the optimistix solution, the node positions, the largest residual force on a
    free node relative to `scale`, and `scale` (N): the heaviest segment's dry weight.
    """
    zeros_free = jnp.zeros((model.free_nodes.shape[0], 3))
    scale = _force_scale(model, env)

    def residual(free_positions, _):
        return _free_forces(model, env, t, free_positions) / scale

    solver = optx.LevenbergMarquardt(rtol=rtol, atol=atol)
    solution = optx.least_squares(residual, solver, start[model.free_nodes], max_steps=max_steps, throw=False)
    positions, _ = lag.full_state(model, t, solution.value, zeros_free)
    remaining = jnp.max(jnp.abs(residual(solution.value, None)), initial=0.0)
    return solution, positions, remaining, scale


@eqx.filter_jit
def _descend(model, env, start, t, max_steps):
    """Node positions after descending the potential energy Π (BFGS) from `start`, and
    the steps taken.

    Only a starting point for `_solve`, so it stops at `max_steps` without complaint.
    Π is scaled by the heaviest segment's dry weight times the network's length, so
    that the tolerances are relative.
    """
    free = model.free_nodes
    zeros_free = jnp.zeros((free.shape[0], 3))
    weight = jnp.max(model.line.mass_per_length * env.gravity * model.segment_length)
    scale = jnp.maximum(weight * jnp.sum(model.segment_length), 1e-12)

    def energy(free_positions, _):
        positions, _ = lag.full_state(model, t, free_positions, zeros_free)
        return lag.potential_energy(model, env, positions) / scale

    solver = optx.BFGS(rtol=1e-10, atol=1e-10)
    solution = optx.minimise(energy, solver, start[free], max_steps=max_steps, throw=False)
    positions, _ = lag.full_state(model, t, solution.value, zeros_free)
    return positions, solution.stats["num_steps"]
