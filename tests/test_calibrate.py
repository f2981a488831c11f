"""Calibration against known truth: synthetic records with 2 % noise, fitted from a
start 2x off, must give back the coefficients they were made with; the loss's gradient
must match central finite differences; bad input must fail clearly.

The fits are module fixtures, and the record sets share shapes, so that each compiled
step serves several tests.
"""

import math
import time
import warnings

import diffrax
import numpy as np
import optax
import pytest

import jaxcable as jc
from jaxcable.calibration import HorizontalTow, VerticalTow, synthetic_record

TRUTH = {"normal_drag": 1.2, "tangential_drag": 0.01, "specific_drag": 0.5}
START = {name: 2 * value for name, value in TRUTH.items()}
TIMES = np.linspace(0.0, 30.0, 151)
STEP_UP = np.interp(TIMES, [0.0, 10.0, 13.0, 30.0], [1.0, 1.0, 2.0, 2.0])  # the branched-systems paper's step, scaled
STEP_DOWN = np.interp(TIMES, [0.0, 10.0, 13.0, 30.0], [1.5, 1.5, 1.0, 1.0])
SMALL_TOW = dict(cable_length=100.0, segments=4, cable_axial_stiffness=2e6, cable_axial_damping=5e3)
NEUTRAL = 1025.0 * math.pi * 0.0173**2 / 4  # kg/m: the default cable's displaced mass


def depressor(segments=4, **kw):
    tow = {**SMALL_TOW, "segments": segments}
    return HorizontalTow(**tow, end_mass=100.0, end_volume=0.015, end_drag_area=0.1, **kw)


def streamer(segments=4):
    # Nearly neutral, with a small drogue: the cable streams almost along the flow,
    # so its tension is mostly tangential drag.
    return HorizontalTow(
        **{**SMALL_TOW, "segments": segments},
        cable_mass_per_length=1.05 * NEUTRAL,
        end_mass=2.0,
        end_volume=0.0015,
        end_drag_area=0.05,
    )


def within(result, name, tolerance):
    error = abs(result.values[name] / TRUTH[name] - 1)
    assert error < tolerance, f"{name}: fitted {result.values[name]}, truth {TRUTH[name]} ({100 * error:.2f} % off)"


@pytest.fixture(scope="module")
def vertical_records():
    return [
        synthetic_record(VerticalTow(leader_lift=lift), np.linspace(0.0, 20.0, 101), seed=i, name=f"lift {lift} N")
        for i, lift in enumerate([160.0, 220.0, 300.0])
    ]


@pytest.fixture(scope="module")
def k0_fit(vertical_records):
    return jc.calibrate(vertical_records, {"specific_drag": START["specific_drag"]}, progress=False)


@pytest.fixture(scope="module")
def axial_fit():
    records = [
        synthetic_record(depressor(), TIMES, {"speed": STEP_UP}, seed=10, name="depressor"),
        synthetic_record(streamer(), TIMES, {"speed": STEP_UP}, seed=11, name="streamer"),
    ]
    start = {k: START[k] for k in ("normal_drag", "tangential_drag")}
    return jc.calibrate(records, start, progress=False)


@pytest.fixture(scope="module")
def depressor_fit():
    records = [
        synthetic_record(depressor(), TIMES, {"speed": STEP_UP}, seed=20, name="depressor up"),
        synthetic_record(depressor(end_added_mass=0.5), TIMES, {"speed": STEP_DOWN}, seed=21, name="depressor down"),
    ]
    start = {k: START[k] for k in ("normal_drag", "tangential_drag")}
    with pytest.warns(UserWarning, match="tangential_drag .* is poorly identified"):
        return jc.calibrate(records, start, progress=False)


def test_recovers_specific_drag_from_vertical_tows(k0_fit):
    within(k0_fit, "specific_drag", 0.05)
    assert k0_fit.converged and not k0_fit.warnings
    # White noise on the model's own records: the residuals look like noise, and the
    # uncertainty is hardly widened.
    assert not any(c.discrepancy for c in k0_fit.residual_checks.values())
    assert all(1.0 <= f <= 1.1 for f in k0_fit.inflation.values())
    assert k0_fit.loss[-1] < 0.05 * k0_fit.loss[0]
    # The error is consistent with the uncertainty the fit reports.
    assert abs(k0_fit.values["specific_drag"] - TRUTH["specific_drag"]) < 4 * k0_fit.uncertainty["specific_drag"]


