"""The branched-systems paper's trawl study: the first stage of the tension after a speed step against the
axial-wave closed form, and the study's measures on series built by hand."""

import numpy as np
import pytest

from jaxcable.examples._anchored_line import ADDED_MASS, AXIAL_STIFFNESS, MASS_PER_LENGTH
from studies import towed_trawl as s2


@pytest.mark.slow
def test_first_stage_is_the_axial_wave():
    # An elastic tow cable whose end speeds up by Δv carries an axial wave of tension
    # Z Δv cos θ, Z = √(C_E (m + m_a)), until it comes back from the branch point. The
    # front is spread over the 0.02 s step, three of the ten 20 m segments, hence 2 %.
    config = dict(segments=(10, 5), start=299.0, end=dict(short=300.4), dense=0.4)
    run = s2.run_trawl("elastic step", config, case=((1.0, 3.0), False, False, "short"))
    measured, predicted = s2.front_jump(run)
    impedance = np.sqrt(AXIAL_STIFFNESS * (MASS_PER_LENGTH + ADDED_MASS))
    assert predicted == pytest.approx(impedance * 2.0 * np.cos(run.front_angle))
    assert measured == pytest.approx(predicted, rel=0.02)


def _run(times, tension, speeds=(1.0, 3.0)):
    """A trawl run with the given tension on every point, the junctions at rest."""
    tension = np.asarray(tension, dtype=float)[:, None] * np.ones(4)
    return s2.TrawlRun(
        name="by hand",
        speeds=speeds,
        viscous=True,
        waves=False,
        times=times,
        tension=tension,
        junctions=np.zeros((times.size, 5, 3)),
        points=dict(zip(s2.POINTS, range(4))),
        steady=None,
        front_angle=0.0,
        steps=0,
        wall_time=0.0,
    )


def test_snaps_and_jerks_on_a_series_by_hand():
    t = np.arange(290.0, 320.0, 1e-3)
    # A fall: 30 kN until the step, slack from 300.2 to 300.5 s, a snap peaking at
    # 25 kN at 300.7 s, and 15 kN from 302 s on.
    tension = np.where(t < 300.0, 30e3, 15e3)
    tension = np.where((t >= 300.2) & (t < 300.5), -100.0, tension)
    tension = np.where((t >= 300.5) & (t < 302.0), 15e3 + 10e3 * np.exp(-(((t - 300.7) / 0.1) ** 2)), tension)
    run = _run(t, tension, speeds=(3.0, 1.0))
    found = s2.snaps(run, segments=[0])
    assert len(found) == 1
    snap = found[0]
    assert snap.slack_from == pytest.approx(300.2, abs=2e-3)
    assert snap.slack_to == pytest.approx(300.5, abs=2e-3)
    assert snap.peak == pytest.approx(25e3, rel=1e-6)
    assert snap.peak_time == pytest.approx(300.7, abs=2e-3)
    assert snap.settled == pytest.approx(15e3)
    peak, level = s2.jerk(run)
    assert peak == pytest.approx(25e3, rel=1e-6)
    assert level == pytest.approx(15e3)
    # A rise's jerk is its first peak, even though the tension dips after it.
    rise = _run(t, np.where(t < 300.0, 10e3, 20e3 + np.where(t < 300.3, 15e3, -5e3) * (t < 301.0)))
    assert s2.jerk(rise) == pytest.approx((35e3, 20e3))
    assert s2.snaps(rise) == []


def test_levels_and_settling_by_hand():
    t = np.arange(200.0, 400.0, 0.05)
    # A mean that steps from 10 to 20 kN at 300 s with a 20 s time constant, under a
    # 5.6 s wave of 1 kN amplitude before and 3 kN after.
    rise = np.where(t < 300.0, 0.0, 1 - np.exp(-(t - 300.0) / 20.0))
    amplitude = np.where(t < 300.0, 1e3, 3e3)
    run = _run(t, 10e3 + 10e3 * rise + amplitude * np.sin(2 * np.pi * t / s2.WAVE_PERIOD))
    lv = s2.levels(run, run.at("tow point"))
    assert lv.mean_before == pytest.approx(10e3, rel=0.02)
    assert lv.range_before == pytest.approx(2e3, rel=0.01)
    assert lv.range_after == pytest.approx(6e3, rel=0.02)
    # 90 % of the way: 20 ln 10 = 46 s, less the mean's shortfall over the last span.
    assert s2.settling_time(run) == pytest.approx(20 * np.log(10), rel=0.05)
