"""The discrete catenary (`jaxcable._statics.catenary`): a single line's statics in numpy.

Against things independent of it:

- the compiled solver (`solve_statics` under `jit`, which the closed form never takes),
  on the anchored line, a MoorDyn-like chain lying partly on the seabed, the same chain
  with a nonlinear law whose slack switch's band holds every segment, and the chain
  half chain, half wire, by per-segment properties: node positions within 1e-6 m,
  tensions within 1e-6 of their own;
- jaxcable's JAX equations at the positions found (the forces, tensions and
  reactions the compiled path would report there);
- Irvine's elastic catenary (`helpers.Irvine`), which the discrete one approaches as
  1/N² (the polyline lumps each segment's weight on its ends, a trapezoid rule);
- the tension law it inverts, `jaxcable._model.materials`'.

The three chains share one compiled solver: the same topology and tree structure,
other values.
"""

import equinox as eqx
import numpy as np
import optimistix as optx
import pytest
from helpers import Irvine

import jaxcable as jc
from jaxcable._equations import lagrangian as lag
from jaxcable._statics import catenary
from jaxcable._statics.solution import FORCE_TOLERANCE

RHO, G = 1025.0, 9.81
compiled = eqx.filter_jit(jc.solve_statics)  # traced: always the root finder

# A MoorDyn-like mooring leg: 250 m of 50 mm chain from an anchor on the bed in 60 m of
# water to a buoy 229.3 m away (the bundled wave_mooring scene's), about half of it on
# the bed.
DEPTH, SPAN, LENGTH, SEGMENTS = 60.0, 229.3, 250.0, 30
CHAIN_MASS, CHAIN_DIAMETER, CHAIN_EA = 49.75, 0.09, 2.135e8


def chain(law=None, **fields):
    """The mooring leg on a `jc.Seabed()`, with a `NonlinearElastic` law (linear by
    default) and its line's `fields` replaced (per-segment arrays)."""
    line = jc.LineType(CHAIN_MASS, CHAIN_DIAMETER, law or jc.NonlinearElastic(CHAIN_EA, 0.0))
    model = jc.CableNetwork.from_branches(
        np.array([[0.0, 0.0, -DEPTH], [SPAN, 0.0, 0.0]]),
        [jc.Branch(0, 1, line, LENGTH, SEGMENTS)],
        {0: jc.Fixed(), 1: jc.Fixed()},
    )
    replaced = eqx.tree_at(lambda m: [getattr(m.line, name) for name in fields], model, list(fields.values()))
    return replaced, jc.Environment(RHO, G, depth=DEPTH, seabed=jc.Seabed())


def assert_same_equilibrium(model, env):
    """The closed form's equilibrium is the compiled solver's; returns the closed form's."""
    closed = catenary.catenary_statics(model, env)
    assert closed is not None and closed.method == "discrete catenary"
    reference = compiled(model, env)
    assert reference.method == "pseudo-transient continuation"
    assert closed.result == optx.RESULTS.successful
    assert float(closed.residual) <= FORCE_TOLERANCE * float(closed.force_scale)
    np.testing.assert_allclose(closed.state.positions, reference.state.positions, rtol=0, atol=1e-6)
    np.testing.assert_allclose(closed.tension, reference.tension, rtol=1e-6)
    scale = float(np.max(np.abs(reference.tension)))
    np.testing.assert_allclose(closed.reactions, reference.reactions, rtol=0, atol=1e-6 * scale)
    assert float(closed.force_scale) == pytest.approx(float(reference.force_scale), rel=1e-6)
    assert float(closed.required_strain) == pytest.approx(float(reference.required_strain), rel=1e-12)
    return closed


def test_anchored_line_against_the_compiled_solver():
    """The anchored line (nonlinear-elastic, C_E1 = 0.1 C_E), its fairlead driven
    harmonically (placed at t = 0 by its motion); and what the JAX equations give at
    the positions found: the same forces, tensions and reactions."""
    model, env = jc.examples.anchored_line(20, 30, 0.1)
    env = env.without_waves()
    closed = assert_same_equilibrium(model, env)
    positions, rest = closed.state.positions, np.zeros(closed.state.positions.shape)
    forces = np.asarray(lag.static_forces(model, env, 0.0, positions, True))
    assert np.max(np.abs(forces[model.free_nodes])) == pytest.approx(float(closed.residual), rel=1e-6, abs=1e-9)
    np.testing.assert_allclose(closed.tension, lag.tension(model, positions, rest), rtol=1e-12)
    np.testing.assert_allclose(closed.reactions, lag.reactions(model, env, 0.0, positions, rest, rest), atol=1e-7)


