"""Static equilibrium against closed forms.

References, all independent of jaxcable (the catenaries are in `helpers.py`):

- Irvine's elastic catenary (H. M. Irvine, *Cable Structures*, MIT Press 1981, §2.2):
  the shape of an extensible cable of unstretched length L₀, axial stiffness EA and
  submerged weight w per unstretched length, parametrised by the Lagrangian
  (unstretched) coordinate s, with the two closure equations for span and height
  solved for the horizontal tension H and the end's vertical reaction V.
- Statics of the whole line: the supports carry the whole submerged weight and, with no
  current, no net horizontal force.
- A nearly straight vertical line in a uniform current: the horizontal reaction is the
  integrated normal drag ½ ρ K_n d U² · length, and the buoy's offset is q L² / (2 B).

The polyline puts each segment's weight half on each end node (its potential uses the
mid-depth), a trapezoid rule along the cable, so the discrete solution converges to the
continuum at O(1/N²): errors fall by about 4 per doubling of N.

The accuracy tests call `solve_statics` through `eqx.filter_jit`, one compilation per
model shape; the failure tests call it eagerly and under `jit`, whose documented error
is the same `equinox.EquinoxRuntimeError` (a `RuntimeError`) both ways.
"""

from pathlib import Path

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx
import pytest
from helpers import Irvine, chain_nodes, hand_forces, rigid_top_tension

import jaxcable as jc
from jaxcable._statics.solve import _check_geometry, _water_loads
from jaxcable._statics.start import start_shape

RHO, G = 1025.0, 9.81
solve = eqx.filter_jit(jc.solve_statics)
RHO_ENV = jc.Environment(water_density=RHO, gravity=G)


def hand_tension(model, positions, ea):
    """Hooke's law from the node positions, T = EA (S/L − 1), S the segment's length."""
    ends = np.asarray(model.segment_nodes)
    stretched = np.linalg.norm(positions[ends[:, 1]] - positions[ends[:, 0]], axis=1)
    return np.maximum(ea * (stretched / np.asarray(model.segment_length) - 1), 0.0)


# ---------------------------------------------------------------------------------------
# 1, 3. A single catenary between an anchor and a fairlead.
# ---------------------------------------------------------------------------------------

MASS, DIAMETER, EA = 50.0, 0.1, 5.0e6  # kg/m, m, N: strains of about 1 %
W = (MASS - RHO * np.pi * DIAMETER**2 / 4) * G  # submerged weight per length (N/m)
LENGTH = 200.0
AZIMUTH = np.radians(30.0)  # the line's vertical plane, off the x axis
HEADING = np.array([np.cos(AZIMUTH), np.sin(AZIMUTH), 0.0])
ANCHOR = np.array([10.0, -5.0, -100.0])
SPAN, HEIGHT = 150.0, 100.0
FAIRLEAD = ANCHOR + SPAN * HEADING + np.array([0.0, 0.0, HEIGHT])
RESOLUTIONS = (10, 20, 40)


def catenary_model(n_segments):
    line = jc.LineType(MASS, DIAMETER, jc.LinearElastic(EA), normal_drag=0.0, tangential_drag=0.0)
    return jc.CableNetwork.from_branches(
        np.stack([ANCHOR, FAIRLEAD]),
        [jc.Branch(0, 1, line, LENGTH, n_segments)],
        constraints={0: jc.Fixed(), 1: jc.Fixed()},
    )


@pytest.fixture(scope="module")
def irvine():
    return Irvine(SPAN, HEIGHT, LENGTH, W, EA)


@pytest.fixture(scope="module")
def catenaries():
    env = jc.Environment(water_density=RHO, gravity=G)
    out = {}
    for n in RESOLUTIONS:
        model = catenary_model(n)
        out[n] = (model, solve(model, env))
    return out


def test_reference_catenary_is_elastic(irvine):
    """The reference is a genuinely elastic case: the inextensible catenary's top
    tension differs by far more than the tolerances below."""
    elastic = np.hypot(irvine.H, irvine.V)
    rigid = rigid_top_tension(SPAN, HEIGHT, LENGTH, W)
    assert abs(rigid / elastic - 1) > 0.01
    # End strain is about 1.5 %: elasticity lengthens the line by metres.
    assert 0.005 < elastic / EA < 0.05


