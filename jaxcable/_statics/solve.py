"""Static equilibrium under gravity, buoyancy and a steady current.

The equilibrium is found by pseudo-transient continuation: implicit Euler steps of the
overdamped motion `D ẋ = Q_f(x)` (D each free node's mass with its displaced water),
each the linear step `(D/Δτ − ∂Q_f/∂x) δ = Q_f` and Newton's corrections towards the
step's end. The pseudo-time step Δτ grows where the linear model predicted the
force well and shrinks where it did not (as a trust region), so that far from the
equilibrium the steps follow the damped motion (a slack line settling in a current, a
buoyant line floating up through slack) and near it they are Newton's. The term `D/Δτ`
keeps the linear systems regular where slack segments have no stiffness; each is
solved along the network's graph by [`jaxcable.NetworkJacobian`][], O(N). Stiff
networks are first solved softened, then stiffened stage by stage (see
`_equilibrium`), from a start whose chains sag or hang along their loads (a buoyant
line arched upward; `_statics/start.py`). The root finder is `_statics/pseudo_transient.py`;
`benchmarks/statics_fuzz.py` runs it on random legal scenes.
"""

import dataclasses
import functools
import typing

import equinox as eqx
import jax
import jax.numpy as jnp
import lineax as lx
import numpy as np
import optimistix as optx
from jaxtyping import Array, Float, Int

from .. import _checks as checks
from .._equations import lagrangian as lag
from .._model.indexing import sum_into
from .._model.network import CableNetwork, check_held, network_conditions
from .._model.state import State
from .._programs import RUN_ONCE, program
from .._sea.environment import Environment
from .._solver.jacobian import NetworkJacobian
from .._typing import RealScalarLike
from .catenary import applies, catenary_statics
from .pseudo_transient import PseudoTransient
from .solution import (
    FORCE_TOLERANCE,
    MAX_REQUIRED_STRAIN,
    MAX_STEPS,
    StaticSolution,
    failure_message,
    still_water,
)
from .start import start_shape

# Stiffness continuation (see `_equilibrium`): the softest network's typical strain,
# the stages from it to the network itself, and the force tolerance of those stages,
# relative to the scene's force scale (each only starts the next).
SOFT_STRAIN = 0.01
STAGES = 6
STAGE_TOLERANCE = 1e-3


