"""Implicit steps that scale with the network: the Jacobian from coloured JVPs, factored
along the graph.

An implicit step (Kvaerno, ImplicitEuler, KenCarp) solves linear systems with the
matrix `A = ∂/∂k [f(y₀ + h γ k) − k]` of its stage equations, f the free nodes' first-
order vector field. diffrax's default materialises A densely (one JVP per unknown) and
factors it by LU: O(N) JVPs and O(N³) flops for N nodes. With lumped mass, though, a
node's acceleration depends only on its own state and that of the nodes it shares a
segment with, so A is block-sparse along the network's graph: one 6 × 6 block
(position and velocity, x y z) per pair of neighbouring free nodes.

[`jaxcable.NetworkJacobian`][] exploits this twice:

- **Coloured JVPs.** Nodes that share no neighbour (distance-2 colouring) get the same
  colour, and one JVP per colour and component recovers every block, whatever N: 18
  JVPs for a line (3 colours), 30 for the bundled Y-branch and 36 for the buoy net
  (5 and 6 colours by the greedy colouring).
- **A block-tridiagonal factorisation.** Nodes are renumbered by reverse Cuthill–McKee
  and grouped in runs of the resulting bandwidth b (1 for a line, a few for a branched
  system, a net's width for a net), which makes A block-tridiagonal in groups of 6b
  unknowns (the bundled Y-branch has b = 2, the 3 × 3 buoy net b = 4). It is factored
  by block elimination in one `lax.scan`: O(N b²) flops.

With consistent mass, A is dense (the mass matrix's inverse couples every node), and
the dense solve stays.
"""

import itertools
from typing import Any

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import lineax as lx
import numpy as np

from .._model.network import CableNetwork, Topology


