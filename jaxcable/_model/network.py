"""The model: a cable network as a graph of nodes and straight segments.

A single line, a branched system and a net are all the same object: segments are the
edges of a graph, given by `segment_nodes`, and every per-segment or per-node quantity is
an array whose first axis is indexed by segment or node. Float arrays are ordinary
pytree leaves, so any of them can be differentiated, swept with `eqx.tree_at`, or
vmapped. The topology (a [`Topology`][] of node indices, and motions' structure) is
static: part of the model's tree structure, known when tracing, never batched.
"""

from collections.abc import Mapping, Sequence
from typing import NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Bool, Float, Int

from .. import _checks as checks
from .._names import HYDRODYNAMICS as HYDRODYNAMICS
from .._names import MASS_MATRICES as MASS_MATRICES
from .._sea.environment import Environment
from .._typing import RealLike
from .indexing import incidence
from .materials import AbstractTensionLaw
from .motion import AbstractMotion


class LineType(eqx.Module):
    """The properties of a cable, per unit unstretched length.

    Every field is a scalar or an array with one entry per segment.

    **Arguments:**

    - `mass_per_length`: m (kg/m), in air.
    - `diameter`: d (m), the hydrodynamic diameter used for drag.
    - `tension_law`: a [`jaxcable.AbstractTensionLaw`][], such as
        [`jaxcable.NonlinearElastic`][].
    - `area`: F (m²), the displaced cross-section for buoyancy and added mass;
        `π d² / 4` by default.
    - `normal_drag`: K_n (–), giving C_n = ½ ρ K_n d. MoorDyn's `Cd`.
    - `tangential_drag`: K_τ (–), giving C_τ = ½ ρ K_τ π d. MoorDyn's `CdAx`.
    - `normal_added_mass`: C_a (–), added mass per length `C_a ρ F` normal to the line.
        MoorDyn's `Ca`.
    - `tangential_added_mass`: C_aτ (–), the same along the line. MoorDyn's `CaAx`.
    - `bending_stiffness`: EI (N·m²), MoorDyn's `EI`. `None` (the default) or zero
        everywhere: a cable without bending, whose programs compile no bending code.
        Otherwise each node inside a line takes the bending energy
        `EI/ℓ̄ (1 − cos θ)`, θ the angle between its two segments and ℓ̄ their mean
        unstretched length (see `jaxcable._equations.bending`). Zero on concrete values is
        `None`, so that the same file gives the same program with or without an `EI`
        column of zeros; to sweep EI from zero, build the line with a nonzero EI.

    **Raises:**

    `ValueError` naming the field and value for a non-finite or non-positive mass,
    diameter, area or axial stiffness, a negative drag, added mass, bending stiffness,
    damping or slack width, or a tension law that does not rise with strain up to
    ε = 1 ([`jaxcable.AbstractTensionLaw.rising`][]).
    """

    mass_per_length: Float[Array, "*segments"]
    diameter: Float[Array, "*segments"]
    tension_law: AbstractTensionLaw
    area: Float[Array, "*segments"]
    normal_drag: Float[Array, "*segments"]
    tangential_drag: Float[Array, "*segments"]
    normal_added_mass: Float[Array, "*segments"]
    tangential_added_mass: Float[Array, "*segments"]
    bending_stiffness: Float[Array, "*segments"] | None

    def __init__(
        self,
        mass_per_length: RealLike,
        diameter: RealLike,
        tension_law: AbstractTensionLaw,
        area: RealLike | None = None,
        normal_drag: RealLike = 1.2,
        tangential_drag: RealLike = 0.008,
        normal_added_mass: RealLike = 1.0,
        tangential_added_mass: RealLike = 0.0,
        bending_stiffness: RealLike | None = None,
    ):
        if not isinstance(tension_law, AbstractTensionLaw):
            raise ValueError(f"LineType.tension_law must be a jaxcable tension law, got {tension_law!r}")
        self.mass_per_length = checks.float_array("LineType.mass_per_length", mass_per_length)
        self.diameter = checks.float_array("LineType.diameter", diameter)
        if area is None:
            self.area = checks.on_device(np.pi * checks.on_host(self.diameter) ** 2 / 4)
        else:
            self.area = checks.float_array("LineType.area", area)
        self.tension_law = tension_law
        self.normal_drag = checks.float_array("LineType.normal_drag", normal_drag)
        self.tangential_drag = checks.float_array("LineType.tangential_drag", tangential_drag)
        self.normal_added_mass = checks.float_array("LineType.normal_added_mass", normal_added_mass)
        self.tangential_added_mass = checks.float_array("LineType.tangential_added_mass", tangential_added_mass)
        self.bending_stiffness = None
        if bending_stiffness is not None:
            ei = checks.float_array("LineType.bending_stiffness", bending_stiffness)
            # Concrete zeros are no bending: the scene then compiles none of its code.
            if checks.traced(ei) or np.any(checks.on_host(ei) != 0):
                self.bending_stiffness = ei
        checks.enforce(self.conditions())

    def conditions(self) -> list[checks.Condition]:
        """What the fields require, checked at construction on concrete values and, on
        traced or swept ones, by `simulate`, `solve_statics` and `sweep`."""
        law = self.tension_law
        out = []
        for name in ("mass_per_length", "diameter", "area"):
            out += [
                checks.finite(f"LineType.{name}", getattr(self, name)),
                checks.sign(f"LineType.{name}", getattr(self, name)),
            ]
        names = ("normal_drag", "tangential_drag", "normal_added_mass", "tangential_added_mass", "bending_stiffness")
        for name in names:
            value = getattr(self, name)
            if value is None:
                continue
            out += [checks.finite(f"LineType.{name}", value), checks.sign(f"LineType.{name}", value, allow_zero=True)]
        return out + [
            checks.finite("LineType.tension_law.axial_stiffness", law.axial_stiffness),
            checks.sign("LineType.tension_law.axial_stiffness", law.axial_stiffness),
            checks.finite("LineType.tension_law.quadratic_stiffness", law.quadratic_stiffness()),
            law.rising("LineType.tension_law"),
            checks.finite("LineType.tension_law.damping", law.damping()),
            checks.sign("LineType.tension_law.damping", law.damping(), allow_zero=True),
            checks.finite("LineType.tension_law.slack_width", law.slack_width),
            checks.sign("LineType.tension_law.slack_width", law.slack_width, allow_zero=True),
        ]


