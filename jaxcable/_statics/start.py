"""The start of the statics' continuation: each chain of segments between constrained
nodes or junctions laid as a catenary sagging (or arching) along its load, so that the
first pseudo-time steps start near the equilibrium's shape."""

import functools
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from .._model.network import _GUESS_STRETCH, Topology


class _Chains(NamedTuple):
    """The network's chains (see `chains`), as static index arrays."""

    ends: np.ndarray  # (chains, 2): each chain's first and last node
    tail: np.ndarray  # (chains,): whether its last node is a free node that joins nothing else
    moving: np.ndarray  # the nodes a start shape places: inner nodes, and a tail's last
    owner: np.ndarray  # each moving node's chain
    segments: np.ndarray  # every chain's segments, chain by chain, each from its first node
    before: np.ndarray  # each moving node's place in `segments`: the segment that ends at it
    first: np.ndarray  # (chains,): where each chain starts in `segments`


@functools.lru_cache(maxsize=32)
def _chains(topology: Topology) -> _Chains:
    """The network's chains: runs of segments through nodes that join exactly two (not
    constrained, not a line's end). A tail is a chain whose last node is a free node
    that joins nothing else (a hanging line's end, a riser's buoy). A chain that
    places nothing (one segment between two junctions, a loop) is left out."""
    neighbours = [[] for _ in range(topology.n_nodes)]
    for s, (i, j) in enumerate(topology.segment_nodes):
        neighbours[i].append((j, s))
        neighbours[j].append((i, s))
    junction = np.zeros(topology.n_nodes, dtype=bool)
    junction[topology.line_ends] = True
    constrained = np.zeros(topology.n_nodes, dtype=bool)
    constrained[topology.constrained_nodes] = True
    seen, ends, tail, moving, owner, segments, before, first = set(), [], [], [], [], [], [], []
    for start in topology.line_ends:
        for node, segment in neighbours[start]:
            if segment in seen:
                continue
            path, run = [int(start)], [segment]
            seen.add(segment)
            while not junction[node]:
                path.append(int(node))
                node, segment = next((n, s) for n, s in neighbours[node] if s != segment)
                run.append(segment)
                seen.add(segment)
            path.append(int(node))
            tip = [len(neighbours[k]) == 1 and not constrained[k] for k in (path[0], path[-1])]
            if tip[0] and tip[1]:
                continue  # a loose piece: `check_held` refuses it
            if tip[0]:
                path.reverse()
                run.reverse()
            placed = path[1:] if tip[0] or tip[1] else path[1:-1]
            if not placed or path[0] == path[-1]:
                continue
            ends.append((path[0], path[-1]))
            tail.append(tip[0] or tip[1])
            owner += [len(ends) - 1] * len(placed)
            moving += placed
            before += [len(segments) + k for k in range(len(placed))]
            first.append(len(segments))
            segments += run
    arrays = (ends, tail, moving, owner, segments, before, first)
    return _Chains(*(np.asarray(x, dtype=np.int64) for x in arrays))