def test_catenary_fairlead_tension_and_angle(catenaries, irvine):
    """The fairlead's support force against Irvine's end tension, converging at O(1/N²)."""
    exact_tension = np.hypot(irvine.H, irvine.V)
    exact_angle = np.degrees(np.arctan2(irvine.V, irvine.H))
    tension_error, angle_error = [], []
    for n in RESOLUTIONS:
        model, static = catenaries[n]
        assert static.result == optx.RESULTS.successful
        assert list(np.asarray(model.constrained_nodes)) == [0, 1]
        reaction = np.asarray(static.reactions)[1]  # the fairlead support, on the line
        horizontal = reaction[:2] @ HEADING[:2]  # pulls away from the anchor: +
        assert abs(reaction[:2] @ np.array([-HEADING[1], HEADING[0]])) < 1e-8 * exact_tension
        tension_error.append(abs(np.linalg.norm(reaction) / exact_tension - 1))
        angle_error.append(abs(np.degrees(np.arctan2(reaction[2], horizontal)) - exact_angle))
    tension_error, angle_error = np.array(tension_error), np.array(angle_error)
    # O(1/N²): each halving of the segment length cuts the error by about 4.
    assert np.all(3.0 < tension_error[:-1] / tension_error[1:]) and np.all(tension_error[:-1] / tension_error[1:] < 5.0)
    assert np.all(np.diff(angle_error) < 0)
    assert tension_error[-1] < 5e-4  # 0.05 % at N = 40
    assert angle_error[-1] < 0.02  # degrees


def test_catenary_shape_and_sag(catenaries, irvine):
    """Node positions are the catenary's material points s_k = k L₀/N, and the largest
    sag below the chord matches the continuum's."""
    s_fine = np.linspace(0.0, LENGTH, 200_001)
    x_fine, z_fine = irvine.xz(s_fine)
    exact_sag = np.max(HEIGHT / SPAN * x_fine - z_fine)
    position_error, sag_error = [], []
    for n in RESOLUTIONS:
        model, static = catenaries[n]
        nodes = np.asarray(static.state.positions)[chain_nodes(n)] - ANCHOR
        along = nodes[:, :2] @ HEADING[:2]
        across = nodes[:, :2] @ np.array([-HEADING[1], HEADING[0]])
        assert np.max(np.abs(across)) < 1e-9 * LENGTH  # stays in its vertical plane
        x, z = irvine.xz(np.linspace(0.0, LENGTH, n + 1))
        position_error.append(np.max(np.hypot(along - x, nodes[:, 2] - z)) / LENGTH)
        sag_error.append(abs(np.max(HEIGHT / SPAN * along - nodes[:, 2]) / exact_sag - 1))
    position_error = np.array(position_error)
    ratios = position_error[:-1] / position_error[1:]
    assert np.all((3.5 < ratios) & (ratios < 4.5)), ratios
    assert position_error[-1] < 1e-4  # 2 cm on a 200 m line
    assert np.all(np.diff(sag_error) < 0)
    assert sag_error[-1] < 1e-3


def test_catenary_segment_tensions(catenaries, irvine):
    """Every segment's tension against Irvine's T(s) at the segment's midpoint, and
    against Hooke's law evaluated by hand from the solved node positions."""
    errors = []
    for n in RESOLUTIONS:
        model, static = catenaries[n]
        tension = np.asarray(static.tension)
        midpoints = (np.arange(n) + 0.5) * LENGTH / n
        errors.append(np.max(np.abs(tension / irvine.tension(midpoints) - 1)))
        by_hand = hand_tension(model, np.asarray(static.state.positions), EA)
        np.testing.assert_allclose(tension, by_hand, rtol=1e-9)
    errors = np.array(errors)
    assert np.all(3.0 < errors[:-1] / errors[1:])
    assert errors[-1] < 5e-4


def test_reactions_carry_the_weight(catenaries, irvine):
    """The supports carry the whole submerged weight w L₀, exactly at any N (the
    lumped halves of the end segments included), and no net horizontal force; the
    anchor's vertical reaction is Irvine's w L₀ − V."""
    for n in RESOLUTIONS:
        _, static = catenaries[n]
        reactions = np.asarray(static.reactions)
        np.testing.assert_allclose(reactions[:, 2].sum(), W * LENGTH, rtol=1e-10)
        np.testing.assert_allclose(reactions[0, :2], -reactions[1, :2], rtol=1e-10, atol=1e-8 * W * LENGTH)
        assert reactions[0, :2] @ HEADING[:2] < 0  # the anchor pulls back along the line
    _, static = catenaries[RESOLUTIONS[-1]]
    reactions = np.asarray(static.reactions)
    np.testing.assert_allclose(reactions[0, 2], W * LENGTH - irvine.V, rtol=2e-3)
    np.testing.assert_allclose(np.hypot(*reactions[0, :2]), irvine.H, rtol=5e-4)


def test_default_guess_is_taut_when_coarse():
    """`CableNetwork.from_branches` promises a sagged guess "stretched by 0.1 % so that
    every segment carries tension" (its docstring), also when coarse."""
    n = 5
    model = catenary_model(n)
    positions = np.asarray(model.node_positions)
    ends = np.asarray(model.segment_nodes)
    strain = np.linalg.norm(positions[ends[:, 1]] - positions[ends[:, 0]], axis=1) / (LENGTH / n) - 1
    assert np.all(strain > 0), strain


