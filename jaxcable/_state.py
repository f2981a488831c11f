"""The state of a network: node positions and velocities, nothing else.

Tension and strain are pure functions of (model, state); see `_lagrangian`.
"""

import equinox as eqx
import numpy as np
from jaxtyping import Array, Float


class State(eqx.Module):
    """Node positions (m) and velocities (m/s), each of shape `(nodes, 3)`.

    Only the free nodes' entries are used as initial conditions: constrained nodes
    always follow their motions.
    """

    positions: Float[Array | np.ndarray, "nodes 3"]
    velocities: Float[Array | np.ndarray, "nodes 3"]
