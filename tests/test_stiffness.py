"""The mooring's stiffness against references that do not differentiate the statics:
central differences of re-solved equilibria; Irvine's elastic catenary in closed form
(the polyline converging to it at O(1/N²)); a taut weightless line's EA/L and T/S; the
supports' global balance; and, for a body, the 6 × 6 composed by hand from the lines'
3 × 3s and rigid-body kinematics, and central differences of exactly rotated poses.

The default tests compile one program, for a turret mooring (three lines sharing one
attachment point), and reuse it: the taut lines differ in leaves only, and the
re-solved equilibria of the differences come out of the same program (its second
output is `solve_statics`' solution)."""

import dataclasses
import warnings

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx
import pytest
from helpers import BedCatenary, Irvine
from scipy.spatial.transform import Rotation

import jaxcable as jc
from jaxcable._advice import Labels, advise
from jaxcable._statics.solution import FORCE_TOLERANCE, MAX_STEPS
from jaxcable._statics.solve import nearby_equilibrium
from jaxcable._statics.stiffness import _supports_moved, pinned_stiffness, stiffness_and_statics
from jaxcable.io import advice_lines

MASS, DIAMETER, EA = 80.0, 0.1, 5e8  # kg/m, m, N
SPAN, RISE, LENGTH = 300.0, 100.0, 350.0  # m: each anchor 300 m out from its attachment point and 100 m down
SEGMENTS = 8
TURRET = np.array([20.0, 0.0, -10.0])  # m, from the body's reference point
REFERENCE = np.zeros(3)
TURRET_LINES = (0.0, 120.0, 240.0)  # the lines' azimuths (degrees), towards their anchors


def chain() -> jc.LineType:
    return jc.LineType(mass_per_length=MASS, diameter=DIAMETER, tension_law=jc.LinearElastic(EA))


def neutral(env: jc.Environment) -> jc.LineType:
    """A line as heavy as the water it displaces: straight when taut."""
    area = 3e-4
    return jc.LineType(
        mass_per_length=float(env.water_density) * area, diameter=DIAMETER, tension_law=jc.LinearElastic(EA), area=area
    )


def turn(degrees: float) -> np.ndarray:
    return Rotation.from_euler("z", degrees, degrees=True).as_matrix()


def cross_matrix(v) -> np.ndarray:
    """`[v]×`, with `[v]× x = v × x`."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def mooring(points, lines, line: jc.LineType, length: float = LENGTH, segments: int = SEGMENTS):
    """Attachment points (nodes 0, 1, ...) at `points` (m), and a line for each
    `(point, azimuth)` of `lines` to its anchor (the nodes after the points), `SPAN`
    out along the azimuth and `RISE` down: the same line turned. Every end held."""
    points = [np.asarray(p, dtype=float) for p in points]
    anchors = [points[k] + turn(azimuth) @ [SPAN, 0.0, -RISE] for k, azimuth in lines]
    count = len(points)
    return jc.CableNetwork.from_branches(
        junctions=np.array(points + anchors),
        branches=[jc.Branch(count + i, k, line, length, segments) for i, (k, _) in enumerate(lines)],
        constraints={k: jc.Fixed() for k in range(count + len(lines))},
    )


def wet_weight(env: jc.Environment) -> float:
    """w (N/m) of `chain()`."""
    return (MASS - float(env.water_density) * np.pi * DIAMETER**2 / 4) * float(env.gravity)


def irvine(env: jc.Environment, azimuth: float) -> np.ndarray:
    """The continuous line's 3 × 3 at its upper end, for a line whose anchor lies along
    `azimuth`: Irvine's, whose span runs from the anchor to that end, turned by
    azimuth + 180°."""
    q = turn(azimuth + 180.0)
    return q @ Irvine(SPAN, RISE, LENGTH, wet_weight(env), EA).support_stiffness() @ q.T


def moved(model: jc.CableNetwork, nodes, shift) -> jc.CableNetwork:
    """`model` with `nodes` moved by `shift` (m), shape `(len(nodes), 3)`."""
    return eqx.tree_at(lambda m: m.node_positions, model, model.node_positions.at[np.asarray(nodes)].add(shift))


def reactions(model, env) -> np.ndarray:
    """The supports' reactions (N), shape `(constrained, 3)`, from the statics solved
    afresh: the solution that `jc.stiffness`'s program returns beside K, so that the
    differences compile nothing new."""
    _, solution, _ = stiffness_and_statics(model, env, 0.0, None, MAX_STEPS, FORCE_TOLERANCE)
    return np.asarray(solution.reactions)


def central_differences(model, env, steps) -> np.ndarray:
    """∂R/∂x of every support by central differences of re-solved statics, moving each
    support along each axis by `steps[axis]` (m), shape `(3 c, 3 c)`."""
    count = model.constrained_nodes.size
    columns = []
    for node in range(count):
        for axis in range(3):
            shift = np.zeros((count, 3))
            shift[node, axis] = steps[axis]
            plus = reactions(moved(model, model.constrained_nodes, shift), env)
            minus = reactions(moved(model, model.constrained_nodes, -shift), env)
            columns.append((plus - minus).ravel() / (2 * steps[axis]))
    return np.stack(columns, axis=1)


@pytest.fixture(scope="module")
def turret():
    """The turret mooring, its water, and every support's stiffness, `(4, 3, 4, 3)`
    (the turret, then the anchors)."""
    env = jc.Environment()
    model = mooring([TURRET], [(0, a) for a in TURRET_LINES], chain())
    return model, env, np.asarray(jc.stiffness(model, env))


def test_central_differences_of_re_solved_statics(turret):
    """K against `(R(x + h e) − R(x − h e)) / 2h`, every support moved along every axis.
    At h = 1 cm the truncation, (h/ℓ)² K with ℓ ≈ 10–100 m the length over which the
    stiffness changes (the sag, the span), is 1e-6 of K or less; the re-solved
    equilibria are Newton's to rounding, about 1e-10 of the reactions' 5e5 N, which the
    difference turns into 5e-5/2h ≈ 2.5e-3 N/m, 4e-7 of K's 7e3 N/m. Hence 1e-5."""
    model, env, stiffness = turret
    differences = central_differences(model, env, [1e-2] * 3)
    np.testing.assert_allclose(stiffness.reshape(12, 12), differences, atol=1e-5 * np.abs(differences).max())