class Body(eqx.Module):
    """A point body at a node: a buoy, a clump weight, a diverter, a cage.

    Every field is a scalar or an array with one entry per node (`force`: a 3-vector, or
    one per node). Its drag is `(½ ρ C_D A + k₀ m_o g) |u| u` on the relative velocity
    u: form drag, Zhukov's specific-weight law `R = k₀ u² m_o g` (Zhukov's growing-element thesis, eq. 3), or
    both.

    **Arguments:**

    - `mass`: M (kg), in air.
    - `volume`: V (m³), displaced; buoyancy is ρ V g.
    - `drag_area`: C_D A (m²), MoorDyn's `CdA`.
    - `specific_drag`: k₀ (s²/m²), the specific-weight drag coefficient.
    - `organism_mass`: m_o (kg), the mass that k₀ refers to; `mass` by default.
    - `added_mass`: C_a (–), added mass `C_a ρ V`, MoorDyn's `Ca`.
    - `force`: a constant force (N) in the fixed frame, shape `(3,)`: a trawl
        diverter's spreading force (the branched-systems paper's F₀), a thruster, a load not otherwise
        modelled. Zero by default.
    - `height`: h (m). 0 (default): a point body, always fully submerged. Positive: a
        vertical column of height h and cross-section V/h centred on its node, which
        can float (a surface buoy, a float): its buoyancy, drag and fluid inertia act
        on the part below the water's surface, the waves' η at the node's (x, y); its
        added mass on the part below the still-water level z = 0, since the mass
        matrix does not depend on time.
    """

    mass: Float[Array, "*nodes"]
    volume: Float[Array, "*nodes"]
    drag_area: Float[Array, "*nodes"]
    specific_drag: Float[Array, "*nodes"]
    organism_mass: Float[Array, "*nodes"]
    added_mass: Float[Array, "*nodes"]
    force: Float[Array, "*nodes 3"]
    height: Float[Array, "*nodes"]

    def __init__(
        self,
        mass: RealLike = 0.0,
        volume: RealLike = 0.0,
        drag_area: RealLike = 0.0,
        specific_drag: RealLike = 0.0,
        organism_mass: RealLike | None = None,
        added_mass: RealLike = 0.0,
        force: RealLike = (0.0, 0.0, 0.0),
        height: RealLike = 0.0,
    ):
        self.mass = checks.float_array("Body.mass", mass)
        self.volume = checks.float_array("Body.volume", volume)
        self.drag_area = checks.float_array("Body.drag_area", drag_area)
        self.specific_drag = checks.float_array("Body.specific_drag", specific_drag)
        self.organism_mass = (
            self.mass if organism_mass is None else checks.float_array("Body.organism_mass", organism_mass)
        )
        self.added_mass = checks.float_array("Body.added_mass", added_mass)
        self.height = checks.float_array("Body.height", height)
        self.force = checks.float_array("Body.force", force)
        checks.enforce(self.conditions())
        if self.force.shape[-1:] != (3,):
            raise ValueError(f"Body.force must be a 3-vector (N), got shape {self.force.shape}")

    def conditions(self) -> list[checks.Condition]:
        """What the fields require (see [`jaxcable.LineType`][]'s)."""
        out = []
        for name in ("mass", "volume", "drag_area", "specific_drag", "organism_mass", "added_mass", "height"):
            value = getattr(self, name)
            out += [checks.finite(f"Body.{name}", value), checks.sign(f"Body.{name}", value, allow_zero=True)]
        return out + [checks.finite("Body.force", self.force)]


class Branch(NamedTuple):
    """One edge of a network's graph, divided into equal segments.

    - `start`, `end`: indices of the junction nodes it joins.
    - `line`: its [`jaxcable.LineType`][] (scalar fields).
    - `length`: its unstretched length (m).
    - `segments`: how many segments to divide it into.
    """

    start: int
    end: int
    line: LineType
    length: float
    segments: int


