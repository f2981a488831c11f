"""`CableNetwork(hydrodynamics="nodes")`: drag, Morison's inertia force and added mass
lumped at the nodes, as MoorDyn lumps them (`Line::getStateDeriv`, v2.7), checked
against that loop written out independently here; its agreement with the segment form
as segments shrink; and its refusals. The runs against MoorDyn itself are in
`test_cli_run.py`."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcable as jc
from jaxcable._equations import lagrangian as eq
from jaxcable.io import SceneError

LINE = jc.LineType(
    mass_per_length=8.0,
    diameter=0.05,
    tension_law=jc.LinearElastic(2e7),
    normal_drag=1.2,
    tangential_drag=0.2,
    normal_added_mass=1.0,
    tangential_added_mass=0.3,
)
CHAIN = jc.LineType(
    mass_per_length=40.0,
    diameter=0.09,
    tension_law=jc.LinearElastic(5e8),
    normal_drag=2.4,
    tangential_drag=1.15,
    normal_added_mass=1.0,
    tangential_added_mass=0.5,
)


def _two_lines(hydrodynamics="nodes", bodies=None):
    """A rope from an anchor up through the surface to a point, and a chain from that
    free point to a fairlead: the point joins two lines, as a MoorDyn point does, and
    the rope's top segments cross z = 0 once the shape is raised."""
    junctions = np.array([[0.0, 0.0, -40.0], [30.0, 5.0, -20.0], [70.0, 0.0, 0.0]])
    return jc.CableNetwork.from_branches(
        junctions,
        [jc.Branch(0, 1, LINE, 40.0, 6), jc.Branch(1, 2, CHAIN, 50.0, 5)],
        {0: jc.Fixed(), 2: jc.Fixed()},
        bodies=bodies,
        mass_matrix="lumped",
        hydrodynamics=hydrodynamics,
    )


def _state(model):
    """A bent shape, partly above z = 0, and a velocity that varies along it."""
    rng = np.random.default_rng(3)
    x = np.asarray(model.node_positions) + rng.normal(0.0, 0.7, (model.n_nodes, 3))
    x[[6, 7], 2] = (3.0, 6.0)  # the rope's top two interior nodes above the surface
    v = rng.normal(0.0, 0.4, (model.n_nodes, 3))
    held = model.constrained_nodes  # where their fixed supports hold them
    x[held], v[held] = np.asarray(model.node_positions)[held], 0.0
    return x, v


def _environment():
    wave = jc.Airy(height=2.0, period=8.0, depth=60.0)
    return jc.Environment(current=(0.6, -0.2, 0.0), free_surface=True, depth=60.0, waves=(wave,))


def _moordyn_lumped(model, env, t, x, v, lines):
    """MoorDyn's node loop, line by line, written from `Line.cpp`: for node i of a line
    with N segments, q the unit chord through its neighbours (its segment's direction
    at the line's ends), l the unstretched segment lengths, F the segments' submerged
    fractions, and the submerged length ½(l_{i−1} F_{i−1} + l_i F_i):

        Dp = ½ ρ d Cd ℓ |v_p| v_p,   Dq = ½ ρ d π CdAx ℓ |v_q| v_q,
        Ap = ρ (1 + Ca) A ℓ a_p,     Aq = ρ (1 + CaAx) A ℓ a_q,
        M  = m ℓ_full I + ρ A ℓ (Ca (I − q qᵀ) + CaAx q qᵀ),

    summed where lines meet, as MoorDyn's points sum their lines' end nodes."""
    rho = float(env.water_density)
    force = np.zeros((model.n_nodes, 3))
    mass = np.zeros((model.n_nodes, 3, 3))
    u = np.asarray(env.water_velocity(jnp.asarray(x), t)) - v
    a = np.asarray(env.water_acceleration(jnp.asarray(x), t))
    for nodes, segments in lines:
        n = len(segments)
        lengths = np.asarray(model.segment_length)[segments]
        z = x[nodes, 2]
        submerged = np.empty(n)
        for s in range(n):
            z0, z1 = z[s], z[s + 1]
            if max(z0, z1) <= 0:
                submerged[s] = 1.0
            elif min(z0, z1) >= 0:
                submerged[s] = 0.0
            else:
                submerged[s] = -min(z0, z1) / abs(z1 - z0)
        props = {k: np.asarray(getattr(model.line, k))[segments[0]] for k in ("mass_per_length", "diameter", "area")}
        cd, cdax = (float(np.asarray(getattr(model.line, k))[segments[0]]) for k in ("normal_drag", "tangential_drag"))
        ca, caax = (
            float(np.asarray(getattr(model.line, k))[segments[0]])
            for k in ("normal_added_mass", "tangential_added_mass")
        )
        for i in range(n + 1):
            lo, hi = max(i - 1, 0), min(i + 1, n)
            chord = x[nodes[hi]] - x[nodes[lo]]
            q = chord / np.linalg.norm(chord)
            left = (lengths[i - 1], submerged[i - 1]) if i > 0 else (0.0, 0.0)
            right = (lengths[i], submerged[i]) if i < n else (0.0, 0.0)
            full = 0.5 * (left[0] + right[0])
            wet = 0.5 * (left[0] * left[1] + right[0] * right[1])
            k = nodes[i]
            uq = (u[k] @ q) * q
            up = u[k] - uq
            force[k] += (
                0.5
                * rho
                * props["diameter"]
                * wet
                * (cd * np.linalg.norm(up) * up + np.pi * cdax * np.linalg.norm(uq) * uq)
            )
            aq = (a[k] @ q) * q
            force[k] += rho * props["area"] * wet * ((1 + ca) * (a[k] - aq) + (1 + caax) * aq)
            qq = np.outer(q, q)
            mass[k] += props["mass_per_length"] * full * np.eye(3)
            mass[k] += rho * props["area"] * wet * (ca * (np.eye(3) - qq) + caax * qq)
    return force, mass