def test_catenary_coarse_from_default_guess(irvine):
    model = catenary_model(5)
    static = solve(model, jc.Environment(water_density=RHO, gravity=G))
    reaction = np.asarray(static.reactions)[1]
    # O(1/N²) from the N = 10 error of 0.2 %: about 1 % at N = 5.
    assert abs(np.linalg.norm(reaction) / np.hypot(irvine.H, irvine.V) - 1) < 0.02


def test_buoyant_line_starts_arched_up_and_rests_there(irvine):
    """The catenary line made buoyant (displaced mass 1.5 times its own): from_branches
    still hangs it on a downward catenary, which the start shape turns upward, keeping
    its segments. Its equilibrium is the mirror image of the heavy line's with the
    fairlead below the anchor: Irvine's elastic catenary of weight −w (the problem
    reflected through a horizontal plane), to the discretisation's O(1/N²)."""
    n = 20
    displaced = 1.5 * MASS
    line = jc.LineType(MASS, DIAMETER, jc.LinearElastic(EA), area=displaced / RHO, normal_drag=0.0, tangential_drag=0.0)
    model = jc.CableNetwork.from_branches(
        np.stack([ANCHOR, FAIRLEAD]), [jc.Branch(0, 1, line, LENGTH, n)], constraints={0: jc.Fixed(), 1: jc.Fixed()}
    )
    height_over_chord = lambda p: (p - ANCHOR)[:, 2] - (p - ANCHOR) @ HEADING * HEIGHT / SPAN  # noqa: E731
    given = np.asarray(model.node_positions)
    water = _water_loads(model, RHO_ENV, 0.0, model.node_positions)
    start = np.asarray(start_shape(model, RHO_ENV, model.node_positions, water))
    assert np.max(height_over_chord(given)[2:]) < 0 < np.min(height_over_chord(start)[2:])
    ends = np.asarray(model.segment_nodes)
    chords = np.linalg.norm(start[ends[:, 1]] - start[ends[:, 0]], axis=1) / np.asarray(model.segment_length)
    assert np.all((chords > 0.99) & (chords < 1.001 + 1e-9))

    static = solve(model, RHO_ENV)
    assert static.result == optx.RESULTS.successful and int(static.steps) < 100
    mirrored = Irvine(SPAN, -HEIGHT, LENGTH, -(MASS - displaced) * G, EA)
    top = np.linalg.norm(np.asarray(static.reactions)[1])
    assert abs(top / np.hypot(mirrored.H, mirrored.V) - 1) < 4 / n**2
    assert abs(top / np.hypot(irvine.H, irvine.V) - 1) > 0.1  # not the heavy line's


def test_buoyant_line_hanging_from_a_point_starts_standing_up():
    """A buoyant line hanging from a point, which would float up through slack, starts
    turned about that point to stand up from it, every segment kept."""
    line = jc.LineType(MASS, DIAMETER, jc.LinearElastic(EA), area=1.5 * MASS / RHO)
    top, bottom = np.array([0.0, 0.0, -50.0]), np.array([0.0, 0.0, -150.0])
    model = jc.CableNetwork.from_branches(
        np.stack([top, bottom]), [jc.Branch(0, 1, line, 100.0, 10)], constraints={0: jc.Fixed()}
    )
    env = jc.Environment(water_density=RHO, gravity=G)
    start = np.asarray(
        start_shape(model, env, model.node_positions, _water_loads(model, env, 0.0, model.node_positions))
    )
    ends = np.asarray(model.segment_nodes)
    given = np.asarray(model.node_positions)
    np.testing.assert_allclose(
        np.linalg.norm(start[ends[:, 1]] - start[ends[:, 0]], axis=1),
        np.linalg.norm(given[ends[:, 1]] - given[ends[:, 0]], axis=1),
        rtol=1e-12,
    )
    assert np.min(start[1:, 2]) > top[2] and start[1, 2] > top[2] + 99.0  # the free end stands above


def test_forward_derivative_in_the_supports_against_central_differences():
    """`jax.jvp` of the reactions in the fairlead's position from the model's own start
    (whose loads, a norm of a zero drag, once gave the continuation a NaN tangent)
    matches central differences of re-solved statics. From a concrete `initial` with
    the model's positions carrying tangents, the geometry check once converted the
    tracer (`TracerArrayConversionError`); it is left to the solve there, as under
    `jit` (checked on the check alone, to keep the suite short: the derivative is the
    same implicit adjoint's)."""
    model = catenary_model(5)
    tangent = jnp.zeros((model.n_nodes, 3)).at[1].set(HEADING)  # the fairlead, along the span

    def top(positions):
        moved = eqx.tree_at(lambda m: m.node_positions, model, positions)
        return jc.solve_statics(moved, RHO_ENV).reactions[1]

    step = 1e-4 * SPAN
    x = model.node_positions
    differences = (
        np.asarray(solve_reactions(x + step * tangent)) - np.asarray(solve_reactions(x - step * tangent))
    ) / (2 * step)
    _, derivative = jax.jvp(top, (x,), (tangent,))
    np.testing.assert_allclose(derivative, differences, rtol=1e-5, atol=1e-6 * np.max(np.abs(differences)))

    initial = solve(model, RHO_ENV).state.positions

    def checked(positions):
        _check_geometry(eqx.tree_at(lambda m: m.node_positions, model, positions), initial, 0.0)
        return positions

    jax.jvp(checked, (x,), (tangent,))