def test_each_line_against_irvines_elastic_catenary(turret):
    """Each anchor's 3 × 3 is its line's (the turret held, the other lines do not move)
    and equals the line's upper end's (below), so it is Irvine's, turned to the line's
    azimuth. The polyline's own error is second order, 0.54/N² of the largest entry
    (`test_converges_to_irvine_at_second_order` measures it): within 1/N², 1.6 % at
    N = 8. The turret's is the three lines' sum."""
    model, env, stiffness = turret
    expected = [irvine(env, a) for a in TURRET_LINES]
    scale = np.abs(expected[0]).max()
    for k, line in enumerate(expected, start=1):
        np.testing.assert_allclose(stiffness[k, :, k, :], line, atol=scale / SEGMENTS**2)
        # Against its value, not only the scale: across the plane H/l, the smallest entry.
        across = turn(TURRET_LINES[k - 1])[:, 1]
        np.testing.assert_allclose(across @ stiffness[k, :, k, :] @ across, across @ line @ across, rtol=SEGMENTS**-2)
    fairlead = np.asarray(jc.stiffness(model, env, 0))  # the same program: every support's columns
    assert fairlead.shape == (3, 3)
    np.testing.assert_array_equal(fairlead, stiffness[0, :, 0, :])
    np.testing.assert_allclose(fairlead, sum(expected), atol=3 * scale / SEGMENTS**2)
    # MoorPy's sign: the lines pull a displaced support back. Three-fold symmetry
    # makes the turret's isotropic in the plane.
    assert np.all(np.linalg.eigvalsh(0.5 * (fairlead + fairlead.T)) > 0)
    np.testing.assert_allclose(fairlead[0, 0], fairlead[1, 1], rtol=1e-9)
    np.testing.assert_allclose(fairlead[0, 1], 0.0, atol=1e-9 * fairlead[0, 0])


