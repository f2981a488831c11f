"""Which segments of a network can reach the seabed, or rise above the still-water
level, during a run: a geometric bound from the supports, the lines' lengths and the
supports' motions, for the stability check and for leaving out what a run cannot meet.

The seabed's contact modes are the fastest of a scene that has one (its spring and
damper act on a node's small mass: |λ| of 1,700 1/s against 600 for the axial mode of
a 40-segment steel rope). Counted for every segment, they refuse a fixed step on a line
that hangs from its anchor and never reaches the bed, and send the run to adaptive
steps. A node is held within reach of each support by the lines between them: along
the shortest path of segments from support c, it lies in the ball of radius
`D_c = Σ L (1 + ε_max)` about the support's position, widened by how far the support
moves (`AbstractMotion.excursion`). Its lowest possible z is then at least

- `z_c − down_c − D_c` for every support c (the bottom of one ball), and
- the lowest point of the intersection of the balls of every pair of supports (the
  line between an anchor and a fairlead cannot sag below the lens the two spheres
  bound),

and its highest at most the same bounds mirrored in z. A segment can reach the bed (or
rise above the surface) where one of its nodes can: it is straight, so its lowest and
highest points are nodes. The bound assumes nothing about the dynamics: no strain
beyond ε_max (below), the supports within their excursions.

ε_max is the strain at which the segment's tension law carries `BREAKING_STRESS` on its
section area F: `C_E ε + C_E1 ε² = σ F`. No mooring material carries that stress
(steel wire breaks at 1.8–2.2 GPa on its metal area, the strongest fibre ropes below
that on theirs, chain's breaking load is far lower on its volume-equivalent area), so
a line would have broken before stretching further. A soft line (small C_E for its
area) gets a long reach, and counts where it can sag to the bed.
"""

import dataclasses
import heapq

import numpy as np

from .._sea.environment import Environment
from .network import CableNetwork

BREAKING_STRESS = 4.0e9
"""σ (Pa): a stress on a segment's section area F that no mooring line carries (module
notes); the strain it takes bounds how far a line can stretch."""


def largest_strain(model: CableNetwork) -> np.ndarray:
    """ε_max of each segment (module notes), shape `(segments,)`: the strain at which its
    tension law carries `BREAKING_STRESS` on its area; infinite where the law never
    reaches that tension (a falling quadratic term) or the area is not positive."""
    law = model.line.tension_law
    shape = (model.n_segments,)
    c_e = np.broadcast_to(np.asarray(law.axial_stiffness, dtype=float), shape)
    c_e1 = np.broadcast_to(np.asarray(law.quadratic_stiffness(), dtype=float), shape)
    load = BREAKING_STRESS * np.broadcast_to(np.asarray(model.line.area, dtype=float), shape)
    discriminant = c_e**2 + 4 * c_e1 * load
    with np.errstate(invalid="ignore", divide="ignore"):
        # The smaller positive root of C_E1 ε² + C_E ε − σF, in the form that holds at C_E1 = 0.
        strain = 2 * load / (c_e + np.sqrt(np.maximum(discriminant, 0.0)))
    return np.where((discriminant >= 0) & (load > 0) & np.isfinite(strain), strain, np.inf)


def path_lengths(model: CableNetwork, stretch: np.ndarray, sources: np.ndarray) -> np.ndarray:
    """The shortest path (m) along segments from each node in `sources` to every node,
    each segment's length its rest length times `stretch` (shape `(segments,)`): shape
    `(sources, nodes)`, infinite where no path joins them. Dijkstra's algorithm from each
    source, O(segments log nodes) each: a line of 10,000 segments takes about 30 ms a
    support."""
    ends = np.asarray(model.segment_nodes)
    length = np.broadcast_to(np.asarray(model.segment_length, dtype=float), (model.n_segments,)) * stretch
    # Each node's neighbours, both directions of every segment, as compressed rows.
    heads = np.concatenate([ends[:, 0], ends[:, 1]])
    order = np.argsort(heads, kind="stable")
    neighbours = np.concatenate([ends[:, 1], ends[:, 0]])[order].tolist()
    weights = np.concatenate([length, length])[order].tolist()
    first = np.searchsorted(heads[order], np.arange(model.n_nodes + 1)).tolist()
    distance = np.full((len(sources), model.n_nodes), np.inf)
    for row, source in enumerate(np.asarray(sources).tolist()):
        best = [np.inf] * model.n_nodes
        best[source] = 0.0
        queue = [(0.0, source)]
        while queue:
            d, node = heapq.heappop(queue)
            if d > best[node]:
                continue
            for k in range(first[node], first[node + 1]):
                other, through = neighbours[k], d + weights[k]
                if through < best[other]:
                    best[other] = through
                    heapq.heappush(queue, (through, other))
        distance[row] = best
    return distance


