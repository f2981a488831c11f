"""Bending stiffness: the discrete bending energy at each hinge of a line.

A hinge is a node inside a line ([`jaxcable._network.Topology`][]'s `hinge_nodes`),
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

Everything here is component-major, `(3, nodes)`, as in `jaxcable._lagrangian`.
"""

import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float

from ._hydro import dot
from ._indexing import sum_into, take
from ._network import CableNetwork


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


def _hinges(model: CableNetwork, stretched, tangent) -> tuple[Array, Array, Array, Array, Array, Array]:
    """Each hinge's stiffness EI/ℓ̄ (N·m), unit segments u₁ and u₂, their stretched
    lengths (m), and cos θ, from the segments' stretched lengths and unit tangents
    (shapes `(segments,)` and `(3, segments)`): a hinge's segments are the network's,
    turned where a segment runs towards the hinge's previous node or from its next."""
    nodes, segments = model.topology.hinge_nodes, model.topology.hinge_segments
    ends = model.topology.segment_nodes

    def unit(k, towards):
        u = take(tangent, segments[k])
        sign = np.where(ends[segments[k], 1] == nodes[towards], 1.0, -1.0)
        return u if np.all(sign > 0) else u * sign

    u1, u2 = unit(0, 1), unit(1, 2)
    s1, s2 = take(stretched, segments[0]), take(stretched, segments[1])
    ei = model.line.bending_stiffness
    assert ei is not None, "a hinge needs the line's bending stiffness (see has_bending)"
    ei = jnp.broadcast_to(ei, (model.n_segments,))
    length = model.segment_length
    # The means' ratio: (EI_a + EI_b)/2 over (L_a + L_b)/2.
    stiffness = (take(ei, segments[0]) + take(ei, segments[1])) / (
        take(length, segments[0]) + take(length, segments[1])
    )
    return stiffness, u1, u2, s1, s2, dot(u1, u2)


def bending_energy(model: CableNetwork, stretched, tangent) -> Float[Array, ""]:
    """Σ EI/ℓ̄ (1 − cos θ) (J) over the hinges, from the segments' stretched lengths
    (m, shape `(segments,)`) and unit tangents (component-major `(3, segments)`)."""
    stiffness, _, _, _, _, cos = _hinges(model, stretched, tangent)
    return jnp.sum(stiffness * (1.0 - cos))


def bending_forces(model: CableNetwork, stretched, tangent) -> Float[Array, "3 nodes"]:
    """`−∂E/∂x` (N) of [`bending_energy`][], written out, component-major `(3, nodes)`,
    from the segments' geometry as `bending_energy` takes it."""
    stiffness, u1, u2, s1, s2, cos = _hinges(model, stretched, tangent)
    g1 = stiffness * (u2 - cos * u1) / s1
    g2 = stiffness * (u1 - cos * u2) / s2
    plans = model.topology.hinge_sums
    # Each role summed onto the nodes apart: slices along a line, where summing one
    # concatenation of the three made XLA recompute g₁ and g₂ in every slice.
    return sum_into(-g1, plans[0]) + sum_into(g1 - g2, plans[1]) + sum_into(g2, plans[2])