def test_balance_translation_and_symmetry(turret):
    """What the physics requires of any mooring's stiffness: the reactions together
    carry the lines' fixed weight, so their sum does not change (each column sums to
    zero over the supports); moving every support together moves the lines rigidly
    (each row sums to zero); in still water the forces have a potential, so K is
    symmetric. Together, for a line between two supports, its two ends' 3 × 3s are
    equal: so the turret's is the sum of the anchors', the lines' own 3 × 3s."""
    _, _, stiffness = turret
    scale = np.abs(stiffness).max()
    np.testing.assert_allclose(stiffness.sum(axis=0), 0.0, atol=1e-9 * scale)
    np.testing.assert_allclose(stiffness.sum(axis=2), 0.0, atol=1e-9 * scale)
    np.testing.assert_allclose(stiffness.reshape(12, 12), stiffness.reshape(12, 12).T, atol=1e-9 * scale)
    lines = sum(stiffness[k, :, k, :] for k in (1, 2, 3))
    np.testing.assert_allclose(stiffness[0, :, 0, :], lines, atol=1e-9 * scale)


def test_taut_weightless_lines_are_ea_over_l_along_and_t_over_s_across(turret):
    """Neutrally buoyant lines stretched 1 % between the same supports are straight
    whatever N: along each ∂T/∂S = EA/L (L unstretched), across it the tension turns,
    T/S (S stretched). Exact, so to rounding (the same compiled program as the
    catenaries': only leaves differ)."""
    _, env, _ = turret
    chord = np.hypot(SPAN, RISE)
    length = chord / 1.01
    model = mooring([TURRET], [(0, a) for a in TURRET_LINES], neutral(env), length)
    stiffness = np.asarray(jc.stiffness(model, env))
    tension = EA * (chord / length - 1)
    total = np.zeros((3, 3))
    for k, azimuth in enumerate(TURRET_LINES, start=1):
        along = turn(azimuth) @ [SPAN, 0.0, -RISE] / chord
        across = np.eye(3) - np.outer(along, along)
        expected = EA / length * np.outer(along, along) + tension / chord * across
        np.testing.assert_allclose(stiffness[k, :, k, :], expected, rtol=0, atol=1e-9 * EA / length)
        np.testing.assert_allclose(stiffness[0, :, k, :], -expected, rtol=0, atol=1e-9 * EA / length)
        # The transverse part alone, 1 % of the axial, to its own precision.
        np.testing.assert_allclose(np.trace(across @ stiffness[k, :, k, :]) / 2, tension / chord, rtol=1e-9)
        total += expected
    np.testing.assert_allclose(stiffness[0, :, 0, :], total, rtol=0, atol=1e-9 * EA / length)


# --------------------------------------------------------------------------------------
# A body held by the lines.


def by_hand(stiffness, reaction, points, reference):
    """The 6 × 6 of a body whose attachment points are at `points` (m), composed from
    their stiffness `(n, 3, n, 3)` (cross terms included) and reactions `(n, 3)` and
    the kinematics of a small rigid motion, δx_i = δu + δθ × a_i, a_i = x_i − r:

        K_uu = Σ K_ij                     K_uθ = −Σ K_ij [a_j]×
        K_θu = Σ [a_i]× K_ij              K_θθ = Σ [R_i]× [a_i]× − Σ [a_i]× K_ij [a_j]×

    the term in R_i from the arm turning under the reaction. Also the lines' moment on
    the body about r, M = Σ a_i × (−R_i)."""
    arms = [cross_matrix(p - reference) for p in points]
    k6 = np.zeros((6, 6))
    for i, a_i in enumerate(arms):
        k6[3:, 3:] += cross_matrix(reaction[i]) @ a_i
        for j, a_j in enumerate(arms):
            k = stiffness[i, :, j, :]
            k6[:3, :3] += k
            k6[:3, 3:] -= k @ a_j
            k6[3:, :3] += a_i @ k
            k6[3:, 3:] -= a_i @ k @ a_j
    moment = -sum(np.cross(p - reference, r) for p, r in zip(points, reaction))
    return k6, moment


def assert_columns_close(found, expected, tolerance):
    """Each column within `tolerance` of the largest entry of its own column of
    `expected`: a 6 × 6's columns have units of their own (per metre, per radian)."""
    scale = np.abs(expected).max(axis=0)
    np.testing.assert_allclose(found / scale, expected / scale, rtol=0, atol=tolerance)