def solve_statics(
    model: CableNetwork,
    env: Environment,
    *,
    t: RealScalarLike = 0.0,
    initial: State | None = None,
    max_steps: int = MAX_STEPS,
    force_tolerance: float = FORCE_TOLERANCE,
    throw: bool = True,
) -> StaticSolution:
    """Find the static equilibrium of `model` in `env`, with constrained nodes at their
    positions at time `t` (s).

    Solves `Q_f(x, 0) = 0` for the free node positions: gravity, buoyancy, the tension
    laws, a body's constant force, the seabed's spring and the steady drag of the
    water's velocity at time `t` (the current; and the waves' at `t`, where they are
    not ramped out: pass `env.without_waves()` for still water). The method is
    pseudo-transient continuation, damped motion towards rest that turns into Newton's
    method near it, with the network's structured Jacobian (see the module's notes).
    It starts from `initial` or `model.node_positions` ([`jaxcable.CableNetwork.from_branches`][]
    puts each branch on a catenary sagging downward). From `model.node_positions`,
    each run of segments between junctions is first put on its own analytic shape
    under its load, where that lowers the load's potential: the catenary hanging along
    its weight, buoyancy and drag (so a buoyant line starts arched upward), or, for a
    line with a free end, turned about its other end to hang along its load. An
    `initial` is used as given. Unlike a plain Newton or least-squares solve it needs
    no taut start: slack segments only slow it.

    Equilibrium is a force on every free node no larger than `force_tolerance` times the
    scene's force scale (the largest tension, wet weight of a segment or body, or
    drag; `StaticSolution.force_scale`), plus rounding, 16 ε times the largest EA. So a
    4 mN force left on a 50 kN line of EA 7.5e12 N is equilibrium, and so is a
    near-massless line's nanonewtons.

    A single line between two supports in still water (no current or waves, nothing on
    its inner nodes, no bending; on the seabed or off it), called with concrete values
    and no `initial`, is solved instead as the discrete catenary, in numpy and in
    milliseconds, with nothing to compile (`jaxcable._statics.catenary`): the same equilibrium
    of the same equations, to rounding. `StaticSolution.method` says which way a
    solution was found; a line the catenary cannot solve takes the solver.

    The solver is one compiled program with no branches on values, so it takes the same
    path eagerly, under `jit` and under `vmap` (where it steps until every case is
    done). Derivatives are implicit (optimistix's `ImplicitAdjoint`, solved with the
    same structured Jacobian), so `jax.grad` through it costs one linear solve;
    where the equilibrium is not unique (a slack line lying on a frictionless bed) the
    Jacobian is singular and so is the derivative.

    **Arguments:**

    - `model`, `env`: the network and the water.
    - `t`: the time (s) at which constrained nodes are placed.
    - `initial`: a starting guess; `model.node_positions` by default.
    - `max_steps`: pseudo-time steps before giving up, for each of the seven stages of
        the stiffness continuation (static: a new value recompiles).
    - `force_tolerance`: the largest residual force on a free node that counts as
        equilibrium, relative to the scene's force scale (–).
    - `throw`: raise if no equilibrium is found, or if a traced input breaks a
        requirement; otherwise check `result` (and `StaticSolution.failures()`, which
        says why, by case under `jax.vmap`).

    **Returns:**

    A [`jaxcable.StaticSolution`][].

    **Raises:**

    `ValueError`, before solving, if a part of the network has no constrained node, if a
    constrained node lies below the seabed (by more than 0.1 % of the depth), if
    two nodes joined by a segment start at the same point (the tension's direction is
    undefined: both ends of a line at one point, say), or if the segments between two
    constrained nodes would have to stretch by more than `MAX_REQUIRED_STRAIN` (100 %)
    on average to reach from one to the other (a line far shorter than the distance
    between its ends). Those checks need concrete positions; under `jit` such a scene
    fails to converge instead. `ValueError` naming the field and value of a bad input.
    Where the model or the water is traced (built or batched inside `jax.vmap` or
    `jit`), `equinox.EquinoxRuntimeError` naming the field with `throw=True`; with
    `throw=False` nothing is raised: a case that breaks a requirement comes back failed,
    with `invalid_input` set, and the other cases are solved. With `throw=True`,
    `equinox.EquinoxRuntimeError` (a `RuntimeError`) if no equilibrium is found,
    eagerly and under `jit` alike, saying why where the values are concrete.
    """
    check_held(model)
    start = model.node_positions if initial is None else initial.positions
    conditions = network_conditions(model, env)
    checks.enforce(conditions)
    traced = checks.traced_conditions(conditions)
    broken = None
    if throw:
        start = checks.guard(start, traced, hint=_VMAP_HINT)
    elif traced:  # a case that breaks one starts from NaN, on which the root find stops at once
        broken = checks.violations(traced)
        start = jnp.where(jnp.any(broken[0]), jnp.nan, start)
    if initial is None:
        # A single line in still water is a discrete catenary, found in numpy in
        # milliseconds where this solver compiles for seconds.
        closed_form = catenary_statics(model, env, t, force_tolerance)
        if closed_form is not None:
            return closed_form
    _check_geometry(model, start, t)
    solution = _equilibrium(model, env, start, t, max_steps, force_tolerance, initial is None, still_water(env), False)
    if not throw:
        return solution if broken is None else _with_invalid_input(solution, traced, *broken)
    failed = solution.result != optx.RESULTS.successful
    if checks.traced(failed):
        message = (
            "solve_statics found no equilibrium: the largest force left on a free node is above "
            f"force_tolerance ({force_tolerance}) times the scene's force scale after at most {max_steps} "
            "steps (max_steps). Call it outside jit, or with throw=False and read the solution's residual, "
            "worst_node and result, to see where."
        )
    else:
        message = failure_message(solution, force_tolerance, max_steps) if bool(failed) else ""
    residual = checks.raise_if(solution.residual, failed, message)
    return eqx.tree_at(lambda s: s.residual, solution, residual)


# Said with the error of a traced input: under `vmap` it fails the whole batch.
_VMAP_HINT = (
    "; under jax.vmap, solve_statics(..., throw=False) solves the other cases and returns this one failed, and "
    "StaticSolution.failures() names it"
)


