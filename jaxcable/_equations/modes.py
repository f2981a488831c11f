"""The fastest and slowest modes of a discretised network, from its parameters alone:
each segment's highest axial mode (taut, and inside the slack switch's band), its
highest bending mode, the modes of a node on the seabed, and the mooring's longest
natural periods about an equilibrium.

The fastest bound an explicit step ([`jaxcable.stable_step`][], and the advice's
explicit-step check); the slowest are the periods a wave may resonate with
([`jaxcable.advise`][]).
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._model.network import CableNetwork
from .._model.reach import seabed_reach
from .._sea.environment import Environment
from .lagrangian import generalised_forces, inertial_forces

# The natural periods listed by default, and the largest model (free nodes × 3) whose
# dense eigenproblem `natural_periods` solves.
NATURAL_PERIODS, MODAL_UNKNOWNS = 6, 1500


def stiffest_axial_mode(model, env: Environment | None = None) -> tuple[float, float, int]:
    """The fastest axial mode of the discretised lines.

    The highest axial mode moves neighbouring nodes in opposition:
    `m_n λ² + 4 c λ + 4 k = 0` with segment stiffness k = EA / l, damping c = C_v / l
    and the mass that mode sees at a node, m_n = m l with a lumped mass matrix and
    m l / 3 with the consistent one (whose row is m l (1, 4, 1) / 6), m including the
    tangential added mass. Lumped, ω_n = 2 √(EA / m) / l, the anchored-line paper's and MoorDyn's
    stiffness bound; consistent, √3 times that.

    **Arguments:**

    - `model`, `env`: the network and the water; or a built scene alone
        ([`jaxcable.io.BuiltScene`][]: anything with `model`, `environment` and `labels`).

    **Returns:**

    `(ω_n (rad/s), |λ| (1/s), segment index)`: the natural frequency and the largest
    eigenvalue magnitude, damping included, at the segment where |λ| is largest.
    """
    model, env, _ = unpack(model, env, None)
    omega, eigenvalues = _axial_modes(model, env)
    magnitude = np.abs(eigenvalues)
    s = int(np.argmax(magnitude))
    return float(omega[s]), float(magnitude[s]), s


def fastest_eigenvalues(
    model,
    env: Environment | None = None,
    bending: bool = True,
    duration: float | None = None,
    slack_band: bool = False,
) -> np.ndarray:
    """The eigenvalues λ (1/s, complex) that bound an explicit step: each segment's
    highest axial mode ([`stiffest_axial_mode`][jaxcable._equations.modes.stiffest_axial_mode]),
    taut, and with `slack_band` inside its slack switch's band too
    ([`_slack_band_modes`][]), and its highest bending mode where the line has EI
    ([`bending_modes`][jaxcable._equations.modes.bending_modes]), and, with a seabed, the
    contact and friction modes of a node on it
    ([`seabed_mode`][jaxcable._equations.modes.seabed_mode]) for each segment that can reach
    the bed in a run of `duration` (s; any length where `None`), by
    [`seabed_reach`][jaxcable._model.reach.seabed_reach]'s bound. Of each pair of roots the
    one of larger magnitude (the other is its conjugate, or a slower real root). Shape
    `(modes,)`. Without the bending modes if not `bending`."""
    model, env, _ = unpack(model, env, None)
    _, axial = _axial_modes(model, env)
    if slack_band:
        axial = np.concatenate([axial, _slack_band_modes(model, env)])
    if bending and model.line.bending_stiffness is not None:
        axial = np.concatenate([axial, 1j * bending_modes(model, env)])  # undamped
    touching = seabed_reach(model, env, duration)
    if not touching.any():
        return axial
    damping, stiffness, friction = _seabed_rates(model, env, touching)
    contact = -0.5 * (damping + np.sqrt((damping**2 - 4 * stiffness).astype(complex)))
    return np.concatenate([axial, contact, -friction[friction > 0].astype(complex)])


def _axial_modes(
    model: CableNetwork,
    env: Environment,
    stiffness_factor: float | np.ndarray = 1.0,
    damping_factor: float | np.ndarray = 1.0,
):
    """Each segment's highest axial mode: ω_n (rad/s) and the eigenvalue λ (1/s,
    complex) of larger magnitude, roots of `m_n λ² + 4 c λ + 4 k = 0`, shape
    `(segments,)`; with the segments' stiffness and damping scaled by the factors given
    (`_slack_band_modes`), whose leading axes lead the results' (`(points, 1)` gives
    `(points, segments)`)."""
    line = model.line
    length = np.asarray(model.segment_length)
    rho = float(env.water_density)
    mass = np.asarray(line.mass_per_length) + rho * np.asarray(line.area) * np.asarray(line.tangential_added_mass)
    node_mass = mass * length / (3.0 if model.mass_matrix == "consistent" else 1.0)
    stiffness = stiffness_factor * np.asarray(line.tension_law.axial_stiffness) / length
    damping = damping_factor * np.asarray(line.tension_law.damping()) / length
    shape = np.broadcast_shapes(np.shape(stiffness_factor), np.shape(damping_factor), (model.n_segments,))
    omega = np.broadcast_to(2 * np.sqrt(stiffness / node_mass), shape)
    half_trace = np.broadcast_to(2 * damping / node_mass, shape)
    return omega, -half_trace - np.sqrt((half_trace**2 - omega**2).astype(complex))


# Points s = ε/w of the slack switch's band at which `_slack_band_modes` takes a
# segment's modes: its stiffest (s = 3/4) and those about it, where the damping is less.
_BAND_POINTS = np.array([0.25, 0.5, 0.625, 0.75, 0.875, 1.0])


def _slack_band_modes(model: CableNetwork, env: Environment) -> np.ndarray:
    """The highest axial modes of segments inside their slack switch's band, λ (1/s,
    complex), at the points `_BAND_POINTS`, for the segments whose switch is smooth
    (`slack_width` w > 0).

    Across the band `0 < ε < w` the elastic tension `C_E ε H(ε)`, with `H = s²(3 − 2s)`
    and `s = ε/w` (`jaxcable._model.materials.slack_switch`), has the tangent stiffness
    `C_E (9s² − 8s³)`, up to 27/16 C_E at s = 3/4, while the damping `C_v H` is 27/32 of
    C_v there: a segment passing through the band (a line going slack or snapping
    taut) has a faster, less damped mode than the taut segment. On the damped 40-segment
    rope of `benchmarks/first_contact.py` RK4 steps of 3.5 ms went non-finite at its
    first slack, and 3.24 ms put a 563 kN spike in a 138 kN history, where the taut
    mode alone allowed 4.6 ms; the band's modes bound the step at 3.4 ms.

    They occur only where a line goes slack, which a taut line (the Low & Langley
    jumper, a buoy's tether) never does: [`jaxcable._solver.stability.stable_step`][], which
    chooses a step, counts them; `fixed_step_growth`, which judges one a user or a
    file gave, does not."""
    width = np.broadcast_to(np.asarray(model.line.tension_law.slack_width, dtype=float), (model.n_segments,))
    smooth = width > 0
    if not smooth.any():
        return np.zeros(0, complex)
    p = _BAND_POINTS[:, None]
    return _axial_modes(model, env, 9 * p**2 - 8 * p**3, p**2 * (3 - 2 * p))[1][:, smooth].ravel()


def bending_modes(model: CableNetwork, env: Environment) -> np.ndarray:
    """Each segment's highest bending mode ω_b (rad/s), zero without EI.

    The zigzag w_k = (−1)^k across hinges turns each by 4w/ℓ, so the hinge energy
    `EI/ℓ (1 − cos θ) ≈ EI θ²/(2ℓ)` (`jaxcable._equations.bending`) gives the stiffness 16 EI/ℓ³
    per node against the lumped node mass μ ℓ: `ω_b = 4 √(EI/μ) / ℓ²`, μ with the
    normal added mass. Against the axial mode's `2 √(EA/μ)/ℓ` it is faster only where
    ℓ < 2 √(EI/EA), a segment shorter than about a solid section's diameter."""
    line = model.line
    if line.bending_stiffness is None:
        return np.zeros(model.n_segments)
    length = np.asarray(model.segment_length)
    rho = float(env.water_density)
    mass = np.asarray(line.mass_per_length) + rho * np.asarray(line.area) * np.asarray(line.normal_added_mass)
    return np.broadcast_to(4 * np.sqrt(np.asarray(line.bending_stiffness) / mass) / length**2, (model.n_segments,))


def seabed_mode(model: CableNetwork, env: Environment, touching=None) -> tuple[float, str]:
    """The fastest local mode of a node on the seabed, as |λ| (1/s), and what sets it.

    A node of mass M (m + ρF C_a per length; a third of it with the consistent mass
    matrix, as for the axial mode) on contact area A = d per length sees the bed's
    spring k A and damper c A: |λ| = (c' + √(c'² − 4k'))/2 with c' = cA/M, k' = kA/M
    (√k' if underdamped), independent of the segment length. Friction below its
    `friction_speed` v_s is a viscous drag μN/v_s on a node carrying N, its wet weight
    w per length: |λ| = μ w / (v_s M) along the bed, with M's tangential added mass;
    MoorDyn's friction (`friction_damping` c_f, per node) is μ c_f / (M l), l the
    segment length.

    **Arguments:**

    - `model`, `env`: the network and the water.
    - `touching`: the segments that can reach the bed (a boolean mask); all by default.

    **Returns:**

    `(|λ| (1/s), "damping" | "stiffness" | "friction")`; `(0.0, "")` without a seabed.
    """
    if env.seabed is None:
        return 0.0, ""
    mask = np.ones(model.n_segments, bool) if touching is None else np.asarray(touching, bool)
    if not mask.any():
        return 0.0, ""
    damping, stiffness, friction = _seabed_rates(model, env, mask)
    discriminant = damping**2 - 4 * stiffness
    contact = np.where(discriminant > 0, 0.5 * (damping + np.sqrt(np.maximum(discriminant, 0))), np.sqrt(stiffness))
    if friction.max() > contact.max():
        return float(friction.max()), "friction"
    return float(contact.max()), "damping" if np.any(discriminant > 0) else "stiffness"


def _seabed_rates(model: CableNetwork, env: Environment, mask: np.ndarray) -> tuple[np.ndarray, ...]:
    """Per masked segment, the bed's damping c' (1/s) and stiffness k' (1/s²) on a
    node's normal mass, and friction's viscous rate μ w / (v_s M) (1/s) on its
    tangential mass (`seabed_mode`)."""
    bed = env.seabed
    assert bed is not None
    line = model.line
    rho, g = float(env.water_density), float(env.gravity)
    fields = {
        f: np.broadcast_to(np.asarray(getattr(line, f)), (model.n_segments,))[mask]
        for f in ("mass_per_length", "area", "diameter", "normal_added_mass", "tangential_added_mass")
    }
    share = 3.0 if model.mass_matrix == "consistent" else 1.0
    m, area, d = fields["mass_per_length"], fields["area"], fields["diameter"]
    normal = (m + rho * area * fields["normal_added_mass"]) / share
    along = (m + rho * area * fields["tangential_added_mass"]) / share
    if bed.friction_damping is not None:
        length = np.broadcast_to(np.asarray(model.segment_length), (model.n_segments,))[mask]
        friction = float(bed.friction) * float(bed.friction_damping) / (along * length)
    else:
        weight = np.maximum((m - rho * area) * g, 0.0)
        friction = float(bed.friction) * weight / (float(bed.friction_speed) * along)
    return float(bed.damping) * d / normal, float(bed.stiffness) * d / normal, friction


def natural_periods(model: CableNetwork, env: Environment, positions, count: int = NATURAL_PERIODS) -> np.ndarray:
    """The mooring's `count` longest natural periods (s) about `positions` (m, an
    equilibrium of every node, shape `(nodes, 3)`): 2π/ω from the generalised
    eigenvalues ω² of K v = ω² M v, K = −∂Q_f/∂x_f the free nodes' stiffness (forces
    at rest in `env` without its waves, supports held where `model` has them) and M the
    mass matrix on them, added mass included. Undamped; eigenvalues that are not real
    and positive (a mechanism, a slack line) are left out. Empty for a model of more
    than `MODAL_UNKNOWNS` unknowns, whose dense eigenproblem would cost more than the
    advice."""
    free = np.asarray(model.free_nodes)
    n = 3 * free.size
    if n == 0 or n > MODAL_UNKNOWNS:
        return np.zeros(0)
    matrices = _modal_matrices(model, env.without_waves(), jnp.asarray(positions))
    stiffness, mass = (np.asarray(m) for m in matrices)
    # M is positive definite (masses and added masses), so K v = ω² M v is M⁻¹K's problem:
    # numpy's, without importing SciPy (0.12 s of every start) for one call.
    squared = np.linalg.eigvals(np.linalg.solve(mass, stiffness))
    real, imaginary = np.real(squared), np.imag(squared)
    oscillating = np.isfinite(squared) & (real > 0) & (np.abs(imaginary) <= 1e-6 * np.abs(squared))
    return np.sort(2 * np.pi / np.sqrt(real[oscillating]))[::-1][:count]


@eqx.filter_jit
def _modal_matrices(model: CableNetwork, still: Environment, positions):
    """K = −∂Q_f/∂x_f at rest and M_ff, each of shape `(3 free, 3 free)`: compiled once
    per model structure."""
    free = model.free_nodes
    n = 3 * free.size

    def forces(q):
        at = positions.at[free].set(q)
        return generalised_forces(model, still, 0.0, at, jnp.zeros_like(at))[free]

    def inertia(a):
        return inertial_forces(model, still, positions, jnp.zeros_like(positions).at[free].set(a))[free]

    q = positions[free]
    return -jax.jacfwd(forces)(q).reshape(n, n), jax.jacfwd(inertia)(jnp.zeros_like(q)).reshape(n, n)


def unpack(model, env, labels):
    """`(model, env, labels)`: a built scene's own, unless given."""
    if not isinstance(model, CableNetwork):  # a built scene
        built = model
        return built.model, built.environment if env is None else env, built.labels if labels is None else labels
    if env is None:
        raise ValueError("give the environment with the model (or a BuiltScene alone)")
    return model, env, labels
