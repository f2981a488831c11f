"""Which segments can reach the seabed (`jaxcable._model.reach`), against independent values: the
intersection of two balls by dense sampling and by the symmetric closed form, path
lengths by hand, the largest strain by the quadratic's roots, the supports' excursions
by evaluating their motions densely, the bound against a simulated run's lowest nodes;
and the stability check that counts the seabed's modes only where they can occur."""

import diffrax
import jax
import numpy as np
import pytest

import jaxcable as jc
from jaxcable._model.reach import (
    BREAKING_STRESS,
    for_run,
    largest_strain,
    lens_bottom,
    path_lengths,
    reach_bounds,
    seabed_reach,
    surface_reach,
)
from jaxcable._solver.stability import STABLE_GROWTH, fixed_step_growth


def rope(axial_stiffness=3e7, quadratic=0.0, area=3e-4, damping_ratio=0.8):
    law = jc.NonlinearElastic(axial_stiffness, quadratic) if quadratic else jc.LinearElastic(axial_stiffness)
    line = jc.LineType(mass_per_length=3.0, diameter=0.0195, tension_law=law, area=area)
    return line


def anchored_line(anchor_z: float, segments: int = 20, motion=None, length: float = 400.0):
    """The anchored-line paper's geometry: an anchor at `anchor_z`, a top 346 m away at the surface, a
    line of `length` between them."""
    top = jc.Harmonic(1.57, 5.6) if motion is None else motion
    return jc.CableNetwork.from_branches(
        [[0.0, 0.0, anchor_z], [346.41, 0.0, anchor_z + 200.0]],
        [jc.Branch(0, 1, rope(), length, segments)],
        {0: jc.Fixed(), 1: top},
        mass_matrix="lumped",
    )


def test_lens_bottom_by_sampling_and_by_the_symmetric_closed_form():
    rng = np.random.default_rng(0)
    # Two equal balls side by side: the lens's bottom is z − √(r² − (d/2)²).
    a, b = np.array([0.0, 0.0, 0.0]), np.array([6.0, 0.0, 0.0])
    np.testing.assert_allclose(lens_bottom(a, np.array([5.0]), b, np.array([5.0])), [-4.0], rtol=1e-14)
    # Tilted pairs of unequal balls against the lowest of many points in both.
    for _ in range(5):
        a, b = rng.normal(size=3) * 3, rng.normal(size=3) * 3
        ra, rb = rng.uniform(1, 5, size=2)
        bound = float(lens_bottom(a, np.array([ra]), b, np.array([rb]))[0])
        points = a + ra * rng.uniform(-1, 1, size=(400_000, 3))
        inside = (np.linalg.norm(points - a, axis=1) <= ra) & (np.linalg.norm(points - b, axis=1) <= rb)
        if np.linalg.norm(b - a) > ra + rb:
            assert bound == -np.inf and not inside.any()
            continue
        sampled = points[inside, 2].min()
        assert bound <= sampled + 1e-12  # a bound
        assert sampled - bound < 0.05 * (ra + rb)  # and a tight one
    # One ball inside the other: the inner ball's bottom.
    assert lens_bottom(a, np.array([10.0]), a + 1.0, np.array([2.0]))[0] == pytest.approx(a[2] + 1.0 - 2.0)
    # Balls that do not meet, or an unbounded radius, bound nothing.
    assert lens_bottom(a, np.array([1.0]), a + 5.0, np.array([1.0]))[0] == -np.inf
    assert lens_bottom(a, np.array([np.inf]), a + 5.0, np.array([1.0]))[0] == -np.inf


def test_path_lengths_on_a_branched_network_by_hand():
    # A Y: anchor 0 → junction (2 segments of 10 m), then two branches of 3 × 5 m and 1 × 7 m.
    line = rope()
    model = jc.CableNetwork.from_branches(
        [[0.0, 0.0, -50.0], [30.0, 0.0, -50.0], [20.0, 10.0, -50.0], [10.0, 0.0, -50.0]],
        [jc.Branch(0, 3, line, 20.0, 2), jc.Branch(3, 1, line, 15.0, 3), jc.Branch(3, 2, line, 7.0, 1)],
        {0: jc.Fixed(), 1: jc.Fixed(), 2: jc.Fixed()},
    )
    distance = path_lengths(model, np.ones(model.n_segments), np.array([0, 1, 2]))
    np.testing.assert_allclose(distance[:, 3], [20.0, 15.0, 7.0])
    np.testing.assert_allclose(distance[0, [0, 1, 2]], [0.0, 35.0, 27.0])
    # Stretched by 10 %, every path is 10 % longer.
    np.testing.assert_allclose(path_lengths(model, np.full(model.n_segments, 1.1), np.array([0]))[0], 1.1 * distance[0])


