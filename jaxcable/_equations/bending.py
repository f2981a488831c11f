"""Bending stiffness: the discrete bending energy at each hinge of a line.

A hinge is a node inside a line ([`jaxcable._model.network.Topology`][]'s `hinge_nodes`),
with segments `d₁ = x − x_prev` and `d₂ = x_next − x`, unit `u₁ = d₁/|d₁|`,
`u₂ = d₂/|d₂|`, and the angle θ between them, `cos θ = u₁ · u₂`. Its energy is

    E = EI/ℓ̄ (1 − cos θ) = ½ EI κ² ℓ̄,    κ = 2 sin(θ/2) / ℓ̄,

with EI the mean of its two segments' bending stiffness (N·m²) and ℓ̄ the mean of
their unstretched lengths (m). κ is MoorDyn v2's discrete curvature (`Line.cpp`,
`GetCurvature`: 4 sin(θ/2) over the sum of the two segments' lengths), and ½ EI κ²
per unit length is the elastica's energy, so this is MoorDyn's curvature put into
the Lagrangian. MoorDyn applies forces `EI κ / l` on the two neighbours,
perpendicular to their segments, which is not the gradient of an energy (its ℓ̄ is
stretched, its directions the node's tangent); to first order in θ and the strain the
two agree. The forces here are the exact `−∂E/∂x`:

    ∂cos θ/∂d₁ = (u₂ − cos θ u₁)/|d₁|,   ∂cos θ/∂d₂ = (u₁ − cos θ u₂)/|d₂|,

so the previous node takes `−EI/ℓ̄ ∂cos θ/∂d₁`, the next `+EI/ℓ̄ ∂cos θ/∂d₂`, and the
hinge the difference, which sums to zero (no net force) and to no net moment.

A line's ends, its junctions and bodies are pinned (no hinge), as MoorDyn's points
are; a constrained node inside a line is a hinge, which is how a line is clamped
(prescribe its first two nodes: the first segment's direction is then fixed).

Everything here is component-major, `(3, nodes)`, as in `jaxcable._equations.lagrangian`.
"""

import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float

from .._model.indexing import sum_into, take
from .._model.network import CableNetwork
from .hydro import dot


def has_bending(model: CableNetwork) -> bool:
    """Whether `model` has bending stiffness, known when tracing: a model without it
    compiles none of this module's code.

    **Raises:**

    `ValueError` if the line has bending stiffness but the topology has no hinges
    planned: a line swapped in (`eqx.tree_at`) on a network built without bending.
    """
    bends = model.line.bending_stiffness is not None
    if bends and not model.topology.bending:
        raise ValueError(
            "CableNetwork.line has bending_stiffness but its topology was built without bending: "
            "build the CableNetwork with the bending line (EI is planned when the network is built)"
        )
    return bends


def _hinges(model: CableNetwork, stretched, tangent):
    """Each hinge's stiffness EI/ℓ̄ (N·m), unit segments u₁ and u₂, their stretched
    lengths (m), cos θ, and the signs σ₁, σ₂ (static, ±1) that turn its two segments'
    tangents into u₁ and u₂, from the segments' stretched lengths and unit tangents
    (shapes `(segments,)` and `(3, segments)`). A segment runs from its start node to its
    end; σ is −1 where it runs towards the hinge's previous node or from its next."""
    nodes, segments = model.topology.hinge_nodes, model.topology.hinge_segments
    ends = model.topology.segment_nodes
    signs = [np.where(ends[segments[k], 1] == nodes[k + 1], 1.0, -1.0) for k in (0, 1)]

    def unit(k):
        u = take(tangent, segments[k])
        return u if np.all(signs[k] > 0) else u * signs[k]

    u1, u2 = unit(0), unit(1)
    s1, s2 = take(stretched, segments[0]), take(stretched, segments[1])
    ei = model.line.bending_stiffness
    assert ei is not None, "a hinge needs the line's bending stiffness (see has_bending)"
    ei = jnp.broadcast_to(ei, (model.n_segments,))
    length = model.segment_length
    # The means' ratio: (EI_a + EI_b)/2 over (L_a + L_b)/2.
    stiffness = (take(ei, segments[0]) + take(ei, segments[1])) / (
        take(length, segments[0]) + take(length, segments[1])
    )
    return stiffness, u1, u2, s1, s2, dot(u1, u2), signs


def bending_energy(model: CableNetwork, stretched, tangent) -> Float[Array, ""]:
    """Σ EI/ℓ̄ (1 − cos θ) (J) over the hinges, from the segments' stretched lengths
    (m, shape `(segments,)`) and unit tangents (component-major `(3, segments)`)."""
    stiffness, _, _, _, _, cos, _ = _hinges(model, stretched, tangent)
    return jnp.sum(stiffness * (1.0 - cos))


def bending_pull(model: CableNetwork, stretched, tangent) -> Float[Array, "3 segments"]:
    """`−∂E/∂x` of [`bending_energy`][] (N), written out, as a pull along each segment:
    the force on its start node, and its negative on its end node, as the axial
    tension's `T τ`, so that the two are summed onto the nodes together. From the
    segments' geometry as `bending_energy` takes it; component-major `(3, segments)`.

    With g₁ = −∂E/∂d₁ and g₂ = −∂E/∂d₂ (module notes), the previous node takes −g₁ and
    the hinge g₁ along its first segment, the hinge −g₂ and the next node g₂ along its
    second: a pull of −σ g on each, σ its sign."""
    stiffness, u1, u2, s1, s2, cos, signs = _hinges(model, stretched, tangent)
    g1 = stiffness * (u2 - cos * u1) / s1
    g2 = stiffness * (u1 - cos * u2) / s2
    plans = model.topology.hinge_sums

    def along(g, k):
        return sum_into(g if np.all(signs[k] > 0) else g * signs[k], plans[k])

    return -(along(g1, 0) + along(g2, 1))