def solve_reactions(positions):
    """The fairlead's reaction (N), statics re-solved with `catenary_model(5)`'s nodes at
    `positions` (m)."""
    model = eqx.tree_at(lambda m: m.node_positions, catenary_model(5), jnp.asarray(positions))
    return solve(model, RHO_ENV).reactions[1]


def test_network_with_no_free_node_is_its_own_equilibrium():
    """One taut segment between two fixed points in a current: nothing to solve, and
    the reactions are the hand-summed forces on its ends (tension, half the wet weight
    and half the drag each). `jc.advise` finds that rest too."""
    line = jc.LineType(MASS, DIAMETER, jc.LinearElastic(EA))
    model = jc.CableNetwork.from_branches(
        np.stack([ANCHOR, FAIRLEAD]),
        [jc.Branch(0, 1, line, 0.99 * float(np.linalg.norm(FAIRLEAD - ANCHOR)), 1)],
        constraints={0: jc.Fixed(), 1: jc.Fixed()},
    )
    assert model.free_nodes.size == 0
    flow = np.array([0.5, 0.3, 0.0])
    env = jc.Environment(water_density=RHO, gravity=G, current=flow)
    static = jc.solve_statics(model, env)
    assert static.result == optx.RESULTS.successful and int(static.steps) == 0 and float(static.residual) == 0.0
    tension, force = hand_forces(model, env, np.asarray(model.node_positions), {}, flow)
    np.testing.assert_allclose(static.tension, tension, rtol=1e-12)
    np.testing.assert_allclose(static.reactions, -force, rtol=1e-10, atol=1e-10 * np.max(np.abs(force)))
    advice = jc.advise(model, env)
    assert advice.statics_error is None and advice.rest_max_tension == pytest.approx(tension[0], rel=1e-12)


# ---------------------------------------------------------------------------------------
# 2. A Y-shaped network: three anchors, one free junction carrying a clump weight.
# ---------------------------------------------------------------------------------------

Y_MASS, Y_DIAMETER, Y_EA = 20.0, 0.06, 2.0e6
Y_W = (Y_MASS - RHO * np.pi * Y_DIAMETER**2 / 4) * G
Y_SUPPORTS = np.array([[100.0, 0.0, 0.0], [-50.0, 86.6, -10.0], [-50.0, -86.6, 5.0]])
Y_LENGTHS = (115.0, 105.0, 120.0)
Y_SEGMENTS = 20
CLUMP_MASS, CLUMP_VOLUME = 800.0, 0.1


@pytest.fixture(scope="module")
def y_network():
    line = jc.LineType(Y_MASS, Y_DIAMETER, jc.LinearElastic(Y_EA), normal_drag=0.0, tangential_drag=0.0)
    model = jc.CableNetwork.from_branches(
        np.vstack([Y_SUPPORTS, [0.0, 0.0, -40.0]]),
        [jc.Branch(k, 3, line, Y_LENGTHS[k], Y_SEGMENTS) for k in range(3)],
        constraints={0: jc.Fixed(), 1: jc.Fixed(), 2: jc.Fixed()},
        bodies={3: jc.Body(mass=CLUMP_MASS, volume=CLUMP_VOLUME)},
    )
    static = solve(model, jc.Environment(water_density=RHO, gravity=G))
    positions = np.asarray(static.state.positions)
    branches = []
    for k in range(3):
        chord = positions[3] - positions[k]
        span = np.hypot(chord[0], chord[1])
        branches.append((Irvine(span, chord[2], Y_LENGTHS[k], Y_W, Y_EA), chord[:2] / span))
    return model, static, branches


