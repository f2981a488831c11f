"""The README's anchored line: a 400 m nonlinear-elastic rope from an anchor 200 m down
to a fairlead moved harmonically, in a 0.5 m/s current. Its top segment goes slack
near 3 s and snaps back, so derivatives through it are the README's example of an
ill-conditioned sensitivity (`benchmarks/derivative_growth.py`)."""

from .._model.materials import NonlinearElastic
from .._model.motion import Fixed, Harmonic
from .._model.network import Branch, CableNetwork, LineType
from .._sea.environment import Environment


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