def check_body(model, env, nodes, reference, stiffness):
    """`jc.body_stiffness` against `by_hand` (and its rotational block's asymmetry,
    ½ [M]×) and against central differences of poses: the attachment points moved by
    exact rotations (SciPy's) and translations, the statics re-solved, F and M summed
    here. Steps 1 cm and 1e-3 rad (a few cm at the points): the truncation is
    (h/ℓ)² ≈ 1e-6 of K, as for the supports, and rounding less. Returns the 6 × 6."""
    points = np.asarray(model.node_positions)[nodes]
    k6 = np.asarray(jc.body_stiffness(model, env, nodes, reference))
    rows = np.searchsorted(model.constrained_nodes, nodes)
    expected, moment = by_hand(stiffness[rows][:, :, rows], reactions(model, env)[rows], points, reference)
    assert_columns_close(k6, expected, 1e-8)
    np.testing.assert_allclose(k6[3:, :3], k6[:3, 3:].T, atol=1e-8 * np.abs(k6[3:, :3]).max())
    antisymmetric = 0.5 * (k6[3:, 3:] - k6[3:, 3:].T)
    assert np.linalg.norm(moment) > 1e5  # N m: the lines' weight pulls on arms off the reference point
    np.testing.assert_allclose(antisymmetric, 0.5 * cross_matrix(moment), atol=1e-8 * np.abs(k6[3:, 3:]).max())

    def loads(pose):
        rotation = Rotation.from_rotvec(pose[3:]).as_matrix()
        arms = (points - reference) @ rotation.T
        pull = -reactions(moved(model, nodes, pose[:3] + arms - (points - reference)), env)[rows]
        return np.concatenate([pull.sum(axis=0), np.cross(arms, pull).sum(axis=0)])

    columns = []
    for j, h in enumerate([1e-2] * 3 + [1e-3] * 3):
        e = np.zeros(6)
        e[j] = h
        columns.append(-(loads(e) - loads(-e)) / (2 * h))
    assert_columns_close(k6, np.stack(columns, axis=1), 1e-5)
    return k6


def test_body_on_the_turret(turret):
    """A body moored by three lines sharing one attachment point 20 m fore and 10 m
    below its reference point: by hand and by differences (`check_body`); its
    translational block the sum of the lines' 3 × 3s, each the first one turned to its
    azimuth (the symmetric spread)."""
    model, env, stiffness = turret
    k6 = check_body(model, env, [0], REFERENCE, stiffness)
    first = stiffness[1, :, 1, :]
    turned = sum(turn(a) @ first @ turn(a).T for a in TURRET_LINES)
    np.testing.assert_allclose(k6[:3, :3], turned, atol=1e-8 * np.abs(turned).max())


# --------------------------------------------------------------------------------------
# The advice reports a coupled point's stiffness, where asked.


def test_advice_reports_a_coupled_points_stiffness(turret):
    """`advise(..., stiffness=True)` on the turret mooring named as a scene would name
    it, the turret coupled: its 3 × 3 (the same program's), said in kN/m; without
    `stiffness`, a line that says how to get it."""
    model, env, stiffness = turret
    # `from_branches`' numbering: the junctions, then each line's interior nodes and
    # segments, anchor to turret.
    inner = SEGMENTS - 1
    lines = tuple(
        (
            f"line{i}",
            np.array([1 + i, *range(4 + inner * i, 4 + inner * (i + 1)), 0]),
            np.arange(SEGMENTS * i, SEGMENTS * (i + 1)),
        )
        for i in range(3)
    )
    labels = Labels(lines, ("chain",) * 3, ("turret", "anchor0", "anchor1", "anchor2"), coupled=(0,))
    advice = advise(model, env, labels=labels, stiffness=True)
    (reported,) = advice.stiffness
    assert reported.point == "turret" and reported.node == 0
    np.testing.assert_array_equal(reported.matrix, stiffness[0, :, 0, :])
    diagonal = ", ".join(f"{x / 1e3:.4g}" for x in np.diag(stiffness[0, :, 0, :]))
    assert any(f"point turret: stiffness at rest K_xx, K_yy, K_zz = {diagonal} kN/m" in t for t in advice_lines(advice))
    hint = advice_lines(dataclasses.replace(advice, stiffness=()))
    assert any(t.startswith("coupled point(s) turret: jaxcable info --stiffness adds") for t in hint)


# --------------------------------------------------------------------------------------
# Bad input: refused before anything compiles.


