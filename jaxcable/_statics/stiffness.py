"""The mooring's stiffness: how the supports' reactions change as the supports move,
by forward-mode differentiation through the statics.

A support (an anchor, a fairlead, a body's attachment point) is a constrained node; its
reaction `R` is the force it exerts on the network at equilibrium
(`StaticSolution.reactions`), so the lines pull it with `F = −R`. Moving the supports
moves the equilibrium, and

    K = ∂R/∂x = −∂F/∂x    (N/m)

is MoorPy's stiffness (`getCoupledStiffness`): positive where the lines restore, as a
spring does. It is `jax.jacfwd` of the reactions through
[`jaxcable.solve_statics`][], whose derivatives are implicit (optimistix's
`ImplicitAdjoint`): each column is a linear solve with the network's Jacobian at the
equilibrium, O(N) on its graph, so the free nodes' response is exact, not re-found by
finite differences. The supports are moved by offsets to their reference positions
(`CableNetwork.node_positions`, from which their motions are measured), so a moving
support is moved at time `t` by the same offset. One program per network computes
every support's three columns, so that any choice of nodes, and a body's stiffness,
share it.

A rigid body held by several lines ([`body_stiffness`][]) moves its attachment points
with its pose: a translation u and a rotation θ (a rotation vector, exact by
Rodrigues' formula) about a reference point r take an attachment point x to
`r + u + R(θ)(x − r)`. Its 6 × 6 stiffness is `−∂(F, M)/∂(u, θ)` at the pose now, F the
lines' total force on the body and M their total moment about the reference point,
which moves with the body. The lever arms a_i turn with the body, which adds to the
rotational block a geometric term `Σ [R_i]× [a_i]×` (`[·]×` the cross-product matrix)
beside the lines' own `−Σ [a_i]× K_i [a_i]×`. So the rotational block is not
symmetric unless the lines' total moment about the reference point vanishes: its
antisymmetric part is `½ [M]×`. That is no error. The Hessian of the lines' energy in
(u, θ) is symmetric, and differs from this Jacobian by `½ [M]×`, the derivative of
the map from the rotation vector to the body's angular increments; the Jacobian is
what a body's equations of motion, written with moments, need, and what MoorPy's body
stiffness (`Body.getStiffnessA`) is. A current makes any of these stiffnesses
unsymmetric too, since drag has no potential.
"""

import warnings
from collections.abc import Sequence

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx
from jaxtyping import Array, ArrayLike, Float

from .. import _checks as checks
from .._equations import lagrangian as lag
from .._model.network import CableNetwork, check_held, network_conditions
from .._model.state import State
from .._programs import program
from .._sea.environment import Environment
from .._typing import RealScalarLike
from .solution import FORCE_TOLERANCE, MAX_STEPS, StaticSolution
from .solve import failure_message, nearby_equilibrium, solve_statics

# Below this squared angle (rad²) Rodrigues' coefficients are taken from their Taylor
# series, whose next terms (s³/5040) are far below rounding there; above it, the closed
# form, whose cancellation costs at most ε/s ≈ 2e-8 relative.
_SMALL_ANGLE_SQUARED = 1e-8