class Topology:
    """The graph of a network, as hashable static structure: which nodes each segment
    joins and which nodes are constrained.

    Held in a static field of [`jaxcable.CableNetwork`][], so it is known when tracing
    (under `jit`, `vmap` and in sweeps): topology checks run, the structured Jacobian
    applies, and indexing with it compiles to constant gathers. Two models whose
    topologies differ have different tree structures, so `jit` recompiles for them and
    a sweep refuses a topology that depends on its parameters.

    The arrays are read-only numpy copies; equality compares them, and the hash of
    their bytes is computed once, since `jit` hashes static structure on every call.

    **Arguments:**

    - `n_nodes`: the number of nodes.
    - `segment_nodes`: the two nodes each segment joins, shape `(segments, 2)`.
    - `constrained_nodes`: the constrained nodes, increasing, shape `(constrained,)`.
    - `line_ends`: nodes where a line ends besides those that join other than two
        segments and the constrained ones (a point joining two lines, a body), for the
        node stations below.

    **Node stations** (for `CableNetwork(hydrodynamics="nodes")`, MoorDyn's lumped
    hydrodynamics): a node inside a line is one station, whose direction is the chord
    through its two neighbours; at a line's end each segment that meets there is a
    station of its own, along that segment. `station_node[k]` is station k's node and
    `station_chord[:, k]` the two nodes whose difference gives its direction; stations
    run in node order, so that on a chain these are slices. `station_sums` plans the sum
    of the segments' ends (starts, then ends) onto stations, and `node_stations` that of
    stations onto nodes (`jaxcable._model.indexing.sum_into`).

    **Hinges** (with `bending=True`, for a line's bending stiffness): every node that
    joins exactly two segments and is not in `line_ends` (as given) bends.
    `hinge_nodes[:, k]` is hinge k's (previous, own, next) node, `hinge_segments[:, k]`
    its two segments (the one to the previous node first), and `hinge_sums[k]` plans
    the sum of per-hinge values onto their k-th segments (a segment is the first of at
    most one hinge, and the second of at most one). A
    constrained node inside a line bends too, so that prescribing a
    line's first two nodes clamps it (a cantilever); a line's end, a junction, a
    body's node and `from_branches`' junctions are pinned, as MoorDyn's points are.
    Without `bending` there are no hinges.
    """

    __slots__ = (
        "n_nodes",
        "segment_nodes",
        "constrained_nodes",
        "free_nodes",
        "node_sums",
        "placement",
        "line_ends",
        "station_node",
        "station_chord",
        "station_sums",
        "node_stations",
        "bending",
        "hinge_nodes",
        "hinge_segments",
        "hinge_sums",
        "_hash",
    )

    def __init__(
        self,
        n_nodes: int,
        segment_nodes: np.ndarray,
        constrained_nodes: np.ndarray,
        line_ends: np.ndarray | Sequence[int] = (),
        bending: bool = False,
    ):
        def frozen(array):
            array = np.array(array, dtype=np.int32)
            array.flags.writeable = False
            return array

        self.n_nodes = int(n_nodes)
        self.segment_nodes = frozen(np.reshape(segment_nodes, (-1, 2)))
        self.constrained_nodes = frozen(constrained_nodes)
        self.free_nodes = frozen(np.setdiff1d(np.arange(self.n_nodes), self.constrained_nodes))
        # Static plans for `jaxcable._model.indexing`: which of the segments' ends (starts, then
        # ends) meet at each node, and where each node sits in (free nodes, constrained).
        self.node_sums = frozen(incidence(self.segment_nodes.T.reshape(-1), self.n_nodes))
        self.placement = frozen(np.argsort(np.concatenate([self.free_nodes, self.constrained_nodes])))

        ends_at = self.segment_nodes.T.reshape(-1)  # each segment end's node: starts, then ends
        degree = np.bincount(ends_at, minlength=self.n_nodes)
        ends = np.zeros(self.n_nodes, dtype=bool)
        ends[np.asarray(line_ends, dtype=np.int64)] = True
        self.bending = bool(bending)
        self.hinge_nodes, self.hinge_segments = (frozen(a) for a in _hinges(self.segment_nodes, ends, bending))
        plans = [incidence(segments, self.segment_nodes.shape[0]) for segments in self.hinge_segments]
        most = max(plan.shape[1] for plan in plans)
        self.hinge_sums = frozen(
            np.stack([np.pad(p, ((0, 0), (0, most - p.shape[1])), constant_values=-1) for p in plans])
        )
        ends[self.constrained_nodes] = True
        ends |= degree != 2
        self.line_ends = frozen(np.flatnonzero(ends))
        far = np.roll(ends_at, ends_at.size // 2)  # the other node of each end's segment
        # One station per segment end at a line's end, one per node inside a line (its
        # two ends share it); stable order by node, then by end.
        order = np.argsort(ends_at, kind="stable")
        first = np.ones(ends_at.size, dtype=bool)
        first[1:] = (ends_at[order][1:] != ends_at[order][:-1]) | ends[ends_at[order][1:]]
        station_of = np.empty(ends_at.size, dtype=np.int64)
        station_of[order] = np.cumsum(first) - 1
        n_stations = int(first.sum())
        self.station_node = frozen(ends_at[order][first])
        # Direction: at a line's end from the node to its segment's other node; inside
        # a line from one neighbour to the other (the sign does not matter: every load
        # uses the direction twice).
        head = order[first]  # each station's first end
        tail = order[np.append(np.flatnonzero(first)[1:], ends_at.size) - 1]  # and its last
        self.station_chord = frozen(np.stack([np.where(ends[ends_at[head]], ends_at[head], far[head]), far[tail]]))
        self.station_sums = frozen(incidence(station_of, n_stations))
        self.node_stations = frozen(incidence(self.station_node, self.n_nodes))
        self._hash = hash(
            (
                self.n_nodes,
                self.segment_nodes.tobytes(),
                self.constrained_nodes.tobytes(),
                self.line_ends.tobytes(),
                self.bending,
                self.hinge_nodes.tobytes(),
            )
        )

    def __hash__(self) -> int:
        return self._hash

    def __program_key__(self) -> tuple:
        """What defines the topology, as builtin values that are the same in every process
        (`__hash__` is not: Python salts the hash of bytes), for `jaxcable._programs`."""
        return (
            self.n_nodes,
            self.segment_nodes.tobytes(),
            self.constrained_nodes.tobytes(),
            self.line_ends.tobytes(),
            self.bending,
            self.hinge_nodes.tobytes(),
        )

    def __eq__(self, other) -> bool:
        return (
            isinstance(other, Topology)
            and self._hash == other._hash
            and self.n_nodes == other.n_nodes
            and np.array_equal(self.segment_nodes, other.segment_nodes)
            and np.array_equal(self.constrained_nodes, other.constrained_nodes)
            and np.array_equal(self.line_ends, other.line_ends)
            and self.bending == other.bending
            and np.array_equal(self.hinge_nodes, other.hinge_nodes)
        )

    def __repr__(self) -> str:
        return (
            f"Topology(nodes={self.n_nodes}, segments={len(self.segment_nodes)}, "
            f"constrained={self.constrained_nodes.tolist()})"
        )


def _hinges(segment_nodes: np.ndarray, ends: np.ndarray, bending: bool) -> tuple[np.ndarray, np.ndarray]:
    """The bending hinges of `Topology`: `(nodes, segments)`, shapes `(3, hinges)` and
    `(2, hinges)`; none without `bending`. `ends` marks the nodes given as line ends."""
    if not bending:
        return np.zeros((3, 0), np.int64), np.zeros((2, 0), np.int64)
    n_segments = segment_nodes.shape[0]
    ends_at = segment_nodes.T.reshape(-1)  # each segment end's node: starts, then ends
    degree = np.bincount(ends_at, minlength=ends.size)
    hinges = np.flatnonzero((degree == 2) & ~ends)
    plan = incidence(ends_at, ends.size)[hinges]  # the two segment ends at each hinge
    segments = plan % n_segments
    # The other node of each of the two segments: its end's if the hinge is its start.
    other = np.where(plan < n_segments, segment_nodes[segments, 1], segment_nodes[segments, 0])
    return np.stack([other[:, 0], hinges, other[:, 1]]), segments.T


class CableNetwork(eqx.Module):
    """A cable system: nodes joined by straight, extensible segments.

    **Arguments:**

    - `node_positions`: reference positions (m), shape `(nodes, 3)`. For a constrained
        node this is the position its motion is measured from; for a free node it is the
        initial guess for statics and the default initial state.
    - `segment_nodes`: integer array, shape `(segments, 2)`: the two nodes each segment
        joins.
    - `segment_length`: unstretched lengths L (m), shape `(segments,)`.
    - `line`: a [`jaxcable.LineType`][] whose fields are scalars or per-segment arrays.
    - `constraints`: a mapping from node index to its [`jaxcable.AbstractMotion`][]
        ([`jaxcable.Fixed`][], [`jaxcable.Harmonic`][], [`jaxcable.Sampled`][]). Every
        other node is free.
    - `bodies`: a mapping from node index to a [`jaxcable.Body`][] (scalar fields).
    - `mass_matrix`: `"consistent"` (the kinetic energy of the polyline, weights 1/3 and
        1/6, as Bezverkhyy & Korniienko) or `"lumped"` (half of each segment to each end,
        as MoorDyn).
    - `drag_points`: Gauss–Legendre points per segment for the drag's virtual work.
    - `hydrodynamics`: where drag, Morison's inertia force and added mass act.
        `"segments"` (the default): along each segment, about its direction, drag and
        inertia by `drag_points`-point quadrature of their virtual work over its
        stretched length. `"nodes"`: MoorDyn's lumped form (`Line.cpp`), at each node,
        on the water's velocity relative to the node, about the node's direction (the
        chord through its two neighbours inside a line, the segment's own at a line's
        end), on half of each neighbouring segment's unstretched length; it needs
        `mass_matrix="lumped"`. The two agree as segments shrink; a MoorDyn file is
        read with `"nodes"`, so that the same file gives MoorDyn's answer.
    - `line_ends`: nodes where a line ends, for `hydrodynamics="nodes"`, besides those
        that join other than two segments, the constrained nodes and those with a body
        (all line ends already). [`CableNetwork.from_branches`][] adds its junctions.

    **Raises:**

    `ValueError` naming the field and value for non-finite input, non-positive lengths,
    masses, stiffnesses or diameters, node indices out of range, a segment joining a
    node to itself, mismatched shapes, or an unknown option. Float values that are
    traced here (a model built inside `jit` or `vmap`) are checked by the same
    `conditions()` where they are used: [`jaxcable.simulate`][] and
    [`jaxcable.solve_statics`][] by `eqx.error_if`, [`jaxcable.sweep`][] per case.

    The graph is static: `topology`, a hashable [`Topology`][], with `segment_nodes`,
    `constrained_nodes` and `free_nodes` as numpy integer arrays.

    A part of the network that no constrained node holds is allowed: it moves freely
    (a free ascent, a drifting buoy), and only [`jaxcable.solve_statics`][], which has
    no equilibrium to find for it, refuses it.
    """

    node_positions: Float[Array, "nodes 3"]
    segment_length: Float[Array, " segments"]
    line: LineType
    body: Body | None
    motions: tuple[AbstractMotion, ...]
    topology: Topology = eqx.field(static=True)
    mass_matrix: str = eqx.field(static=True)
    drag_points: int = eqx.field(static=True)
    hydrodynamics: str = eqx.field(static=True)

    def __init__(
        self,
        node_positions: RealLike,
        segment_nodes: RealLike,
        segment_length: RealLike,
        line: LineType,
        constraints: Mapping[int, AbstractMotion],
        bodies: Mapping[int, Body] | None = None,
        mass_matrix: str = "consistent",
        drag_points: int = 3,
        hydrodynamics: str = "segments",
        line_ends: Sequence[int] = (),
    ):
        self.mass_matrix = checks.option("CableNetwork.mass_matrix", mass_matrix, MASS_MATRICES)
        if not (isinstance(drag_points, int) and drag_points >= 1):
            raise ValueError(f"CableNetwork.drag_points must be a positive integer, got {drag_points!r}")
        self.drag_points = drag_points
        self.hydrodynamics = checks.option("CableNetwork.hydrodynamics", hydrodynamics, HYDRODYNAMICS)
        if self.hydrodynamics == "nodes" and self.mass_matrix != "lumped":
            raise ValueError(
                "CableNetwork.hydrodynamics='nodes' (MoorDyn's lumped form) needs mass_matrix='lumped', "
                f"got mass_matrix={mass_matrix!r}"
            )

        self.node_positions = checks.float_array("CableNetwork.node_positions", node_positions)
        if self.node_positions.ndim != 2 or self.node_positions.shape[1] != 3:
            raise ValueError(f"CableNetwork.node_positions must have shape (nodes, 3), got {self.node_positions.shape}")
        n_nodes = self.node_positions.shape[0]

        edges = np.asarray(segment_nodes)
        if edges.ndim != 2 or edges.shape[1] != 2 or edges.shape[0] == 0:
            raise ValueError(f"CableNetwork.segment_nodes must have shape (segments, 2), got {edges.shape}")
        if not np.issubdtype(edges.dtype, np.integer):
            raise ValueError(f"CableNetwork.segment_nodes must be integers, got dtype {edges.dtype}")
        out_of_range = (edges < 0) | (edges >= n_nodes)
        if np.any(out_of_range):
            s, k = np.argwhere(out_of_range)[0]
            raise ValueError(
                f"CableNetwork.segment_nodes[{s}, {k}] = {edges[s, k]} is out of range for {n_nodes} nodes"
            )
        loops = np.flatnonzero(edges[:, 0] == edges[:, 1])
        if loops.size:
            s = loops[0]
            raise ValueError(f"CableNetwork.segment_nodes[{s}] joins node {edges[s, 0]} to itself")
        n_segments = edges.shape[0]

        self.segment_length = checks.float_array("CableNetwork.segment_length", segment_length, (n_segments,))
        checks.positive("CableNetwork.segment_length", self.segment_length)
        self.line = _broadcast_leaves("CableNetwork.line", line, n_segments)

        constrained = sorted(int(k) for k in constraints)
        for k in constrained:
            if not 0 <= k < n_nodes:
                raise ValueError(f"CableNetwork.constraints has node {k}, out of range for {n_nodes} nodes")
            if not isinstance(constraints[k], AbstractMotion):
                raise ValueError(f"CableNetwork.constraints[{k}] must be a motion, got {constraints[k]!r}")
        self.motions = tuple(constraints[k] for k in constrained)

        bodies = dict(bodies or {})
        for k, b in bodies.items():
            if not 0 <= int(k) < n_nodes:
                raise ValueError(f"CableNetwork.bodies has node {k}, out of range for {n_nodes} nodes")
            if not isinstance(b, Body):
                raise ValueError(f"CableNetwork.bodies[{k}] must be a Body, got {b!r}")
        self.body = _scatter_bodies(bodies, n_nodes)

        ends = sorted({int(k) for k in line_ends} | {int(k) for k in bodies})
        for k in ends:
            if not 0 <= k < n_nodes:
                raise ValueError(f"CableNetwork.line_ends has node {k}, out of range for {n_nodes} nodes")
        self.topology = Topology(
            n_nodes, edges, np.asarray(constrained, dtype=np.int32), ends, self.line.bending_stiffness is not None
        )

    def conditions(self) -> list[checks.Condition]:
        """Every float field's requirements, its line's, bodies' and motions': checked
        at construction on concrete values; [`jaxcable.simulate`][] and
        [`jaxcable.solve_statics`][] guard traced ones, and [`jaxcable.sweep`][] checks
        each case's."""
        return [
            checks.finite("CableNetwork.node_positions", self.node_positions),
            checks.finite("CableNetwork.segment_length", self.segment_length),
            checks.sign("CableNetwork.segment_length", self.segment_length),
            *self.line.conditions(),
            *(self.body.conditions() if self.body is not None else []),
            *(c for motion in self.motions for c in motion.conditions()),
        ]

    @property
    def segment_nodes(self) -> Int[np.ndarray, "segments 2"]:
        """The two nodes each segment joins, shape `(segments, 2)` (static, numpy)."""
        return self.topology.segment_nodes

    @property
    def constrained_nodes(self) -> Int[np.ndarray, " constrained"]:
        """The constrained nodes, increasing, in the order of `motions` (static, numpy)."""
        return self.topology.constrained_nodes

    @property
    def free_nodes(self) -> Int[np.ndarray, " free"]:
        """The free nodes, increasing, shape `(free,)` (static, numpy)."""
        return self.topology.free_nodes

    @property
    def n_nodes(self) -> int:
        return self.topology.n_nodes

    @property
    def n_segments(self) -> int:
        return self.topology.segment_nodes.shape[0]

    @classmethod
    def from_branches(
        cls,
        junctions: RealLike,
        branches: Sequence[Branch],
        constraints: Mapping[int, AbstractMotion],
        bodies: Mapping[int, Body] | None = None,
        **options,
    ) -> "CableNetwork":
        """Build a network from its junctions and the branches between them.

        Each branch is divided into `branch.segments` equal segments. Junction `k` keeps
        node index `k`; interior nodes follow, branch by branch. Interior nodes start on
        the straight chord when the branch is taut there; a branch longer than its chord
        starts on a catenary sagging downward, stretched by 0.1 % so that every segment
        carries tension. That makes a good initial guess for
        [`jaxcable.solve_statics`][]: a stiff line starts close to its equilibrium.
        Traced lengths or junctions (a function of them under `jax.grad`, `jit` or
        `vmap`) are accepted, and every branch then starts on its chord: statics finds
        the shape, and only `simulate(..., initial="rest")` would start from there.

        **Arguments:**

        - `junctions`: positions (m), shape `(junctions, 3)`.
        - `branches`: the edges, as [`jaxcable.Branch`][]. All must use the same class
            of tension law; use [`jaxcable.KelvinVoigt`][] with zero coefficients to mix.
        - `constraints`, `bodies`, `**options`: as for [`jaxcable.CableNetwork`][],
            keyed by node: junction k is node k, and the branches' interior nodes
            follow, branch by branch from its start (a buoyancy module, or a second
            prescribed node that clamps a line, sits on one of them).
        """
        junctions = checks.float_array("CableNetwork.from_branches junctions", junctions)
        if junctions.ndim != 2 or junctions.shape[1] != 3:
            raise ValueError(f"junctions must have shape (junctions, 3), got {junctions.shape}")
        if not branches:
            raise ValueError("branches must not be empty")
        # Lengths and junctions are data, not topology: traced (under `jax.grad` of a
        # function that builds the model, say), they are kept in JAX, and each branch's
        # nodes start on its chord, since the catenary guess is solved in numpy. Statics
        # puts every run of segments on its analytic shape first, from either start.
        lazy = checks.traced((junctions, [branch.length for branch in branches]))
        xp = jnp if lazy else np
        positions = [junctions if lazy else np.asarray(junctions)]
        edges, lengths = [], []
        next_node = junctions.shape[0]
        for b, branch in enumerate(branches):
            if not (isinstance(branch.segments, int) and branch.segments >= 1):
                raise ValueError(f"branches[{b}].segments must be a positive integer, got {branch.segments!r}")
            for name in ("start", "end"):
                k = getattr(branch, name)
                if not 0 <= k < junctions.shape[0]:
                    raise ValueError(f"branches[{b}].{name} = {k} is out of range for {junctions.shape[0]} junctions")
            # On the host where concrete, so that `length / n` below compiles nothing.
            length = checks.on_host(checks.float_array(f"branches[{b}].length", branch.length, ()))
            checks.positive(f"branches[{b}].length", length)
            n = branch.segments
            start, end = positions[0][branch.start], positions[0][branch.end]
            if lazy:
                positions.append(start + jnp.linspace(0.0, 1.0, n + 1)[1:-1, None] * (end - start))
            else:
                positions.append(_initial_chain(np.asarray(start), np.asarray(end), n, float(length))[1:-1])
            chain = [branch.start, *range(next_node, next_node + n - 1), branch.end]
            next_node += n - 1
            edges += list(zip(chain[:-1], chain[1:]))
            lengths.append(xp.full(n, length / n))
        for field, keyed in (("constraints", constraints), ("bodies", bodies or {})):
            for key in keyed:
                if not (isinstance(key, (int, np.integer)) and 0 <= key < next_node):
                    raise ValueError(
                        f"CableNetwork.from_branches {field}: key {key!r} is not a node; junction k is node k "
                        f"(0 to {junctions.shape[0] - 1} here) and the branches' interior nodes follow, to "
                        f"{next_node - 1}"
                    )
        line_ends = [*range(junctions.shape[0]), *options.pop("line_ends", ())]
        return cls(
            node_positions=xp.concatenate(positions),
            segment_nodes=np.asarray(edges),
            segment_length=xp.concatenate(lengths),
            line=_stack_lines(branches),
            constraints=constraints,
            bodies=bodies,
            line_ends=line_ends,
            **options,
        )


# Initial stretch of a sagged branch: enough to put every segment clear of the slack
# switch, small next to the strains that equilibrium will settle on for soft ropes.
_GUESS_STRETCH = 1e-3


def _initial_chain(start: np.ndarray, end: np.ndarray, n: int, length: float) -> np.ndarray:
    """`n + 1` points from `start` to `end`: straight if the chord is at least the
    stretched length, otherwise on the catenary of that length hanging in the vertical
    plane of the chord (sideways, for a vertical chord), spaced at equal arc length.
    Each of the `n` chords is at least `length / n` stretched by `_GUESS_STRETCH`.

    The catenary is the equilibrium of an inextensible line of uniform weight, so a
    stiff line (EA large against its weight) starts close to equilibrium. On the Low &
    Langley jumper a parabola guess needed 1,651 Levenberg–Marquardt iterations, the
    catenary 56."""
    chord = end - start
    span = np.linalg.norm(chord)
    target = length / n * (1 + _GUESS_STRETCH)
    if span == 0 or span >= n * target:
        return start + np.linspace(0.0, 1.0, n + 1)[:, None] * chord
    gravity = np.array([0.0, 0.0, -1.0])
    if np.linalg.norm(np.cross(chord, gravity)) < 1e-9 * span:
        gravity = np.array([1.0, 0.0, 0.0])  # a vertical chord: sag sideways
    rise = -chord @ gravity
    across = chord + rise * gravity
    h = np.linalg.norm(across)

    def nodes(arc_length):
        # z = a cosh((x − x0)/a) + c through (0, 0) and (h, rise) with arc length S:
        # √(S² − rise²) = 2a sinh(h / 2a) fixes a, and tanh((h/2 − x0)/a) = rise / S.
        reach = np.sqrt(arc_length**2 - rise**2)
        low, high = 1e-6 * h, 1e6 * h  # 2a sinh(h/2a) falls from ∞ to h as a grows
        for _ in range(200):
            a = np.sqrt(low * high)
            low, high = (a, high) if 2 * a * np.sinh(min(h / (2 * a), 700.0)) > reach else (low, a)
        x0 = h / 2 - a * np.arctanh(rise / arc_length)
        stations = np.linspace(0.0, arc_length, n + 1)
        x = x0 + a * np.arcsinh(stations / a + np.sinh(-x0 / a))
        z = a * (np.cosh((x - x0) / a) - np.cosh(x0 / a))
        return start + x[:, None] * (across / h) - z[:, None] * gravity

    # Chords are a little shorter than the arcs they span: lengthen until each is enough.
    arc_length = n * target
    for _ in range(20):
        shortest = np.min(np.linalg.norm(np.diff(nodes(arc_length), axis=0), axis=1))
        if shortest >= target:
            break
        arc_length *= target / shortest * (1 + 1e-12)
    points = nodes(arc_length)
    points[-1] = end  # exact, not to rounding
    return points


def _broadcast_leaves(name: str, module: eqx.Module, size: int):
    """Broadcast every float leaf of `module` to shape `(size,)`, naming a mismatch."""
    leaves, treedef = jax.tree_util.tree_flatten_with_path(module)
    out = [checks.float_array(name + jax.tree_util.keystr(path), leaf, (size,)) for path, leaf in leaves]
    return jax.tree.unflatten(treedef, out)


def _stack_lines(branches: Sequence[Branch]) -> LineType:
    """The branches' line types, one entry per segment, branch by branch.

    One `concatenate` of a broadcast per branch, not a `stack` of a copy per segment:
    stacking compiled a program with one operand per segment, which took 19 s at
    10,000 segments and grew as their square."""
    kinds = {type(branch.line.tension_law) for branch in branches}
    if len(kinds) > 1:
        names = sorted(k.__name__ for k in kinds)
        raise ValueError(
            f"all branches must share one class of tension law, got {names}; express them all "
            "as KelvinVoigt (with zero coefficients where a term is absent)"
        )
    slack = {getattr(branch.line.tension_law, "slack_damping", False) for branch in branches}
    if len(slack) > 1:
        raise ValueError("all branches' tension laws must share one slack_damping (KelvinVoigt), got both")
    counts = [branch.segments for branch in branches]
    lines = [branch.line for branch in branches]
    if any(line.bending_stiffness is not None for line in lines):
        # A line without bending joins one with it as EI = 0, so that the trees match.
        lines = [
            eqx.tree_at(lambda t: t.bending_stiffness, line, 0.0, is_leaf=lambda x: x is None)
            if line.bending_stiffness is None
            else line
            for line in lines
        ]

    def stack(*xs):
        xp = jnp if checks.traced(xs) else np  # numpy compiles nothing for concrete lines
        return checks.on_device(
            xp.concatenate([xp.broadcast_to(xp.asarray(x, dtype=float), (n,)) for x, n in zip(xs, counts)])
        )

    return jax.tree.map(stack, *lines)


def _scatter_bodies(bodies: Mapping[int, Body], n_nodes: int) -> Body:
    zero = Body()
    if not bodies:
        return jax.tree.map(lambda x: checks.on_device(np.zeros((n_nodes, *x.shape))), zero)
    nodes = np.asarray(sorted(bodies), dtype=np.int32)
    given = [bodies[k] for k in sorted(bodies)]
    if checks.traced(given):
        stacked = jax.tree.map(lambda *xs: jnp.stack(xs), *given)
        return jax.tree.map(lambda x: jnp.zeros((n_nodes, *x.shape[1:])).at[nodes].set(x), stacked)

    def scatter(*xs):  # in numpy, which compiles nothing for concrete bodies
        out = np.zeros((n_nodes, *np.shape(xs[0])))
        out[nodes] = np.stack([np.asarray(x) for x in xs])
        return checks.on_device(out)

    return jax.tree.map(scatter, *given)


def without_absent_bodies(model: CableNetwork) -> CableNetwork:
    """`model` with `body` None where it carries no body: every body array concrete and
    zero (a bare line or net), as the dynamics programs take it.

    The equations leave a None body's terms out (`jaxcable._equations.lagrangian`), so
    its program computes no drag, buoyancy or submerged fraction on arrays of zeros,
    which XLA cannot fold at run time since they are the program's arguments: the 40-
    segment rope of `benchmarks/first_contact.py` (row `line40`) ran its 300,000
    midpoint steps in 3.1 s without them against 3.6 s with them, and a warm 256-case
    sweep of the anchored line took 14.8 s against 17.2 s. A model with any body, or
    whose bodies are traced (differentiated, swept), keeps them; so does one that a
    user gave bodies with `eqx.tree_at` after building it, since it is decided on the
    values. A drag law (`specific_drag`) without organism mass, and added mass or a
    height without volume, act on nothing."""
    body = model.body
    if body is None or checks.traced(body):
        return model
    acting = (body.mass, body.volume, body.drag_area, body.organism_mass, body.force)
    if any(np.any(np.asarray(x) != 0) for x in acting):
        return model
    return eqx.tree_at(lambda m: m.body, model, None)


def below_seabed(heights: Float[ArrayLike, "*points"], depth: Float[ArrayLike, ""]) -> Bool[ArrayLike, "*points"]:
    """Which `heights` z (m) are below a seabed at z = −`depth` (m) by more than 0.1 % of
    the depth. A support may rest pressed into the penalty bed, as a chain lying on it
    does by its wet weight over k d (millimetres for MoorDyn's default bed); one metres
    below it is an input error."""
    return checks.on_host(heights) < -checks.on_host(depth) * (1 + 1e-3)


def network_conditions(model: CableNetwork, env: Environment) -> list[checks.Condition]:
    """What `model` and `env` require, each of its own fields and together: every
    constrained node (anchor, fairlead) at or above the seabed, where there is one.

    A support below the bed drags the nodes next to it into the bed's penalty spring,
    whose force k δ A grows with the depth δ below it: an anchor 100 m under a 3e6 Pa/m
    bed gave 8 MN (see `below_seabed`).
    """
    out = model.conditions() + env.conditions()
    if env.seabed is None or env.depth is None:
        return out
    nodes = model.constrained_nodes
    heights = checks.on_host(model.node_positions)[nodes, 2]
    depth = checks.on_host(env.depth)
    bed = -depth
    below = below_seabed(heights, depth)

    def detail() -> str:
        k = int(np.argmax(np.asarray(below)))
        return (
            f"CableNetwork.node_positions: constrained node {int(nodes[k])} is at z = {float(heights[k]):g} m, "
            f"below the seabed at z = {float(bed):g} m (Environment.depth = {float(depth):g} m): raise it "
            "to the bed or deepen the water"
        )

    return out + [
        checks.Condition(
            "CableNetwork.node_positions (a constrained node's z)",
            below,
            heights,
            "must be at or above the seabed",
            detail,
        )
    ]


def unheld_nodes(model: CableNetwork) -> np.ndarray | None:
    """The nodes of the first connected part of the graph with no constrained node (a
    part that nothing holds, which has no static equilibrium), or `None` where every
    part is held. The topology is static, so this runs under `jit` and `vmap` too,
    when tracing."""
    edges = np.asarray(model.segment_nodes)
    constrained = np.asarray(model.constrained_nodes)
    labels = np.arange(model.n_nodes)
    while True:
        merged = np.minimum(labels[edges[:, 0]], labels[edges[:, 1]])
        updated = labels.copy()
        np.minimum.at(updated, edges[:, 0], merged)
        np.minimum.at(updated, edges[:, 1], merged)
        updated = updated[updated]
        if np.array_equal(updated, labels):
            break
        labels = updated
    held = set(labels[constrained].tolist())
    for component in np.unique(labels):
        if component not in held:
            return np.flatnonzero(labels == component)
    return None


def check_held(model: CableNetwork) -> None:
    """Raise `ValueError` unless every connected part of the graph has a constrained
    node (see `unheld_nodes`)."""
    members = unheld_nodes(model)
    if members is not None:
        shown = ", ".join(map(str, members[:8])) + (", ..." if members.size > 8 else "")
        raise ValueError(
            f"solve_statics: nodes [{shown}] form a part of the network with no constrained "
            "node, so it has no equilibrium; fix or prescribe the motion of at least one of "
            "them, or simulate it from a given initial state"
        )