@pytest.mark.unchecked  # wrong types on purpose: jaxcable's own errors, not jaxtyping's
def test_bad_nodes_and_reference_are_named(turret):
    model, env, _ = turret
    with pytest.raises(ValueError, match=r"nodes has node 5, which is not a constrained node.*\[0, 1, 2, 3\]"):
        jc.stiffness(model, env, 5)
    with pytest.raises(ValueError, match=r"names a node twice: \[1, 1\]"):
        jc.stiffness(model, env, [1, 1])
    with pytest.raises(ValueError, match=r"at least one constrained node"):
        jc.stiffness(model, env, [])
    with pytest.raises(ValueError, match=r"body_stiffness: nodes must be a sequence"):
        jc.body_stiffness(model, env, 0, REFERENCE)
    with pytest.raises(ValueError, match=r"body_stiffness: reference must be a 3-vector \(m\), got shape \(2,\)"):
        jc.body_stiffness(model, env, [0], [0.0, 0.0])


# --------------------------------------------------------------------------------------
# Slow: convergence, a spread of shared points, and derivatives of the stiffness itself
# (which design by gradients needs).


@pytest.mark.slow
def test_converges_to_irvine_at_second_order():
    """One line's upper end at N = 8, 16, 32: the error against Irvine falls by 4 each
    doubling (order 2 within 0.05), and Richardson's extrapolation from 16 and 32,
    (4 K₃₂ − K₁₆)/3, agrees with the closed form to 1e-5."""
    env = jc.Environment()
    expected = irvine(env, 0.0)
    scale = np.abs(expected).max()
    found = {
        n: np.asarray(jc.stiffness(mooring([TURRET], [(0, 0.0)], chain(), segments=n), env, 0)) for n in (8, 16, 32)
    }
    errors = [np.abs(found[n] - expected).max() / scale for n in (8, 16, 32)]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    np.testing.assert_allclose(orders, 2.0, atol=0.05)
    np.testing.assert_allclose((4 * found[32] - found[16]) / 3, expected, atol=1e-5 * scale)


@pytest.mark.slow
def test_body_on_a_spread_of_shared_points():
    """Six lines from three attachment points 120° apart (each point's two lines leave
    at its azimuth ± 20°), the reference point off the body's axis: `check_body`, and
    the translational block the sum of the six lines' 3 × 3s (each anchor's)."""
    env = jc.Environment()
    points = [turn(a) @ [20.0, 0.0, -10.0] for a in (0.0, 120.0, 240.0)]
    lines = [(k, a + s) for k, a in enumerate((0.0, 120.0, 240.0)) for s in (-20.0, 20.0)]
    model = mooring(points, lines, chain())
    stiffness = np.asarray(jc.stiffness(model, env))
    k6 = check_body(model, env, [0, 1, 2], np.array([2.0, -3.0, 5.0]), stiffness)
    lines_sum = sum(stiffness[k, :, k, :] for k in range(3, 9))
    np.testing.assert_allclose(k6[:3, :3], lines_sum, atol=1e-8 * np.abs(lines_sum).max())


@pytest.mark.slow
def test_stiffness_is_differentiable_and_vmaps_over_designs():
    """`jax.grad` of a line's K_xx at its upper end with respect to its length (every
    segment scaled) against central differences of K_xx (step 1e-4 of the length:
    truncation ~1e-8, rounding ~1e-7 of the derivative), and a `vmap` over lengths
    against one call each."""
    env = jc.Environment()
    model = mooring([TURRET], [(0, 0.0)], chain())

    def k_xx(scale):
        longer = eqx.tree_at(lambda m: m.segment_length, model, model.segment_length * scale)
        return jc.stiffness(longer, env, 0)[0, 0]

    gradient = jax.grad(k_xx)(1.0)
    h = 1e-4
    difference = (k_xx(1.0 + h) - k_xx(1.0 - h)) / (2 * h)
    np.testing.assert_allclose(gradient, difference, rtol=1e-5)
    assert gradient < 0  # a longer line is softer
    scales = jnp.array([0.99, 1.0, 1.01])
    np.testing.assert_allclose(jax.vmap(k_xx)(scales), [k_xx(s) for s in scales], rtol=1e-10)


def on_the_bed(segments: int):
    """`validation/stiffness.py`'s chain on a frictionless bed: 500 m from an anchor on
    the bed 150 m down to a fairlead 400 m along at −5 m, about 330 m lying."""
    model = jc.CableNetwork.from_branches(
        junctions=np.array([[400.0, 0.0, -5.0], [0.0, 0.0, -150.0]]),
        branches=[jc.Branch(1, 0, chain(), 500.0, segments)],
        constraints={0: jc.Fixed(), 1: jc.Fixed()},
    )
    env = jc.Environment(depth=150.0, seabed=jc.Seabed(stiffness=3e6))
    wet = (MASS - float(env.water_density) * np.pi * DIAMETER**2 / 4) * float(env.gravity)
    return model, env, BedCatenary(400.0, 145.0, 500.0, wet, EA).support_stiffness()