def test_largest_strain_by_the_roots_of_the_tension_law():
    load = BREAKING_STRESS * 3e-4
    model = anchored_line(-200.0)
    np.testing.assert_allclose(largest_strain(model), load / 3e7, rtol=1e-14)
    for quadratic in (3e6, -1.2e7):
        line = rope(quadratic=quadratic)
        model = jc.CableNetwork.from_branches(
            [[0.0, 0.0, -50.0], [10.0, 0.0, -50.0]], [jc.Branch(0, 1, line, 10.0, 2)], {0: jc.Fixed(), 1: jc.Fixed()}
        )
        roots = np.roots([quadratic, 3e7, -load])
        expected = roots[(roots.imag == 0) & (roots.real > 0)].real.min()
        np.testing.assert_allclose(largest_strain(model), expected, rtol=1e-12)
    # A law that turns down before carrying the stress (its peak C_E/2 at ε = 1, below
    # σF on a 1 m² section) never bounds the stretch.
    line = rope(quadratic=-1.5e7, area=1.0)
    model = jc.CableNetwork.from_branches(
        [[0.0, 0.0, -50.0], [10.0, 0.0, -50.0]], [jc.Branch(0, 1, line, 10.0, 2)], {0: jc.Fixed(), 1: jc.Fixed()}
    )
    assert np.isinf(largest_strain(model)).all()


TABLE = ([0.0, 1.0, 2.0, 3.0, 4.0], [[0, 0, 0], [1, 0, -2], [3, 1, 0], [0, 0, 1], [0, 0, 0]])


@pytest.mark.filterwarnings("ignore:Sampled. the cubic spline")  # the spline's overshoot is the point
@pytest.mark.parametrize(
    "make",
    [
        lambda: jc.Harmonic(2.0, 5.0, direction=(1.0, 0.0, -1.0), phase=0.3, ramp=4.0),
        lambda: jc.Sampled(*TABLE),
        lambda: jc.Sampled(*TABLE, interpolation="pchip"),
        lambda: jc.Sampled(*TABLE, interpolation="linear"),
        lambda: jc.Towing([0.0, 2.0, 5.0], [1.0, -3.0, 2.0], direction=(1.0, 0.0, -0.5)),
    ],
    ids=["harmonic", "cubic", "pchip", "linear", "towing"],
)
def test_motion_excursions_bound_the_motion_evaluated_densely(make):
    motion = make()
    duration = 6.0
    times = np.linspace(0.0, duration, 6001)
    displacement = np.asarray(jax.vmap(motion.displacement)(times))
    down, up, reach = motion.excursion(duration)
    assert max(0.0, -displacement[:, 2].min()) <= down + 1e-12
    assert max(0.0, displacement[:, 2].max()) <= up + 1e-12
    assert np.linalg.norm(displacement, axis=1).max() <= reach + 1e-12
    if not isinstance(motion, jc.Towing):  # the others' bounds are reached or nearly
        assert -displacement[:, 2].min() > 0.9 * down
        assert displacement[:, 2].max() > 0.9 * up
    assert jc.Fixed().excursion(duration) == (0.0, 0.0, 0.0)