def test_noise_estimate_matches_the_noise_put_in(k0_fit, vertical_records):
    # synthetic_record's noise is 2 % of each series' RMS; the fit's estimate, from each
    # record's residuals, should find it (101 samples: about 7 % sampling error).
    for record in vertical_records:
        for name in ("speed", "tension"):
            put_in = 0.02 * np.sqrt(np.mean(record.columns[name] ** 2))
            assert abs(k0_fit.noise[(record.name, name)] / put_in - 1) < 0.25
    pooled = [k0_fit.residuals[i]["tension"] for i in range(3)]
    assert all(r.shape == (101,) for r in pooled)


@pytest.mark.slow
def test_recovers_both_drag_coefficients_with_an_axial_flow_record(axial_fit):
    within(axial_fit, "normal_drag", 0.05)
    within(axial_fit, "tangential_drag", 0.10)
    assert axial_fit.converged and not axial_fit.warnings
    assert all(axial_fit.success)


@pytest.mark.slow  # its fit takes a minute or two of the default suite
def test_without_axial_flow_tangential_drag_is_flagged(depressor_fit):
    within(depressor_fit, "normal_drag", 0.05)
    assert depressor_fit.relative_uncertainty["tangential_drag"] > 5 * depressor_fit.relative_uncertainty["normal_drag"]
    assert any("tangential_drag" in w and "cannot be trusted" in w for w in depressor_fit.warnings)
    assert not any("not independent noise" in w for w in depressor_fit.warnings)
    assert all(f <= 1.1 for f in depressor_fit.inflation.values())
    assert "tangential_drag" in depressor_fit.summary() and "warning:" in depressor_fit.summary()


def test_adam_also_recovers_specific_drag(vertical_records):
    result = jc.calibrate(
        vertical_records, {"specific_drag": 1.0}, optimizer=optax.adam(0.05), max_steps=120, progress=False
    )
    within(result, "specific_drag", 0.05)


def test_an_optimizer_that_takes_no_step_is_a_stall_not_convergence(vertical_records):
    """An update that leaves the coefficients where they were (here an optimizer with
    a zero learning rate; in practice a line search that finds no lower loss along an
    inaccurate gradient) stops the fit as stalled, with a warning, instead of
    evaluating the same point again and calling the unchanged loss convergence."""
    with pytest.warns(UserWarning, match=r"the optimizer stalled after 1 iteration\(s\)"):
        result = jc.calibrate(
            vertical_records, {"specific_drag": 1.0}, optimizer=optax.sgd(0.0), max_steps=5, progress=False
        )
    assert result.stalled and not result.converged and result.iterations == 1
    assert result.values["specific_drag"] == 1.0
    assert "stalled: no step lowered the loss" in result.summary()


@pytest.mark.slow  # 32 s of the default suite
def test_loose_tolerance_derivatives_are_checked_and_the_tolerance_tightened(vertical_records, k0_fit):
    """Forward-mode derivatives ride along with the simulation, whose step-size
    controller sees only the states' error: at rtol = atol = 1e-4 those of the vertical
    tows differ from central differences by 59 % (1e-3: 1,000 times themselves; 1e-5:
    4.7 %; 1e-6: 0.6 %, measured). `calibrate` checks them at the start and tightens the
    tolerance 100-fold until they agree within 5 %, then fits there; the default
    tolerance already agrees."""
    assert k0_fit.tolerances == (1e-6, 1e-6) and max(k0_fit.tangent_error.values()) < 0.05
    assert "derivatives within" in k0_fit.summary()
    loose = jc.calibration.calibration_solver(rtol=1e-4, atol=1e-4)
    problem, _ = jc._calibration.problem.fitting_problem(vertical_records, ("specific_drag",), loose)
    start = np.log(np.array([START["specific_drag"]]))
    assert jc._calibration.calibrate._tangent_error(problem, start)[0] > 0.3
    result = jc.calibrate(vertical_records, {"specific_drag": START["specific_drag"]}, solver=loose, progress=False)
    assert result.tolerances == pytest.approx((1e-6, 1e-6))
    assert result.tangent_error["specific_drag"] < 0.05
    within(result, "specific_drag", 0.05)
    assert result.converged and not result.warnings