def lens_bottom(a: np.ndarray, ra: np.ndarray, b: np.ndarray, rb: np.ndarray) -> np.ndarray:
    """The lowest z (m) of the intersection of the ball of radius `ra` about `a` and of
    radius `rb` about `b` (centres shape `(3,)`, radii shape `(nodes,)`); −∞ where the
    balls do not meet or a radius is infinite (no bound)."""
    offset = b - a
    d = float(np.linalg.norm(offset))
    with np.errstate(invalid="ignore"):
        # A ball's bottom inside the other ball is the lens's bottom.
        a_bottom_inside = (offset[0] ** 2 + offset[1] ** 2 + (offset[2] + ra) ** 2) <= rb**2
        b_bottom_inside = (offset[0] ** 2 + offset[1] ** 2 + (offset[2] - rb) ** 2) <= ra**2
        if d > 0:
            # Otherwise the lowest point of the circle where the spheres meet: its centre
            # at x along the axis from a, its radius h, in the plane normal to the axis.
            x = (d**2 + ra**2 - rb**2) / (2 * d)
            h = np.sqrt(np.maximum(ra**2 - x**2, 0.0))
            axis_z = offset[2] / d
            circle = a[2] + x * axis_z - h * np.sqrt(max(1.0 - axis_z**2, 0.0))
        else:
            circle = np.full(np.shape(ra), -np.inf)
    bottom = np.where(a_bottom_inside, a[2] - ra, np.where(b_bottom_inside, b[2] - rb, circle))
    meets = np.isfinite(ra) & np.isfinite(rb) & (ra + rb >= d)
    return np.where(meets, bottom, -np.inf)


def reach_bounds(model: CableNetwork, duration: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Bounds on each node's z (m) over a run of `duration` (s; any length where `None`):
    `(lowest, highest)`, each shape `(nodes,)`, by the module notes' balls about the
    supports (the highest as the lowest of the network mirrored in z = 0). ∓∞ for a
    node that no support holds (a free part of the network)."""
    supports = np.asarray(model.constrained_nodes)
    if supports.size == 0:
        return np.full(model.n_nodes, -np.inf), np.full(model.n_nodes, np.inf)
    excursions = np.array([motion.excursion(duration) for motion in model.motions], dtype=float).reshape(-1, 3)
    down, up, widen = excursions.T
    reference = np.asarray(model.node_positions, dtype=float)[supports]
    distance = path_lengths(model, 1.0 + largest_strain(model), supports)
    mirrored = reference * np.array([1.0, 1.0, -1.0])
    lowest = np.max(reference[:, 2, None] - down[:, None] - distance, axis=0)
    highest = np.min(reference[:, 2, None] + up[:, None] + distance, axis=0)
    for i in range(len(supports)):
        for j in range(i + 1, len(supports)):
            ri, rj = distance[i] + widen[i], distance[j] + widen[j]
            lowest = np.maximum(lowest, lens_bottom(reference[i], ri, reference[j], rj))
            highest = np.minimum(highest, -lens_bottom(mirrored[i], ri, mirrored[j], rj))
    return lowest, highest


def seabed_reach(model: CableNetwork, env: Environment, duration: float | None = None) -> np.ndarray:
    """Which segments can reach the seabed (z = −depth) in a run of `duration` (s; any
    length where `None`): a boolean mask, shape `(segments,)`, all false without a
    seabed. Conservative (module notes): a segment left out cannot touch the bed
    without a line stretching beyond ε_max or a support leaving its motion's bounds."""
    if env.seabed is None or env.depth is None:
        return np.zeros(model.n_segments, bool)
    reaches = reach_bounds(model, duration)[0] <= -float(env.depth)
    return np.any(reaches[np.asarray(model.segment_nodes)], axis=1)


def surface_reach(model: CableNetwork, duration: float | None = None) -> np.ndarray:
    """Which segments can reach above the still-water level z = 0 in a run of `duration`
    (s), where the free surface cuts them: a boolean mask, shape `(segments,)`, by the
    same bound as [`seabed_reach`][jaxcable._model.reach.seabed_reach]. A segment whose ends
    stay at or below z = 0 is wholly submerged, as without the surface."""
    reaches = reach_bounds(model, duration)[1] > 0.0
    return np.any(reaches[np.asarray(model.segment_nodes)], axis=1)


def for_run(model: CableNetwork, env: Environment, duration: float | None = None) -> Environment:
    """`env` as a run of `duration` (s) of `model` needs it ("model no more than a scene
    needs"): without its seabed where no segment can reach the bed
    ([`seabed_reach`][jaxcable._model.reach.seabed_reach]), and without the free surface
    where no segment can rise above z = 0 ([`surface_reach`][jaxcable._model.reach.surface_reach]),
    so that the run's program compiles neither. The forces are the same: the bed's are
    zero above it, and a segment below z = 0 is wholly wet either way. On a 40-segment
    line the seabed costs 7 % of an evaluation, the free surface 30 %."""
    if env.seabed is not None and not seabed_reach(model, env, duration).any():
        env = env.without_seabed()
    if env.free_surface and not surface_reach(model, duration).any():
        env = dataclasses.replace(env, free_surface=False)
    return env