def _with_invalid_input(solution: StaticSolution, conditions: list[checks.Condition], broken, values) -> StaticSolution:
    """`solution`, failed where the traced `conditions` are `broken` (`checks.violations`,
    with each one's first bad value), naming the first one broken and its value
    (`StaticSolution.invalid_input`): a case of a batch that `throw=False` keeps from
    failing the others."""
    index = jnp.where(jnp.any(broken), jnp.argmax(broken), -1).astype(jnp.int32)
    # As a sweep marks an invalid case; pyright takes an Enumeration's members for literals.
    invalid: optx.RESULTS = optx.RESULTS.nonfinite_input  # pyright: ignore[reportAssignmentType]
    result = optx.RESULTS.where(index >= 0, invalid, solution.result)
    return dataclasses.replace(
        solution,
        result=result,
        invalid_input=index,
        invalid_value=values[jnp.maximum(index, 0)],
        input_requirements=tuple(f"{c.name} {c.requirement}" for c in conditions),
    )


def prepare(
    model: CableNetwork,
    env: Environment,
    *,
    t: RealScalarLike = 0.0,
    max_steps: int = MAX_STEPS,
    force_tolerance: float = FORCE_TOLERANCE,
) -> None:
    """Start compiling the programs of `solve_statics(model, env, t=t, ...)` from the
    model's own start, in a background thread, where the command line keeps programs
    (`jaxcable._programs`). Nothing otherwise, nor where the discrete catenary
    applies (`jaxcable._statics.catenary.applies`), which needs no program."""
    if applies(model, env, t):
        return
    _required_strain.prepare(model, t)
    _equilibrium.prepare(model, env, model.node_positions, t, max_steps, force_tolerance, True, still_water(env), False)


def _check_geometry(model: CableNetwork, start, t) -> None:
    """Refuse, naming the nodes, a start whose segments have zero length, or two
    constrained nodes farther apart than `1 + MAX_REQUIRED_STRAIN` times the shortest
    unstretched chain of segments between them. Concrete values only."""
    if checks.traced((start, model.node_positions, model.segment_length, model.motions, t)):
        return
    needed, pair, distance, chain, held = (np.asarray(x) for x in _required_strain(model, t))
    positions = np.asarray(start, dtype=float).copy()
    constrained = np.asarray(model.constrained_nodes)
    positions[constrained] = held
    ends = np.asarray(model.segment_nodes)
    length = np.asarray(model.segment_length)
    chord = np.linalg.norm(positions[ends[:, 1]] - positions[ends[:, 0]], axis=1)
    zero = np.flatnonzero(chord <= 1e-12 * length)
    if zero.size:
        s = int(zero[0])
        i, j = ends[s]
        raise ValueError(
            f"solve_statics: segment {s} joins nodes {i} and {j}, which start at the same point "
            f"{positions[i].tolist()} m, so the direction of its tension is undefined. Both ends of a line at "
            "one point? Give the line ends apart, or an initial shape with its nodes apart"
        )
    if needed > MAX_REQUIRED_STRAIN:
        i, j = constrained[pair]
        raise ValueError(
            f"solve_statics: constrained nodes {i} and {j} are {distance:.6g} m apart, but the shortest chain of "
            f"segments between them is {chain:.6g} m long unstretched: it must stretch {100 * needed:.3g} % to "
            f"reach, more than the {100 * MAX_REQUIRED_STRAIN:.0f} % allowed. Is a line's length or an end's "
            "position wrong?"
        )


