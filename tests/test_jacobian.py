"""The structured implicit Jacobian against dense linear algebra.

References: `jax.jacfwd` materialises each stage Jacobian densely and
`numpy.linalg.solve` solves with it; the distance-2 property of the colouring is
checked on the graphs themselves; a structured implicit run is compared with diffrax's
own dense one.
"""

import diffrax
import jax
import jax.numpy as jnp
import lineax as lx
import numpy as np
import pytest
import scipy.sparse as sparse
from scipy.sparse.csgraph import reverse_cuthill_mckee

import jaxcable as jc
from jaxcable._simulation.simulate import vector_field
from jaxcable._solver.jacobian import (
    NetworkJacobian,
    _distance2_colouring,
    _free_edges,
    _neighbours,
    _reverse_cuthill_mckee,
)
from jaxcable.examples import anchored_line, scene_path


def _scene(name):
    built = jc.load_scene(scene_path(name)).build()
    return built.model, built.environment


@pytest.fixture(scope="module")
def models():
    line = anchored_line(8, mass_matrix="lumped")
    # A line with bending stiffness, whose hinges couple nodes two apart.
    bending = jc.LineType(20.0, 0.1, jc.LinearElastic(1e7), bending_stiffness=5e4)
    bent = jc.CableNetwork.from_branches(
        np.array([[0.0, 0.0, -40.0], [50.0, 0.0, 0.0]]),
        [jc.Branch(0, 1, bending, 70.0, 8)],
        {0: jc.Fixed(), 1: jc.Fixed()},
        mass_matrix="lumped",
    )
    return {
        "line": line,
        "bending": (bent, jc.Environment()),
        "y_branch": _scene("y_branch"),
        "buoy_net": _scene("buoy_net"),
    }


def _stage(model, env, step):
    """An implicit stage's function `k ↦ h f(y + h k) − k` about a moving state, as
    diffrax's ESDIRK stages have it (γ folded into h), and its zero point."""
    free = model.free_nodes
    rng = np.random.default_rng(1)
    y = (
        model.node_positions[free] + 0.01 * rng.normal(size=(free.size, 3)),
        jnp.asarray(0.1 * rng.normal(size=(free.size, 3))),
    )

    def fn(k, args):
        moved = jax.tree.map(lambda a, b: a + step * b, y, k)
        return jax.tree.map(lambda f, b: step * f - b, vector_field(0.3, moved, (model, env)), k)

    return fn, jax.tree.map(jnp.zeros_like, y)


def _dense(fn, k):
    """The stage Jacobian as a dense `(6n, 6n)` matrix, unknowns node by node."""

    def flat(tree):
        return jnp.concatenate([a for a in tree], axis=1).reshape(-1)

    n = k[0].shape[0]

    def unflat(v):
        return v.reshape(n, 6)[:, :3], v.reshape(n, 6)[:, 3:]

    return np.asarray(jax.jacfwd(lambda v: flat(fn(unflat(v), None)))(flat(k))), flat, unflat


# The net with loops takes 40 s of the default suite's 2 cores: slow.
@pytest.mark.parametrize(
    "name",
    [
        "line",
        "bending",
        pytest.param("y_branch", marks=pytest.mark.slow),
        pytest.param("buoy_net", marks=pytest.mark.slow),
    ],
)
def test_solve_matches_dense_jacobian(models, name):
    """Solves and transposed solves agree with `numpy.linalg.solve` on the `jacfwd`
    Jacobian, on a line, a branched system and a net with loops, at a step long enough
    for the stiff terms to dominate the identity."""
    model, env = models[name]
    fn, k = _stage(model, env, 0.05)
    dense, flat, unflat = _dense(fn, k)
    solver = NetworkJacobian(model)
    operator = lx.JacobianLinearOperator(fn, k, None)
    rhs = unflat(jnp.asarray(np.random.default_rng(2).normal(size=dense.shape[0])))
    state = solver.init(operator, {})
    solution, result, _ = solver.compute(state, rhs, {})
    assert result == lx.RESULTS.successful
    expected = np.linalg.solve(dense, np.asarray(flat(rhs)))
    np.testing.assert_allclose(flat(solution), expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())
    transposed, _ = solver.transpose(state, {})
    solution_t, _, _ = solver.compute(transposed, rhs, {})
    expected_t = np.linalg.solve(dense.T, np.asarray(flat(rhs)))
    np.testing.assert_allclose(flat(solution_t), expected_t, rtol=1e-9, atol=1e-9 * np.abs(expected_t).max())