class NetworkJacobian(lx.AbstractLinearSolver):
    """A lineax linear solver for the implicit stages of a lumped-mass network: it
    builds the stage Jacobian from coloured JVPs and factors it block-tridiagonally
    along the network's graph, so that a step costs O(N), not O(N³).

    [`jaxcable.simulate`][] and [`jaxcable.sweep`][] put it into an implicit solver's
    root finder by themselves, in place of lineax's automatic choice; build it
    directly to insist on it (an error, not a silent dense solve, if the model cannot
    use it), or to use it elsewhere, as `diffrax.Kvaerno5(root_finder=optx.Newton(rtol,
    atol, linear_solver=NetworkJacobian(model)))`. For diffrax's dense Jacobian and LU
    instead, put `lineax.LU()` in the root finder.

    The operator it solves must map the free nodes' `(positions, velocities)` (each of
    shape `(free, 3)`, or any pytree whose leaves have the free nodes as their first
    axis) to the same, and couple only nodes that share a segment.

    **Arguments:**

    - `model`: a [`jaxcable.CableNetwork`][] with `mass_matrix="lumped"`. Its topology
        is static, so this may be built inside `jit` or `vmap` (from a traced model).
        Or a model's `topology`, to solve another operator that couples only nodes
        sharing a segment, whatever the mass matrix: the free nodes' static force
        Jacobian, as [`jaxcable.solve_statics`][] does.

    **Raises:**

    `ValueError` if the model's mass matrix is consistent (its stage Jacobian is
    dense).
    """

    nodes: int = eqx.field(static=True)
    colours: tuple[int, ...] = eqx.field(static=True)
    pairs: tuple[tuple[int, int], ...] = eqx.field(static=True)
    order: tuple[int, ...] = eqx.field(static=True)
    group: int = eqx.field(static=True)

    def __init__(self, model: CableNetwork | Topology):
        if isinstance(model, CableNetwork) and model.mass_matrix != "lumped":
            raise ValueError(
                "NetworkJacobian needs CableNetwork.mass_matrix='lumped', got "
                f"{model.mass_matrix!r}: a consistent mass matrix's inverse couples every node, "
                "so the stage Jacobian is dense"
            )
        # Bending couples each hinge's two neighbours as well (`jaxcable._equations.bending`).
        hinges = model.topology.hinge_nodes if isinstance(model, CableNetwork) else model.hinge_nodes
        coupled = np.concatenate([model.segment_nodes, hinges[[0, 2]].T])
        edges = _free_edges(coupled, model.free_nodes, model.n_nodes)
        n = len(model.free_nodes)
        neighbours = _neighbours(n, edges)
        self.nodes = n
        self.colours = tuple(int(c) for c in _distance2_colouring(neighbours))
        self.pairs = tuple(
            (int(i), int(j)) for i, j in np.concatenate([np.stack([np.arange(n)] * 2, 1), edges, edges[:, ::-1]])
        )
        order = _reverse_cuthill_mckee(neighbours)
        position = np.argsort(order)
        bandwidth = int(np.max(np.abs(position[edges[:, 0]] - position[edges[:, 1]]))) if len(edges) else 1
        self.order = tuple(int(i) for i in order)
        self.group = max(bandwidth, 1)

    @property
    def n_colours(self) -> int:
        """Distinct colours: the JVPs per Jacobian are this times the unknowns per node."""
        return max(self.colours, default=-1) + 1

    def init(self, operator: lx.AbstractLinearOperator, options: dict[str, Any]):
        del options
        layout = _Layout(operator.in_structure(), self.nodes)
        if operator.out_structure() != operator.in_structure():
            raise ValueError("NetworkJacobian solves square systems whose input and output are the free nodes' state")
        blocks = self._blocks(operator, layout)
        return blocks, _factor(*blocks), layout

    def _blocks(self, operator, layout):
        """The operator's nonzero 6 × 6 blocks, by coloured JVPs, arranged as the
        (lower, diagonal, upper) blocks of a block-tridiagonal matrix over groups."""
        n, d, c = self.nodes, layout.width, self.n_colours
        colours = np.asarray(self.colours)
        seeds = np.zeros((c, d, n, d))
        for e in range(d):
            seeds[colours, e, np.arange(n), e] = 1.0
        products = jax.vmap(lambda s: layout.to_nodes(operator.mv(layout.from_nodes(s))))(
            jnp.asarray(seeds.reshape(c * d, n, d), dtype=layout.dtype)
        ).reshape(c, d, n, d)
        rows, cols = np.asarray(self.pairs).T
        # Column e of block (i, j) is output i of the product seeded on j's colour and
        # component e: no other node of that colour reaches i.
        values = jnp.swapaxes(products[colours[cols], :, rows, :], -1, -2)

        b = self.group
        groups = -(-n // b)
        position = np.argsort(np.asarray(self.order)) if n else np.zeros(0, int)
        g, slot = np.divmod(position, b)
        matrix = jnp.zeros((3, groups, b, b, d, d), dtype=layout.dtype)
        matrix = matrix.at[g[cols] - g[rows] + 1, g[rows], slot[rows], slot[cols]].set(values)
        # Slots past the last node pad the last group: give them an identity.
        padding = np.arange(n, groups * b)
        matrix = matrix.at[1, padding // b, padding % b, padding % b].set(jnp.eye(d, dtype=layout.dtype))
        lower, diagonal, upper = jnp.swapaxes(matrix, 3, 4).reshape(3, groups, b * d, b * d)
        return lower, diagonal, upper

    def compute(self, state, vector, options):
        del options
        _, (lower, inverse, coupling), layout = state
        b, groups = self.group, lower.shape[0]
        r = layout.to_nodes(vector)
        r = jnp.concatenate(
            [r[np.asarray(self.order, dtype=int)], jnp.zeros((groups * b - self.nodes, layout.width), r.dtype)]
        )
        r = r.reshape(groups, -1)

        def forward(previous, inputs):
            low, inv, rhs = inputs
            y = inv @ (rhs - low @ previous)
            return y, y

        _, y = jax.lax.scan(forward, jnp.zeros_like(r[0]), (lower, inverse, r))

        def backward(following, inputs):
            x = inputs[0] - inputs[1] @ following
            return x, x

        _, x = jax.lax.scan(backward, jnp.zeros_like(r[0]), (y, coupling), reverse=True)
        x = x.reshape(groups * b, -1)[: self.nodes]
        solution = jnp.zeros_like(x).at[np.asarray(self.order, dtype=int)].set(x)
        result = lx.RESULTS.where(jnp.all(jnp.isfinite(solution)), lx.RESULTS.successful, lx.RESULTS.singular)
        return layout.from_nodes(solution), result, {}

    def transpose(self, state, options):
        (lower, diagonal, upper), _, layout = state

        # Block (g, g−1) of Aᵀ is block (g−1, g) of A transposed, and so on.
        def t(a):
            return jnp.swapaxes(a, -1, -2)

        zero = jnp.zeros_like(lower[:1])
        blocks = (
            jnp.concatenate([zero, t(upper[:-1])]),
            t(diagonal),
            jnp.concatenate([t(lower[1:]), zero]),
        )
        return (blocks, _factor(*blocks), layout), options

    def conj(self, state, options):
        return state, options

    def assume_full_rank(self):
        return True


class _Layout(eqx.Module):
    """Between the operator's pytree (leaves of shape `(nodes, ...)`) and one
    `(nodes, width)` array of each node's unknowns."""

    structure: Any = eqx.field(static=True)
    nodes: int = eqx.field(static=True)

    def __init__(self, structure, nodes):
        leaves = jax.tree.leaves(structure)
        if not leaves or any(leaf.shape[:1] != (nodes,) for leaf in leaves):
            shapes = [leaf.shape for leaf in leaves]
            raise ValueError(
                f"NetworkJacobian: every unknown must have the {nodes} free nodes as its first axis, got shapes "
                f"{shapes}"
            )
        self.structure = structure
        self.nodes = nodes

    @property
    def width(self) -> int:
        return sum(int(np.prod(leaf.shape[1:])) for leaf in jax.tree.leaves(self.structure))

    @property
    def dtype(self):
        return jnp.result_type(*jax.tree.leaves(self.structure))

    def to_nodes(self, tree):
        return jnp.concatenate([leaf.reshape(self.nodes, -1) for leaf in jax.tree.leaves(tree)], axis=1)

    def from_nodes(self, array):
        leaves, treedef = jax.tree.flatten(self.structure)
        sizes = np.cumsum([int(np.prod(leaf.shape[1:])) for leaf in leaves])[:-1]
        parts = jnp.split(array, sizes, axis=-1)
        return jax.tree.unflatten(
            treedef, [p.reshape(*array.shape[:-2], *leaf.shape).astype(leaf.dtype) for p, leaf in zip(parts, leaves)]
        )


def _factor(lower, diagonal, upper):
    """Block LU without pivoting between groups (pivoting within each diagonal block):
    returns `(lower, D⁻¹, D⁻¹ U)` per group, with D the Schur complements."""

    def step(coupling, blocks):
        low, diag, up = blocks
        inverse = _inverse(diag - low @ coupling)
        coupling = inverse @ up
        return coupling, (inverse, coupling)

    _, (inverse, coupling) = jax.lax.scan(step, jnp.zeros_like(upper[0]), (lower, diagonal, upper))
    return lower, inverse, coupling


def _inverse(a):
    """The inverse of a small square matrix by Gauss–Jordan elimination with partial
    pivoting.

    Written out rather than LAPACK's LU: a batched LU was seen to deadlock under
    `vmap` across two host devices on a two-core machine (see `_equations.lagrangian`), and
    sweeps vmap this.
    """
    m = a.shape[-1]
    rows = jnp.arange(m)
    augmented = jnp.concatenate([a, jnp.eye(m, dtype=a.dtype)], axis=-1)

    def eliminate(k, aug):
        pivot = jnp.argmax(jnp.where(rows >= k, jnp.abs(aug[:, k]), -1.0))
        swapped = aug.at[k].set(aug[pivot]).at[pivot].set(aug[k])
        row = swapped[k] / swapped[k, k]
        factors = jnp.where(rows == k, 0.0, swapped[:, k])
        return (swapped - factors[:, None] * row[None, :]).at[k].set(row)

    return jax.lax.fori_loop(0, m, eliminate, augmented, unroll=m <= 24)[:, m:]


def _free_edges(segment_nodes: np.ndarray, free_nodes: np.ndarray, n_nodes: int) -> np.ndarray:
    """Segments between two free nodes, in the free nodes' numbering, shape
    `(edges, 2)`; each pair once."""
    index = np.full(n_nodes, -1)
    index[free_nodes] = np.arange(len(free_nodes))
    edges = index[segment_nodes]
    edges = edges[np.all(edges >= 0, axis=1)]
    return np.unique(np.sort(edges, axis=1), axis=0).reshape(-1, 2)


def _neighbours(n: int, edges: np.ndarray) -> list[list[int]]:
    """Each node's neighbours, from the graph's `(edges, 2)` node pairs."""
    neighbours = [[] for _ in range(n)]
    for i, j in edges:
        neighbours[i].append(int(j))
        neighbours[j].append(int(i))
    return neighbours


def _distance2_colouring(neighbours: list[list[int]]) -> np.ndarray:
    """A greedy colouring in which no two nodes within two edges share a colour, so
    that the JVP seeded on one colour never sums two columns into one row."""
    colours = np.full(len(neighbours), -1)
    for i, near in enumerate(neighbours):
        reach = set(near).union(*(neighbours[j] for j in near)) - {i}
        taken = {colours[j] for j in reach}
        colours[i] = next(c for c in itertools.count() if c not in taken)
    return colours


def _reverse_cuthill_mckee(neighbours: list[list[int]]) -> np.ndarray:
    """A node order of small bandwidth: breadth first from a least-connected node of
    each component, neighbours by increasing degree, reversed (Cuthill–McKee). A line
    comes out in order, bandwidth 1."""
    n = len(neighbours)
    degree = [len(near) for near in neighbours]
    seen = np.zeros(n, bool)
    order: list[int] = []
    for start in sorted(range(n), key=degree.__getitem__):
        if seen[start]:
            continue
        seen[start] = True
        head = len(order)
        order.append(start)
        while head < len(order):
            for j in sorted(neighbours[order[head]], key=degree.__getitem__):
                if not seen[j]:
                    seen[j] = True
                    order.append(j)
            head += 1
    return np.asarray(order[::-1], dtype=int)


def with_network_jacobian(solver: diffrax.AbstractSolver, model: CableNetwork) -> diffrax.AbstractSolver:
    """`solver` with [`jaxcable.NetworkJacobian`][] in its root finder where it applies: an
    implicit solver whose Newton-type root finder has lineax's automatic linear solver,
    on a lumped-mass model (under `jit` and in sweeps too: the topology is static). A linear solver the user chose
    (`lineax.LU()` for a dense solve, or `NetworkJacobian(model)` itself) is kept."""
    root_finder = getattr(solver, "root_finder", None)
    if (
        isinstance(solver, diffrax.AbstractImplicitSolver)
        and isinstance(getattr(root_finder, "linear_solver", None), lx.AutoLinearSolver)
        and model.mass_matrix == "lumped"
    ):
        return eqx.tree_at(lambda s: s.root_finder.linear_solver, solver, NetworkJacobian(model))
    return solver