def test_derivatives_that_never_agree_are_warned_of(vertical_records, monkeypatch):
    """Where no tolerance down to 1e-10 brings the derivatives within 5 % of central
    differences, the fit runs at the one that came closest and warns, naming the
    coefficient and the difference."""
    tried = []

    def far_off(problem, log_values):
        tolerances = jc._calibration.problem.solver_tolerances(problem)
        assert tolerances is not None
        rtol = tolerances[0]
        tried.append(rtol)
        return np.array([0.5 if rtol > 1e-9 else 0.8])

    monkeypatch.setattr(jc._calibration.calibrate, "_tangent_error", far_off)
    with pytest.warns(UserWarning, match=r"derivatives of the residuals in specific_drag differ .* by 50 %"):
        result = jc.calibrate(vertical_records, {"specific_drag": 1.0}, max_steps=3, progress=False)
    assert tried == pytest.approx([1e-6, 1e-8, 1e-10])
    assert result.tolerances == (1e-6, 1e-6) and result.tangent_error == {"specific_drag": 0.5}


def test_linear_gain_is_zero_at_a_least_squares_minimum():
    """The stall check's measure: the share of the squared residuals one Gauss–Newton
    step removes. At the least-squares solution of a linear model it is zero (to
    rounding); for residuals that lie in the Jacobian's column space, one."""
    rng = np.random.default_rng(0)
    jacobian, data = rng.normal(size=(200, 2)), rng.normal(size=200)
    solution = np.linalg.lstsq(jacobian, data, rcond=None)[0]
    assert jc._calibration.calibrate._linear_gain(jacobian, jacobian @ solution - data) < 1e-20
    assert jc._calibration.calibrate._linear_gain(jacobian, jacobian @ np.array([1.0, -2.0])) == pytest.approx(1.0)
    assert 0.0 < jc._calibration.calibrate._linear_gain(jacobian, jacobian @ (solution + 0.1) - data) < 1.0


def test_progress_bar_times_iterations_after_the_compiling_one(vertical_records, monkeypatch):
    """The first iteration compiles the simulations; the bar starts its clock (and so its
    estimate of the time left) only after it, and says it is compiling until then."""
    bars, first_done = [], []
    make_bar, evaluate = jc._calibration.calibrate._bar, jc._calibration.problem.evaluate

    def recorded_bar(total, progress):
        bars.append(make_bar(total, progress))
        assert bars[-1].desc == "calibrate (compiling)"
        return bars[-1]

    def timed_evaluate(*args):
        out = evaluate(*args)
        first_done.append(time.time())
        return out

    monkeypatch.setattr(jc._calibration.calibrate, "_bar", recorded_bar)
    monkeypatch.setattr(jc._calibration.calibrate, "evaluate", timed_evaluate)
    jc.calibrate(vertical_records, {"specific_drag": 1.0}, optimizer=optax.adam(0.05), max_steps=3, progress=True)
    (bar,) = bars
    assert "compiling" not in bar.desc and bar.n == 3 and bar.total == 3
    assert bar.start_t >= first_done[0]


