"""Hydrodynamic loads: quadratic drag and Morison inertia on line segments and bodies.

The line drag per unit stretched length on a relative velocity `u = V − Ṙ` is

    f = C_n |u_n| u_n + C_τ |u_τ| u_τ,   C_n = ½ ρ K_n d,   C_τ = ½ ρ K_τ π d,

split into the parts normal (`u_n`) and tangential (`u_τ`) to the segment. These are the
same reference areas as MoorDyn's Cd (on d·l) and CdAx (on π·d·l).

Vectors are component-major: shape `(3, ...)`, the components first (see [`dot`][]).
"""

import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

# A velocity far below anything physical (m/s). Keeps |u| differentiable at u = 0,
# where the gradient of a plain norm is NaN; the drag there is ~1e-24 N, i.e. zero.
_TINY_SPEED = 1e-12


def dot(a: Float[ArrayLike, "3 *#batch"], b: Float[ArrayLike, "3 *#batch"]) -> Float[Array, "*batch"]:
    """`a · b` over the first axis, the vectors' components.

    Vectors here are component-major, shape `(3, ...)`, and the sum is written out: XLA's
    CPU backend vectorises arithmetic along the long last axis, where a short trailing
    axis of 3 (and a reduction or concatenation over it) costs several times the
    arithmetic (`benchmarks/profile_evaluation.py`)."""
    a, b = jnp.asarray(a), jnp.asarray(b)
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def matvec(m: Float[ArrayLike, "3 3 *#batch"], v: Float[ArrayLike, "3 *#batch"]) -> Float[Array, "3 ..."]:
    """`m v` for component-major 3 × 3 matrices, shape `(3, 3, ...)`."""
    m, v = jnp.asarray(m), jnp.asarray(v)
    return m[:, 0] * v[0] + m[:, 1] * v[1] + m[:, 2] * v[2]


def safe_norm(v: Float[ArrayLike, "3 ..."]) -> Float[Array, "*batch"]:
    """`|v|` over the first axis, with a finite gradient at `v = 0`."""
    v = jnp.asarray(v)
    return jnp.sqrt(dot(v, v) + _TINY_SPEED**2)


def gauss_legendre(points: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of `points`-point Gauss–Legendre quadrature on `[0, 1]`."""
    nodes, weights = np.polynomial.legendre.leggauss(points)
    return 0.5 * (nodes + 1.0), 0.5 * weights


def line_drag(
    relative_velocity: Float[ArrayLike, "3 *#batch"],
    tangent: Float[ArrayLike, "3 *#batch"],
    normal_coefficient: Float[ArrayLike, "*#batch"],
    tangential_coefficient: Float[ArrayLike, "*#batch"],
) -> Float[Array, "3 ..."]:
    """Drag per unit length, `C_n |u_n| u_n + C_τ |u_τ| u_τ` (N/m), component-major.

    **Arguments:**

    - `relative_velocity`: u = V − Ṙ (m/s), water relative to the line.
    - `tangent`: the unit tangent τ of the segment.
    - `normal_coefficient`: C_n = ½ ρ K_n d (kg/m²).
    - `tangential_coefficient`: C_τ = ½ ρ K_τ π d (kg/m²).
    """
    relative_velocity, tangent = jnp.asarray(relative_velocity), jnp.asarray(tangent)
    normal_coefficient, tangential_coefficient = jnp.asarray(normal_coefficient), jnp.asarray(tangential_coefficient)
    along = dot(relative_velocity, tangent)
    u_normal = relative_velocity - along * tangent
    # |u_τ| = |u · τ| for a unit τ: no square root (which XLA keeps in a kernel of its
    # own, recomputing its operands on each side), and |s| s is differentiable at 0.
    return (
        normal_coefficient * safe_norm(u_normal) * u_normal
        + (tangential_coefficient * jnp.abs(along) * along) * tangent
    )


def line_inertia(
    fluid_acceleration: Float[ArrayLike, "3 *#batch"],
    tangent: Float[ArrayLike, "3 *#batch"],
    normal_coefficient: Float[ArrayLike, "*#batch"],
    tangential_coefficient: Float[ArrayLike, "*#batch"],
) -> Float[Array, "3 ..."]:
    """Morison's inertia force per unit length from the water's acceleration,
    `c_n a_n + c_τ a_τ` (N/m), split like `line_drag`, component-major.

    **Arguments:**

    - `fluid_acceleration`: a (m/s²), the water's acceleration.
    - `tangent`: the unit tangent τ of the segment.
    - `normal_coefficient`: c_n = ρ F (1 + C_a) (kg/m): Froude–Krylov plus added mass.
    - `tangential_coefficient`: c_τ = ρ F (1 + C_aτ) (kg/m).
    """
    fluid_acceleration, tangent = jnp.asarray(fluid_acceleration), jnp.asarray(tangent)
    normal_coefficient, tangential_coefficient = jnp.asarray(normal_coefficient), jnp.asarray(tangential_coefficient)
    a_tangential = dot(fluid_acceleration, tangent) * tangent
    return normal_coefficient * (fluid_acceleration - a_tangential) + tangential_coefficient * a_tangential


def body_drag(
    relative_velocity: Float[ArrayLike, "3 *#batch"], coefficient: Float[ArrayLike, "*#batch"]
) -> Float[Array, "3 ..."]:
    """Quadratic drag on a body, `c |u| u` (N), component-major.

    Both of jaxcable's body laws have this form: `c = ½ ρ C_D A` for form drag, and
    `c = k₀ m g` for Zhukov's specific-weight law `R = k₀ u² m g` (Zhukov's growing-element thesis, eq. 3).
    """
    relative_velocity, coefficient = jnp.asarray(relative_velocity), jnp.asarray(coefficient)
    return coefficient * safe_norm(relative_velocity) * relative_velocity


def submerged_interval(
    z_start: Float[Array, " segments"], z_end: Float[Array, " segments"]
) -> tuple[Float[Array, " segments"], Float[Array, " segments"]]:
    """`(a, b)`: the part `ξ ∈ [a, b]` of each straight segment `R(ξ)` that lies below
    the still-water level z = 0, given its ends' heights (m). `a = b` when it is all
    above. The ends move continuously with the nodes, so integrals over `[a, b]`
    (buoyancy, drag, added mass) do too as a segment crosses the surface.
    """
    below = (z_start <= 0) & (z_end <= 0)
    above = (z_start >= 0) & (z_end >= 0) & ~below
    crossing = z_start / jnp.where(below | above, 1.0, z_start - z_end)  # where z(ξ) = 0
    start_below = z_start < 0
    a = jnp.where(below | above | start_below, 0.0, crossing)
    b = jnp.where(below, 1.0, jnp.where(above, 0.0, jnp.where(start_below, crossing, 1.0)))
    return a, b
