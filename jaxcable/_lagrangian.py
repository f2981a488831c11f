"""The equations of motion, from the Lagrangian of the polyline (seed 003).

Between nodes i and j a segment is `R(ξ) = x_i (1 − ξ) + x_j ξ`, `ξ ∈ [0, 1]` (eq. 7).

- Kinetic energy `K = ½ Σ L ∫₀¹ m |Ṙ|² dξ`. Integrated exactly, it gives the consistent
  mass matrix (shape-function weights 1/3 and 1/6); integrated at the two ends
  (trapezoid rule), the lumped one.
- Added mass is Morison's inertia force, `−ρ F (C_a (I − ττᵀ) + C_aτ ττᵀ) R̈`, entered by
  its virtual work as seed 003 and MoorDyn do, and moved to the left-hand side: the mass
  matrix M(x) carries `μ = m I + ρ F (...)` per length. When C_a ≠ C_aτ, M depends on the
  segments' directions and `½ vᵀMv + Π` is not conserved: it changes at the rate
  `½ vᵀ Ṁ v` (tested). With isotropic added mass it is conserved exactly.
- Potential energy `Π = Σ L ∫₀^ε T de + Σ (m − ρF) g L z̄ + Σ (M g z + ρ g V Φ(z)) − Σ F·x`
  (bodies' constant forces F), plus the seabed's penalty energy `Σ ½ k δ² A` where
  nodes press into it. Φ = −z for a submerged body; a body with a height that pierces
  the surface has the buoyancy of its submerged part only. The conservative
  forces are `−∂Π/∂x`, by `jax.grad`. With `Environment.free_surface`, buoyancy, drag,
  fluid inertia and added mass act on the part of each segment below z = 0 only.
- Non-conservative loads enter by their virtual work `Q = Σ ∫ f · ∂R/∂x |∂R/∂l| dl`:
  drag on the velocity relative to the water, and (with waves) Morison's inertia force
  from the water's acceleration, both by Gauss–Legendre quadrature along each segment;
  the viscous part of the tension; the seabed's damping and friction; and the same
  loads on point bodies.

Prescribed nodes are eliminated (seed 003, eq. 8): with the free and constrained blocks
of the mass matrix, `M_ff a_f = Q_f − M_fc a_c`. What remains at the constrained nodes,
`M a − Q`, is the reaction of their supports.

Everything here is a pure function of `(model, environment, t, positions, velocities)`.
"""

import jax
import jax.numpy as jnp
import lineax as lx
import numpy as np
from jaxtyping import Array, Float

from . import _checks as checks
from ._environment import Environment
from ._hydro import body_drag, gauss_legendre, line_drag, line_inertia, safe_norm, submerged_interval
from ._network import CableNetwork

# ∫₀¹ N_a N_b dξ for the shape functions N = (1 − ξ, ξ), exact and at the ends.
_SHAPE_WEIGHTS = {
    "consistent": np.array([[1 / 3, 1 / 6], [1 / 6, 1 / 3]]),
    "lumped": np.array([[1 / 2, 0.0], [0.0, 1 / 2]]),
}


# Conjugate-gradient iterations for the consistent solve. The condition number is at most
# 3, so the error falls below 2 (√3 − 1)^k / (√3 + 1)^k ≈ 1e-17 after 30 iterations. A fixed
# count, not a tolerance: lineax's tolerances are absolute and per element, and in reverse
# mode they would apply to the cotangent, making gradients depend on the loss's scale.
_CG_ITERATIONS = 30


def _scatter(model: CableNetwork, at_start: Array, at_end: Array) -> Float[Array, " nodes *trailing"]:
    """Sum per-segment arrays (of any trailing shape) onto the segments' end nodes."""
    ids = model.segment_nodes.T.reshape(-1)
    return jax.ops.segment_sum(jnp.concatenate([at_start, at_end]), ids, num_segments=model.n_nodes)


def constrained_motion(model: CableNetwork, t) -> tuple[Array, Array, Array]:
    """Positions (m), velocities (m/s) and accelerations (m/s²) of the constrained
    nodes at time `t`, each of shape `(constrained, 3)`."""
    reference = model.node_positions[model.constrained_nodes]
    if not model.motions:
        empty = jnp.zeros((0, 3))
        return empty, empty, empty
    r, v, a = (jnp.stack(k) for k in zip(*(m.kinematics(t) for m in model.motions)))
    return reference + r, v, a