@functools.partial(program, compiler_options=RUN_ONCE)
def _required_strain(model: CableNetwork, t):
    """The largest mean strain (–) that a chain of segments between two constrained
    nodes needs to reach from one to the other at time `t`: their distance over the
    shortest such chain's unstretched length, less 1; −1 where no two are joined.
    Also that pair (indices into `constrained_nodes`, shape `(2,)`), their distance
    (m), the chain's length (m), and the constrained nodes' positions (m, shape
    `(constrained, 3)`). Traceable, so that a sweep's case is judged too."""
    constrained = model.constrained_nodes
    ends = model.segment_nodes
    length = jnp.broadcast_to(model.segment_length, (model.n_segments,))
    count = constrained.size
    # Bellman–Ford from every constrained node at once: a chain of n segments settles
    # in n rounds, and no chain is longer than the network has nodes.
    start = jnp.full((count, model.n_nodes), jnp.inf).at[np.arange(count), constrained].set(0.0)

    def relax(_, reach):
        reach = reach.at[:, ends[:, 1]].min(reach[:, ends[:, 0]] + length)
        return reach.at[:, ends[:, 0]].min(reach[:, ends[:, 1]] + length)

    chain = jax.lax.fori_loop(0, model.n_nodes, relax, start)[:, constrained]
    held, _, _ = lag.constrained_motion(model, t)
    distance = jnp.linalg.norm(held[:, None, :] - held[None, :, :], axis=-1)
    joined = jnp.isfinite(chain) & ~np.eye(count, dtype=bool)
    strain = jnp.where(joined, distance / jnp.where(joined, chain, 1.0) - 1.0, -1.0)
    worst = jnp.argmax(strain)  # `check_held` has made sure of a constrained node
    pair = jnp.stack(jnp.divmod(worst, count))
    return jnp.max(strain), pair, jnp.ravel(distance)[worst], jnp.ravel(chain)[worst], held


def nearby_equilibrium(model, env, start: State, t, max_steps, force_tolerance) -> StaticSolution:
    """The equilibrium from `start`, the equilibrium of a network nearby (the same
    network with its supports moved a little), by the last stage of `solve_statics`'
    continuation alone, as `solve_statics(..., throw=False)` gives it otherwise: the
    softer stages would move the nodes away only for the stiffer ones to bring them
    back. Traceable; for `jaxcable.stiffness`, which finds tens of such equilibria."""
    return _equilibrium(model, env, start.positions, t, max_steps, force_tolerance, False, still_water(env), True)