@pytest.mark.slow
def test_a_line_on_the_seabed_has_the_continuous_lines_stiffness():
    """Where the line rests on the bed the fairlead's 3 × 3 is within 1 % of the
    continuous line's closed form (MoorPy's catenary with seabed contact) at 40
    segments, where the exact derivative of the polyline's equilibrium, pinned at its
    last node on the bed, is off by 4.4 % in K_zz."""
    model, env, expected = on_the_bed(40)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the fairlead is far enough above the bed: no warning
        k = np.asarray(jc.stiffness(model, env, 0))
    scale = np.abs(expected).max()
    np.testing.assert_allclose(k, expected, atol=0.01 * scale)
    pinned, _, _ = pinned_stiffness(model, env, 0.0, None, MAX_STEPS, FORCE_TOLERANCE)
    assert abs(float(pinned[0, 2, 0, 2]) / expected[2, 2] - 1) > 0.03


@pytest.mark.slow
def test_a_line_on_the_seabed_converges_to_the_continuous_line():
    """The fairlead's 3 × 3 against the closed form at 32 to 64 segments in steps of
    4, the largest difference relative to the largest entry: within 2 % throughout,
    not monotone (1.2 % at 32, 1.7 % at 36, 0.34 % at 40: how the sawtooth's period
    changes across the samples depends on where the touchdown sits), and 0.07 % at 64."""
    errors = {}
    for n in range(32, 65, 4):
        model, env, expected = on_the_bed(n)
        k = np.asarray(jc.stiffness(model, env, 0))
        errors[n] = np.abs(k - expected).max() / np.abs(expected).max()
    assert max(errors.values()) < 0.02, errors
    assert errors[64] < 0.002, errors


@pytest.mark.slow
def test_a_spread_on_the_seabed_has_the_continuous_lines_stiffness():
    """A body held by three chains 120° apart in 200 m, each with about 336 m on the bed
    (32 segments a line): `jc.body_stiffness`'s translational block against the sum of
    the three lines' closed forms turned to their headings, within 0.5 % of the largest
    entry (0.07 % measured; a fixed amplitude of half a segment, 13 m, gave 8 %)."""
    depth, fairlead, anchor, length = 200.0, 20.0, 820.0, 850.0
    headings = np.radians([0.0, 120.0, 240.0])
    ring = np.stack([np.cos(headings), np.sin(headings), np.zeros(3)], axis=1)
    fairleads = fairlead * ring + [0.0, 0.0, -5.0]
    anchors = anchor * ring + [0.0, 0.0, -depth]
    model = jc.CableNetwork.from_branches(
        junctions=np.concatenate([fairleads, anchors]),
        branches=[jc.Branch(3 + i, i, chain(), length, 32) for i in range(3)],
        constraints={k: jc.Fixed() for k in range(6)},
    )
    env = jc.Environment(depth=depth, seabed=jc.Seabed(stiffness=3e6))
    wet = (MASS - float(env.water_density) * np.pi * DIAMETER**2 / 4) * float(env.gravity)
    line = BedCatenary(anchor - fairlead, depth - 5.0, length, wet, EA).support_stiffness()
    expected = np.zeros((3, 3))
    for along in ring:  # the line's axes: from the anchor to the fairlead, across, up
        axes = np.stack([-along, np.cross([0.0, 0.0, 1.0], -along), [0.0, 0.0, 1.0]], axis=1)
        expected += axes @ line @ axes.T
    k = np.asarray(jc.body_stiffness(model, env, [0, 1, 2], np.array([0.0, 0.0, -5.0])))[:3, :3]
    np.testing.assert_allclose(k, expected, atol=0.005 * np.abs(expected).max())