def full_state(model: CableNetwork, t, free_positions, free_velocities):
    """Node positions and velocities, shape `(nodes, 3)`, from the free unknowns."""
    r, v, _ = constrained_motion(model, t)
    positions = model.node_positions.at[model.free_nodes].set(free_positions).at[model.constrained_nodes].set(r)
    velocities = jnp.zeros_like(positions).at[model.free_nodes].set(free_velocities)
    return positions, velocities.at[model.constrained_nodes].set(v)


def segment_geometry(model: CableNetwork, positions):
    """Stretched length S (m), unit tangent τ and strain ε = S/L − 1 of each segment."""
    start, end = positions[model.segment_nodes[:, 0]], positions[model.segment_nodes[:, 1]]
    chord = end - start
    stretched = safe_norm(chord)
    return stretched, chord / stretched[:, None], stretched / model.segment_length - 1.0


def strain_rate(model: CableNetwork, positions, velocities) -> Float[Array, " segments"]:
    """ε̇ = τ · (v_j − v_i) / L (1/s)."""
    _, tangent, _ = segment_geometry(model, positions)
    dv = velocities[model.segment_nodes[:, 1]] - velocities[model.segment_nodes[:, 0]]
    return jnp.sum(tangent * dv, axis=-1) / model.segment_length


def tension(model: CableNetwork, positions, velocities) -> Float[Array, " segments"]:
    """Segment tension T(ε, ε̇) (N)."""
    _, _, strain = segment_geometry(model, positions)
    return model.line.tension_law.tension(strain, strain_rate(model, positions, velocities))


def potential_energy(model: CableNetwork, env: Environment, positions) -> Float[Array, ""]:
    """Π (J): elastic energy, gravity minus buoyancy, and the potential −F·x of the
    bodies' constant forces."""
    line, body = model.line, model.body
    _, _, strain = segment_geometry(model, positions)
    elastic = jnp.sum(model.segment_length * line.tension_law.elastic_energy_density(strain))
    z = positions[:, 2]
    z_start, z_end = z[model.segment_nodes[:, 0]], z[model.segment_nodes[:, 1]]
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
    body_buoyancy = env.water_density * body.volume * env.gravity
    energy = (
        elastic
        + jnp.sum(weight * mid_depth - displaced * submerged_depth)
        + jnp.sum(body.mass * env.gravity * z + body_buoyancy * column_buoyancy_potential(z, body.height))
        - jnp.sum(body.force * positions)
    )
    if env.seabed is not None and env.depth is not None:  # a seabed comes with a depth (Environment checks)
        penetration = jnp.maximum(-env.depth - z, 0.0)
        energy = energy + 0.5 * env.seabed.stiffness * jnp.sum(contact_area(model) * penetration**2)
    return energy


def contact_area(model: CableNetwork) -> Float[Array, " nodes"]:
    """Each node's seabed contact area (m²): half the projected area d L of each segment
    that meets there, as MoorDyn's `kBot` and `cBot` refer to."""
    half = 0.5 * model.line.diameter * model.segment_length
    return _scatter(model, half, half)


def mass_per_length(model: CableNetwork, env: Environment, positions) -> Float[Array, "segments 3 3"]:
    """μ = m I + ρ F (C_a (I − ττᵀ) + C_aτ ττᵀ) (kg/m), each segment's mass per unit
    unstretched length, the fluid's added mass included."""
    line = model.line
    _, tangent, _ = segment_geometry(model, positions)
    axial = tangent[:, :, None] * tangent[:, None, :]
    added = env.water_density * line.area
    if env.free_surface:
        # The submerged fraction's added mass, spread along the segment as the rest.
        a, b = submerged_interval(positions[model.segment_nodes[:, 0], 2], positions[model.segment_nodes[:, 1], 2])
        added = added * (b - a)
    eye = jnp.eye(3)
    return (
        line.mass_per_length[:, None, None] * eye
        + (added * line.normal_added_mass)[:, None, None] * (eye - axial)
        + (added * line.tangential_added_mass)[:, None, None] * axial
    )


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