def _lines(model):
    """`(nodes, segments)` of each branch, as `from_branches` numbers them."""
    return [
        (np.array([0, *range(3, 8), 1]), np.arange(0, 6)),
        (np.array([1, *range(8, 12), 2]), np.arange(6, 11)),
    ]


def test_the_nodal_form_is_moordyns_node_loop():
    """Drag and Morison's inertia (a current and an Airy wave, with the free surface:
    two of the rope's segments cross it) and the lumped mass blocks, node by node,
    against MoorDyn's loop; where the two lines meet, each keeps its own end segment's
    direction, as MoorDyn's line end nodes do."""
    model = _two_lines()
    env = _environment()
    x, v = _state(model)
    t = 3.7
    lines = _lines(model)
    for nodes, segments in lines:
        np.testing.assert_array_equal(model.segment_nodes[segments], np.stack([nodes[:-1], nodes[1:]], 1))
    z = x[lines[0][0], 2]
    assert np.sum((z[:-1] < 0) != (z[1:] < 0)) >= 1  # a segment crosses the surface
    force, mass = _moordyn_lumped(model, env, t, x, v, lines)

    # The loads without the line's internal damping (none here) and without bodies.
    got = np.asarray(eq.nonconservative_forces(model, env, t, jnp.asarray(x), jnp.asarray(v)))
    scale = np.max(np.abs(force))
    assert scale > 10.0
    np.testing.assert_allclose(got, force, rtol=0, atol=1e-12 * scale)
    blocks = np.asarray(eq.lumped_blocks(model, env, jnp.asarray(x)))
    np.testing.assert_allclose(blocks, mass, rtol=0, atol=1e-12 * np.max(np.abs(mass)))


def test_the_closed_form_solve_is_the_blocks_inverse():
    """The free nodes' accelerations by the closed form (one direction per node inside a
    line, Sherman–Morrison; two at the point joining the lines, Woodbury) equal a
    direct solve with the 3 × 3 blocks."""
    model = _two_lines(bodies={1: jc.Body(mass=50.0, volume=0.02)})
    env = _environment()
    x, v = _state(model)
    free = model.free_nodes
    a, *_ = eq.free_accelerations(model, env, 1.0, jnp.asarray(x[free]), jnp.asarray(v[free]))
    blocks = np.asarray(eq.lumped_blocks(model, env, jnp.asarray(x)))[free]
    q = np.asarray(eq.generalised_forces(model, env, 1.0, jnp.asarray(x), jnp.asarray(v)))[free]
    np.testing.assert_allclose(np.asarray(a), np.linalg.solve(blocks, q[..., None])[..., 0], rtol=1e-11, atol=1e-11)


def test_isotropic_added_mass_gives_the_segment_forms_matrix():
    """With C_a = C_aτ the blocks do not depend on directions: the two forms' lumped
    matrices are the same, to rounding."""
    line = _replace(LINE, tangential_added_mass=LINE.normal_added_mass)
    chain = _replace(CHAIN, tangential_added_mass=CHAIN.normal_added_mass)
    junctions = np.array([[0.0, 0.0, -40.0], [30.0, 5.0, -20.0], [70.0, 0.0, 0.0]])
    branches = [jc.Branch(0, 1, line, 40.0, 6), jc.Branch(1, 2, chain, 50.0, 5)]
    env = _environment()
    blocks = []
    for form in ("segments", "nodes"):
        model = jc.CableNetwork.from_branches(
            junctions, branches, {0: jc.Fixed(), 2: jc.Fixed()}, mass_matrix="lumped", hydrodynamics=form
        )
        x, _ = _state(model)
        blocks.append(np.asarray(eq.lumped_blocks(model, env, jnp.asarray(x))))
    np.testing.assert_allclose(blocks[1], blocks[0], rtol=1e-13, atol=0)


def _replace(line, **fields):
    names = list(fields)
    return eqx.tree_at(lambda m: [getattr(m, k) for k in names], line, [jnp.asarray(fields[k]) for k in names])