@pytest.mark.slow
def test_y_branches_are_elastic_catenaries(y_network):
    """Each branch, taken alone between its anchor and the solved junction, is Irvine's
    catenary: its segment tensions match T(s) at the segment midpoints (both ends
    included) and its nodes lie on the catenary, in the branch's vertical plane."""
    model, static, branches = y_network
    positions = np.asarray(static.state.positions)
    tension = np.asarray(static.tension)
    n = Y_SEGMENTS
    for k, (cat, heading) in enumerate(branches):
        segments = slice(k * n, (k + 1) * n)  # from_branches numbers segments branch by branch
        ends = np.asarray(model.segment_nodes)[segments]
        assert ends[0, 0] == k and ends[-1, 1] == 3
        chain = np.concatenate([ends[:, 0], [3]])
        midpoints = (np.arange(n) + 0.5) * Y_LENGTHS[k] / n
        np.testing.assert_allclose(tension[segments], cat.tension(midpoints), rtol=3e-3)
        relative = positions[chain] - positions[k]
        along = relative[:, :2] @ heading
        across = relative[:, :2] @ np.array([-heading[1], heading[0]])
        assert np.max(np.abs(across)) < 1e-8 * Y_LENGTHS[k]
        x, z = cat.xz(np.linspace(0.0, Y_LENGTHS[k], n + 1))
        assert np.max(np.hypot(along - x, relative[:, 2] - z)) < 1e-3 * Y_LENGTHS[k]


def test_y_junction_force_balance(y_network):
    """The three catenaries' end forces on the junction and the clump's submerged
    weight sum to zero (continuum forces, so to within the discretisation)."""
    _, static, branches = y_network
    total = np.array([0.0, 0.0, -(CLUMP_MASS - RHO * CLUMP_VOLUME) * G])
    scale = 0.0
    for cat, heading in branches:
        # At the junction end the cable pulls back towards its anchor.
        force = -np.array([cat.H * heading[0], cat.H * heading[1], cat.V])
        total += force
        scale = max(scale, np.linalg.norm(force))
    assert np.linalg.norm(total[:2]) < 2e-3 * scale
    assert abs(total[2]) < 5e-3 * scale


def test_y_discrete_equilibrium_by_hand(y_network):
    """At every free node, Hooke's-law tensions along the solved segments plus half of
    each adjacent segment's submerged weight plus the clump's weight balance exactly."""
    model, static, _ = y_network
    positions = np.asarray(static.state.positions)
    ends = np.asarray(model.segment_nodes)
    tension = hand_tension(model, positions, Y_EA)
    chord = positions[ends[:, 1]] - positions[ends[:, 0]]
    unit = chord / np.linalg.norm(chord, axis=1)[:, None]
    weight = Y_W * np.asarray(model.segment_length)
    force = np.zeros_like(positions)
    np.add.at(force, ends[:, 0], tension[:, None] * unit)
    np.add.at(force, ends[:, 1], -tension[:, None] * unit)
    np.add.at(force[:, 2], ends[:, 0], -weight / 2)
    np.add.at(force[:, 2], ends[:, 1], -weight / 2)
    force[3, 2] -= (CLUMP_MASS - RHO * CLUMP_VOLUME) * G
    free = np.asarray(model.free_nodes)
    assert np.max(np.abs(force[free])) < 1e-6 * tension.max()
    # ... and the reactions are what the anchors' own segments need.
    reactions = np.asarray(static.reactions)
    np.testing.assert_allclose(reactions, -force[:3], rtol=1e-7, atol=1e-6 * tension.max())


# ---------------------------------------------------------------------------------------
# 4. A taut vertical line under a buoy, in a uniform current.
# ---------------------------------------------------------------------------------------


def test_current_drag_on_taut_vertical_line():
    """Anchor at 100 m depth, a 100 m neutrally buoyant stiff line and a buoy of net
    buoyancy B. The line stays within a degree of vertical, so the normal drag per
    length is q = ½ ρ K_n d U² over the stretched length L (1 + B/EA): the anchor's
    horizontal reaction is −q L (1 + B/EA), and the line, pulled at constant vertical
    tension B, bends to x(z) = q (L z − z²/2) / B, putting the buoy at q L² / (2B)."""
    diameter, normal_drag, speed, ea, length = 0.05, 1.2, 1.0, 1.0e9, 100.0
    area = np.pi * diameter**2 / 4
    buoy_mass, buoy_volume = 1000.0, 20.0
    buoyancy = (RHO * buoy_volume - buoy_mass) * G
    line = jc.LineType(
        RHO * area, diameter, jc.LinearElastic(ea), area=area, normal_drag=normal_drag, tangential_drag=0.0
    )
    model = jc.CableNetwork.from_branches(
        np.array([[0.0, 0.0, -length], [0.0, 0.0, 0.0]]),
        [jc.Branch(0, 1, line, length, 20)],
        constraints={0: jc.Fixed()},
        bodies={1: jc.Body(mass=buoy_mass, volume=buoy_volume)},
    )
    env = jc.Environment(water_density=RHO, gravity=G, current=(speed, 0.0, 0.0))
    static = solve(model, env)
    q = 0.5 * RHO * normal_drag * diameter * speed**2
    reaction = np.asarray(static.reactions)[0]
    np.testing.assert_allclose(reaction[0], -q * length * (1 + buoyancy / ea), rtol=1e-3)
    assert abs(reaction[1]) < 1e-9 * q * length
    np.testing.assert_allclose(reaction[2], -buoyancy, rtol=1e-3)
    offset = np.asarray(static.state.positions)[1]
    np.testing.assert_allclose(offset[0], q * length**2 / (2 * buoyancy), rtol=5e-3)
    assert offset[0] / length < 0.01  # nearly straight, as the closed form assumes