def test_the_bound_holds_over_a_run_and_flags_a_line_on_the_bed():
    # The anchored line hung 50 m above the bed, driven hard (its top 10 m along x and z).
    model = anchored_line(-200.0, segments=10, motion=jc.Harmonic(10.0, 5.6, direction=(1.0, 0.0, 1.0)))
    env = jc.Environment(depth=250.0, seabed=jc.Seabed())
    lowest, highest = reach_bounds(model, 12.0)
    static = jc.solve_statics(model, env)
    run = jc.simulate(model, env, 12.0, ts=np.linspace(0.0, 12.0, 241), initial=static.state)
    assert bool(run.success)
    z = np.asarray(run.positions)[:, :, 2]
    assert (z.min(axis=0) >= lowest - 1e-9).all() and (z.max(axis=0) <= highest + 1e-9).all()
    assert not seabed_reach(model, env, 12.0).any()
    # On the bed: the anchor at the depth, and a line long enough to lie along it.
    on_bed = anchored_line(-250.0, segments=10, length=520.0)
    reaches = seabed_reach(on_bed, env, 12.0)
    static = np.asarray(jc.solve_statics(on_bed, env).state.positions)
    below = static[:, 2] < -250.0 + 1e-6
    assert reaches[below[np.asarray(on_bed.segment_nodes)].any(axis=1)].all()
    # No seabed, no contact.
    assert not seabed_reach(on_bed, jc.Environment(depth=250.0), 12.0).any()


def test_a_bed_out_of_reach_leaves_moordyns_step_stable():
    # The midpoint rule at MoorDyn's 2 ms on a damped (ζ = 0.8) 40-segment line: its axial
    # modes alone allow it; the bed's contact (|λ| ≈ 1,700 1/s) would not, and counts
    # only where the line can reach the bed.
    spec = jc.io.LineTypeSpec(
        "rope",
        mass_per_length=3.0,
        diameter=0.0195,
        axial_stiffness=3e7,
        axial_damping_ratio=0.8,
        area=3e-4,
        normal_added_mass=1.3,
        tangential_added_mass=1.3,
    )

    def scene(anchor_z):
        points = (
            jc.io.PointSpec("anchor", "fixed", (0.0, 0.0, anchor_z)),
            jc.io.PointSpec("top", "fixed", (346.41, 0.0, anchor_z + 200.0)),
        )
        water = jc.io.Water(depth=250.0, seabed=jc.io.SeabedSpec())
        lines = (jc.io.LineSpec("1", "rope", 0, 1, 400.0, 40),)
        run = jc.io.RunSettings(mass_matrix="lumped", hydrodynamics="nodes")  # as a MoorDyn file is read
        return jc.io.Scene(points, (spec,), lines, water=water, run=run).build()

    steps = 300_000
    assert fixed_step_growth(diffrax.Midpoint(), 0.002, scene(-200.0), steps=steps) <= STABLE_GROWTH
    assert fixed_step_growth(diffrax.Midpoint(), 0.002, scene(-250.0), steps=steps) > STABLE_GROWTH


def test_a_run_leaves_out_a_seabed_and_a_surface_no_line_can_reach():
    """The run's water has no seabed where no segment can reach it, and no free surface
    where none can rise above z = 0; the tensions are those of the run that carries
    both, whose extra forces are zero there."""
    model = anchored_line(-200.0, segments=10, motion=jc.Harmonic(1.57, 5.6), length=400.0)
    deep = jc.CableNetwork.from_branches(  # the same line with its top 20 m down
        [[0.0, 0.0, -220.0], [346.41, 0.0, -20.0]],
        [jc.Branch(0, 1, rope(), 400.0, 10)],
        {0: jc.Fixed(), 1: jc.Harmonic(1.57, 5.6)},
        mass_matrix="lumped",
    )
    env = jc.Environment(depth=250.0, seabed=jc.Seabed(), free_surface=True)
    assert not seabed_reach(deep, env, 5.0).any() and not surface_reach(deep, 5.0).any()
    run_env = for_run(deep, env, 5.0)
    assert run_env.seabed is None and not run_env.free_surface
    # A top at the surface: the segments next to it may rise above it.
    assert surface_reach(model, 5.0)[-1] and for_run(model, env, 5.0).free_surface
    on_bed = anchored_line(-250.0, segments=10, length=520.0)
    assert for_run(on_bed, env, 5.0).seabed is not None
    static = jc.solve_statics(deep, env)
    ts = np.linspace(0.0, 2.0, 41)
    carried = jc.simulate(deep, env, 2.0, ts=ts, initial=static.state)
    left_out = jc.simulate(deep, run_env, 2.0, ts=ts, initial=static.state)
    # To rounding: with the surface, a wholly wet segment's buoyancy is written through
    # its submerged interval [0, 1], a different sum of the same terms (2e-11 apart).
    np.testing.assert_allclose(left_out.tension, carried.tension, rtol=1e-9, atol=1e-6)
