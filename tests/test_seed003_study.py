"""The seed 003 study's building blocks, against references computed here.

- Statics of `seed003_case` against the elastic catenary with seed 003's nonlinear law,
  integrated by quadrature (independent of jaxcable): the end forces agree to the
  polyline's O(1/N²) error, and the change that C_E1 makes is reproduced even though it
  is smaller than that error.
- The slack-time measure on a rectified sine, whose slack fraction is known.
- The swept study's linear cases against plain `jaxcable.simulate` runs of the line
  with a `LinearElastic` law, with a sweep per angle and with one sweep over angle ×
  ratio: batching, the angle's lookup and the C_E1 substitution change nothing.
- The claims' verdict on made-up tables with known answers.
"""

import equinox as eqx
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import ElasticCatenary

import jaxcable as jc
from jaxcable.examples.seed003 import AREA, DEPTH, MASS_PER_LENGTH
from studies.seed003 import seed003_case, seed003_study, slack_time, verdict

RHO, G = 1025.0, 9.81
N = 20  # one shape for every test here: one compilation of each program


def catenary_end_tensions(span, height, length, weight, c_e, c_e1):
    """Top and bottom tension of an elastic catenary with T = C_E ε + C_E1 ε², from the
    bottom (`helpers.ElasticCatenary`)."""
    catenary = ElasticCatenary(length, weight, c_e, c_e1, span, height, [weight * length, weight * length / 2])
    return catenary.tension(length), catenary.tension(0.0)


@pytest.mark.parametrize("angle", [30.0, 60.0])
def test_static_end_forces_match_the_nonlinear_elastic_catenary(angle):
    c_e = 1e6  # soft, so that the stretch (≈ 1.5 %) and C_E1's part in it matter
    weight = (MASS_PER_LENGTH - RHO * AREA) * G
    span = DEPTH / np.tan(np.radians(angle))
    forces, expected = {}, {}
    for ratio in (0.0, 0.2):
        model, env = seed003_case(N, angle, ratio, c_e)
        static = jc.solve_statics(model, env)
        length = float(jnp.sum(model.segment_length))
        top, bottom = catenary_end_tensions(span, DEPTH, length, weight, c_e, ratio * c_e)
        # Node 0 is the anchor, node 1 the fairlead: the supports' forces on the line.
        reactions = np.asarray(static.reactions)
        forces[ratio], expected[ratio] = np.linalg.norm(reactions[1]), top
        # The polyline converges at O(1/N²): about 7e-4 low at N = 20 (3e-3 at N = 10).
        assert np.linalg.norm(reactions[1]) == pytest.approx(top, rel=1.5e-3)
        assert np.linalg.norm(reactions[0]) == pytest.approx(bottom, rel=2e-3)
        # The line hangs: the supports carry its whole submerged weight.
        assert np.isclose(float(static.reactions[:, 2].sum()), weight * length, rtol=1e-9)
    # C_E1 = 0.2 C_E stretches the line less and raises the tension a little (≈ 7 N here,
    # below the discretisation error); the difference is reproduced to 2 %.
    assert expected[0.2] - expected[0.0] > 0
    assert forces[0.2] - forces[0.0] == pytest.approx(expected[0.2] - expected[0.0], rel=0.02)


def test_case_sets_both_stiffnesses_on_every_segment():
    model, env = seed003_case(N, 45.0, 0.2, 2.5e6)
    law = model.line.tension_law
    assert np.allclose(law.axial_stiffness, 2.5e6) and law.axial_stiffness.shape == (N,)
    assert np.allclose(law.quadratic_coefficient, 0.5e6) and law.quadratic_coefficient.shape == (N,)
    static = jc.solve_statics(model, env)
    eps = np.asarray(static.strain)
    assert eps.min() > 1e-3
    assert np.allclose(np.asarray(static.tension), 2.5e6 * eps + 0.5e6 * eps**2, rtol=1e-12)