def test_body_force_tilts_a_hanging_weight():
    """A weight W on a weightless line (neutrally buoyant, m = ρ F), pushed sideways by a
    constant body force F: the line takes the resultant's direction, so the weight
    hangs at (sin θ, 0, −cos θ) L (1 + T/EA) with tan θ = |F|/W and T = √(F² + W²),
    and the support reacts with −(F, 0, −W)."""
    length, ea, mass, push = 10.0, 1.0e6, 100.0, np.array([300.0, 0.0, 0.0])
    weight = mass * G
    area = 1e-4
    line = jc.LineType(RHO * area, 0.01, jc.LinearElastic(ea), area=area)
    model = jc.CableNetwork.from_branches(
        np.array([[0.0, 0.0, 0.0], [1.0, 0.0, -length]]),
        [jc.Branch(0, 1, line, length, 4)],
        constraints={0: jc.Fixed()},
        bodies={1: jc.Body(mass=mass, force=push)},
    )
    static = solve(model, RHO_ENV)
    tension = np.hypot(push[0], weight)
    theta = np.arctan2(push[0], weight)
    expected = length * (1 + tension / ea) * np.array([np.sin(theta), 0.0, -np.cos(theta)])
    np.testing.assert_allclose(np.asarray(static.state.positions)[1], expected, atol=1e-7 * length)
    np.testing.assert_allclose(np.asarray(static.tension), tension, rtol=1e-9)
    np.testing.assert_allclose(np.asarray(static.reactions)[0], [-push[0], 0.0, weight], atol=1e-6 * weight)


def test_body_force_must_be_a_vector():
    with pytest.raises(ValueError, match=r"Body.force must be a 3-vector \(N\), got shape \(2,\)"):
        jc.Body(mass=1.0, force=(1.0, 2.0))
    with pytest.raises(ValueError, match="Body.force"):
        jc.Body(mass=1.0, force=(1.0, np.nan, 0.0))


# ---------------------------------------------------------------------------------------
# 5. No equilibrium from a slack guess.
# ---------------------------------------------------------------------------------------


def slack_guess(model, n):
    """Free nodes on the 180 m chord of the 200 m line: every segment compressed."""
    positions = np.asarray(model.node_positions).copy()
    fractions = np.linspace(0.0, 1.0, n + 1)[1:-1]
    positions[2:] = ANCHOR + fractions[:, None] * (FAIRLEAD - ANCHOR)
    assert np.linalg.norm(FAIRLEAD - ANCHOR) < LENGTH
    return jc.State(positions, np.zeros_like(positions))


def test_slack_guess_recovers():
    """From a slack guess no segment has stiffness to move with; the damped motion of
    the pseudo-time steps lets the line sag, and the equilibrium is the one found from
    the taut guess."""
    n = 10
    model = catenary_model(n)
    env = jc.Environment(water_density=RHO, gravity=G)
    recovered = jc.solve_statics(model, env, initial=slack_guess(model, n))
    direct = jc.solve_statics(model, env)
    np.testing.assert_allclose(recovered.state.positions, direct.state.positions, atol=1e-6)


def test_slack_guess_recovers_under_jit():
    """`jit` of `solve_statics` with the model as an argument takes the same steps, and
    finds the eager equilibrium."""
    n = 10
    model = catenary_model(n)
    env = jc.Environment(water_density=RHO, gravity=G)
    guess = slack_guess(model, n)
    traced = eqx.filter_jit(lambda m, g: jc.solve_statics(m, env, initial=g))(model, guess)
    eager = jc.solve_statics(model, env, initial=guess)
    direct = jc.solve_statics(model, env)
    assert traced.result == optx.RESULTS.successful
    np.testing.assert_allclose(traced.state.positions, eager.state.positions, atol=1e-9)
    np.testing.assert_allclose(traced.state.positions, direct.state.positions, atol=1e-6)
    # The guess is far from the equilibrium: the solve had somewhere to go.
    assert np.max(np.abs(np.asarray(guess.positions) - np.asarray(direct.state.positions))) > 1.0


