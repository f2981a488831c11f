"""The anchored line (Bezverkhyy & Korniienko), the core validation case, and the README's
line in a current.

Bezverkhyy & Korniienko, *the influence of nonlinear-elastic material properties on the
dynamics of underwater cable systems*. One end is anchored at depth H = 200 m; the other
is attached to a floating object at the surface and driven along x by
`x_N = A sin(ωt) + X_N` (eq. 6), with the wave amplitude law
`A = 0.085 (g T_w² / 2π)^0.75`.

The paper gives C_n, C_τ and C_a as dimensional coefficients; they are converted here to
jaxcable's K_n, K_τ and C_a with the diameter of a solid section of area F. The paper
does not give C_E. jaxcable takes C_E = 3.0e7 N, which is E ≈ 100 GPa (a steel wire
rope's effective modulus on its metallic area) times F = 0.0003 m²; a 3 kg/m line with
that area is a steel rope. The unstretched length is the chord from anchor to fairlead
at the design angle.

The paper's sea is "plane progressive waves" acting on the line, and the floating
object is moved by them. `anchored_line(..., waves=True)` adds that wave
([`anchored_line_wave`][jaxcable.examples._anchored_line.anchored_line_wave]): an Airy wave of amplitude A
and period T_w in the 200 m of water, phased so that the water at the surface under the
fairlead moves along x exactly as the fairlead does. Without it (the default) the line
hangs in still water and only its top is driven.
"""

import numpy as np

from .._model.materials import AbstractTensionLaw, NonlinearElastic
from .._model.motion import Fixed, Harmonic
from .._model.network import Branch, CableNetwork, LineType
from .._sea.environment import Environment
from .._sea.waves import Airy, airy_wavenumber, floater_amplitude

DEPTH = 200.0  # H (m)
MASS_PER_LENGTH = 3.0  # m (kg/m)
AREA = 0.0003  # F (m²)
NORMAL_DRAG = 15.6  # C_n (kg/m²)
TANGENTIAL_DRAG = 0.78  # C_τ (kg/m²)
ADDED_MASS = 0.4  # m_a (kg/m), on the whole relative acceleration (Bezverkhyy & Korniienko, eq. 4)
AXIAL_STIFFNESS = 3.0e7  # C_E (N): our choice, see the module docstring
WAVE_PERIOD = 5.6  # T_w (s)


def anchored_line_type(tension_law: AbstractTensionLaw, water_density: float = 1025.0) -> LineType:
    """The anchored-line paper's cable (m = 3 kg/m, F = 0.0003 m², C_n = 15.6 and C_τ = 0.78 kg/m²,
    C_a = 0.4 kg/m on the whole relative acceleration) with the given tension law; seed
    002 uses the same cable. The drag coefficients are converted to K_n, K_τ on the
    diameter of a circle of area F."""
    rho = water_density
    diameter = float(np.sqrt(4 * AREA / np.pi))
    return LineType(
        mass_per_length=MASS_PER_LENGTH,
        diameter=diameter,
        area=AREA,
        tension_law=tension_law,
        normal_drag=NORMAL_DRAG / (0.5 * rho * diameter),
        tangential_drag=TANGENTIAL_DRAG / (0.5 * rho * np.pi * diameter),
        normal_added_mass=ADDED_MASS / (rho * AREA),
        tangential_added_mass=ADDED_MASS / (rho * AREA),
    )


def anchored_line_wave(angle_degrees: float = 30.0, period: float = WAVE_PERIOD, gravity: float = 9.81) -> Airy:
    """The paper's progressive wave, locked in phase to the fairlead's motion.

    An Airy wave of amplitude A = 0.085 (g T_w²/2π)^0.75 (height 2A) and period T_w in
    water of depth H = 200 m, travelling along +x (from the anchor towards the floating
    object), with `η = A cos(k x − ω t + θ₀)`. A surface particle's horizontal
    displacement is then `A coth(kd) sin(ω t − k x − θ₀)`; `θ₀ = −k X_N`, X_N = H cot α,
    makes it `A coth(kd) sin(ω t)` at the fairlead, the fairlead's own motion
    `x_N = A sin(ω t) + X_N` (eq. 6): the floating object moves with the water. At
    T_w = 5.6 s the water is deep (kd = 25.7) and coth(kd) − 1 is 5e-23.

    **Arguments:**

    - `angle_degrees`: α (°), which places the fairlead.
    - `period`: T_w (s).
    - `gravity`: g (m/s²).
    """
    amplitude = floater_amplitude(period, gravity)
    k = airy_wavenumber(period, DEPTH, gravity)
    fairlead_x = DEPTH / np.tan(np.radians(angle_degrees))
    return Airy(2 * amplitude, period, DEPTH, gravity=gravity, phase=-k * fairlead_x)