@functools.partial(program, compiler_options=RUN_ONCE)
def _equilibrium(model, env, start, t, max_steps, force_tolerance, shaped, still, nearby) -> StaticSolution:
    """The whole solve, compiled once per topology and option set; from `start`
    improved by `start_shape` if `shaped`, a caller's `initial` as given otherwise;
    without the water's loads where `still` (`still_water`); the network itself
    alone, without the softer stages, where `nearby` (`nearby_equilibrium`)."""
    free = model.free_nodes
    zeros_free = jnp.zeros((free.shape[0], 3))

    graph = NetworkJacobian(model.topology)

    def solve(model, env, t, start, tolerance):
        """A root find that carries no derivative (its inputs carry none)."""
        return optx.root_find(
            lambda x, _: _forces(model, env, t, x, tolerance, still),
            PseudoTransient(graph=graph),
            start,
            has_aux=True,
            options={
                "mass": _pseudo_mass(model, env)[free],
                "shortest": jnp.min(model.segment_length),
                "taut": _taut_strain(model),
            },
            max_steps=max_steps,
            throw=False,
        )

    # Continuation in stiffness: first the network with its stiffnesses scaled down so
    # that its strains are about `SOFT_STRAIN`, then stiffer by equal factors, each
    # stage from the last one's equilibrium, and last the network itself. A stiff
    # segment turned by a small step stretches by its square, so the linear model that
    # a step trusts holds only for tiny turns: a light riser of EA 3.8e9 N in a 1.6 m/s
    # current, which must swing tens of metres from its vertical guess, crept 0.1 m a
    # step and ran out of 1,000 steps; softened, it swings in a few.
    # One `scan` over all the stages, the last one the network itself at the caller's
    # tolerance, so that the root find is traced and compiled once: tracing it takes
    # seconds of a warm `jaxcable run`, and a second copy for the last stage nearly
    # doubled the tracing and lengthened the compile by a fifth, for the same steps.
    # No stage carries a derivative (`_implicit` gives the equilibrium its own), nor
    # does the start: the equilibrium's derivative does not depend on it, and the loads
    # evaluated there (a norm of a zero drag) have none that is finite.
    fixed = jax.lax.stop_gradient((model, env, t, start))
    # The water's loads at the start, evaluated once for the softening and the start shape.
    placed = lag.full_state(fixed[0], t, fixed[3][free], zeros_free)[0]
    water = _water_loads(*fixed[:3], placed, still)
    softest = jnp.clip(
        _load_sum(fixed[0], fixed[1], water) / (SOFT_STRAIN * jnp.max(_stiffness(fixed[0]))), 1e-300, 1.0
    )

    def stage(carry, k):
        x, _ = carry
        final = k == STAGES
        soft = _scaled_stiffness(fixed[0], jnp.where(final, 1.0, softest ** ((STAGES - k) / STAGES)))
        tolerance = jnp.where(final, force_tolerance, STAGE_TOLERANCE)
        found = solve(soft, fixed[1], fixed[2], x, tolerance)
        return (found.value, found.result), found.stats["num_steps"]

    start = start_shape(fixed[0], fixed[1], placed, water) if shaped else fixed[3]
    if free.size:
        (value, found), stage_steps = jax.lax.scan(
            stage, (start[free], optx.RESULTS.successful), jnp.arange(STAGES if nearby else 0, STAGES + 1)
        )
        value = _implicit(model, env, t, value, graph)
    else:  # every node constrained: nothing to solve, the reactions still to find
        value, found, stage_steps = zeros_free, optx.RESULTS.successful, jnp.zeros(1, int)
    positions, _ = lag.full_state(model, t, value, zeros_free)
    forces, water = lag.static_loads(model, env, t, positions, still)
    left = jnp.max(jnp.abs(forces[free]), axis=1, initial=0.0)
    remaining = jnp.max(left, initial=0.0)
    scale = _force_scale(model, env, positions, water)
    # Judged here, not by the solver's code alone: a step limit that ends on a force
    # within the tolerance is still an equilibrium.
    within = remaining <= force_tolerance * scale + _rounding(model)
    # Under `jit` and `vmap` the geometry that `solve_statics` refuses eagerly (a line
    # far too short for its ends) may still reach an "equilibrium" at absurd tension:
    # failed here, so that a sweep reports the case.
    needed = _required_strain(model, t)[0]
    result = optx.RESULTS.where(
        within & (needed <= MAX_REQUIRED_STRAIN),
        optx.RESULTS.successful,
        optx.RESULTS.where(found == optx.RESULTS.successful, optx.RESULTS.nonlinear_divergence, found),
    )
    worst = jnp.asarray(free)[jnp.argmax(left)] if free.size else jnp.asarray(0)
    velocities = jnp.zeros_like(positions)
    _, _, strain = lag.segment_geometry(model, positions)
    tension = lag.tension(model, positions, velocities)
    ends = model.segment_nodes
    at_node = jnp.zeros(model.n_nodes).at[ends[:, 0]].max(jnp.abs(tension)).at[ends[:, 1]].max(jnp.abs(tension))
    drag = water[worst]
    on_seabed = jnp.asarray(False)
    if env.depth is not None and env.seabed is not None:
        on_seabed = positions[worst, 2] < -env.depth
    return StaticSolution(
        state=State(positions, velocities),
        strain=strain,
        tension=tension,
        reactions=-forces[model.constrained_nodes],  # (M a − Q)_c at rest
        residual=remaining,
        force_scale=scale,
        worst_node=jnp.asarray(worst, jnp.int32),
        worst_tension=at_node[worst],
        worst_drag=jnp.linalg.norm(drag),
        worst_on_seabed=on_seabed,
        required_strain=needed,
        result=result,
        steps=jnp.sum(stage_steps).astype(jnp.int32),
        invalid_input=jnp.asarray(-1, jnp.int32),
        invalid_value=jnp.asarray(jnp.nan),
    )


# Jitted inside statics' trace so that it is traced once, not once for each of the
# root find's evaluations (its first, each step's Newton corrections and JVPs, the
# step's truncation and its end point): JAX reuses the jaxpr of a call with the same
# argument types, and the lowered program calls one function.
@eqx.filter_jit
def _forces(model, env, t, free_positions, relative, still):
    """The free nodes' forces (N) and, as the auxiliary output, the tolerance (N) and
    the segments' strains (–), which steps are truncated by."""
    positions, _ = lag.full_state(model, t, free_positions, jnp.zeros_like(free_positions))
    forces, water = lag.static_loads(model, env, t, positions, still)
    tolerance = relative * _force_scale(model, env, positions, water) + _rounding(model)
    strain = lag.segment_geometry(model, positions)[2]
    return forces[model.free_nodes], (tolerance, strain)