def stiffness(
    model: CableNetwork,
    env: Environment,
    nodes: int | Sequence[int] | None = None,
    *,
    t: RealScalarLike = 0.0,
    initial: State | None = None,
    max_steps: int = MAX_STEPS,
    force_tolerance: float = FORCE_TOLERANCE,
    throw: bool = True,
) -> Float[Array, "3 3"] | Float[Array, "nodes 3 nodes 3"]:
    """The stiffness (N/m) of the network's supports at its static equilibrium: how the
    force that each of `nodes` exerts on the network (its reaction,
    `StaticSolution.reactions`) changes as each of them moves.

    `K[i, a, j, b] = ∂R_ia/∂x_jb`, R_i the reaction of `nodes[i]` and x_j the position
    of `nodes[j]`, every other support held and the free nodes at equilibrium. The lines
    pull a support with `F = −R`, so `K = −∂F/∂x`, MoorPy's sign: positive on the
    diagonal where the lines pull a support back, as a spring. `K[i, :, i, :]` is a
    fairlead's own 3 × 3 stiffness; `K[i, :, j, :]` (i ≠ j) the cross terms, the change
    of one support's reaction as another moves.

    Computed by `jax.jacfwd` through [`jaxcable.solve_statics`][] (the module's notes):
    exact derivatives of the polyline's equilibrium, which converge to the continuous
    line's as its segments shrink, at second order. Where a line rests on the seabed
    the exact derivative is that of a line pinned at its last node on the bed, which
    converges to the wrong limit (4.5 % low in K_zz on a chain with 330 m on the bed):
    there each column is instead the slope of the reactions through seven equilibria,
    the support moved each way by up to twice the motion that lifts one node off the
    bed, combined so that the sawtooth of the nodes lifting off one by one cancels.
    Against the continuous line's closed form, the largest difference relative to the
    largest entry is 0.07 % to 1.7 % at 32 to 64 segments on that chain, not monotone
    in the segments, and 0.07 % on a three-chain spread at 32 segments a line
    (`pytest -m slow tests/test_stiffness.py`). It takes 36 more equilibria per
    support, found one after another from the equilibrium, and compiles their program.
    A support too close to the bed to be moved so far keeps the pinned columns, and a
    `UserWarning` names it.
    Traceable: under `jit`, `vmap` (over designs) and differentiable again, with
    respect to the model's and the water's float leaves (`jax.grad` of a stiffness with
    respect to a line's length, say).

    **Arguments:**

    - `model`, `env`: the network and the water.
    - `nodes`: the constrained nodes whose stiffness to take: one node index, for its
        3 × 3 stiffness, or a sequence of them, for their stiffness and cross terms;
        every constrained node by default.
    - `t`: the time (s) at which the supports are placed.
    - `initial`, `max_steps`, `force_tolerance`: as for [`jaxcable.solve_statics`][].
    - `throw`: raise if no equilibrium is found; otherwise the stiffness of a failed
        solve is NaN.

    **Returns:**

    The stiffness (N/m): shape `(3, 3)` for one node, `K[a, b] = ∂R_a/∂x_b`;
    `(nodes, 3, nodes, 3)` for a sequence (or `None`), whose
    `reshape(3 * len(nodes), 3 * len(nodes))` is the square matrix with each node's x,
    y and z in turn.

    **Raises:**

    `ValueError` naming `nodes` and the value if a node is not a constrained node or
    is given twice; as [`jaxcable.solve_statics`][] for a network it cannot solve.
    """
    chosen, single = _constrained_rows(model, nodes, "stiffness")
    _check_inputs(model, env)
    matrix, solution, pinned = stiffness_and_statics(model, env, t, initial, max_steps, force_tolerance)
    matrix = _finish(matrix, solution, throw, force_tolerance, max_steps)
    _warn_pinned(model, pinned, chosen, "stiffness")
    if single:
        (row,) = chosen
        return matrix[row, :, row, :]
    if chosen == tuple(range(model.constrained_nodes.size)):
        return matrix
    rows = np.asarray(chosen)
    return matrix[rows][:, :, rows]