def _body_mass(model: CableNetwork, env: Environment, positions) -> Float[Array, " nodes"]:
    body = model.body
    wet = column_submerged_fraction(positions[:, 2], body.height)
    return body.mass + body.added_mass * env.water_density * body.volume * wet


def _segment_blocks(model: CableNetwork, env: Environment, positions, weights) -> Float[Array, "segments 2 2 3 3"]:
    """Each segment's 6 × 6 mass matrix as 2 × 2 blocks: `W_ab L μ`."""
    mu = mass_per_length(model, env, positions) * model.segment_length[:, None, None]
    return weights[None, :, :, None, None] * mu[:, None, None]


def inertial_forces(model: CableNetwork, env: Environment, positions, accelerations) -> Float[Array, "nodes 3"]:
    """`M(x) a` (N): the generalised inertia of node accelerations `a` (m/s²), shape
    `(nodes, 3)`."""
    blocks = _segment_blocks(model, env, positions, _SHAPE_WEIGHTS[model.mass_matrix])
    per_end = jnp.einsum("sabij,sbj->sai", blocks, accelerations[model.segment_nodes])
    return _scatter(model, per_end[:, 0], per_end[:, 1]) + _body_mass(model, env, positions)[:, None] * accelerations


def lumped_blocks(model: CableNetwork, env: Environment, positions) -> Float[Array, "nodes 3 3"]:
    """The 3 × 3 blocks of the lumped mass matrix (kg), shape `(nodes, 3, 3)`, whichever
    matrix the model uses: they are also the consistent solve's preconditioner."""
    blocks = _segment_blocks(model, env, positions, _SHAPE_WEIGHTS["lumped"])
    return _scatter(model, blocks[:, 0, 0], blocks[:, 1, 1]) + _body_mass(model, env, positions)[
        :, None, None
    ] * jnp.eye(3)


def kinetic_energy(model: CableNetwork, env: Environment, positions, velocities) -> Float[Array, ""]:
    """½ vᵀ M(x) v (J): the kinetic energy of the line, bodies and added fluid mass.

    With the line's added mass anisotropic (C_a ≠ C_aτ), this plus `potential_energy` is
    not a conserved quantity even without drag; see the module docstring."""
    return 0.5 * jnp.sum(velocities * inertial_forces(model, env, positions, velocities))


def nonconservative_forces(model: CableNetwork, env: Environment, t, positions, velocities) -> Float[Array, "nodes 3"]:
    """Generalised forces (N) of drag, fluid inertia, internal damping, the seabed's
    damping and friction, and the loads on bodies."""
    line, body = model.line, model.body
    rho = env.water_density
    stretched, tangent, strain = segment_geometry(model, positions)

    xi, w = gauss_legendre(model.drag_points)
    ends = model.segment_nodes
    xi, w = jnp.broadcast_to(xi, (model.n_segments, xi.size)), jnp.broadcast_to(w, (model.n_segments, w.size))
    if env.free_surface:
        # Quadrature over the submerged part [a, b] only.
        a, b = submerged_interval(positions[ends[:, 0], 2], positions[ends[:, 1], 2])
        xi, w = a[:, None] + (b - a)[:, None] * xi, (b - a)[:, None] * w

    def along(field):
        return field[ends[:, 0], None] * (1 - xi)[..., None] + field[ends[:, 1], None] * xi[..., None]

    points = along(positions)  # (segments, points, 3)
    relative = env.water_velocity(points, t) - along(velocities)
    normal = 0.5 * rho * line.normal_drag * line.diameter  # C_n
    tangential = 0.5 * rho * line.tangential_drag * jnp.pi * line.diameter  # C_τ
    f = line_drag(relative, tangent[:, None, :], normal[:, None], tangential[:, None])
    if env.has_fluid_acceleration:
        # Morison's inertia on the water's acceleration: Froude–Krylov (the 1) plus
        # added mass, normal and tangential to the segment, as MoorDyn writes it.
        displaced = rho * line.area
        f = f + line_inertia(
            env.water_acceleration(points, t),
            tangent[:, None, :],
            (displaced * (1 + line.normal_added_mass))[:, None],
            (displaced * (1 + line.tangential_added_mass))[:, None],
        )
    drag_start = stretched[:, None] * jnp.einsum("sp,spk->sk", w * (1 - xi), f)
    drag_end = stretched[:, None] * jnp.einsum("sp,spk->sk", w * xi, f)

    law = line.tension_law
    viscous = law.tension(strain, strain_rate(model, positions, velocities)) - law.elastic_tension(strain)
    pull = viscous[:, None] * tangent
    forces = _scatter(model, drag_start + pull, drag_end - pull)

    z = positions[:, 2]
    wet = column_submerged_fraction(z, body.height)
    if env.waves:
        # A floating column is wet up to the wave's surface η, not to z = 0: its buoyancy
        # there is the waves' main heave force on a surface buoy (ρ g A η at the
        # waterline), which the Morison terms at its centre cannot give. The potential
        # holds the still-water part; the rest is added here. With the Morison
        # Froude–Krylov term on the wet volume this is, to first order, the wave
        # pressure on the column's bottom.
        still = wet
        wet = column_submerged_fraction(z - env.surface_elevation(positions[:, 0], positions[:, 1], t), body.height)
        forces = forces.at[:, 2].add(rho * env.gravity * body.volume * (wet - still))
    coefficient = (0.5 * rho * body.drag_area + body.specific_drag * body.organism_mass * env.gravity) * wet
    forces = forces + body_drag(env.water_velocity(positions, t) - velocities, coefficient)
    if env.has_fluid_acceleration:
        forces = forces + (rho * body.volume * (1 + body.added_mass) * wet)[..., None] * env.water_acceleration(
            positions, t
        )
    if env.seabed is not None:
        forces = forces + seabed_forces(model, env, positions, velocities)
    return forces


