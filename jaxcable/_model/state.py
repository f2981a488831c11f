"""The state of a network: node positions and velocities, nothing else.

Tension and strain are pure functions of (model, state); see `_equations.lagrangian`.
"""

import equinox as eqx
import numpy as np
from jaxtyping import Array, Float


class State(eqx.Module):
    """Node positions (m) and velocities (m/s), each of shape `(nodes, 3)`, or
    `(cases, nodes, 3)` for one state per case (a [`jaxcable.sweep`][]'s `initial`).

    Only the free nodes' entries are used as initial conditions: constrained nodes
    always follow their motions.
    """

    positions: Float[Array | np.ndarray, "*cases nodes 3"]
    velocities: Float[Array | np.ndarray, "*cases nodes 3"]