def _arc(n):
    """A rope on a circular arc, its nodes at exactly the unstretched spacing, moving
    across a current: the two forms differ only by how they place the loads."""
    length, radius = 60.0, 40.0
    theta = length / radius
    chord = 2 * radius * np.sin(theta / (2 * n))  # the node spacing along the arc
    angles = np.linspace(-theta / 2, theta / 2, n + 1)
    x = np.stack([radius * np.sin(angles), 0.0 * angles, -60.0 + radius * (1 - np.cos(angles))], 1)
    edges = np.stack([np.arange(n), np.arange(1, n + 1)], 1)
    v = np.stack([0.3 * np.cos(3 * angles), 0.2 + 0 * angles, 0.4 * np.sin(2 * angles)], 1)
    models = [
        jc.CableNetwork(
            x, edges, np.full(n, chord), LINE, {0: jc.Fixed(), n: jc.Fixed()}, mass_matrix="lumped", hydrodynamics=f
        )
        for f in ("segments", "nodes")
    ]
    return models, x, v


def test_the_two_forms_agree_as_segments_shrink():
    """The lumped loads converge to the segment form's quadrature: the total force's
    difference falls about fourfold each time the segments halve."""
    env = jc.Environment(current=(0.8, 0.0, 0.1))
    differences = []
    for n in (8, 16, 32):
        models, x, v = _arc(n)
        totals = [
            np.asarray(eq.nonconservative_forces(m, env, 0.0, jnp.asarray(x), jnp.asarray(v))).sum(0) for m in models
        ]
        differences.append(np.linalg.norm(totals[1] - totals[0]) / np.linalg.norm(totals[0]))
    assert differences[0] > 1e-4  # the forms do differ at coarse segments
    assert differences[1] < differences[0] / 3 and differences[2] < differences[1] / 3, differences


def test_nodal_forces_have_the_derivative_of_central_differences():
    """The nodal loads' Jacobian in the positions (through each node's direction and
    the submerged fractions) against central differences."""
    model = _two_lines()
    env = _environment()
    x, v = _state(model)

    def loads(flat):
        return eq.nonconservative_forces(model, env, 1.3, flat.reshape(-1, 3), jnp.asarray(v)).ravel()

    flat = jnp.asarray(x).ravel()
    jacobian = np.asarray(jax.jacfwd(loads)(flat))
    h = 1e-6
    for k in (5, 3 * 7 + 2, 3 * 9, 3 * 1 + 1):  # inside a line, at the surface, the point
        step = np.zeros(flat.size)
        step[k] = h
        central = (np.asarray(loads(flat + step)) - np.asarray(loads(flat - step))) / (2 * h)
        np.testing.assert_allclose(jacobian[:, k], central, rtol=1e-6, atol=1e-6 * np.max(np.abs(central)))


def test_the_nodal_form_needs_the_lumped_matrix_and_a_known_name(tmp_path):
    junctions = np.array([[0.0, 0.0, -40.0], [30.0, 5.0, -20.0]])
    branch = [jc.Branch(0, 1, LINE, 40.0, 4)]
    with pytest.raises(ValueError, match=r"hydrodynamics='nodes'.*needs mass_matrix='lumped'.*'consistent'"):
        jc.CableNetwork.from_branches(junctions, branch, {0: jc.Fixed(), 1: jc.Fixed()}, hydrodynamics="nodes")
    with pytest.raises(ValueError, match=r"CableNetwork.hydrodynamics.*'node'"):
        jc.CableNetwork.from_branches(junctions, branch, {0: jc.Fixed(), 1: jc.Fixed()}, hydrodynamics="node")
    with pytest.raises(ValueError, match=r"CableNetwork.line_ends has node 7"):
        jc.CableNetwork.from_branches(junctions, branch, {0: jc.Fixed(), 1: jc.Fixed()}, line_ends=[7])
    scene = tmp_path / "scene.toml"
    text = (
        '[simulation]\nhydrodynamics = "nodes"\n\n'
        "[line_types.rope]\nmass_per_length = 3.0\ndiameter = 0.02\naxial_stiffness = 3e7\n\n"
        '[points.a]\ntype = "fixed"\nposition = [0.0, 0.0, -40.0]\n\n'
        '[points.b]\ntype = "fixed"\nposition = [30.0, 0.0, -20.0]\n\n'
        '[[lines]]\ntype = "rope"\nfrom = "a"\nto = "b"\nlength = 40.0\nsegments = 4\n'
    )
    scene.write_text(text)
    with pytest.raises(SceneError, match=r"hydrodynamics.*needs mass_matrix = \"lumped\""):
        jc.read_scene(scene)
    scene.write_text(text.replace('hydrodynamics = "nodes"', 'hydrodynamics = "nodes"\nmass_matrix = "lumped"'))
    assert jc.read_scene(scene).build().model.hydrodynamics == "nodes"