@pytest.mark.slow
def test_gradient_matches_central_differences():
    # One joint problem over both rigs, so that every coefficient is loaded; tight
    # tolerances, so that the finite differences see the same discretisation.
    import equinox as eqx

    from jaxcable._calibration import problem as _problem

    times = np.linspace(0.0, 10.0, 41)
    speed = np.interp(times, [0.0, 4.0, 6.0, 10.0], [1.0, 1.0, 2.0, 2.0])
    records = [
        synthetic_record(depressor(), times, {"speed": speed}, seed=0, name="h"),
        synthetic_record(VerticalTow(leader_lift=200.0), times, seed=1, name="v"),
    ]
    names = ("normal_drag", "tangential_drag", "specific_drag")
    problem, _ = _problem.fitting_problem(records, names, jc.calibration.rig_solver(rtol=1e-10, atol=1e-10))
    log_values = np.log(np.array([1.5, 0.015, 0.7]))
    loss = eqx.filter_jit(problem.loss)
    step = 1e-4
    central = np.array([(loss(log_values + step * e) - loss(log_values - step * e)) / (2 * step) for e in np.eye(3)])
    # The solver's adjoint is the gradient mode: forward for ForwardMode, else reverse.
    for adjoint in (diffrax.ForwardMode(), diffrax.RecursiveCheckpointAdjoint()):
        mode = eqx.tree_at(lambda p: p.solver.adjoint, problem, adjoint)
        assert mode.gradient == ("forward" if isinstance(adjoint, diffrax.ForwardMode) else "reverse")
        _, grad, _ = _problem.evaluate(log_values, mode)
        np.testing.assert_allclose(
            np.asarray(grad), central, rtol=1e-4, atol=1e-4 * np.max(np.abs(central)), err_msg=mode.gradient
        )


@pytest.mark.parametrize(
    "change, message",
    [
        (dict(start={"drag": 1.0}), r"unknown coefficient 'drag'; known: normal_drag, tangential_drag, specific_drag"),
        (dict(start={"specific_drag": -1.0}), r"start\['specific_drag'\] must be positive and finite, got -1.0"),
        (dict(start={}), r"start names no coefficient to fit"),
        (dict(start={"normal_drag": 1.0}), r"no record's rig depends on 'normal_drag'"),
        # A string and a diffrax solver where their hints say otherwise, on purpose: the
        # error calibrate itself gives a caller who runs no type checker.
        pytest.param(
            dict(optimizer="adam"),
            r"optimizer must be an optax GradientTransformation.*got 'adam'",
            marks=pytest.mark.unchecked,
        ),
        pytest.param(
            dict(solver=diffrax.Tsit5()),
            r"solver must be a jaxcable.SolverConfig, got Tsit5\(\)",
            marks=pytest.mark.unchecked,
        ),
        (dict(tests=[]), r"no records to fit"),
    ],
)
def test_calibrate_rejects_bad_arguments(change, message):
    record = jc.io.TowingRecord(times=[0.0, 1.0], columns={"tension": [1.0, 2.0]}, conditions={"rig": "vertical_tow"})
    arguments = dict(tests=[record], start={"specific_drag": 1.0})
    arguments.update(change)
    with pytest.raises(ValueError, match=message):
        jc.calibrate(arguments.pop("tests"), arguments.pop("start"), progress=False, **arguments)


def test_calibrate_rejects_records_that_do_not_fit_their_rig():
    no_speed = jc.io.TowingRecord(times=[0.0, 1.0], columns={"tension": [1.0, 2.0]}, name="tow.csv")
    with pytest.raises(ValueError, match=r"tow.csv has no 'speed' column, which HorizontalTow needs as input"):
        jc.calibrate([(depressor(), no_speed)], {"normal_drag": 1.0}, progress=False)
    speed_only = jc.io.TowingRecord(times=[0.0, 1.0], columns={"speed": [1.0, 1.0]}, name="tow.csv")
    with pytest.raises(ValueError, match=r"tow.csv measures none of HorizontalTow's observables"):
        jc.calibrate([(depressor(), speed_only)], {"normal_drag": 1.0}, progress=False)
    headless = jc.io.TowingRecord(times=[0.0, 1.0], columns={"tension": [1.0, 2.0]}, name="tow.csv")
    with pytest.raises(ValueError, match=r"tow.csv: no 'rig' in the header"):
        jc.calibrate([headless], {"specific_drag": 1.0}, progress=False)


