"""jaxcable.equations: the equations of motion, for users who look under `simulate`.

The Lagrangian's parts and the forces it gives, as pure functions of a model, an
environment and a state (`_equations/lagrangian.py` derives them), the first-order vector field
that [`jaxcable.simulate`][] integrates, the smoothed slack switch H(ε) of the tension
laws, and the stiffest axial mode that limits an explicit step.
"""

from ._equations.lagrangian import (
    generalised_forces as generalised_forces,
)
from ._equations.lagrangian import (
    kinetic_energy as kinetic_energy,
)
from ._equations.lagrangian import (
    potential_energy as potential_energy,
)
from ._equations.lagrangian import (
    tension as tension,
)
from ._equations.modes import stiffest_axial_mode as stiffest_axial_mode
from ._model.materials import slack_switch as slack_switch
from ._simulation.simulate import vector_field as vector_field