def test_chain_partly_on_the_seabed_against_the_compiled_solver():
    """About half the chain rests on the bed, pressed in by its weight over the bed's
    k d: the penalty spring is part of the discrete equations."""
    model, env = chain()
    closed = assert_same_equilibrium(model, env)
    z = np.asarray(closed.state.positions)[:, 2]
    on_bed = z < -DEPTH
    assert 8 < np.sum(on_bed) < SEGMENTS - 8
    wet_weight = (CHAIN_MASS - RHO * np.pi * CHAIN_DIAMETER**2 / 4) * G
    # Away from the anchor and the touchdown a node sinks by its weight over its
    # spring, w L / (k d L): the fifth from the anchor, 42 m along the bed.
    assert -DEPTH - z[model.free_nodes[4]] == pytest.approx(wet_weight / (3e6 * CHAIN_DIAMETER), rel=1e-3)


def test_nonlinear_law_inside_its_slack_band_against_the_compiled_solver():
    """C_E1 = 0.2 C_E and a slack switch smoothed over strains up to 1e-3, above every
    segment's strain: each segment's tension is the law's quintic inside the band,
    which the closed form inverts numerically."""
    law = jc.NonlinearElastic(CHAIN_EA, 0.2 * CHAIN_EA, slack_width=1e-3)
    model, env = chain(law)
    closed = assert_same_equilibrium(model, env)
    assert 0 < float(np.min(closed.strain)) and float(np.max(closed.strain)) < 1e-3


def test_per_segment_properties_against_the_compiled_solver():
    """The lower half a heavy chain, the upper half a lighter, softer wire with a
    quadratic term, per segment."""
    lower = np.arange(SEGMENTS) < SEGMENTS // 2
    law = jc.NonlinearElastic(np.where(lower, CHAIN_EA, 4e7), np.where(lower, 0.0, 4e6))
    model, env = chain(
        law,
        mass_per_length=np.where(lower, CHAIN_MASS, 8.0),
        diameter=np.where(lower, CHAIN_DIAMETER, 0.04),
        area=np.where(lower, np.pi * CHAIN_DIAMETER**2 / 4, np.pi * 0.04**2 / 4),
    )
    assert_same_equilibrium(model, env)


def test_many_segments_converge_to_the_elastic_catenary_as_one_over_n_squared():
    """Irvine's catenary (no bed) at the nodes' unstretched arc lengths: the largest
    distance from it falls by 4 (to within 10 %) each time N doubles, to millimetres
    at N = 80 on this line of 200 m sagging 46 m below its chord."""
    span, height, length, mass, diameter, ea = 150.0, 100.0, 200.0, 50.0, 0.1, 5e6
    line = jc.LineType(mass, diameter, jc.LinearElastic(ea))
    anchor = np.array([10.0, -5.0, -100.0])
    exact = Irvine(span, height, length, (mass - RHO * np.pi * diameter**2 / 4) * G, ea)

    def error(n):
        model = jc.CableNetwork.from_branches(
            np.stack([anchor, anchor + [span, 0.0, height]]),
            [jc.Branch(0, 1, line, length, n)],
            {0: jc.Fixed(), 1: jc.Fixed()},
        )
        static = catenary.catenary_statics(model, jc.Environment(RHO, G))
        assert static is not None
        order = np.concatenate([[0], np.arange(2, n + 1), [1]])  # from_branches' nodes along the line
        relative = np.asarray(static.state.positions)[order] - anchor
        x, z = exact.xz(np.linspace(0.0, length, n + 1))
        return float(np.max(np.hypot(relative[:, 0] - x, relative[:, 2] - z)))

    errors = np.array([error(n) for n in (10, 20, 40, 80)])
    np.testing.assert_allclose(errors[:-1] / errors[1:], 4.0, rtol=0.1)
    assert errors[-1] < 5e-3


def test_the_law_and_its_inverse_are_materials_own():
    """`_Law.tension` is `elastic_tension` of jaxcable's laws, sharp and smoothed, inside
    the band and above it; `_Law.strain` inverts it to rounding, and its compliance is
    the derivative's inverse (central differences)."""
    strain = np.concatenate([np.geomspace(1e-9, 8e-6, 7), np.geomspace(2e-5, 0.5, 7)])  # off the bands' tops
    laws = [jc.NonlinearElastic(3e7, 3e6), jc.NonlinearElastic(3e7, -1e7, 1e-4), jc.LinearElastic(5e8, 0.0)]
    for law in laws:
        numpy_law = catenary._Law.of(law, strain.size)
        tension = numpy_law.tension(strain)
        np.testing.assert_allclose(tension, law.elastic_tension(strain), rtol=1e-13)
        inverse, compliance = numpy_law.strain(tension)
        np.testing.assert_allclose(inverse, strain, rtol=1e-11)
        step = 1e-6 * strain
        slope = (numpy_law.tension(strain + step) - numpy_law.tension(strain - step)) / (2 * step)
        np.testing.assert_allclose(compliance * slope, 1.0, rtol=1e-6)


