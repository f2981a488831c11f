"""The equations of motion, from the Lagrangian of the polyline (Bezverkhyy & Korniienko).

Between nodes i and j a segment is `R(ξ) = x_i (1 − ξ) + x_j ξ`, `ξ ∈ [0, 1]` (eq. 7).

- Kinetic energy `K = ½ Σ L ∫₀¹ m |Ṙ|² dξ`. Integrated exactly, it gives the consistent
  mass matrix (shape-function weights 1/3 and 1/6); integrated at the two ends
  (trapezoid rule), the lumped one.
- Added mass is Morison's inertia force, `−ρ F (C_a (I − ττᵀ) + C_aτ ττᵀ) R̈`, entered by
  its virtual work as Bezverkhyy & Korniienko and MoorDyn do, and moved to the left-hand
  side: the mass
  matrix M(x) carries `μ = m I + ρ F (...)` per length. When C_a ≠ C_aτ, M depends on the
  segments' directions and `½ vᵀMv + Π` is not conserved: it changes at the rate
  `½ vᵀ Ṁ v` (tested). With isotropic added mass it is conserved exactly.
- Potential energy `Π = Σ L ∫₀^ε T de + Σ EI/ℓ̄ (1 − cos θ) + Σ (m − ρF) g L z̄ + Σ (M g z + ρ g V Φ(z)) − Σ F·x`
  (bodies' constant forces F; the bending term, at each node inside a line whose
  line has EI, is `jaxcable._equations.bending`'s), plus the seabed's penalty energy `Σ ½ k δ² A` where
  nodes press into it. Φ = −z for a submerged body; a body with a height that pierces
  the surface has the buoyancy of its submerged part only. The conservative forces
  are `−∂Π/∂x`, written out term by term and tested against `jax.grad` of Π. With
  `Environment.free_surface`, buoyancy, drag, fluid inertia and added mass act on the
  part of each segment below z = 0 only.
- Non-conservative loads enter by their virtual work `Q = Σ ∫ f · ∂R/∂x |∂R/∂l| dl`:
  drag on the velocity relative to the water, and (with waves) Morison's inertia force
  from the water's acceleration, both by Gauss–Legendre quadrature along each segment;
  the viscous part of the tension; the seabed's damping and friction; and the same
  loads on point bodies.

Prescribed nodes are eliminated (Bezverkhyy & Korniienko, eq. 8): with the free and constrained blocks
of the mass matrix, `M_ff a_f = Q_f − M_fc a_c`. What remains at the constrained nodes,
`M a − Q`, is the reaction of their supports.

Everything here is a pure function of `(model, environment, t, positions, velocities)`.
"""

import jax
import jax.numpy as jnp
import lineax as lx
import numpy as np
from jaxtyping import Array, ArrayLike, Float

from .. import _checks as checks
from .._model.indexing import sum_into, take
from .._model.network import CableNetwork
from .._sea.environment import Environment
from . import bending as bending
from .hydro import body_drag, dot, gauss_legendre, line_drag, line_inertia, matvec, safe_norm, submerged_interval

# ∫₀¹ N_a N_b dξ for the shape functions N = (1 − ξ, ξ), exact and at the ends.
_SHAPE_WEIGHTS = {
    "consistent": np.array([[1 / 3, 1 / 6], [1 / 6, 1 / 3]]),
    "lumped": np.array([[1 / 2, 0.0], [0.0, 1 / 2]]),
}

# The vertical unit vector, component-major (a column that broadcasts over nodes).
_UP = np.array([0.0, 0.0, 1.0])[:, None]


# The most segments that may meet at a free node for the lumped solve's closed form
# (`_lumped_solve`): two, as along a line; a junction takes the 3 × 3 blocks.
_CLOSED_FORM_SEGMENTS = 2

# Conjugate-gradient iterations for the consistent solve. The condition number is at most
# 3, so the error falls below 2 (√3 − 1)^k / (√3 + 1)^k ≈ 1e-17 after 30 iterations. A fixed
# count, not a tolerance: lineax's tolerances are absolute and per element, and in reverse
# mode they would apply to the cotangent, making gradients depend on the loss's scale.
_CG_ITERATIONS = 30

# Internally every vector array is component-major, shape `(3, nodes)` or `(3,
# segments, ...)`, and every 3 × 3 block `(3, 3, nodes)`: XLA's CPU backend vectorises
# along the last axis, so the long axis goes there (see `_hydro.dot`). The functions
# without a leading underscore take and return the public layout, `(nodes, 3)`; the
# transposes at that boundary cancel where one calls another.


def _cm(vectors: ArrayLike) -> Array:
    """`(..., 3)` → component-major `(3, ...)`; a single 3-vector becomes a column."""
    vectors = jnp.asarray(vectors)
    return vectors[:, None] if vectors.ndim == 1 else jnp.moveaxis(vectors, -1, 0)


def _public(vectors: Array) -> Array:
    """Component-major `(3, ...)` → the public layout `(..., 3)`."""
    return jnp.moveaxis(vectors, 0, -1)


def _scatter(model: CableNetwork, at_start: Array, at_end: Array) -> Float[Array, "*leading nodes"]:
    """Sum per-segment arrays (segments on the last axis) onto the segments' end nodes."""
    return sum_into(jnp.concatenate([at_start, at_end], axis=-1), model.topology.node_sums)