def test_slack_time_of_a_rectified_sine():
    times = np.linspace(0.0, 12.0, 12001)  # three 4 s periods
    tension = np.maximum(np.sin(2 * np.pi * times / 4.0), 0.0) * 1e4
    seconds, fraction = slack_time(times, tension)
    assert abs(fraction - 0.5) < 2e-3  # T = 0 over each negative half, plus the zero crossings
    assert abs(seconds - 6.0) < 0.02
    # A threshold counts the near-slack samples too: sin ≤ 0.5 for 2/3 of a period.
    assert abs(slack_time(times, tension, threshold=0.5e4)[1] - 2 / 3) < 2e-3


@pytest.mark.parametrize("one_sweep", [False, True], ids=["sweep_per_angle", "one_sweep"])
def test_batched_study_matches_plain_simulations(one_sweep):
    """The swept study's linear cases equal plain runs of a LinearElastic line, whether
    each angle has a sweep of its own or one sweep takes every angle and ratio."""
    angles, c_e, window, rtol = (45.0, 60.0), 1e7, (1.0, 2.0), 1e-9
    study = seed003_study(
        angles,
        (0.0, 0.2),
        axial_stiffness=c_e,
        n_segments=N,
        duration=2.0,
        window=window,
        sample_rate=50.0,
        rtol=rtol,
        atol=rtol,
        one_sweep=one_sweep,
    )
    assert [(c.angle, c.ratio) for c in study.cases] == [(a, r) for a in angles for r in (0.0, 0.2)]
    assert set(study.run_s_by_angle) == (set() if one_sweep else set(angles))
    for angle in angles:
        model, env = seed003_case(N, angle, 0.0, c_e)
        linear = eqx.tree_at(lambda m: m.line.tension_law, model, jc.LinearElastic(jnp.full(N, c_e), 1e-5))
        static = jc.solve_statics(model, env)  # C_E1 = 0: the linear law's equilibrium
        config = jc.SolverConfig(rtol=rtol, atol=rtol)
        result = jc.simulate(linear, env, 2.0, ts=np.linspace(*window, 51), initial=static.state, solver=config)
        case = study.case(angle, 0.0)
        assert case.success and study.case(angle, 0.2).success
        np.testing.assert_array_equal(case.static_tension, np.asarray(static.tension))
        np.testing.assert_allclose(case.arc_length, np.cumsum(model.segment_length) - model.segment_length / 2)
        np.testing.assert_allclose(case.tension, np.asarray(result.tension), rtol=1e-5, atol=1e-4 * case.peak_line)
        assert case.peak_top == pytest.approx(float(result.tension[:, -1].max()), rel=1e-5)
        assert case.slack_fraction == np.mean(np.asarray(result.tension[:, -1]) <= 0.0)
        # C_E1 > 0 stiffens: the same geometry holds a little more tension.
        assert study.case(angle, 0.2).static_tension[-1] > case.static_tension[-1]
        assert not np.allclose(study.case(angle, 0.2).tension, case.tension, rtol=1e-7, atol=0)


def _rows(peaks):
    return [{"angle_deg": a, "ratio": r, "peak_top_N": p, "peak_strain": 0.005} for (a, r), p in peaks.items()]


def test_verdict_recognises_the_papers_claims_and_their_absence():
    paper = {}
    for r, scale in ((0.0, 1.0), (0.2, 0.8)):  # 20 % lower at C_E1 = 0.2 C_E
        paper |= {(30.0, r): 1e5 * scale, (45.0, r): 1.02e5 * scale, (60.0, r): 0.76e5 * scale}
    v = verdict(_rows(paper))
    assert v["claim1"] is True and v["claim2"] is True
    assert v["ratio_effect"][45.0][0.2] == pytest.approx(-0.2)
    flat = {(a, r): 1e5 for a in (30.0, 45.0, 60.0) for r in (0.0, 0.2)}
    v = verdict(_rows(flat))
    assert v["claim1"] is False and v["claim2"] is False
    assert "DOES NOT APPEAR" in v["text"]
    assert verdict(_rows({(30.0, 0.0): 1.0, (30.0, 0.2): 0.8}))["claim2"] is None