def start_shape(model, env, positions, water):
    """`positions` (m, shape `(nodes, 3)`), with each chain (see `chains`) put on its
    own analytic shape under its load, where that lowers the load's potential. The
    load is the chain's wet weight, bodies' weight, buoyancy and constant force, and
    the drag on it at rest, summed into one direction ĝ. A chain between two nodes
    goes on the inextensible catenary of its length (stretched by the 0.1 % that
    `CableNetwork.from_branches` stretches it) hanging along ĝ in the plane of its
    chord and ĝ: its nodes at their arc lengths, where that catenary's nodes have less
    potential `−Σ F · x` under the nodes' loads F than the given ones. A tail is turned
    about its first node until its chord points along ĝ, where it points against it.
    So a buoyant line that `from_branches` hung on a downward catenary starts arched
    upward, and a buoyant line hanging from a point starts standing up from it, rather
    than floating up through slack, which the root finder crosses only in many short
    steps (as on random scenes of `benchmarks/statics_fuzz.py`); a line in a current
    starts in the plane its drag tilts it into; and a start nearer the equilibrium than
    the catenary (a solved shape, whose stretch lowers it further) is kept."""
    chains = _chains(model.topology)
    if not chains.moving.size:
        return positions
    ends, tail, moving, owner = chains.ends, chains.tail, chains.moving, chains.owner
    line, body = model.line, model.body
    g, rho = env.gravity, env.water_density
    up = jnp.array([0.0, 0.0, 1.0])
    wet = jnp.broadcast_to((rho * line.area - line.mass_per_length) * g * model.segment_length, (model.n_segments,))
    nodes = model.segment_nodes
    lift = jnp.zeros(model.n_nodes).at[nodes[:, 0]].add(0.5 * wet).at[nodes[:, 1]].add(0.5 * wet)
    lift = lift + (rho * body.volume - body.mass) * g
    load = (lift[:, None] * up + body.force + water)[moving]
    count = ends.shape[0]
    down = _unit(jax.ops.segment_sum(load, owner, count))
    pivot, far = positions[ends[:, 0]], positions[ends[:, 1]]
    chord = far - pivot

    # A chain between two nodes, in the frame of its catenary: `rise` along −ĝ,
    # `across` the rest of the chord, and arc lengths along its segments.
    rise = -jnp.sum(chord * down, axis=-1)
    across = chord + rise[:, None] * down
    h = jnp.linalg.norm(across, axis=-1)
    length = jnp.broadcast_to(model.segment_length, (model.n_segments,))[chains.segments]
    of_segment = np.repeat(np.arange(count), np.diff([*chains.first, length.size]))
    run = jnp.cumsum(length)
    fraction = (run[chains.before] - (run - length)[chains.first][owner]) / jax.ops.segment_sum(
        length, of_segment, count
    )[owner]
    target = (1 + _GUESS_STRETCH) * length
    slack = (h > 0) & (jnp.sum(target) > 0) & ~tail
    slack = slack & (jax.ops.segment_sum(target, of_segment, count) > jnp.linalg.norm(chord, axis=-1))
    h = jnp.where(slack, h, 1.0)

    def catenary(total):
        """The chains' moving nodes on catenaries of arc lengths `total` (m)."""
        reach = jnp.sqrt(jnp.where(slack, jnp.maximum(total**2 - rise**2, 0.0), 1.0))

        def bisect(_, bounds):  # 2a sinh(h/2a) falls from ∞ to h as a grows
            low, high = bounds
            a = jnp.sqrt(low * high)
            longer = 2 * a * jnp.sinh(jnp.minimum(h / (2 * a), 700.0)) > reach
            return jnp.where(longer, a, low), jnp.where(longer, high, a)

        a = jnp.sqrt(jnp.prod(jnp.stack(jax.lax.fori_loop(0, 100, bisect, (1e-6 * h, 1e6 * h))), axis=0))
        x0 = h / 2 - a * jnp.arctanh(jnp.clip(rise / total, -1 + 1e-15, 1 - 1e-15))
        a, x0, arc = a[owner], x0[owner], fraction * total[owner]
        x = x0 + a * jnp.arcsinh(arc / a + jnp.sinh(-x0 / a))
        z = a * (jnp.cosh((x - x0) / a) - jnp.cosh(x0 / a))
        return pivot[owner] + x[:, None] * (across / h[:, None])[owner] - z[:, None] * down[owner]

    # Sampled at arc lengths, the chords across a tight bend are shorter than their
    # arcs, so those segments start slack. `from_branches` lengthens the arc until no
    # chord is; here that would stretch the segments away from a coarse chain's bend,
    # by as much as 96 %, where a slack segment only slows the solve.
    shape = catenary(jax.ops.segment_sum(target, of_segment, count))
    given = positions[moving]
    lower = jax.ops.segment_sum(jnp.sum(load * (given - shape), axis=-1), owner, count) < 0
    # (A catenary that overflowed is not finite, so not lower.)
    use = (slack & lower)[owner, None]

    # A tail, turned about its first node from its chord towards ĝ, where they are
    # more than 90° apart (about any axis across the chord where exactly opposite).
    turned = _unit(chord)
    normal = jnp.cross(turned, down)
    across_x = jnp.cross(turned, jnp.array([1.0, 0.0, 0.0]))
    fallback = _unit(
        jnp.where(jnp.linalg.norm(across_x, axis=-1, keepdims=True) > 0.1, across_x, jnp.cross(turned, up))
    )
    axis = jnp.where(jnp.linalg.norm(normal, axis=-1, keepdims=True) > 1e-9, _unit(normal), fallback)
    cos = jnp.sum(turned * down, axis=-1)
    against = tail & (cos < 0)
    cos, sin = jnp.where(against, cos, 1.0), jnp.where(against, jnp.linalg.norm(normal, axis=-1), 0.0)
    # Rodrigues: v cos θ + (k × v) sin θ + k (k · v)(1 − cos θ).
    k, c, s_ = axis[owner], cos[owner, None], sin[owner, None]
    offset = given - pivot[owner]
    rotated = (
        pivot[owner] + offset * c + jnp.cross(k, offset) * s_ + k * jnp.sum(k * offset, -1, keepdims=True) * (1 - c)
    )
    return positions.at[moving].set(jnp.where(use, shape, rotated))


def _unit(vectors):
    """`vectors` (shape `(n, 3)`) over their lengths; zero where a length is zero."""
    length = jnp.linalg.norm(vectors, axis=-1, keepdims=True)
    return vectors / jnp.where(length > 0, length, 1.0)