def _ends(model: CableNetwork, per_node: Array) -> tuple[Array, Array]:
    """A per-node array (nodes on the last axis) at each segment's start and end node."""
    return take(per_node, model.segment_nodes[:, 0]), take(per_node, model.segment_nodes[:, 1])


def _place(model: CableNetwork, free: Array, constrained: Array) -> Array:
    """The per-node array (nodes on the last axis) whose free nodes hold `free` and
    constrained nodes `constrained`."""
    return take(jnp.concatenate([free, constrained], axis=-1), model.topology.placement)


def _constrained_motion(model: CableNetwork, t) -> tuple[Array, Array, Array]:
    reference = take(_cm(model.node_positions), model.constrained_nodes)
    if not model.motions:
        return reference, reference * 0.0, reference * 0.0
    r, v, a = (jnp.stack(k, axis=-1) for k in zip(*(m.kinematics(t) for m in model.motions)))
    return reference + r, v, a


def constrained_motion(model: CableNetwork, t) -> tuple[Array, Array, Array]:
    """Positions (m), velocities (m/s) and accelerations (m/s²) of the constrained
    nodes at time `t`, each of shape `(constrained, 3)`."""
    r, v, a = _constrained_motion(model, t)
    return _public(r), _public(v), _public(a)


def _full_state(model: CableNetwork, t, free_positions, free_velocities):
    r, v, _ = _constrained_motion(model, t)
    return _place(model, free_positions, r), _place(model, free_velocities, v)


def full_state(model: CableNetwork, t, free_positions, free_velocities):
    """Node positions and velocities, shape `(nodes, 3)`, from the free unknowns, shape
    `(free, 3)`."""
    positions, velocities = _full_state(model, t, _cm(free_positions), _cm(free_velocities))
    return _public(positions), _public(velocities)


def _geometry(model: CableNetwork, positions):
    start, end = _ends(model, positions)
    chord = end - start
    stretched = safe_norm(chord)
    return stretched, chord / stretched, stretched / model.segment_length - 1.0


def segment_geometry(model: CableNetwork, positions):
    """Stretched length S (m), unit tangent τ (shape `(segments, 3)`) and strain
    ε = S/L − 1 of each segment."""
    stretched, tangent, strain = _geometry(model, _cm(positions))
    return stretched, _public(tangent), strain


def _strain_rate(model: CableNetwork, tangent, velocities):
    start, end = _ends(model, velocities)
    return dot(tangent, end - start) / model.segment_length


def strain_rate(model: CableNetwork, positions, velocities) -> Float[Array, " segments"]:
    """ε̇ = τ · (v_j − v_i) / L (1/s)."""
    _, tangent, _ = _geometry(model, _cm(positions))
    return _strain_rate(model, tangent, _cm(velocities))


def _tension(model: CableNetwork, positions, velocities):
    _, tangent, strain = _geometry(model, positions)
    return model.line.tension_law.tension(strain, _strain_rate(model, tangent, velocities))


def tension(model: CableNetwork, positions, velocities) -> Float[Array, " segments"]:
    """Segment tension T(ε, ε̇) (N)."""
    return _tension(model, _cm(positions), _cm(velocities))


def _potential_energy(model: CableNetwork, env: Environment, positions) -> Float[Array, ""]:
    line, body = model.line, model.body
    _, _, strain = _geometry(model, positions)
    elastic = jnp.sum(model.segment_length * line.tension_law.elastic_energy_density(strain))
    z = positions[2]
    z_start, z_end = _ends(model, z)
    mid_depth = 0.5 * (z_start + z_end)
    weight = line.mass_per_length * env.gravity * model.segment_length
    displaced = env.water_density * line.area * env.gravity * model.segment_length
    # Buoyancy's potential is −ρ g F L ∫ z dξ over the submerged part: with the surface,
    # the part ξ ∈ [a, b], where z is linear, so the integral is (b − a) z((a + b)/2).
    if env.free_surface:
        a, b = submerged_interval(z_start, z_end)
        submerged_depth = (b - a) * (z_start + (z_end - z_start) * 0.5 * (a + b))
    else:
        submerged_depth = mid_depth
    energy = elastic + jnp.sum(weight * mid_depth - displaced * submerged_depth)
    if body is not None:
        body_buoyancy = env.water_density * body.volume * env.gravity
        energy = (
            energy
            + jnp.sum(body.mass * env.gravity * z + body_buoyancy * column_buoyancy_potential(z, body.height))
            - jnp.sum(_cm(body.force) * positions)
        )
    if env.seabed is not None and env.depth is not None:  # a seabed comes with a depth (Environment checks)
        penetration = jnp.maximum(-env.depth - z, 0.0)
        energy = energy + 0.5 * env.seabed.stiffness * jnp.sum(contact_area(model) * penetration**2)
    if bending.has_bending(model):
        energy = energy + bending.bending_energy(model, *_geometry(model, positions)[:2])
    return energy


def potential_energy(model: CableNetwork, env: Environment, positions) -> Float[Array, ""]:
    """Π (J): elastic energy (axial, and bending where the line has EI), gravity minus
    buoyancy, and the potential −F·x of the bodies' constant forces, at node
    `positions` (m), shape `(nodes, 3)`."""
    return _potential_energy(model, env, _cm(positions))