@pytest.mark.unchecked  # a string where the hint says a rig, on purpose: calibrate's own error
def test_calibrate_rejects_a_pair_without_a_rig():
    speed_only = jc.io.TowingRecord(times=[0.0, 1.0], columns={"speed": [1.0, 1.0]}, name="tow.csv")
    with pytest.raises(ValueError, match=r"tests\[0\] must pair a towing rig with a record"):
        jc.calibrate([("rig", speed_only)], {"normal_drag": 1.0}, progress=False)


def test_synthetic_noise_follows_its_stated_model():
    rig = VerticalTow(leader_lift=250.0)
    times = np.linspace(0.0, 10.0, 2001)
    clean = synthetic_record(rig, times, noise=0.0)
    noisy = synthetic_record(rig, times, noise=0.02, seed=3)
    again = synthetic_record(rig, times, noise=0.02, seed=3)
    for name in rig.observables:
        rms = np.sqrt(np.mean(clean.columns[name] ** 2))
        deviation = noisy.columns[name] - clean.columns[name]
        assert abs(np.std(deviation) / (0.02 * rms) - 1) < 0.05  # 2,001 samples: ~1.6 % sampling error
        assert abs(np.mean(deviation)) < 4 * 0.02 * rms / math.sqrt(times.size)
        np.testing.assert_array_equal(noisy.columns[name], again.columns[name])
    assert clean.conditions == rig.conditions()
    with pytest.raises(ValueError, match=r"VerticalTow has no observable 'depth'"):
        synthetic_record(rig, times, observables=["depth"])
    with pytest.raises(ValueError, match=r"HorizontalTow needs input 'speed'"):
        synthetic_record(depressor(), times)
    with pytest.raises(ValueError, match=r"noise must be non-negative, got -0.1"):
        synthetic_record(rig, times, noise=-0.1)


def test_command_line_calibrate(vertical_records, tmp_path, capsys):
    import json

    from jaxcable._cli import main

    paths = []
    for k, record in enumerate(vertical_records):
        paths.append(tmp_path / f"tow{k}.csv")
        jc.io.write_record(paths[-1], record, units={"tension": "kN"})
    out, plot = tmp_path / "fit.json", tmp_path / "fit.png"
    status = main(
        [
            "calibrate",
            *map(str, paths),
            "--fit",
            "specific_drag=1.0",
            "--no-progress",
            "--out",
            str(out),
            "--plot",
            str(plot),
            "--segments",
            "1",
            "--check-segments",
        ]
    )
    assert status == 0
    printed = capsys.readouterr().out
    assert "specific_drag" in printed and "converged" in printed
    # The vertical rig's tether at 2 segments is too stiff for the default step limit:
    # the check says so, and the fit stands.
    assert "warning: cannot check the segmentation: discretisation_check: tow0.csv" in printed
    saved = json.loads(out.read_text())
    assert abs(saved["values"]["specific_drag"] / TRUTH["specific_drag"] - 1) < 0.05
    assert saved["records"] == ["tow0.csv", "tow1.csv", "tow2.csv"] and saved["warnings"] == []
    assert saved["inflation"]["specific_drag"] <= 1.1
    assert {c["observable"] for c in saved["residual_checks"]} == {"speed", "tension"}
    assert plot.stat().st_size > 10_000


def test_command_line_calibrate_errors(tmp_path, capsys):
    from jaxcable._cli import main

    bad = tmp_path / "bad.csv"
    bad.write_text("# rig = vertical_tow\ntime [s], tension [kN]\n0, 1\n1, nan\n")
    assert main(["calibrate", str(bad), "--fit", "specific_drag=1.0", "--no-progress"]) == 2
    assert "bad.csv, line 4: column 'tension' is NaN" in capsys.readouterr().err
    assert main(["calibrate", str(bad), "--fit", "specific_drag", "--no-progress"]) == 2
    assert "--fit 'specific_drag': give NAME=START" in capsys.readouterr().err
    assert main(["calibrate", str(bad), "--fit", "specific_drag=1", "--segments", "0", "--no-progress"]) == 2
    assert "--segments must be a positive integer, got 0" in capsys.readouterr().err