def seabed_forces(model: CableNetwork, env: Environment, positions, velocities) -> Float[Array, "nodes 3"]:
    """The seabed's damping and friction on each node (N); its spring is in
    `potential_energy`."""
    bed, depth = env.seabed, env.depth
    assert bed is not None and depth is not None, "seabed_forces needs a seabed (which comes with a depth)"
    area = contact_area(model)
    touching = positions[:, 2] < -depth
    penetration = jnp.maximum(-depth - positions[:, 2], 0.0)
    damping = jnp.where(touching, -bed.damping * area * velocities[:, 2], 0.0)
    normal_force = bed.stiffness * area * penetration
    sliding = velocities.at[:, 2].set(0.0)
    speed = jnp.sqrt(jnp.sum(sliding**2, axis=-1) + bed.friction_speed**2)
    friction = -(bed.friction * normal_force / speed)[:, None] * sliding
    return friction.at[:, 2].add(damping)


def internal_forces(model: CableNetwork, positions, velocities) -> Float[Array, "nodes 3"]:
    """The line's own axial forces (N), `T(ε, ε̇) τ` pulling each segment's ends
    together, on every node, shape `(nodes, 3)`: the stiff part of `Q`, which an
    implicit–explicit solver treats implicitly. Equal to the elastic part of
    `−∂Π/∂x` plus the viscous pull in `nonconservative_forces`."""
    _, tangent, _ = segment_geometry(model, positions)
    pull = tension(model, positions, velocities)[:, None] * tangent
    return _scatter(model, pull, -pull)


def generalised_forces(model: CableNetwork, env: Environment, t, positions, velocities) -> Float[Array, "nodes 3"]:
    """All generalised forces Q (N) on every node, shape `(nodes, 3)`."""
    conservative = -jax.grad(potential_energy, argnums=2)(model, env, positions)
    return conservative + nonconservative_forces(model, env, t, positions, velocities)


def _inverse_3x3(blocks: Float[Array, "n 3 3"]) -> Float[Array, "n 3 3"]:
    """The inverses of 3 × 3 blocks, by the adjugate.

    In closed form rather than LAPACK's batched LU: it fuses with the rest of the
    step, and the batched LU was seen to deadlock under vmap across two host devices
    on a two-core machine. The blocks are mass matrices, m I plus a rank-one added
    mass, so they are well conditioned and the adjugate loses nothing.
    """
    a = blocks
    cofactor = jnp.stack(
        [
            jnp.cross(a[..., 1, :], a[..., 2, :]),
            jnp.cross(a[..., 2, :], a[..., 0, :]),
            jnp.cross(a[..., 0, :], a[..., 1, :]),
        ],
        axis=-2,
    )
    determinant = jnp.sum(a[..., 0, :] * cofactor[..., 0, :], axis=-1)
    # The rows' cross products are the columns of det · A⁻¹.
    return jnp.swapaxes(cofactor, -1, -2) / determinant[..., None, None]