@pytest.mark.slow
def test_jacobian_is_as_sparse_as_the_graph(models):
    """The dense Jacobian's nonzero blocks lie on the graph's pairs, the structure the
    colouring relies on: no node's force depends on a node two segments away."""
    model, env = models["buoy_net"]
    fn, k = _stage(model, env, 0.05)
    dense, _, _ = _dense(fn, k)
    n = k[0].shape[0]
    blocks = np.abs(dense.reshape(n, 6, n, 6)).max(axis=(1, 3)) > 0
    pattern = np.zeros((n, n), bool)
    pattern[tuple(np.asarray(NetworkJacobian(model).pairs).T)] = True
    assert not np.any(blocks & ~pattern)
    # Every neighbour pair couples (the colouring is not larger than it must be).
    assert np.all(blocks[pattern])


@pytest.mark.parametrize(
    "edges, n",
    [
        (np.stack([np.arange(9), np.arange(1, 10)], 1), 10),  # a line
        (np.array([[0, 1], [1, 2], [1, 3], [3, 4], [3, 5], [5, 6]]), 7),  # a tree
        # A 4 × 4 grid: loops.
        (
            np.array(
                [[i * 4 + j, i * 4 + j + 1] for i in range(4) for j in range(3)]
                + [[i * 4 + j, (i + 1) * 4 + j] for i in range(3) for j in range(4)]
            ),
            16,
        ),
    ],
)
def test_colouring_separates_nodes_within_two_edges(edges, n):
    graph = sparse.coo_matrix(
        (np.ones(2 * len(edges)), (*np.concatenate([edges, edges[:, ::-1]]).T,)), shape=(n, n)
    ).tocsr()
    colours = _distance2_colouring(_neighbours(n, edges))
    reach = (graph + graph @ graph).toarray() > 0
    i, j = np.nonzero(reach)
    off = i != j
    assert np.all(colours[i[off]] != colours[j[off]])
    # The ordering is a permutation, and its bandwidth matches scipy's reverse
    # Cuthill–McKee's on the same graph.
    order = _reverse_cuthill_mckee(_neighbours(n, edges))
    assert sorted(order) == list(range(n))

    def width(order):
        return int(np.max(np.abs(np.argsort(order)[edges[:, 0]] - np.argsort(order)[edges[:, 1]])))

    assert width(order) <= width(reverse_cuthill_mckee(graph, symmetric_mode=True))
    # A line needs 3 colours and has bandwidth 1; the greedy colouring and the
    # ordering should find that.
    if n == 10:
        assert colours.max() + 1 == 3
        assert width(order) == 1


def test_free_edges_drop_constrained_nodes():
    # Nodes 0 and 4 are constrained; free nodes 1, 2, 3 renumber to 0, 1, 2.
    segments = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [2, 1]])
    np.testing.assert_array_equal(_free_edges(segments, np.array([1, 2, 3]), 5), [[0, 1], [1, 2]])


def kvaerno5(linear_solver):
    """diffrax's default `Kvaerno5` (VeryChord at the step controller's tolerances)
    with the given linear solver in its root finder."""
    root_finder = diffrax.with_stepsize_controller_tols(diffrax.VeryChord)(linear_solver=linear_solver)
    return diffrax.Kvaerno5(root_finder=root_finder)


@pytest.fixture(scope="module")
def implicit_runs():
    model, env = anchored_line(6, mass_matrix="lumped")
    static = jc.solve_statics(model, env)
    ts = np.linspace(0.0, 2.0, 21)
    linear_solvers = {"structured": NetworkJacobian(model), "dense": lx.LU()}
    runs = {
        name: jc.simulate(
            model, env, 2.0, ts=ts, initial=static.state, solver=jc.SolverConfig(kvaerno5(linear), rtol=1e-8, atol=1e-8)
        )
        for name, linear in linear_solvers.items()
    }
    return runs