def contact_area(model: CableNetwork) -> Float[Array, " nodes"]:
    """Each node's seabed contact area (m²): half the projected area d L of each segment
    that meets there, as MoorDyn's `kBot` and `cBot` refer to."""
    half = 0.5 * model.line.diameter * model.segment_length
    return _scatter(model, jnp.broadcast_to(half, (model.n_segments,)), jnp.broadcast_to(half, (model.n_segments,)))


def _submerged_fraction(model: CableNetwork, env: Environment, positions) -> Float[Array, "*segments"]:
    """The fraction of each segment below z = 0 with the free surface; 1 without."""
    if not env.free_surface:
        return jnp.ones(())
    a, b = submerged_interval(*_ends(model, positions[2]))
    return b - a


def _displaced_mass(model: CableNetwork, env: Environment, positions) -> Float[Array, "*segments"]:
    """ρ F (kg/m) per unit length of each segment; with the free surface, times the
    submerged fraction, so that added mass is spread along the segment as the rest."""
    return env.water_density * model.line.area * _submerged_fraction(model, env, positions)


def _station_directions(model: CableNetwork, positions) -> Float[Array, "3 stations"]:
    """The unit direction of each node station (`Topology`'s), for
    `hydrodynamics="nodes"`: MoorDyn's `q`, from one neighbour to the other inside a
    line, along the segment at a line's end."""
    chord = model.topology.station_chord
    d = take(positions, chord[1]) - take(positions, chord[0])
    return d / jnp.sqrt(dot(d, d))


def _to_stations(model: CableNetwork, per_segment) -> Float[Array, " stations"]:
    """Half of each segment's `per_segment` to each of its ends' node stations, summed."""
    half = jnp.broadcast_to(0.5 * per_segment, (model.n_segments,))
    return sum_into(jnp.concatenate([half, half]), model.topology.station_sums)


def _mass_per_length(model: CableNetwork, env: Environment, positions, tangent) -> Float[Array, "3 3 segments"]:
    line = model.line
    axial = tangent[:, None] * tangent[None, :]
    added = _displaced_mass(model, env, positions)
    eye = np.eye(3)[:, :, None]
    return (
        line.mass_per_length * eye
        + added * line.normal_added_mass * (eye - axial)
        + added * line.tangential_added_mass * axial
    )


def mass_per_length(model: CableNetwork, env: Environment, positions) -> Float[Array, "segments 3 3"]:
    """μ = m I + ρ F (C_a (I − ττᵀ) + C_aτ ττᵀ) (kg/m), each segment's mass per unit
    unstretched length, the fluid's added mass included."""
    positions = _cm(positions)
    _, tangent, _ = _geometry(model, positions)
    return jnp.moveaxis(_mass_per_length(model, env, positions, tangent), -1, 0)


def column_submerged_fraction(z: Array | np.ndarray | float, height: Array | np.ndarray | float) -> Array:
    """The fraction below z = 0 of a vertical column of `height` h (m) centred at `z`
    (m): 1 for a point body (h = 0) wherever it is."""
    safe = jnp.where(height > 0, height, 1.0)
    return jnp.where(height > 0, jnp.clip((0.5 * safe - z) / safe, 0.0, 1.0), 1.0)


def column_buoyancy_potential(z: Array | np.ndarray | float, height: Array | np.ndarray | float) -> Array:
    """Φ(z) (m) with Φ' = −(submerged fraction): a column's buoyancy potential is
    ρ g V Φ(z). Φ = −z while the column is under water, is quadratic while it pierces
    the surface, and 0 once it is clear of it; a point body's Φ is −z everywhere."""
    safe = jnp.where(height > 0, height, 1.0)
    low, high = -0.5 * safe, 0.5 * safe
    w = jnp.clip(z, low, high)
    piercing = (high * w - 0.5 * w**2 - high * low + 0.5 * low**2) / safe
    return jnp.where(height > 0, -jnp.minimum(z, low) - piercing, -z)


def _with_body_mass(model: CableNetwork, env: Environment, positions, x, times: ArrayLike = 1.0):
    """`x + m_b times` (kg, or kg·m/s² where `times` is an acceleration): each node's
    body mass with its added mass, `m_b`, shape `(nodes,)`, times `times`; `x` where the
    model has no bodies (`body` None, [`jaxcable._model.network.without_absent_bodies`][])."""
    body = model.body
    if body is None:
        return x
    wet = column_submerged_fraction(positions[2], body.height)
    return x + (body.mass + body.added_mass * env.water_density * body.volume * wet) * times


def _inertial_forces(model: CableNetwork, env: Environment, positions, accelerations) -> Float[Array, "3 nodes"]:
    _, tangent, _ = _geometry(model, positions)
    if model.hydrodynamics == "nodes":
        isotropic, axial, directions, plan = _lumped_terms(model, env, positions, tangent)
        along = axial * dot(directions, take(accelerations, model.topology.station_node)) * directions
        return isotropic * accelerations + sum_into(along, plan)
    weights = _SHAPE_WEIGHTS[model.mass_matrix]
    mu = _mass_per_length(model, env, positions, tangent) * model.segment_length
    start, end = _ends(model, accelerations)
    at_start, at_end = matvec(mu, start), matvec(mu, end)
    lines = _scatter(
        model, weights[0, 0] * at_start + weights[0, 1] * at_end, weights[1, 0] * at_start + weights[1, 1] * at_end
    )
    return _with_body_mass(model, env, positions, lines, accelerations)