@pytest.mark.slow
def test_the_pinned_derivative_on_the_seabed_at_fine_resolution():
    """The same line at N = 128, where the softest stage of statics' continuation rests
    with compressed segments on the bed (a singular Jacobian) and a derivative through
    every stage once failed in lineax: the exact derivative of the equilibrium against
    the implicit-function formula at the equilibrium, `K = −(J_cc − J_cf J_ff⁻¹ J_fc)`,
    with J the dense Jacobian of the forces by `jax.jacfwd` and numpy's solve (866.8 N/m
    along the span: the line pinned at its last node on the bed, where the continuous
    line's is 885)."""
    from jaxcable._equations import lagrangian as lag

    model, env, _ = on_the_bed(128)
    k, _, solution = pinned_stiffness(model, env, 0.0, None, MAX_STEPS, FORCE_TOLERANCE)
    x = solution.state.positions
    assert int(np.sum(np.asarray(x)[:, 2] < -150.0)) > 60  # most of the line lies on the bed
    jacobian = np.asarray(jax.jacfwd(lambda y: lag.generalised_forces(model, env, 0.0, y, jnp.zeros_like(y)))(x))
    free, held = np.asarray(model.free_nodes), np.asarray(model.constrained_nodes)

    def block(a, b):
        return jacobian[a][:, :, b].reshape(3 * a.size, 3 * b.size)

    reduced = -(block(held, held) - block(held, free) @ np.linalg.solve(block(free, free), block(free, held)))
    expected = reduced.reshape(held.size, 3, held.size, 3)[0, :, 0, :]
    np.testing.assert_allclose(np.asarray(k)[0, :, 0, :], expected, rtol=1e-6, atol=1e-6 * np.abs(expected).max())
    assert 850.0 < expected[0, 0] < 885.0


def test_the_nearby_equilibrium_is_the_equilibrium():
    """The touchdown's equilibria, by the statics' last stage alone from the
    equilibrium before a support moved 5 m, are the discrete catenary's in closed form
    (`solve_statics` of the moved line): the reactions to 1e-6 relative, the nodes to
    a millimetre."""
    model, env, _ = on_the_bed(16)
    here = jc.solve_statics(model, env)
    moved = _supports_moved(model, jnp.zeros((2, 3)).at[0].set([5.0, 0.0, 3.0]))
    near = nearby_equilibrium(moved, env, here.state, 0.0, MAX_STEPS, FORCE_TOLERANCE)
    full = jc.solve_statics(moved, env)
    assert bool(near.result == optx.RESULTS.successful) and full.method == "discrete catenary"
    np.testing.assert_allclose(
        near.reactions, full.reactions, rtol=1e-6, atol=1e-6 * float(jnp.abs(full.reactions).max())
    )
    np.testing.assert_allclose(near.state.positions, full.state.positions, atol=1e-3)


@pytest.mark.slow
def test_the_stiffness_on_the_seabed_differentiates():
    """`jax.grad` of the fairlead's K_xx on the bed, across the touchdown's seven
    equilibria, in the segments' length (a scale of it), against a central difference
    (h = 1e-4; −22,449 against −22,451 N/m, measured)."""
    model, env, _ = on_the_bed(24)

    def k_xx(scale):
        scaled = eqx.tree_at(lambda m: m.segment_length, model, model.segment_length * scale)
        return jc.stiffness(scaled, env, 0)[0, 0]

    h = 1e-4
    central = (k_xx(1.0 + h) - k_xx(1.0 - h)) / (2 * h)
    np.testing.assert_allclose(jax.grad(k_xx)(1.0), central, rtol=1e-3)


@pytest.mark.slow  # 21 s of the default suite
def test_a_support_too_close_to_the_seabed_is_warned_of():
    """A taut line resting on the bed up to a support 20 m above it: the support cannot
    be moved across the touchdown (8 segments of 50 m) without going below the bed, so
    its columns are the pinned line's, and `stiffness` and `body_stiffness` say so,
    naming the node."""
    model = jc.CableNetwork.from_branches(
        junctions=np.array([[399.0, 0.0, -130.0], [0.0, 0.0, -150.0]]),
        branches=[jc.Branch(1, 0, chain(), 400.0, 8)],
        constraints={0: jc.Fixed(), 1: jc.Fixed()},
    )
    env = jc.Environment(depth=150.0, seabed=jc.Seabed(stiffness=3e6))
    with pytest.warns(UserWarning, match=r"stiffness: nodes \[0\] are too close to the seabed"):
        k = jc.stiffness(model, env, 0)
    assert np.all(np.isfinite(np.asarray(k)))
    with pytest.warns(UserWarning, match=r"body_stiffness: nodes \[0\] are too close"):
        jc.body_stiffness(model, env, [0], np.array([399.0, 0.0, -130.0]))