def test_one_segment_between_its_supports_is_its_own_equilibrium():
    """Nothing to solve: Hooke's tension along the chord, and each support carrying
    half the segment's wet weight besides it."""
    length, ea = 100.0, 5e6
    line = jc.LineType(CHAIN_MASS, CHAIN_DIAMETER, jc.LinearElastic(ea))
    ends = np.array([[0.0, 0.0, -DEPTH], [80.0, 0.0, 0.0]])
    model = jc.CableNetwork.from_branches(ends, [jc.Branch(0, 1, line, length, 1)], {0: jc.Fixed(), 1: jc.Fixed()})
    static = catenary.catenary_statics(model, jc.Environment(RHO, G))
    assert static is not None and int(static.steps) == 0 and float(static.residual) == 0.0
    chord = ends[1] - ends[0]
    tension = ea * (np.linalg.norm(chord) / length - 1)
    np.testing.assert_allclose(static.tension, [tension], rtol=1e-12)
    half_weight = 0.5 * (CHAIN_MASS - RHO * np.pi * CHAIN_DIAMETER**2 / 4) * G * length
    pull = tension * chord / np.linalg.norm(chord)
    expected = np.stack([-pull, pull]) + [0.0, 0.0, half_weight]
    np.testing.assert_allclose(static.reactions, expected, rtol=1e-12, atol=1e-9 * tension)


def test_unsupported_scenes_fall_back_to_the_compiled_solver():
    """A current, a body on an inner node, bending, a Y-branch, a line whose top is out
    of the water with the free surface on, and a traced model: no closed form (`None`),
    and `prepare` is left to compile the solver."""
    model, env = chain()
    assert catenary.applies(model, env) and catenary.catenary_statics(model, env) is not None
    current = jc.Environment(RHO, G, current=(0.3, 0.0, 0.0), depth=DEPTH, seabed=jc.Seabed())
    line = jc.LineType(CHAIN_MASS, CHAIN_DIAMETER, jc.NonlinearElastic(CHAIN_EA, 0.0))
    ends = np.array([[0.0, 0.0, -DEPTH], [SPAN, 0.0, 0.0]])
    buoyed = jc.CableNetwork.from_branches(
        np.vstack([ends, [[SPAN / 2, 0.0, -DEPTH / 2]]]),
        [jc.Branch(0, 2, line, LENGTH / 2, 10), jc.Branch(2, 1, line, LENGTH / 2, 10)],
        {0: jc.Fixed(), 1: jc.Fixed()},
        bodies={2: jc.Body(mass=100.0, volume=1.0)},
    )
    stiff = jc.LineType(CHAIN_MASS, CHAIN_DIAMETER, jc.NonlinearElastic(CHAIN_EA, 0.0), bending_stiffness=1e4)
    bent = jc.CableNetwork.from_branches(ends, [jc.Branch(0, 1, stiff, LENGTH, 10)], {0: jc.Fixed(), 1: jc.Fixed()})
    branched = jc.CableNetwork.from_branches(
        np.vstack([ends, [[SPAN, 50.0, 0.0], [SPAN / 2, 0.0, -40.0]]]),
        [jc.Branch(0, 3, line, 130.0, 5), jc.Branch(3, 1, line, 130.0, 5), jc.Branch(3, 2, line, 140.0, 5)],
        {0: jc.Fixed(), 1: jc.Fixed(), 2: jc.Fixed()},
    )
    for unsupported, water in ((model, current), (buoyed, env), (bent, env), (branched, env)):
        assert not catenary.applies(unsupported, water)
        assert catenary.catenary_statics(unsupported, water) is None
    raised = jc.CableNetwork.from_branches(
        np.array([[0.0, 0.0, -DEPTH], [SPAN, 0.0, 5.0]]),
        [jc.Branch(0, 1, line, LENGTH, 10)],
        {0: jc.Fixed(), 1: jc.Fixed()},
    )
    surface = jc.Environment(RHO, G, depth=DEPTH, seabed=jc.Seabed(), free_surface=True)
    assert catenary.applies(raised, surface) and catenary.catenary_statics(raised, surface) is None
    assert catenary.catenary_statics(raised, jc.Environment(RHO, G, depth=DEPTH, seabed=jc.Seabed())) is not None
    traced = []
    eqx.filter_jit(lambda m: traced.append(catenary.applies(m, env)))(model)
    assert traced == [False]


def test_solve_statics_and_a_scene_run_take_the_closed_form():
    """`solve_statics` eagerly and `run_scene` of the bundled anchored line (statics
    only) take the discrete catenary, and the run's summary says so."""
    model, env = chain()
    assert jc.solve_statics(model, env).method == "discrete catenary"
    scene = jc.read_scene(jc.examples.scene_path("anchored_line"))
    run = jc.run_scene(scene, duration=0.0)
    assert run.static is not None and run.static.method == "discrete catenary"
    assert "discrete catenary" in run.summary()