def inertial_forces(model: CableNetwork, env: Environment, positions, accelerations) -> Float[Array, "nodes 3"]:
    """`M(x) a` (N): the generalised inertia of node accelerations `a` (m/s²), shape
    `(nodes, 3)`."""
    return _public(_inertial_forces(model, env, _cm(positions), _cm(accelerations)))


def _lumped_blocks(model: CableNetwork, env: Environment, positions, tangent) -> Float[Array, "3 3 nodes"]:
    eye = np.eye(3)[:, :, None]
    if model.hydrodynamics == "nodes":
        isotropic, axial, directions, plan = _lumped_terms(model, env, positions, tangent)
        return isotropic * eye + sum_into(axial * directions[:, None] * directions[None, :], plan)
    half = 0.5 * _mass_per_length(model, env, positions, tangent) * model.segment_length
    return _with_body_mass(model, env, positions, _scatter(model, half, half), eye)


def _lumped_terms(model: CableNetwork, env: Environment, positions, tangent) -> tuple[Array, Array, Array, np.ndarray]:
    """The lumped blocks as `a I + Σ_k b_k τ_k τ_kᵀ`: `(a, b, τ, plan)`, the isotropic
    mass `a` (kg) per node, shape `(nodes,)`, and the axial excess `b` (kg) along each
    direction `τ` (shape `(3, k)`), summed onto nodes by `plan`
    (`jaxcable._model.indexing.sum_into`), from `μ = (m + ρ F C_a) I + ρ F (C_aτ − C_a) ττᵀ`
    per length. The directions are the segments' (`b = ½ L ρ F (C_aτ − C_a)`, both
    ends), or with `hydrodynamics="nodes"` the node stations' (each station's share of
    its segments). `b` is negative where C_aτ < C_a (MoorDyn's default), and zero for
    isotropic added mass."""
    line = model.line
    added = _displaced_mass(model, env, positions)
    isotropic = model.segment_length * (line.mass_per_length + added * line.normal_added_mass)
    axial = model.segment_length * added * (line.tangential_added_mass - line.normal_added_mass)
    isotropic = _with_body_mass(model, env, positions, _scatter(model, 0.5 * isotropic, 0.5 * isotropic))
    if model.hydrodynamics == "nodes":
        return (
            isotropic,
            _to_stations(model, axial),
            _station_directions(model, positions),
            model.topology.node_stations,
        )
    # The plan indexes segments' starts, then ends: both ends take their segment's term.
    plan = np.where(model.topology.node_sums < 0, -1, model.topology.node_sums % model.n_segments)
    return isotropic, 0.5 * axial, tangent, plan


def _lumped_solve(model: CableNetwork, env: Environment, positions, tangent, rhs) -> Float[Array, "3 free"]:
    """`M_ff⁻¹ rhs` for the lumped matrix, one block per free node, `rhs` of shape
    `(3, free)`.

    Where no free node joins more than two directions (segments, or node stations with
    `hydrodynamics="nodes"`: a line, or a network without junctions among its free
    nodes; the topology is static, so this is known when tracing), each block is
    `a I + b₁ τ₁τ₁ᵀ + b₂ τ₂τ₂ᵀ`, and Woodbury's identity with
    the 2 × 2 capacitance matrix solves it in closed form, about a quarter of the
    arithmetic of forming the 3 × 3 blocks and Cramer's rule (`benchmarks/profile_evaluation.py`
    times both):

        (a I + U B Uᵀ)⁻¹ r = (r − U B (a I₂ + UᵀU B)⁻¹ Uᵀ r) / a,   U = [τ₁ τ₂],

    with UᵀU = [[1, c], [c, 1]], c = τ₁ · τ₂. It is exact for any B (B = 0 for isotropic
    added mass), and the 2 × 2 matrix is nonsingular wherever the block is positive
    definite. A free node at a junction takes the 3 × 3 blocks and Cramer's rule.
    """
    free = model.free_nodes
    isotropic, axial, directions, plan = _lumped_terms(model, env, positions, tangent)
    plan = plan[free]
    if plan.shape[1] > _CLOSED_FORM_SEGMENTS:
        blocks = take(_lumped_blocks(model, env, positions, tangent), free)
        return _solve_3x3(blocks, rhs)
    a = take(isotropic, free)
    t1, b1 = take(directions, plan[:, 0]), take(axial, plan[:, 0])
    if plan.shape[1] == 1:
        # One direction per node (node stations along lines): Sherman–Morrison.
        return (rhs - b1 * dot(t1, rhs) / (a + b1) * t1) / a
    # −1 where a node has fewer than two directions, whose term `take` makes zero.
    t2, b2 = take(directions, plan[:, 1]), take(axial, plan[:, 1])
    s1, s2, c = dot(t1, rhs), dot(t2, rhs), dot(t1, t2)
    d1, d2 = a + b1, a + b2
    scale = 1.0 / (d1 * d2 - c * c * b1 * b2)
    w1 = b1 * (d2 * s1 - c * b2 * s2) * scale
    w2 = b2 * (d1 * s2 - c * b1 * s1) * scale
    return (rhs - w1 * t1 - w2 * t2) / a