def _implicit(model, env, t, value, graph: NetworkJacobian):
    """`value`, the free nodes' equilibrium positions (m, shape `(free, 3)`, found by
    root finds that carry no derivative), unchanged, with the implicit function
    theorem's derivative in everything the forces depend on, `δx = −J⁻¹ (∂Q_f/∂θ) δθ`,
    J = ∂Q_f/∂x at `value` (optimistix's `ImplicitAdjoint`, one linear solve on the
    network's graph; nothing where no derivative is taken). Only the network's own
    equilibrium is differentiated: a softened stage of the continuation can rest with
    compressed segments on the seabed, whose Jacobian is singular (the softest stage
    of `validation/stiffness.py`'s line on the bed at N = 128: 15 such segments,
    smallest singular value 0), and the implicit derivative of every stage, which the
    `scan` computed when each root find had its own adjoint, failed in lineax there
    although the final Jacobian is regular (condition number 1e8).

    Where J is singular the equilibrium has no derivative, and the solve says which
    node nothing holds ([`_EquilibriumSolve`][])."""
    positions, _ = lag.full_state(model, t, jax.lax.stop_gradient(value), jnp.zeros_like(value))
    adjoint = optx.ImplicitAdjoint(linear_solver=_EquilibriumSolve(model, graph, positions))
    return adjoint.apply(_settled, _balance, (jax.lax.stop_gradient(value), model, env, t), frozenset())[0]


class _EquilibriumSolve(lx.AbstractLinearSolver):
    """The network's linear solver for the implicit derivative of an equilibrium, which,
    where the solve fails (J singular: the solution is not finite), names the first free
    node with every segment at it slack, in place of lineax's "operator is singular".

    Such a node is the usual cause: a slack segment pulls with nothing as its ends move
    (the tension law is zero at and below zero strain), and the seabed pushes only up
    (its friction acts on motion, not at rest), so nothing fixes the node sideways and
    the equilibrium is not unique there. The check is on the derivative's path only:
    a program that takes no derivative has no solve and no callback."""

    graph: NetworkJacobian
    loose: Int[Array, ""]
    messages: tuple[str, ...] = eqx.field(static=True)

    def __init__(self, model: CableNetwork, graph: NetworkJacobian, positions: Float[Array, "nodes 3"]):
        self.graph = graph
        taut = (lag.segment_geometry(model, positions)[2] > 0).astype(positions.dtype)
        holding = sum_into(jnp.concatenate([taut, taut]), model.topology.node_sums)  # taut segments at each node
        loose = holding[model.free_nodes] == 0
        self.loose = jnp.where(jnp.any(loose), jnp.argmax(loose) + 1, 0)
        self.messages = (
            "solve_statics: the equilibrium has no derivative: the Jacobian of the free nodes' forces is singular "
            "(or too ill-conditioned to solve) there, so the equilibrium does not depend smoothly on the inputs",
            *(
                f"solve_statics: the equilibrium has no derivative: every segment at node {int(node)} is slack, so "
                "nothing holds that node sideways (a slack segment pulls with nothing, and the seabed pushes only up: "
                "its friction acts on motion, not at rest) and the equilibrium is not unique there. Differentiate "
                "where the line is taut at that node (shorter, or its supports further apart), or leave out what "
                "depends on it"
                for node in model.free_nodes
            ),
        )

    def init(self, operator, options):
        return self.graph.init(operator, options)

    def compute(self, state, vector, options):
        solution, result, stats = self.graph.compute(state, vector, options)
        failed = result != lx.RESULTS.successful
        return eqx.branched_error_if(solution, failed, self.loose, self.messages), result, stats

    def transpose(self, state, options):
        return self.graph.transpose(state, options)

    def conj(self, state, options):
        return self.graph.conj(state, options)

    def assume_full_rank(self):
        return self.graph.assume_full_rank()


# optimistix takes these only as closure-free functions, which a runtime type checker's
# wrapper (the tests' jaxtyping import hook) is not.
@typing.no_type_check
def _settled(inputs):
    """`_implicit`'s primal: the equilibrium as found."""
    return inputs[0], None


@typing.no_type_check
def _balance(root, _, inputs):
    """`_implicit`'s condition: the forces at `root` vanish."""
    _, model, env, t = inputs[:4]
    return _free_forces(model, env, t, root)


def _free_forces(model, env, t, free_positions, still=False):
    positions, _ = lag.full_state(model, t, free_positions, jnp.zeros_like(free_positions))
    return lag.static_forces(model, env, t, positions, still)[model.free_nodes]  # constrained nodes at rest too