def test_a_tension_column_on_a_horizontal_tow_is_flagged_as_not_a_load_cell():
    from jaxcable._calibration.report import _caveats

    columns = {"speed": [1.0, 1.0], "tension": [1.0, 2.0]}
    pairs = [
        (depressor(), jc.io.TowingRecord([0.0, 1.0], columns, name="a.csv")),
        (depressor(), jc.io.TowingRecord([0.0, 1.0], columns, name="b.csv")),
        (depressor(), jc.io.TowingRecord([0.0, 1.0], {"speed": [1.0, 1.0], "tow_load": [1.0, 2.0]}, name="c.csv")),
        (VerticalTow(), jc.io.TowingRecord([0.0, 1.0], {"tension": [1.0, 2.0]}, name="d.csv")),
    ]
    (message,) = _caveats(pairs)
    assert message.startswith("a.csv, b.csv: HorizontalTow's 'tension' is the first segment's tension")
    assert "name it 'tow_load'" in message
    assert "tension" not in synthetic_record(depressor(), TIMES[:5], {"speed": STEP_UP[:5]}).columns


# --------------------------------------------------------------------------------------
# Residuals: noise or model discrepancy


def _ar1(rho, n, rng, size=()):
    """AR(1) series of unit variance, shape `size + (n,)`."""
    e = rng.standard_normal((*size, n))
    out = np.empty_like(e)
    out[..., 0] = e[..., 0]
    for t in range(1, n):
        out[..., t] = rho * out[..., t - 1] + math.sqrt(1 - rho**2) * e[..., t]
    return out


def test_residual_check_passes_white_noise():
    from jaxcable.calibration import residual_check

    rng = np.random.default_rng(5)
    checks = [residual_check(rng.standard_normal(151)) for _ in range(400)]
    # Each of three tests at 3σ: a false alarm in well under 2 % of series.
    assert sum(c.discrepancy for c in checks) < 8
    assert np.mean([c.effective_samples for c in checks]) > 0.97 * 151
    assert abs(np.mean([c.lag1 for c in checks])) < 0.02
    assert abs(np.mean([c.runs - c.expected_runs for c in checks])) < 1.0


def test_residual_check_finds_correlation_offset_and_drift():
    from jaxcable.calibration import residual_check

    rng = np.random.default_rng(6)
    n = 151
    correlated = residual_check(_ar1(0.9, n, rng))
    assert correlated.discrepancy and 0.75 < correlated.lag1 < 0.97
    assert correlated.effective_samples < 0.15 * n
    offset = residual_check(0.01 + 0.02 * rng.standard_normal(n), scale=2.0)
    assert offset.discrepancy and offset.mean_offset == pytest.approx(0.005, abs=0.001)
    drift = residual_check(np.sin(np.linspace(0, 6 * math.pi, n)) + 0.3 * rng.standard_normal(n))
    assert drift.discrepancy and drift.runs_z < -3


def test_effective_sample_size_gives_the_spread_of_a_correlated_mean():
    # The widening rests on var(mean) = σ²/n_eff for correlated residuals: check it on
    # AR(1) noise against the spread of the mean over many series.
    from jaxcable.calibration import residual_check

    rng = np.random.default_rng(7)
    series = _ar1(0.8, 600, rng, size=(1500,))
    effective = np.mean([residual_check(s).effective_samples for s in series[:200]])
    assert np.var(series.mean(axis=1)) * effective == pytest.approx(1.0, rel=0.12)


# --------------------------------------------------------------------------------------
# Hidden truth: records from a model that the fit does not use

FINE = 12  # segments of the model that makes the horizontal records; the fits use 4
REFERENCE = jc.calibration.rig_solver(rtol=1e-8, atol=1e-8, max_steps=1_000_000)


def with_noise(record, level, seed):
    """`record` with synthetic_record's noise model: Gaussian, `level` × each
    observable's RMS, the input (speed) exact."""
    rng = np.random.default_rng(seed)
    columns = {
        k: v if k == "speed" else v + level * np.sqrt(np.mean(v**2)) * rng.standard_normal(v.shape)
        for k, v in record.columns.items()
    }
    return jc.io.TowingRecord(record.times, columns, record.conditions, record.name)