def body_stiffness(
    model: CableNetwork,
    env: Environment,
    nodes: Sequence[int],
    reference: Float[ArrayLike, "3"],
    *,
    t: RealScalarLike = 0.0,
    initial: State | None = None,
    max_steps: int = MAX_STEPS,
    force_tolerance: float = FORCE_TOLERANCE,
    throw: bool = True,
) -> Float[Array, "6 6"]:
    """The 6 × 6 stiffness of a rigid body held by the lines that end at `nodes`, its
    attachment points: translations and small rotations about `reference`.

    The body's pose `(u, θ)` (a translation, m, and a rotation vector, rad) moves each
    attachment point x (its position now, at time `t`) to `r + u + R(θ)(x − r)`, R
    exact (Rodrigues), r the `reference` point. The lines' total force on the body is
    `F = −Σ R_i` and their moment about the reference point, which moves with the body,
    `M = Σ (x_i − r − u) × (−R_i)`, R_i the reactions. The stiffness is

        K = −∂(F, M)/∂(u, θ)    (6 × 6)

    at the pose now: translational block `K[:3, :3]` (N/m), the couplings `K[:3, 3:]`
    (N/rad) and `K[3:, :3]` (N m/m), rotational block `K[3:, 3:]` (N m/rad). Positive
    on the diagonal where the lines restore. The rotational block carries the geometric
    term of the arms turning with the body and is not symmetric unless the lines' total
    moment about `reference` vanishes (see the module's notes); the couplings are each
    other's transpose in still water.

    Several lines may end at one attachment node (a point shared by lines), and
    several attachment nodes may sit at one place. Every other constrained node (the
    anchors) is held. Traceable and differentiable as [`stiffness`][].

    **Arguments:**

    - `model`, `env`: the network and the water.
    - `nodes`: the constrained nodes fixed to the body.
    - `reference`: r (m), the point the rotations and moments are about, shape `(3,)`:
        the body's reference point or centre of gravity.
    - `t`, `initial`, `max_steps`, `force_tolerance`, `throw`: as for [`stiffness`][].

    **Returns:**

    K, shape `(6, 6)`, rows `(F_x, F_y, F_z, M_x, M_y, M_z)` and columns
    `(u_x, u_y, u_z, θ_x, θ_y, θ_z)`, negated.

    **Raises:**

    `ValueError` naming the argument and the value for a node that is not constrained
    or given twice, no nodes, or a `reference` that is not a finite 3-vector; as
    [`jaxcable.solve_statics`][] for a network it cannot solve.
    """
    if isinstance(nodes, (int, np.integer)):
        raise ValueError(f"body_stiffness: nodes must be a sequence of constrained nodes, got {nodes!r}")
    chosen, _ = _constrained_rows(model, nodes, "body_stiffness")
    reference = checks.float_array("body_stiffness: reference", reference)
    if reference.shape != (3,):
        raise ValueError(f"body_stiffness: reference must be a 3-vector (m), got shape {reference.shape}")
    _check_inputs(model, env)
    matrix, solution, pinned = stiffness_and_statics(model, env, t, initial, max_steps, force_tolerance)
    matrix = _finish(matrix, solution, throw, force_tolerance, max_steps)
    _warn_pinned(model, pinned, chosen, "body_stiffness")
    return _rigid_body(model, t, matrix, solution.reactions, chosen, reference)


def _warn_pinned(model: CableNetwork, pinned, rows: tuple[int, ...], caller: str) -> None:
    """Warn where a support among `rows` kept the pinned derivative on the seabed
    (`_across_touchdown`), where `pinned` is concrete."""
    if checks.traced(pinned):
        return
    close = [int(model.constrained_nodes[row]) for row in rows if bool(pinned[row])]
    if close:
        warnings.warn(
            f"{caller}: nodes {close} are too close to the seabed to be moved across the touchdown of the lines on "
            "it, so their columns are the exact derivative of the segmented line, pinned at its last node on the "
            "bed, which can be several per cent off the continuous line's (4.5 % in K_zz on a chain with 330 m on "
            "the bed). More segments make the move needed shorter.",
            stacklevel=3,
        )


def _constrained_rows(model: CableNetwork, nodes, caller: str) -> tuple[tuple[int, ...], bool]:
    """The rows of `nodes` among the model's constrained nodes (static), and whether one
    node was given alone."""
    constrained = np.asarray(model.constrained_nodes)
    single = isinstance(nodes, (int, np.integer))
    if nodes is None:
        given = constrained.tolist()
    elif single:
        given = [int(nodes)]
    else:
        given = [int(k) for k in nodes]
        if not given:
            raise ValueError(f"{caller}: nodes must name at least one constrained node, got {nodes!r}")
    for k in given:
        if k not in constrained:
            raise ValueError(
                f"{caller}: nodes has node {k}, which is not a constrained node; the constrained nodes are "
                f"{constrained.tolist()}"
            )
    if len(set(given)) < len(given):
        raise ValueError(f"{caller}: nodes names a node twice: {given}")
    return tuple(int(np.searchsorted(constrained, k)) for k in given), single