def _water_loads(model, env, t, positions, still=False):
    """The water's loads (N, shape `(nodes, 3)`) on the nodes at rest at `positions`
    (m): the current's drag, and the waves' at `t`, with the bodies' constant forces;
    zeros, not evaluated, where the water is `still` (`still_water`)."""
    return lag.static_loads(model, env, t, positions, still)[1]


def _force_scale(model, env, positions, water):
    """The scene's force scale (N) at `positions`: the largest segment tension, wet
    weight of a segment or a body (weight less buoyancy, either sign), body's constant
    force, or drag (with the waves' inertia) on a node at rest, of the `water`'s loads
    there (`_water_loads`, which its callers have evaluated already). Wet, not dry:
    a near-neutral line's weight and buoyancy cancel, and what is left, not either,
    is what its tensions carry."""
    line, body = model.line, model.body
    g, rho = env.gravity, env.water_density
    velocities = jnp.zeros_like(positions)
    loads = [
        jnp.abs(lag.tension(model, positions, velocities)),
        jnp.abs(line.mass_per_length - rho * line.area) * g * model.segment_length,
        jnp.abs(body.mass - rho * body.volume) * g,
        jnp.linalg.norm(body.force, axis=-1),
        jnp.linalg.norm(water, axis=-1),
    ]
    return jnp.max(jnp.stack([jnp.max(jnp.broadcast_to(x, jnp.shape(x) or (1,))) for x in loads]))


def _stiffness(model):
    """Each segment's C_E (N), the stiffness that continuation scales."""
    return jnp.broadcast_to(model.line.tension_law.axial_stiffness, (model.n_segments,))


def _scaled_stiffness(model, factor):
    """`model` with its tension law's stiffness coefficients (C_E, C_E1, and C_v, which
    does nothing at rest) times `factor`; the slack switch's width and the law's static
    flags (`slack_damping`) unchanged."""
    law = model.line.tension_law
    names = [f.name for f in dataclasses.fields(law) if f.name != "slack_width" and not f.metadata.get("static", False)]
    return eqx.tree_at(
        lambda m: [getattr(m.line.tension_law, n) for n in names],
        model,
        [factor * getattr(law, n) for n in names],
    )


def _load_sum(model, env, water):
    """The loads (N) that a network's tensions must carry, summed: every segment's
    weight and displaced weight, the bodies' weights, buoyancy and constant forces, and
    the `water`'s loads on every node at rest (`_water_loads`). The softened network's
    tensions are about this."""
    line, body = model.line, model.body
    g, rho = env.gravity, env.water_density
    drag = jnp.linalg.norm(water, axis=-1)
    return (
        jnp.sum(
            jnp.broadcast_to((line.mass_per_length + rho * line.area) * g, (model.n_segments,)) * model.segment_length
        )
        + jnp.sum((body.mass + rho * body.volume) * g + jnp.linalg.norm(body.force, axis=-1))
        + jnp.sum(drag)
    )


def _rounding(model):
    """The force (N) that rounding alone leaves on a node: a tension EA ε is known to
    about EA times float64's ε, and a node sums a few of them."""
    return 16 * jnp.finfo(float).eps * jnp.max(model.line.tension_law.axial_stiffness)


def _taut_strain(model):
    """The strain (–) from which each segment counts as taut, shape `(segments,)`: the
    top of its slack switch's band, or 1e-9 for a sharp switch, so that a step truncated
    there (see `PseudoTransient`) still moves."""
    width = jnp.broadcast_to(model.line.tension_law.slack_width, (model.n_segments,))
    return jnp.maximum(width, 1e-9)


def _pseudo_mass(model, env):
    """Each node's mass with its displaced water (kg), shape `(nodes,)`: the damped
    motion's inertia, which sets how far a node moves in a small pseudo-time step."""
    line, body = model.line, model.body
    per_segment = 0.5 * (line.mass_per_length + env.water_density * line.area) * model.segment_length
    segments = jnp.broadcast_to(per_segment, (model.n_segments,))
    ends = model.segment_nodes
    nodes = jnp.zeros(model.n_nodes).at[ends[:, 0]].add(segments).at[ends[:, 1]].add(segments)
    return nodes + body.mass + env.water_density * body.volume