@pytest.fixture(scope="module")
def fine_tow_records():
    """Clean records of the depressor and the streamer at 12 segments, at tight tolerance."""
    return [
        synthetic_record(make(FINE), TIMES, {"speed": STEP_UP}, noise=0.0, solver=REFERENCE, name=make.__name__)
        for make in (depressor, streamer)
    ]


def fit_coarse(records):
    """Fit the 4-segment rigs to `records`, as the records' own headers (12 segments)
    do not say; the warnings are the result's."""
    start = {k: START[k] for k in ("normal_drag", "tangential_drag")}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return jc.calibrate(list(zip((depressor(), streamer()), records)), start, progress=False)


@pytest.fixture(scope="module")
def hidden_fit(fine_tow_records):
    return fit_coarse([with_noise(r, 0.02, seed) for r, seed in zip(fine_tow_records, (30, 31))])


@pytest.mark.slow
def test_hidden_truth_drag_coefficients_from_a_finer_model(hidden_fit):
    # The fit sees 4 segments where the records had 12, and recovers K_n and K_τ within
    # 3 % (0.47 % and 0.11 %, measured) without a warning: at 2 % noise the residuals
    # are noise.
    for name in ("normal_drag", "tangential_drag"):
        error = abs(hidden_fit.values[name] / TRUTH[name] - 1)
        assert error < 0.03, f"{name} {100 * error:.2f} % off"
    assert hidden_fit.warnings == []
    assert hidden_fit.converged and all(hidden_fit.success)
    # No residual shows the 4 segments' discretisation error at 2 % noise, but
    # re-predicting at 8 moves K_n toward the truth by about its standard deviation
    # (linearised +0.23 %; a real refit at 8 segments moved it +0.23 %, measured), and
    # the check says so.
    check = jc.calibration.discretisation_check(hidden_fit)
    assert check.segments == {"depressor": (4, 8), "streamer": (4, 8)}
    assert max(check.shift.values()) < jc.calibration.COMPARABLE  # well within the noise
    assert check.moves["normal_drag"] * math.log(TRUTH["normal_drag"] / hidden_fit.values["normal_drag"]) > 0
    assert any("normal_drag would move" in w for w in check.warnings)


@pytest.mark.slow
def test_finer_model_with_little_noise_is_covered_or_flagged(fine_tow_records):
    # At 0.2 % noise the 4-segment model's discretisation error outweighs the noise:
    # each reported ±2σ interval must hold the truth, or the discrepancy warning fire.
    result = fit_coarse([with_noise(r, 0.002, seed) for r, seed in zip(fine_tow_records, (32, 33))])
    for name in ("normal_drag", "tangential_drag"):
        z = math.log(result.values[name] / TRUTH[name]) / result.relative_uncertainty[name]
        assert abs(z) < 2 or any("not independent noise" in w for w in result.warnings), f"{name}: z = {z:.2f}"
    # Here it fires: the residuals of some series drift, and the uncertainty widens.
    assert any(c.discrepancy for c in result.residual_checks.values())
    assert max(result.inflation.values()) > 1.2


def test_hidden_truth_specific_drag_from_a_reference_integrator(k0_fit):
    # Records integrated at rtol = atol = 1e-10, fitted at the default 1e-6, with fresh
    # noise; the fit shares k0_fit's compiled steps.
    tight = jc.calibration.rig_solver(rtol=1e-10, atol=1e-10)
    records = [
        synthetic_record(
            VerticalTow(leader_lift=lift), np.linspace(0.0, 20.0, 101), seed=50 + i, name=f"{lift} N", solver=tight
        )
        for i, lift in enumerate([160.0, 220.0, 300.0])
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = jc.calibrate(records, {"specific_drag": START["specific_drag"]}, progress=False)
    error = abs(result.values["specific_drag"] / TRUTH["specific_drag"] - 1)
    assert error < 0.05  # 0.065 %, measured
    assert error < 4 * result.relative_uncertainty["specific_drag"]
    assert result.warnings == []