def lumped_blocks(model: CableNetwork, env: Environment, positions) -> Float[Array, "nodes 3 3"]:
    """The 3 × 3 blocks of the lumped mass matrix (kg), shape `(nodes, 3, 3)`, whichever
    matrix the model uses: they are also the consistent solve's preconditioner."""
    positions = _cm(positions)
    _, tangent, _ = _geometry(model, positions)
    return jnp.moveaxis(_lumped_blocks(model, env, positions, tangent), -1, 0)


def kinetic_energy(model: CableNetwork, env: Environment, positions, velocities) -> Float[Array, ""]:
    """½ vᵀ M(x) v (J): the kinetic energy of the line, bodies and added fluid mass.

    With the line's added mass anisotropic (C_a ≠ C_aτ), this plus `potential_energy` is
    not a conserved quantity even without drag; see the module docstring."""
    velocities = _cm(velocities)
    return 0.5 * jnp.sum(velocities * _inertial_forces(model, env, _cm(positions), velocities))


def _water(field, points: Array, t) -> Array:
    """An environment's field (`water_velocity`, `water_acceleration`), which speaks
    the public layout, at component-major `points`."""
    return _cm(field(_public(points), t))


def _nonconservative_forces(
    model: CableNetwork, env: Environment, t, positions, velocities, at_rest: bool = False
) -> Float[Array, "3 nodes"]:
    """With `at_rest` (the nodes' `velocities` zero), without the terms that are then
    zero: the viscous tension and the seabed's damping and friction."""
    body = model.body
    rho = env.water_density
    stretched, tangent, strain = _geometry(model, positions)
    if model.hydrodynamics == "nodes":
        drag_start = drag_end = jnp.zeros_like(tangent)
        forces = _nodal_hydrodynamic_forces(model, env, t, positions, velocities)
    else:
        drag_start, drag_end = _segment_hydrodynamic_forces(model, env, t, positions, velocities, stretched, tangent)
        forces = 0.0

    law = model.line.tension_law
    if law.damped and not at_rest:
        pull = law.viscous_tension(strain, _strain_rate(model, tangent, velocities)) * tangent
        drag_start, drag_end = drag_start + pull, drag_end - pull
    forces = forces + _scatter(model, drag_start, drag_end)

    if env.seabed is not None and not at_rest:
        forces = forces + _seabed_forces(model, env, positions, velocities)
    if body is None:
        return forces
    z = positions[2]
    wet = column_submerged_fraction(z, body.height)
    if env.waves:
        # A floating column is wet up to the wave's surface η, not to z = 0: its buoyancy
        # there is the waves' main heave force on a surface buoy (ρ g A η at the
        # waterline), which the Morison terms at its centre cannot give. The potential
        # holds the still-water part; the rest is added here. With the Morison
        # Froude–Krylov term on the wet volume this is, to first order, the wave
        # pressure on the column's bottom.
        still = wet
        wet = column_submerged_fraction(z - env.surface_elevation(positions[0], positions[1], t), body.height)
        forces = forces + rho * env.gravity * body.volume * (wet - still) * _UP
    coefficient = (0.5 * rho * body.drag_area + body.specific_drag * body.organism_mass * env.gravity) * wet
    forces = forces + body_drag(_water(env.water_velocity, positions, t) - velocities, coefficient)
    if env.has_fluid_acceleration:
        forces = forces + rho * body.volume * (1 + body.added_mass) * wet * _water(env.water_acceleration, positions, t)
    return forces


def _segment_hydrodynamic_forces(model: CableNetwork, env: Environment, t, positions, velocities, stretched, tangent):
    """Drag and Morison's inertia force on the lines by quadrature of their virtual
    work along each segment: what each segment's start and end take, `(3, segments)`
    each."""
    line, rho = model.line, env.water_density
    xi, w = gauss_legendre(model.drag_points)
    count, segments = xi.size, model.n_segments
    start, end = _ends(model, positions)
    start_velocity, end_velocity = _ends(model, velocities)
    # Quadrature over the submerged part [a, b] only, with the surface: the points and
    # weights of shape (points, segments), or (points, 1) without it.
    if env.free_surface:
        a, b = submerged_interval(start[2], end[2])
        points, weights = a + (b - a) * xi[:, None], (b - a) * w[:, None]
    else:
        points, weights = xi[:, None], w[:, None]

    # Every point of every segment in one row, point by point, `(3, points · segments)`:
    # the water's field is then evaluated once, not once a point, which made the
    # program larger by a copy of the waves' kinematics for each point (a net of buoys
    # in a wave: statics compiled in 19.7 s with three points, 11.7 s with one). Not a
    # trailing axis of points, which is slow on XLA's CPU backend (see `_hydro.dot`).
    def at_points(at_start, at_end):
        return (at_start[:, None, :] * (1 - points) + at_end[:, None, :] * points).reshape(3, count * segments)

    def repeated(per_segment):
        return jnp.tile(jnp.broadcast_to(per_segment, (segments,)), count)

    where = at_points(start, end)
    relative = _water(env.water_velocity, where, t) - at_points(start_velocity, end_velocity)
    along = jnp.tile(tangent, (1, count))
    normal = 0.5 * rho * line.normal_drag * line.diameter  # C_n
    tangential = 0.5 * rho * line.tangential_drag * jnp.pi * line.diameter  # C_τ
    f = line_drag(relative, along, repeated(normal), repeated(tangential))
    if env.has_fluid_acceleration:
        # Morison's inertia on the water's acceleration: Froude–Krylov (the 1) plus
        # added mass, normal and tangential to the segment, as MoorDyn writes it.
        displaced = rho * line.area
        f = f + line_inertia(
            _water(env.water_acceleration, where, t),
            along,
            repeated(displaced * (1 + line.normal_added_mass)),
            repeated(displaced * (1 + line.tangential_added_mass)),
        )
    f = f.reshape(3, count, segments)
    drag_start = drag_end = jnp.zeros_like(tangent)
    for k in range(count):
        drag_start = drag_start + stretched * weights[k] * (1 - points[k]) * f[:, k]
        drag_end = drag_end + stretched * weights[k] * points[k] * f[:, k]
    return drag_start, drag_end


