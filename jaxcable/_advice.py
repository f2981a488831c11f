"""Advice on model and solver for a built scene: what limits an explicit step."""

import numpy as np

from ._scene import BuiltScene


def stiffest_axial_mode(built: BuiltScene) -> tuple[float, float, int]:
    """The fastest axial mode of the discretised lines.

    The highest axial mode moves neighbouring nodes in opposition:
    `m_n λ² + 4 c λ + 4 k = 0` with segment stiffness k = EA / l, damping c = C_v / l
    and the mass that mode sees at a node, m_n = m l with a lumped mass matrix and
    m l / 3 with the consistent one (whose row is m l (1, 4, 1) / 6), m including the
    tangential added mass. Lumped, ω_n = 2 √(EA / m) / l, seed 003's and MoorDyn's
    stiffness bound; consistent, √3 times that.

    **Returns:**

    `(ω_n (rad/s), |λ| (1/s), segment index)`: the natural frequency and the largest
    eigenvalue magnitude, damping included, at the segment where |λ| is largest.
    """
    model = built.model
    line = model.line
    length = np.asarray(model.segment_length)
    rho = float(built.environment.water_density)
    mass = np.asarray(line.mass_per_length) + rho * np.asarray(line.area) * np.asarray(line.tangential_added_mass)
    node_mass = mass * length / (3.0 if model.mass_matrix == "consistent" else 1.0)
    stiffness = np.asarray(line.tension_law.axial_stiffness) / length
    damping = np.asarray(line.tension_law.damping()) / length
    omega = 2 * np.sqrt(stiffness / node_mass)
    half_trace = 2 * damping / node_mass
    discriminant = half_trace**2 - omega**2
    magnitude = np.where(discriminant > 0, half_trace + np.sqrt(np.maximum(discriminant, 0)), omega)
    s = int(np.argmax(magnitude))
    return float(omega[s]), float(magnitude[s]), s


def advice(built: BuiltScene, duration: float) -> list[str]:
    """Plain-language advice for running `built` for `duration` (s)."""
    omega, magnitude, s = stiffest_axial_mode(built)
    # Explicit Runge–Kutta methods of order 4–5 are stable for |λ Δt| up to about 3.
    step = 3.0 / magnitude
    lines = [
        f"stiffest axial mode: ω_n = {omega:.4g} rad/s (period {2 * np.pi / omega:.3g} s) at segment {s}; "
        f"with damping |λ| = {magnitude:.4g} 1/s",
        f"an explicit solver (dopri5, tsit5) is stable for steps up to about 3/|λ| = {step:.3g} s, so "
        f"{duration:g} s needs at least ~{int(np.ceil(duration / step)):,} steps",
    ]
    if step < 1e-3:
        lines.append(
            "that step is short: if the run is slow, fewer segments (--segments) lengthen it in proportion, "
            "or an implicit solver (--solver kvaerno5) removes the limit at a higher cost per step"
        )
    return lines