def _check_inputs(model: CableNetwork, env: Environment) -> None:
    """The checks `solve_statics` makes of concrete inputs, made here where the inputs
    are concrete: inside the derivative below they are traced, and would be checked only
    as the program runs."""
    check_held(model)
    checks.enforce(network_conditions(model, env))


def _finish(matrix, solution: StaticSolution, throw: bool, force_tolerance: float, max_steps: int):
    """`matrix`, raised, saying why, with `throw` where the statics failed."""
    failed = solution.result != optx.RESULTS.successful
    if not throw:
        return matrix
    if checks.traced(failed):
        message = (
            "stiffness: solve_statics found no equilibrium, so the stiffness is undefined. Call it outside jit, "
            "or solve_statics with throw=False, to see why"
        )
    else:
        message = failure_message(solution, force_tolerance, max_steps) if bool(failed) else ""
    return checks.raise_if(matrix, failed, message)


def _equilibrium_moved(model, env, offsets, t, initial, max_steps, force_tolerance) -> StaticSolution:
    """The equilibrium with the constrained nodes moved by `offsets` (m), shape
    `(constrained, 3)`, from their reference positions."""
    return solve_statics(
        _supports_moved(model, offsets),
        env,
        t=t,
        initial=initial,
        max_steps=max_steps,
        force_tolerance=force_tolerance,
        throw=False,
    )


def _supports_moved(model: CableNetwork, offsets) -> CableNetwork:
    """The network with its constrained nodes moved by `offsets` (m), shape
    `(constrained, 3)`."""
    nodes = model.constrained_nodes
    return eqx.tree_at(lambda m: m.node_positions, model, model.node_positions.at[nodes].add(offsets))


# Where each support is moved, in its column's amplitude, to fit the slope of the
# reactions across the touchdown (`_across_touchdown`).
_TOUCHDOWN_OFFSETS = np.array([-2.0, -1.0, -0.5, 0.5, 1.0, 2.0])
# Richardson's combination of the least-squares slopes through (0, ±1/2, ±1) and
# (0, ±1, ±2), (4 s₁ − s₂)/3: exact for a cubic, and blind to any function periodic
# over an offset of 1 (an antisymmetric stencil on multiples of 1/2).
_TOUCHDOWN_WEIGHTS = np.array([0.2, -1.5, -0.8, 0.8, 1.5, -0.2]) / 3
# How often the amplitude is re-estimated from the bed load's slope (`_across_touchdown`).
_TOUCHDOWN_ROUNDS = 2


@program
def stiffness_and_statics(model, env, t, initial, max_steps, force_tolerance):
    """`(K, solution, pinned)`: the stiffness of every constrained node, shape
    `(constrained, 3, constrained, 3)` (NaN where no equilibrium was found), the
    equilibrium, and which supports above the bed kept the pinned derivative where lines
    rest on it, shape `(constrained,)` (`_across_touchdown`).

    Every support's columns, whichever a caller asks for: one program per network
    serves any choice of nodes and a body's stiffness, and a column costs one linear
    solve with factors the equilibrium has (a few per cent of the solve). Where a node
    rests on the seabed, the columns are instead the reactions' slope across the
    touchdown (`_across_touchdown`)."""
    matrix, heights, solution = pinned_stiffness(model, env, t, initial, max_steps, force_tolerance)
    pinned = jnp.zeros(model.constrained_nodes.size, bool)
    if env.seabed is not None:
        touching = solution.state.positions[:, 2] < -env.depth
        matrix, pinned = jax.lax.cond(
            jnp.any(touching),
            lambda: _across_touchdown(model, env, t, solution, touching, matrix, heights, max_steps, force_tolerance),
            lambda: (matrix, pinned),
        )
    return jnp.where(solution.result == optx.RESULTS.successful, matrix, jnp.nan), solution, pinned