def _nodal_hydrodynamic_forces(model: CableNetwork, env: Environment, t, positions, velocities):
    """Drag and Morison's inertia force on the lines, lumped at the nodes as MoorDyn's
    `Line::getStateDeriv` lumps them, component-major `(3, nodes)`: at each node
    station, on the water relative to its node, about the station's direction, over
    its share of the submerged unstretched length (half of each of its segments)."""
    line, rho = model.line, env.water_density
    length = model.segment_length * _submerged_fraction(model, env, positions)
    direction = _station_directions(model, positions)
    at = model.topology.station_node
    # The coefficients carry the length here (kg/m), which `line_drag` and
    # `line_inertia` scale by linearly.
    f = line_drag(
        take(_water(env.water_velocity, positions, t) - velocities, at),
        direction,
        _to_stations(model, 0.5 * rho * line.normal_drag * line.diameter * length),
        _to_stations(model, 0.5 * rho * line.tangential_drag * jnp.pi * line.diameter * length),
    )
    if env.has_fluid_acceleration:
        displaced = rho * line.area * length
        f = f + line_inertia(
            take(_water(env.water_acceleration, positions, t), at),
            direction,
            _to_stations(model, displaced * (1 + line.normal_added_mass)),
            _to_stations(model, displaced * (1 + line.tangential_added_mass)),
        )
    return sum_into(f, model.topology.node_stations)


def nonconservative_forces(model: CableNetwork, env: Environment, t, positions, velocities) -> Float[Array, "nodes 3"]:
    """Generalised forces (N) of drag, fluid inertia, internal damping, the seabed's
    damping and friction, and the loads on bodies, shape `(nodes, 3)`."""
    return _public(_nonconservative_forces(model, env, t, _cm(positions), _cm(velocities)))


def _seabed_forces(model: CableNetwork, env: Environment, positions, velocities) -> Float[Array, "3 nodes"]:
    bed, depth = env.seabed, env.depth
    assert bed is not None and depth is not None, "seabed_forces needs a seabed (which comes with a depth)"
    area = contact_area(model)
    touching = positions[2] < -depth
    penetration = jnp.maximum(-depth - positions[2], 0.0)
    damping = jnp.where(touching, -bed.damping * area * velocities[2], 0.0)
    sliding = velocities * (1.0 - _UP)
    if bed.friction_damping is None:
        normal_force = bed.stiffness * area * penetration
        speed = jnp.sqrt(dot(sliding, sliding) + bed.friction_speed**2)
        return -(bed.friction * normal_force / speed) * sliding + damping * _UP
    # MoorDyn's: μ c_f |v| up to μ N, N the whole reaction (spring and damper).
    cap = bed.friction * jnp.abs(bed.stiffness * area * penetration + damping)
    speed_squared = dot(sliding, sliding)
    capped = (bed.friction * bed.friction_damping) ** 2 * speed_squared > cap * cap
    # Double `where`: the capped branch divides by |v|, which is positive wherever it is taken.
    speed = jnp.sqrt(jnp.where(capped, speed_squared, 1.0))
    rate = jnp.where(capped, cap / speed, bed.friction * bed.friction_damping)
    return -rate * sliding + damping * _UP


def seabed_forces(model: CableNetwork, env: Environment, positions, velocities) -> Float[Array, "nodes 3"]:
    """The seabed's damping and friction on each node (N), shape `(nodes, 3)`; its
    spring is in `potential_energy`."""
    return _public(_seabed_forces(model, env, _cm(positions), _cm(velocities)))


def _axial_forces(model: CableNetwork, tension, stretched, tangent) -> Float[Array, "3 nodes"]:
    """Each segment's `tension` (N) along its unit `tangent`, pulling its two ends
    together, and, where the line has EI, the bending forces as pulls along the
    segments (`jaxcable._equations.bending.bending_pull`), summed on the nodes in one sum."""
    pull = tension * tangent
    if bending.has_bending(model):
        pull = pull + bending.bending_pull(model, stretched, tangent)
    return _scatter(model, pull, -pull)


def _internal_forces(model: CableNetwork, positions, velocities) -> Float[Array, "3 nodes"]:
    stretched, tangent, _ = _geometry(model, positions)
    return _axial_forces(model, _tension(model, positions, velocities), stretched, tangent)