def test_failed_statics_raises_the_same_error_eagerly_and_under_jit():
    """Too few steps: solve_statics raises eagerly and under `jit`, naming the step
    limit (eagerly also the cause, the node and the force left: the guess's segments
    are all compressed, so the node is on slack line), and with throw=False reports
    the force left instead."""
    n = 10
    model = catenary_model(n)
    env = jc.Environment(water_density=RHO, gravity=G)
    guess = slack_guess(model, n)
    with pytest.raises(
        eqx.EquinoxRuntimeError,
        match=r"found no equilibrium: node \d+ is on slack line .* when its 2 steps \(max_steps\) ran out.* on node",
    ):
        jc.solve_statics(model, env, initial=guess, max_steps=2)
    with pytest.raises(eqx.EquinoxRuntimeError, match=r"found no equilibrium.*at most 2 steps \(max_steps\)"):
        eqx.filter_jit(lambda m: jc.solve_statics(m, env, initial=guess, max_steps=2))(model)
    quiet = jc.solve_statics(model, env, initial=guess, max_steps=2, throw=False)
    assert quiet.result != optx.RESULTS.successful
    assert float(quiet.residual) > 1e-3 * W * LENGTH / n
    # The residual it reports is the force on the free nodes at its positions.
    positions = quiet.state.positions
    forces = jc.equations.generalised_forces(model, env, 0.0, positions, np.zeros_like(positions))[model.free_nodes]
    np.testing.assert_allclose(float(quiet.residual), float(np.max(np.abs(forces))), rtol=1e-9)


def test_bad_value_in_a_traced_model_is_named():
    """A model whose stiffness was made negative after construction (where the
    constructor could not see it) is refused, naming the field: with the value
    eagerly, by `eqx.error_if` under `jit`."""
    model = catenary_model(4)
    env = jc.Environment(water_density=RHO, gravity=G)
    bad = eqx.tree_at(lambda m: m.line.tension_law.axial_stiffness, model, -model.line.tension_law.axial_stiffness)
    with pytest.raises(ValueError, match="LineType.tension_law.axial_stiffness must be positive, got -"):
        jc.solve_statics(bad, env)
    with pytest.raises(
        eqx.EquinoxRuntimeError,
        match=r"LineType.tension_law.axial_stiffness must be positive; under jax.vmap, solve_statics\(\.\.\., "
        r"throw=False\) solves the other cases",
    ):
        eqx.filter_jit(lambda m: jc.solve_statics(m, env))(bad)


def test_a_bad_case_in_a_vmapped_solve_is_named_and_the_others_solved():
    """`jax.vmap` of `solve_statics(..., throw=False)` over three stiffnesses, the second
    negative: it once raised for the whole batch. Now the good cases are each their own
    equilibrium, the bad one fails at once (no steps, its free nodes NaN), and `failures()`
    names its case, the field and the value."""
    model = catenary_model(4)
    env = jc.Environment(water_density=RHO, gravity=G)
    stiffness = model.line.tension_law.axial_stiffness

    def scaled(factor):
        return eqx.tree_at(lambda m: m.line.tension_law.axial_stiffness, model, factor * stiffness)

    batch = jax.vmap(lambda f: jc.solve_statics(scaled(f), env, throw=False))(jnp.array([1.0, -1.0, 2.0]))
    assert batch.failures() == {
        1: f"solve_statics: invalid input: LineType.tension_law.axial_stiffness must be positive, "
        f"got {-float(np.ravel(stiffness)[0]):g}"
    }
    assert int(batch.steps[1]) == 0 and np.all(np.isnan(np.asarray(batch.state.positions[1][model.free_nodes])))
    assert np.asarray(batch.invalid_input)[[0, 2]].tolist() == [-1, -1] and int(batch.invalid_input[1]) >= 0
    for case, factor in ((0, 1.0), (2, 2.0)):
        alone = jc.solve_statics(scaled(factor), env)
        np.testing.assert_allclose(batch.state.positions[case], alone.state.positions, rtol=0, atol=1e-6)
    assert jc.solve_statics(model, env).failures() == {}


# ---------------------------------------------------------------------------------------
# 6. Equilibrium judged against the scene's forces, and geometry refused before solving.
# ---------------------------------------------------------------------------------------


def free_node_residual(model, env, static, flow=(0.0, 0.0, 0.0)):
    """The largest force (N) on a free node by `helpers.hand_forces`, and the largest
    tension (N)."""
    tension, force = hand_forces(model, env, np.asarray(static.state.positions), {}, flow)
    return float(np.max(np.abs(force[np.asarray(model.free_nodes)]))), float(np.max(tension))