def pinned_stiffness(model, env, t, initial, max_steps, force_tolerance):
    """`(K, heights, solution)`: K as `stiffness_and_statics` gives it, the exact
    derivative of the polyline's equilibrium by `jax.jacfwd` through the statics (a
    line on the seabed pinned at its last node there: `_across_touchdown`), the nodes'
    heights' derivatives in the supports' positions, shape `(nodes, constrained, 3)`,
    and the equilibrium."""

    def outputs(offsets):
        solution = _equilibrium_moved(model, env, offsets, t, initial, max_steps, force_tolerance)
        return (solution.reactions, solution.state.positions[:, 2]), solution

    (matrix, heights), solution = jax.jacfwd(outputs, has_aux=True)(jnp.zeros((model.constrained_nodes.size, 3)))
    return matrix, heights, solution


def _across_touchdown(model, env, t, solution: StaticSolution, touching, exact, heights, max_steps, force_tolerance):
    """The stiffness where lines rest on the seabed: each column the slope of the
    reactions through the equilibrium and six more, the support moved by ±a/2, ±a and
    ±2a along the column's axis (`_TOUCHDOWN_OFFSETS`), each started from `solution`,
    with a the motion over which the bed sheds one resting node's load (at most a
    segment). A support that cannot move so far without going below the bed (an anchor
    on it) keeps its `exact` columns; also returned, which of those are above the bed
    (where the exact columns are the pinned line's, which `stiffness` warns of).

    The exact derivative of the polyline's equilibrium is that of a line pinned at its
    last node on the bed: for an infinitesimal motion that node stays on the penalty
    bed, where the continuous line lifts off (or lays down) along it. Pinned, the
    stiffness converges to the wrong limit (4.5 % low in K_zz at 32 to 128 segments on
    `validation/stiffness.py`'s line with 330 m on the bed, and far off where the
    touchdown node is nearly free: 46 % at 48). As the support moves, the node at the
    touchdown is pressed into the bed less (or more) until it lifts off and the next
    takes its place: the reactions follow the continuous line's plus a sawtooth whose
    period is the motion that lifts one node, a. Samples at multiples of a/2 combined
    by an antisymmetric stencil cancel any periodic part, and Richardson's combination
    (`_TOUCHDOWN_WEIGHTS`) cancels the continuous line's curvature and its cubic term.
    The period is the resting node's load over the rate at which the bed's whole load
    changes: first that rate from the pinned derivative, then from the slope of the
    bed's load across the touchdown (`_TOUCHDOWN_ROUNDS`), as the sawtooth puts the
    pinned rate off by up to a fifth. The period changes with the support's position
    (by a third over one period along the span at 36 segments), which is what is
    left: against the continuous line's closed form (`tests/test_stiffness.py`), the
    largest difference relative to the largest entry is 0.07 % to 1.7 % at 32 to 64
    segments on the line, and 0.07 % at 32 on a three-line spread."""
    length = jnp.broadcast_to(model.segment_length, (model.n_segments,))
    ends = model.segment_nodes
    on_bed = touching[ends[:, 0]] | touching[ends[:, 1]]
    longest = jnp.max(jnp.where(on_bed, length, 0.0))
    area = lag.contact_area(model)

    def bed_loads(positions):  # the bed's load on each node over its stiffness, penetration × area (m³)
        return jnp.maximum(-env.depth - positions[:, 2], 0.0) * area

    node = jnp.max(bed_loads(solution.state.positions))  # a resting node's
    count = model.constrained_nodes.size
    held = solution.state.positions[model.constrained_nodes, 2]
    start = State(solution.state.positions, solution.state.velocities)
    node_index, axis, step = (
        a.ravel() for a in np.meshgrid(np.arange(count), np.arange(3), _TOUCHDOWN_OFFSETS, indexing="ij")
    )
    unit = np.zeros((node_index.size, count, 3))
    unit[np.arange(node_index.size), node_index, axis] = step

    def moved(offsets):
        moved = nearby_equilibrium(_supports_moved(model, offsets), env, start, t, max_steps, force_tolerance)
        return moved.reactions, jnp.sum(bed_loads(moved.state.positions))

    def slopes(shed):
        """The reactions' and the bed load's slopes, with each column's amplitude the
        motion over which the bed sheds one resting node's load at the rate `shed`."""
        amplitude = node / jnp.maximum(shed, node / longest)  # at most a segment
        movable = held - jnp.max(amplitude, axis=1) * np.max(_TOUCHDOWN_OFFSETS) >= -env.depth
        amplitude = jnp.where(movable[:, None], amplitude, 0.0)
        pulls, loads = jax.lax.map(moved, jnp.asarray(unit) * amplitude[node_index, axis][:, None, None])
        pulls = pulls.reshape(count, 3, _TOUCHDOWN_OFFSETS.size, count, 3)
        loads = loads.reshape(count, 3, _TOUCHDOWN_OFFSETS.size)
        scale = jnp.where(amplitude > 0, amplitude, 1.0)  # (constrained, 3)
        pulls = pulls - solution.reactions[None, None, None]
        loads = loads - jnp.sum(bed_loads(solution.state.positions))
        slope = jnp.einsum("s,jbsia->iajb", _TOUCHDOWN_WEIGHTS, pulls) / scale[None, None]
        shed = jnp.abs(jnp.einsum("s,jbs->jb", _TOUCHDOWN_WEIGHTS, loads)) / scale
        return movable, slope, shed

    # The first estimate from the pinned derivative, whose rate is off by as much as
    # its stiffness; the next from the slope across the touchdown. A loop, so that the
    # equilibria's program is traced once.
    shed = jnp.abs(jnp.einsum("n,nja->ja", jnp.where(touching, area, 0.0), heights))
    start_carry = (jnp.zeros(count, bool), exact, shed)
    movable, slope, _ = jax.lax.fori_loop(0, _TOUCHDOWN_ROUNDS, lambda _, carry: slopes(carry[2]), start_carry)
    return jnp.where(movable[None, None, :, None], slope, exact), ~movable & (held > -env.depth)