def internal_forces(model: CableNetwork, positions, velocities) -> Float[Array, "nodes 3"]:
    """The line's own forces (N), `T(ε, ε̇) τ` pulling each segment's ends together
    and, where the line has EI, its bending forces, on every node, shape `(nodes, 3)`:
    the stiff part of `Q`, which an implicit–explicit solver treats implicitly. Equal
    to the elastic part of `−∂Π/∂x` plus the viscous pull in
    `nonconservative_forces`."""
    return _public(_internal_forces(model, _cm(positions), _cm(velocities)))


def _conservative_forces(model: CableNetwork, env: Environment, positions) -> Float[Array, "3 nodes"]:
    """`−∂Π/∂x` (N), component-major `(3, nodes)`, written out term by term.

    The same as `jax.grad` of `_potential_energy` to rounding (tested), which stays the
    definition; written out, the elastic part is the tension law along the tangent the
    drag also uses, and the rest is vertical, so an evaluation skips the reverse pass
    through the geometry (`benchmarks/profile_evaluation.py` times the parts).
    """
    line, body = model.line, model.body
    stretched, tangent, strain = _geometry(model, positions)
    weight = line.mass_per_length * env.gravity * model.segment_length
    displaced = env.water_density * line.area * env.gravity * model.segment_length
    z = positions[2]
    if env.free_surface:
        # ∂/∂z at each end of ∫_a^b z(ξ) dξ, z(ξ) = z_i (1 − ξ) + z_j ξ. The bounds move
        # with the ends too, but only where they sit at the surface, where z = 0.
        a, b = submerged_interval(*_ends(model, z))
        buoyant_end = 0.5 * (b * b - a * a)
        buoyant_start = (b - a) - buoyant_end
    else:
        buoyant_start = buoyant_end = 0.5
    lift = _scatter(model, displaced * buoyant_start - 0.5 * weight, displaced * buoyant_end - 0.5 * weight)
    if body is not None:
        # Φ' = −(the submerged fraction), so a body's buoyancy is ρ g V times that fraction.
        submerged = column_submerged_fraction(z, body.height)
        lift = lift + (env.water_density * body.volume * submerged - body.mass) * env.gravity
    if env.seabed is not None and env.depth is not None:  # as in `_potential_energy`
        lift = lift + env.seabed.stiffness * contact_area(model) * jnp.maximum(-env.depth - z, 0.0)
    elastic = _axial_forces(model, line.tension_law.elastic_tension(strain), stretched, tangent)
    forces = elastic + lift * _UP
    return forces if body is None else forces + _cm(body.force)


def _generalised_forces(model: CableNetwork, env: Environment, t, positions, velocities) -> Float[Array, "3 nodes"]:
    return _conservative_forces(model, env, positions) + _nonconservative_forces(model, env, t, positions, velocities)


def generalised_forces(model: CableNetwork, env: Environment, t, positions, velocities) -> Float[Array, "nodes 3"]:
    """All generalised forces Q (N) on every node, shape `(nodes, 3)`."""
    return _public(_generalised_forces(model, env, t, _cm(positions), _cm(velocities)))


def static_forces(model: CableNetwork, env: Environment, t, positions, still: bool = False) -> Float[Array, "nodes 3"]:
    """`generalised_forces` with every node at rest (N), shape `(nodes, 3)`, without
    the terms that are zero at rest: statics' forces, which compile smaller. With
    `still`, for water known to be still (no current, no waves), without the water's
    loads either, which are then zero too."""
    return static_loads(model, env, t, positions, still)[0]


def static_loads(
    model: CableNetwork, env: Environment, t, positions, still: bool = False
) -> tuple[Float[Array, "nodes 3"], Float[Array, "nodes 3"]]:
    """[`static_forces`][] and the part of them that is not conservative, at rest (the
    current's drag, the waves' loads at `t`, the bodies' constant forces; zeros with
    `still`), each (N) of shape `(nodes, 3)`: statics reads both, and taken together
    the water's loads are evaluated once."""
    positions = _cm(positions)
    water = jnp.zeros_like(positions)
    if not still:
        water = _nonconservative_forces(model, env, t, positions, jnp.zeros_like(positions), True)
    return _public(_conservative_forces(model, env, positions) + water), _public(water)


def _adjugate(blocks: Float[Array, "3 3 n"]) -> tuple[Float[Array, "3 3 n"], Float[Array, " n"]]:
    """The cofactor matrices and determinants of component-major 3 × 3 blocks.

    In closed form rather than LAPACK's batched LU: it fuses with the rest of the
    step, and the batched LU was seen to deadlock under vmap across two host devices
    on a two-core machine. The blocks are mass matrices, m I plus a rank-one added
    mass, so they are well conditioned and the adjugate loses nothing.
    """

    def cross(u, v):
        return jnp.stack([u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]])

    rows = blocks[0], blocks[1], blocks[2]
    cofactor = jnp.stack([cross(rows[1], rows[2]), cross(rows[2], rows[0]), cross(rows[0], rows[1])])
    return cofactor, dot(rows[0], cofactor[0])


def _inverse_3x3(blocks: Float[Array, "3 3 n"]) -> Float[Array, "3 3 n"]:
    """The inverses of component-major 3 × 3 blocks."""
    cofactor, determinant = _adjugate(blocks)
    # The rows' cross products are the columns of det · A⁻¹.
    return jnp.swapaxes(cofactor, 0, 1) / determinant