@pytest.mark.slow
def test_structured_run_matches_dense_run(implicit_runs):
    """Kvaerno5 (VeryChord) with the structured Jacobian follows diffrax's dense one:
    the same steps to rounding, the same tensions to the root finder's tolerance; and
    with the model traced (an argument of `jit`), the automatic choice's run equals the
    dense one too."""
    structured, dense = implicit_runs["structured"], implicit_runs["dense"]
    assert bool(structured.success) and bool(dense.success)
    peak = float(jnp.max(dense.tension))
    assert float(jnp.max(jnp.abs(structured.tension - dense.tension))) < 1e-6 * peak
    assert abs(int(structured.stats["num_steps"]) - int(dense.stats["num_steps"])) <= 2

    import equinox as eqx

    line, env = anchored_line(6, mass_matrix="lumped")
    static = jc.solve_statics(line, env)
    ts = np.linspace(0.0, 2.0, 21)
    run = eqx.filter_jit(
        lambda m: jc.simulate(
            m, env, 2.0, ts=ts, initial=static.state, solver=jc.SolverConfig(diffrax.Kvaerno5(), rtol=1e-8, atol=1e-8)
        )
    )(line)
    np.testing.assert_allclose(run.tension, dense.tension, rtol=1e-6, atol=1e-6 * peak)


def test_auto_applies_only_where_it_holds(models):
    model, env = models["line"]
    consistent, _ = anchored_line(4)
    from jaxcable._solver.jacobian import with_network_jacobian

    stiff = jc.stiff_solver()
    chosen = with_network_jacobian(stiff, model)
    assert isinstance(chosen.root_finder.linear_solver, NetworkJacobian)
    # Consistent mass, explicit solvers and a user's own linear solver are left alone.
    assert with_network_jacobian(stiff, consistent) is stiff
    explicit = diffrax.Dopri5()
    assert with_network_jacobian(explicit, model) is explicit
    own = kvaerno5(lx.LU())
    assert with_network_jacobian(own, model) is own
    structured = kvaerno5(NetworkJacobian(model))
    assert with_network_jacobian(structured, model) is structured


def test_auto_is_structured_under_jit(models):
    """With the model traced (an argument of `jit`), the automatic choice still picks the
    structured solver, with the colouring and order of the eager one (the run with it:
    `test_structured_run_matches_dense_run`)."""
    import equinox as eqx

    from jaxcable._solver.jacobian import with_network_jacobian

    model, _ = models["line"]
    eager = NetworkJacobian(model)
    chosen = []

    @eqx.filter_jit
    def pick(model):
        solver = with_network_jacobian(jc.stiff_solver(), model).root_finder.linear_solver
        chosen.append(solver)
        return model.node_positions

    pick(model)
    assert type(chosen[0]) is NetworkJacobian
    assert (chosen[0].colours, chosen[0].order, chosen[0].group) == (eager.colours, eager.order, eager.group)


def test_structured_refuses_what_it_cannot_do(models):
    """Asking for the structured solver on a consistent-mass model is an error, not a
    silent dense solve."""
    consistent, _ = anchored_line(4)
    with pytest.raises(ValueError, match="mass_matrix='lumped', got 'consistent'"):
        kvaerno5(NetworkJacobian(consistent))


@pytest.mark.slow
def test_sweep_vmaps_the_structured_solver():
    """A sweep with an implicit solver batches the structured solver (`vmap` over
    cases): each case equals its own `simulate` run."""
    import equinox as eqx

    def build(scale):
        model, env = anchored_line(4, mass_matrix="lumped")
        return eqx.tree_at(lambda m: m.motions[1].amplitude, model, model.motions[1].amplitude * scale), env

    ts = np.linspace(0.0, 0.5, 6)
    batch = jc.sweep(build, {"scale": np.array([0.8, 1.2])}, 0.5, ts=ts, solver=jc.SolverConfig(jc.stiff_solver()))
    assert all(batch.success), batch.status
    for k, scale in enumerate([0.8, 1.2]):
        model, env = build(scale)
        initial = jc.solve_statics(model, env).state
        alone = jc.simulate(model, env, 0.5, ts=ts, initial=initial, solver=jc.SolverConfig(jc.stiff_solver()))
        np.testing.assert_allclose(batch.simulation.tension[k], alone.tension, rtol=1e-8, atol=1e-6)