@eqx.filter_jit
def _rigid_body(model, t, matrix, reactions, rows, reference):
    """`body_stiffness`'s 6 × 6 from the supports' stiffness `matrix` and `reactions`
    at the equilibrium: `jax.jacfwd` of the lines' force and moment on the body as its
    pose moves the attachment points (`rows` of the constrained nodes), the reactions
    taken to first order in the pose, `R + K δx`, whose derivative is theirs."""
    held, _, _ = lag.constrained_motion(model, t)
    rows = np.asarray(rows)
    arms = held[rows] - reference
    attached = matrix[rows][:, :, rows]

    def loads(pose):
        turned = arms @ _rotation_matrix(pose[3:]).T
        shift = pose[:3] + turned - arms
        pull = -(reactions[rows] + jnp.einsum("iajb,jb->ia", attached, shift))  # the lines' force on each point
        return jnp.concatenate([jnp.sum(pull, axis=0), jnp.sum(jnp.cross(turned, pull), axis=0)])

    return -jax.jacfwd(loads)(jnp.zeros(6))


def _rotation_matrix(rotation: Float[ArrayLike, "3"]) -> Float[Array, "3 3"]:
    """The rotation by the rotation vector θ (rad): `I + a [θ]× + b [θ]×²`, with
    `a = sin|θ|/|θ|` and `b = (1 − cos|θ|)/|θ|²` (Rodrigues), differentiable at θ = 0,
    where `∂(R x)/∂θ = −[x]×`."""
    theta = jnp.asarray(rotation, dtype=float)
    squared = theta @ theta
    small = squared < _SMALL_ANGLE_SQUARED
    safe = jnp.where(small, 1.0, squared)  # double `where`: no 0/0 in the unused branch's derivative
    angle = jnp.sqrt(safe)
    a = jnp.where(small, 1 - squared / 6 + squared**2 / 120, jnp.sin(angle) / angle)
    b = jnp.where(small, 0.5 - squared / 24 + squared**2 / 720, (1 - jnp.cos(angle)) / safe)
    cross = _cross_matrix(theta)
    return jnp.eye(3) + a * cross + b * cross @ cross


def _cross_matrix(v: Array) -> Float[Array, "3 3"]:
    """`[v]×`, with `[v]× x = v × x`."""
    zero = jnp.zeros_like(v[0])
    return jnp.array([[zero, -v[2], v[1]], [v[2], zero, -v[0]], [-v[1], v[0], zero]])