def _solve_3x3(blocks: Float[Array, "3 3 n"], rhs: Float[Array, "3 n"]) -> Float[Array, "3 n"]:
    """`A⁻¹ b` for each component-major 3 × 3 block, by Cramer's rule: cheaper than
    forming the inverse, which the lumped solve never needs."""
    cofactor, determinant = _adjugate(blocks)
    return (cofactor[0] * rhs[0] + cofactor[1] * rhs[1] + cofactor[2] * rhs[2]) / determinant


FORCE_PARTS = ("all", "internal", "external")


def _free_accelerations(model: CableNetwork, env: Environment, t, free_positions, free_velocities, part: str):
    checks.option("free_accelerations: part", part, FORCE_PARTS)
    positions, velocities = _full_state(model, t, free_positions, free_velocities)
    _, _, constrained_acc = _constrained_motion(model, t)
    free = model.free_nodes
    if part == "internal":
        constrained_acc = jnp.zeros_like(constrained_acc)
    if part == "internal":
        forces = _internal_forces(model, positions, velocities)
    else:
        forces = _generalised_forces(model, env, t, positions, velocities)
        if model.mass_matrix == "consistent":
            # The lumped matrix is block-diagonal, so its M_fc a_c vanishes on the free
            # rows; skipping it saves about a fifth of a lumped evaluation.
            known = _place(model, jnp.zeros_like(free_positions), constrained_acc)
            forces = forces - _inertial_forces(model, env, positions, known)
        if part == "external":
            forces = forces - _internal_forces(model, positions, velocities)
    rhs = take(forces, free)

    _, tangent, _ = _geometry(model, positions)
    if model.mass_matrix == "lumped":
        # Block-diagonal: one block's solve per node, and M_fc = 0.
        a_free = _lumped_solve(model, env, positions, tangent, rhs)
    else:
        # Each element's consistent matrix is [[2/3, 1/3], [1/3, 2/3]] times its lumped
        # one, so the lumped-preconditioned consistent matrix has its spectrum in
        # [1/3, 1]: conjugate gradients converge by a factor 0.27 per O(N) iteration,
        # where a dense factorisation would cost O(N³).
        structure = jax.ShapeDtypeStruct(rhs.shape, rhs.dtype)
        no_motion = jnp.zeros_like(constrained_acc)

        def consistent(a):
            return take(_inertial_forces(model, env, positions, _place(model, a, no_motion)), free)

        # The preconditioner and first guess change how fast CG converges, not where
        # to, so no derivative flows through them (lineax forbids one).
        blocks = take(_lumped_blocks(model, env, positions, tangent), free)
        fixed_inverse = jax.lax.stop_gradient(_inverse_3x3(blocks))

        def lumped_inverse(r):
            return matvec(fixed_inverse, r)

        psd = lx.positive_semidefinite_tag
        a_free = lx.linear_solve(
            lx.FunctionLinearOperator(consistent, structure, psd),
            rhs,
            lx.CG(rtol=0.0, atol=0.0, max_steps=_CG_ITERATIONS),
            options={
                "preconditioner": lx.FunctionLinearOperator(lumped_inverse, structure, psd),
                "y0": lumped_inverse(jax.lax.stop_gradient(rhs)),
            },
            # A non-finite state gives non-finite accelerations, which diffrax rejects
            # as a failed step, rather than an error from deep inside the solve.
            throw=False,
        ).value
    return a_free, positions, velocities, _place(model, a_free, constrained_acc)


def free_accelerations(model: CableNetwork, env: Environment, t, free_positions, free_velocities, part: str = "all"):
    """Solve `M_ff a_f = Q_f − M_fc a_c` for the free nodes' accelerations (m/s²).

    `part` splits the right-hand side for implicit–explicit solvers: `"internal"`
    keeps the line's axial forces alone ([`internal_forces`]), `"external"` the rest,
    `M_fc a_c` included; the two parts' accelerations sum to `"all"`'s.

    Takes the free nodes' positions and velocities, shape `(free, 3)`. Returns
    `(a_f, positions, velocities, a)`: the free accelerations, shape `(free, 3)`, and
    the full node positions, velocities and accelerations (of the part asked for),
    shape `(nodes, 3)`.

    **Raises:**

    `ValueError` naming `part` and the choices if it is not one of `FORCE_PARTS`: a
    misspelt part would otherwise be taken as `"all"`, and an implicit–explicit split
    would then count some forces twice.
    """
    out = _free_accelerations(model, env, t, _cm(free_positions), _cm(free_velocities), part)
    return tuple(_public(x) for x in out)


def _reactions(model: CableNetwork, env: Environment, t, positions, velocities, accelerations):
    residual = _inertial_forces(model, env, positions, accelerations) - _generalised_forces(
        model, env, t, positions, velocities
    )
    return take(residual, model.constrained_nodes)


def reactions(model: CableNetwork, env: Environment, t, positions, velocities, accelerations):
    """Force (N) that each constrained node's support exerts on the network, `(M a − Q)_c`,
    shape `(constrained, 3)`."""
    return _public(_reactions(model, env, t, _cm(positions), _cm(velocities), _cm(accelerations)))