def anchored_line(
    n_segments: int = 20,
    angle_degrees: float = 30.0,
    quadratic_ratio: float = 0.1,
    period: float = WAVE_PERIOD,
    slack_width: float = 1e-5,
    mass_matrix: str = "consistent",
    hydrodynamics: str = "segments",
    waves: bool = False,
) -> tuple[CableNetwork, Environment]:
    """The anchored line, driven at its top.

    **Arguments:**

    - `n_segments`: segments along the line.
    - `angle_degrees`: α, the design angle to the seabed (30, 45 or 60 in the paper).
    - `quadratic_ratio`: C_E1 / C_E (0, 0.05, 0.1 or 0.2 in the paper).
    - `period`: T_w (s), the period of the fairlead motion.
    - `slack_width`: the slack switch's smoothing band (strain).
    - `mass_matrix`: `"consistent"` or `"lumped"`.
    - `hydrodynamics`: `"segments"` or `"nodes"` (MoorDyn's form; with `"lumped"`),
        see [`jaxcable.CableNetwork`][].
    - `waves`: also load the line with the wave that moves its top
        ([`anchored_line_wave`][jaxcable.examples._anchored_line.anchored_line_wave]), in water 200 m
        deep; `False` (default) for still water.

    **Returns:**

    `(model, environment)`: node 0 is the anchor at (0, 0, −H); the last junction, node
    1, is the fairlead at (H cot α, 0, 0).
    """
    if not isinstance(waves, bool):
        raise ValueError(f"anchored_line: waves must be True or False, got {waves!r}")
    if waves:
        wave = anchored_line_wave(angle_degrees, period)
        env = Environment(water_density=1025.0, gravity=9.81, depth=DEPTH, waves=(wave,))
    else:
        env = Environment(water_density=1025.0, gravity=9.81)
    alpha = np.radians(angle_degrees)
    anchor = np.array([0.0, 0.0, -DEPTH])
    fairlead = np.array([DEPTH / np.tan(alpha), 0.0, 0.0])
    line = anchored_line_type(
        NonlinearElastic(AXIAL_STIFFNESS, quadratic_ratio * AXIAL_STIFFNESS, slack_width), float(env.water_density)
    )
    model = CableNetwork.from_branches(
        junctions=np.stack([anchor, fairlead]),
        branches=[Branch(0, 1, line, float(np.linalg.norm(fairlead - anchor)), n_segments)],
        constraints={0: Fixed(), 1: Harmonic(floater_amplitude(period), period, direction=(1.0, 0.0, 0.0))},
        mass_matrix=mass_matrix,
        hydrodynamics=hydrodynamics,
    )
    return model, env


def anchored_line_in_current() -> tuple[CableNetwork, Environment]:
    """The line and water of the README's *Use from Python*: C_E = 3e7 N, C_E1 = 3e6 N,
    m = 3 kg/m, d = 19.5 mm, K_n = 1.2, K_τ = 0.01; anchor at (0, 0, −200) m, fairlead
    at (346.4, 0, 0) m moved along x with amplitude 1.57 m and period 5.6 s; 20
    segments; water of 1025 kg/m³ flowing at 0.5 m/s along x."""
    law = NonlinearElastic(axial_stiffness=3.0e7, quadratic_stiffness=3.0e6)
    line = LineType(mass_per_length=3.0, diameter=0.0195, tension_law=law, normal_drag=1.2, tangential_drag=0.01)
    model = CableNetwork.from_branches(
        junctions=[[0.0, 0.0, -200.0], [346.4, 0.0, 0.0]],
        branches=[Branch(0, 1, line, length=400.0, segments=20)],
        constraints={0: Fixed(), 1: Harmonic(amplitude=1.57, period=5.6)},
    )
    return model, Environment(water_density=1025.0, current=(0.5, 0.0, 0.0))