FORCE_PARTS = ("all", "internal", "external")


def free_accelerations(model: CableNetwork, env: Environment, t, free_positions, free_velocities, part: str = "all"):
    """Solve `M_ff a_f = Q_f − M_fc a_c` for the free nodes' accelerations (m/s²).

    `part` splits the right-hand side for implicit–explicit solvers: `"internal"`
    keeps the line's axial forces alone ([`internal_forces`]), `"external"` the rest,
    `M_fc a_c` included; the two parts' accelerations sum to `"all"`'s.

    Returns `(a_f, positions, velocities, a)`: the free accelerations, shape
    `(free, 3)`, and the full node positions, velocities and accelerations (of the
    part asked for).

    **Raises:**

    `ValueError` naming `part` and the choices if it is not one of `FORCE_PARTS`: a
    misspelt part would otherwise be taken as `"all"`, and an implicit–explicit split
    would then count some forces twice.
    """
    checks.option("free_accelerations: part", part, FORCE_PARTS)
    positions, velocities = full_state(model, t, free_positions, free_velocities)
    _, _, constrained_acc = constrained_motion(model, t)
    free, constrained = model.free_nodes, model.constrained_nodes
    known = jnp.zeros_like(positions)
    if part != "internal":
        known = known.at[constrained].set(constrained_acc)
    if part == "internal":
        forces = internal_forces(model, positions, velocities)
    else:
        forces = generalised_forces(model, env, t, positions, velocities)
        if model.mass_matrix == "consistent":
            # The lumped matrix is block-diagonal, so its M_fc a_c vanishes on the free
            # rows; skipping it saves about a fifth of a lumped evaluation.
            forces = forces - inertial_forces(model, env, positions, known)
        if part == "external":
            forces = forces - internal_forces(model, positions, velocities)
    rhs = forces[free]

    # The lumped matrix is block-diagonal: one 3 × 3 solve per node, and M_fc = 0.
    inverse = _inverse_3x3(lumped_blocks(model, env, positions)[free])
    a_free = jnp.einsum("nij,nj->ni", inverse, rhs)
    if model.mass_matrix == "consistent":
        # Each element's consistent matrix is [[2/3, 1/3], [1/3, 2/3]] times its lumped
        # one, so the lumped-preconditioned consistent matrix has its spectrum in
        # [1/3, 1]: conjugate gradients converge by a factor 0.27 per O(N) iteration,
        # where a dense factorisation would cost O(N³).
        structure = jax.ShapeDtypeStruct(rhs.shape, rhs.dtype)
        zeros = jnp.zeros_like(positions)

        def consistent(a):
            return inertial_forces(model, env, positions, zeros.at[free].set(a))[free]

        # The preconditioner and first guess change how fast CG converges, not where
        # to, so no derivative flows through them (lineax forbids one).
        fixed_inverse = jax.lax.stop_gradient(inverse)

        def lumped_inverse(r):
            return jnp.einsum("nij,nj->ni", fixed_inverse, r)

        psd = lx.positive_semidefinite_tag
        a_free = lx.linear_solve(
            lx.FunctionLinearOperator(consistent, structure, psd),
            rhs,
            lx.CG(rtol=0.0, atol=0.0, max_steps=_CG_ITERATIONS),
            options={
                "preconditioner": lx.FunctionLinearOperator(lumped_inverse, structure, psd),
                "y0": jax.lax.stop_gradient(a_free),
            },
            # A non-finite state gives non-finite accelerations, which diffrax rejects
            # as a failed step, rather than an error from deep inside the solve.
            throw=False,
        ).value
    return a_free, positions, velocities, known.at[free].set(a_free)


def reactions(model: CableNetwork, env: Environment, t, positions, velocities, accelerations):
    """Force (N) that each constrained node's support exerts on the network, `(M a − Q)_c`,
    shape `(constrained, 3)`."""
    residual = inertial_forces(model, env, positions, accelerations) - generalised_forces(
        model, env, t, positions, velocities
    )
    return residual[model.constrained_nodes]