def test_very_stiff_line_is_in_equilibrium_at_rounding():
    """EA = 7.5e12 N on a line of about 50 kN: a tension is known only to about EA times
    float64's ε (1.7e-3 N) per segment, so forces of millinewtons are all that rounding
    leaves. Judged against the tension, not the 2.9 kN weight of a segment, that is
    equilibrium; the earlier test (1e-6 of a segment's weight, 3 mN) refused it. The
    fairlead's force is Irvine's to the discretisation's O(1/N²)."""
    ea, n = 7.5e12, 20
    # The sharp slack switch: strains here are about 1e-8, inside the default
    # smoothing band, which would make the law's stiffness there far below EA.
    line = jc.LineType(MASS, DIAMETER, jc.LinearElastic(ea, 0.0), normal_drag=0.0, tangential_drag=0.0)
    model = jc.CableNetwork.from_branches(
        np.stack([ANCHOR, FAIRLEAD]), [jc.Branch(0, 1, line, LENGTH, n)], constraints={0: jc.Fixed(), 1: jc.Fixed()}
    )
    static = jc.solve_statics(model, RHO_ENV)
    residual, tension = free_node_residual(model, RHO_ENV, static)
    assert 3e4 < tension < 1e5
    assert residual < 1e-6 * tension + 16 * np.finfo(float).eps * ea
    exact = Irvine(SPAN, HEIGHT, LENGTH, W, ea)
    assert abs(np.linalg.norm(np.asarray(static.reactions)[1]) / np.hypot(exact.H, exact.V) - 1) < 5e-3


def test_near_massless_line_is_in_equilibrium():
    """A line of 1 g/m, nearly neutrally buoyant (its wet weight 1e-5 N/m) between two
    anchors: its tensions are millinewtons, and the equilibrium is judged against those,
    not against its dry weight or buoyancy (0.2 N a segment each), which cancel. The
    solved nodes balance by the hand-written force balance, and the fairlead's force is
    Irvine's."""
    mass, diameter, ea, n = 1e-3, 1e-3, 1e5, 10
    area = (mass - 1e-6) / RHO  # wet weight 1e-6 kg/m
    line = jc.LineType(mass, diameter, jc.LinearElastic(ea, 0.0), area=area, normal_drag=0.0, tangential_drag=0.0)
    model = jc.CableNetwork.from_branches(
        np.stack([ANCHOR, FAIRLEAD]), [jc.Branch(0, 1, line, LENGTH, n)], constraints={0: jc.Fixed(), 1: jc.Fixed()}
    )
    static = jc.solve_statics(model, RHO_ENV)
    residual, tension = free_node_residual(model, RHO_ENV, static)
    w = (mass - RHO * area) * G
    assert residual < 1e-6 * tension + 16 * np.finfo(float).eps * ea
    assert tension < 1e-2
    exact = Irvine(SPAN, HEIGHT, LENGTH, w, ea)
    assert abs(np.linalg.norm(np.asarray(static.reactions)[1]) / np.hypot(exact.H, exact.V) - 1) < 2e-2


def test_line_with_both_ends_at_one_point_is_refused():
    line = jc.LineType(MASS, DIAMETER, jc.LinearElastic(EA))
    model = jc.CableNetwork.from_branches(
        np.stack([ANCHOR, ANCHOR]), [jc.Branch(0, 1, line, 50.0, 5)], constraints={0: jc.Fixed(), 1: jc.Fixed()}
    )
    with pytest.raises(ValueError, match=r"segment 0 joins nodes 0 and 2, which start at the same point"):
        jc.solve_statics(model, RHO_ENV)


def test_line_far_too_short_for_its_ends_is_refused():
    """A 1e-6 m line between anchors 400 m apart would have to stretch 4e10 %: said
    before solving, with the figures, rather than as a failure to converge."""
    line = jc.LineType(MASS, DIAMETER, jc.LinearElastic(EA))
    model = jc.CableNetwork.from_branches(
        np.array([[0.0, 0.0, -100.0], [400.0, 0.0, -100.0]]),
        [jc.Branch(0, 1, line, 1e-6, 4)],
        constraints={0: jc.Fixed(), 1: jc.Fixed()},
    )
    with pytest.raises(ValueError, match=r"nodes 0 and 1 are 400 m apart.* 1e-06 m long.* stretch 4e\+10 %"):
        jc.solve_statics(model, RHO_ENV)


def test_scene_line_far_too_short_or_closed_is_refused(tmp_path):
    """The Low & Langley file with its 170 m line shortened to 1 mm (its ends 112 m
    apart), or with both ends at one point: the scene names the line and the cause."""
    text = (Path(__file__).parent / "data" / "lowe_and_langley_2006" / "line.txt").read_text()
    short = tmp_path / "short.txt"
    short.write_text(text.replace("1        2         170", "1        2         0.001"))
    with pytest.raises(jc.io.SceneError, match=r"line 1 must stretch 1.12e\+07 % to reach from point 1 to point 2"):
        jc.load_scene(short).build()
    closed = tmp_path / "closed.txt"
    closed.write_text(text.replace("2     Coupled   0       0       -5", "2     Coupled   -100    0       -55"))
    with pytest.raises(jc.io.SceneError, match=r"both ends of line 1 are at \[-100.0, 0.0, -55.0\]"):
        jc.load_scene(closed).build()
