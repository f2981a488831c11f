"""The branched-systems paper's snap loads (`studies.snap_loads`): the three measures of a snap on a
spike built by hand, with its sampled maximum, its retardation-time mean and its elastic
part in closed form; the convergence criteria on tables built by hand; C_E1 reaching the
scenes' lines; and (slow) one snap of the small net resolved at 1 µs and two tolerances."""

import numpy as np
import pytest

from jaxcable.examples import _moored_net as net
from jaxcable.examples import _towed_trawl as trawl
from jaxcable.examples._anchored_line import AXIAL_STIFFNESS
from studies import moored_net as s2n
from studies import snap_loads as s
from studies import towed_trawl as s2

JUMP = 1e6  # N, the viscous jump as the segment goes taut
DECAY = 2e-4  # s, the spike's time constant
RAMP = 1e6  # N/s, the elastic tension's rise once taut
TAUT = 0.01  # s, when the segment goes taut, in a window of [0, 0.04] s


STIFFNESS = 3e7  # N, C_E of the hand-built segment
RATE = RAMP / STIFFNESS  # 1/s, its strain rate once taut
WIDTH = 1e-5  # –, its slack band


def _window(rtol=1e-6, jump=JUMP) -> s.SnapWindow:
    """A snap built by hand: slack until `TAUT`, then an elastic tension rising at
    `RAMP` to a peak of 15 kN and falling back, and a viscous spike `jump e^(−t/DECAY)`
    (whose C_v ε̇ at `TAUT` is `jump`)."""
    t = np.linspace(0.0, 0.04, 40001)
    after = np.clip(t - TAUT, 0.0, None)
    elastic = np.where(t > TAUT, np.minimum(RAMP * after, 3e4 - RAMP * after), 0.0)
    spike = np.where(t > TAUT, jump * np.exp(-after / DECAY), 0.0)
    strain = np.where(t > TAUT, elastic / STIFFNESS, -RATE * (TAUT - t))
    return s.SnapWindow(rtol, 0.0, t, elastic + spike, elastic, strain, jump / RATE, WIDTH, 0, 0.0)


def test_peaks_of_a_spike_by_hand():
    w = _window()
    fine = s.peaks(w)
    # The first sample past TAUT is 1 µs in: the spike has fallen by e^(−1/200) there.
    assert fine.sampled == pytest.approx(JUMP * np.exp(-1e-6 / DECAY) + RAMP * 1e-6, rel=1e-9)
    assert fine.elastic == pytest.approx(1.5e4, rel=1e-9)
    # The 20 ms mean at its largest, from TAUT: the tent's 175 N·s over [0.01, 0.03] s
    # (its rise, 112.5, and 5 ms of its fall, 62.5) and the spike's whole impulse J τ
    # (200 N·s), over 20 ms: 18.75 kN. Centred on the tent's peak instead it would be
    # 10 kN. The samples' sum of the spike is J τ (1 − dt / 2τ): 0.25 % short.
    assert s2n.SMOOTH == 0.02
    assert fine.smoothed == pytest.approx((175.0 + JUMP * DECAY) / 0.02, rel=5e-3)
    # 4.096 ms samples miss the spike: the largest is the tent's, at 24.576 ms.
    coarse = s.peaks(w, 4096)
    assert coarse.interval == pytest.approx(4.096e-3)
    assert coarse.sampled == pytest.approx(RAMP * (0.024576 - TAUT), rel=1e-6)
    assert coarse.elastic == coarse.sampled


def test_convergence_criteria_by_hand():
    # Two tolerances, the second the first with a spike 0.5 % higher: the sampled and
    # smoothed measures move by less than 1 % with the tolerance, the elastic not at all.
    table = s.convergence([_window(), _window(jump=1.005 * JUMP)], strides=(4096, 16, 4, 2, 1))
    assert [p.interval for p in table[0]] == pytest.approx([4.096e-3, 1.6e-5, 4e-6, 2e-6, 1e-6])
    assert s.converged(table, "elastic") == pytest.approx(1.5e4, rel=1e-9)
    assert s.converged(table, "smoothed") == pytest.approx(table[1][-1].smoothed)
    # The sampled maximum: halving 2 → 1 µs moves it by e^(−1/200) − e^(−2/200) = 0.5 %.
    assert s.converged(table, "sampled") is not None
    assert s.converged(table, "sampled", share=0.004) is None
    # The elastic peak: from 16 µs on within 1 % of the finest (8 N short at 16 µs; 2.8 %
    # at 4.096 ms). The sampled spike: 7.7 % low at 16 µs (its first sample 16 µs past
    # TAUT), 1.5 % at 4 µs, 0.5 % at 2 µs.
    assert s.converged_interval(table, "elastic") == pytest.approx(1.6e-5)
    assert s.converged_interval(table, "sampled") == pytest.approx(2e-6)
    # A tolerance that moves the measure by 5 %: not converged.
    table = s.convergence([_window(), _window(jump=1.5 * JUMP)], strides=(2, 1))
    assert s.converged(table, "sampled") is None
    assert s.converged(table, "elastic") is not None


def test_spike_model_by_hand():
    # The strain leaves the band w = 1e-5 at RATE: 0.3 ms after TAUT, to the sample.
    j = int(np.flatnonzero(_window().strain >= WIDTH)[0])
    assert _window().times[j] - TAUT == pytest.approx(WIDTH / RATE, abs=1.5e-6)
    assert s.spike_model(_window()) == pytest.approx(JUMP + _window().elastic[j], rel=1e-9)
    flat = _window()
    flat.strain = np.minimum(flat.strain, 0.0)
    with pytest.raises(ValueError, match="no snap"):
        s.spike_model(flat)


def test_wave_difference_by_hand():
    elastic = {p: s.WaveTension(10e3, 2e3, 11e3, 9e3) for p in s2.POINTS}
    viscous = dict(elastic, buoy=s.WaveTension(10.1e3, 1.8e3, 10.9e3, 9.1e3))
    d = s.wave_difference(elastic, viscous)
    assert d == pytest.approx(dict(mean=0.01, range=0.1, max=0.1e3 / 11e3))


def test_quadratic_ratio_reaches_every_line():
    # C_E1 = ratio × C_E on the net's steel and rope and on the trawl's cable; 0 by
    # default, as before.
    for ratio in (0.0, 0.2):
        model, _ = net.moored_net(segments=(1, 1, 1, 1), quadratic_ratio=ratio)
        law = model.line.tension_law
        np.testing.assert_allclose(law.quadratic_stiffness(), ratio * law.axial_stiffness, rtol=1e-15)
        assert {float(x) for x in np.asarray(law.axial_stiffness)} == {
            AXIAL_STIFFNESS,
            net.FRAME_ROPE["axial_stiffness"],
        }
        model, _ = trawl.towed_trawl(segments=(2, 1), quadratic_ratio=ratio)
        np.testing.assert_allclose(model.line.tension_law.quadratic_stiffness(), ratio * AXIAL_STIFFNESS, rtol=1e-15)


@pytest.mark.slow
def test_small_net_snap_converges():
    # The largest snap near buoy 2's anchor in the small net (at 23.35 s in its 2 kHz
    # samples), resolved at 1 µs, to rtol = atol = 1e-6 and 5e-7. The elastic peak and the
    # 20 ms mean each move by less than 1 % as the interval and the tolerances are halved;
    # the samples' maximum is the viscous jump, which the 2 kHz samples of the net study
    # miss by far.
    windows = [s.resolve_snap(s2n.SMALL, 23.35, rtol=r, half_window=0.03) for r in (1e-6, 5e-7)]
    table = s.convergence(windows)
    elastic, smoothed = s.converged(table, "elastic"), s.converged(table, "smoothed")
    assert elastic is not None and smoothed is not None
    resolved = table[-1][-1].sampled
    at_2khz = s.peaks(windows[-1], 512).sampled  # 0.512 ms
    assert resolved > 2 * elastic
    assert at_2khz < 0.9 * resolved
    # The resolved peak is the viscous jump C_v ε̇ as the segment leaves the slack band,
    # with ε̇ from central differences of its strain at 1 µs.
    assert resolved == pytest.approx(s.spike_model(windows[-1]), rel=0.05)


def test_find_snap_needs_dense_samples():
    # A net run sampled at 20 Hz to 19.2 s and at 2 kHz after, with a spike near the
    # anchor at 23.35 s and a larger one at 12 s: the snap is found where the samples
    # are dense, and not at all where they are not.
    times = np.concatenate([np.arange(0.0, 19.2, 0.05), np.linspace(19.2, 44.8, 51201)])
    tension = np.zeros((times.size, 4))
    tension[np.argmin(np.abs(times - 23.35)), 3] = 5e4
    tension[np.argmin(np.abs(times - 12.0)), 3] = 9e4
    run = s2n.NetRun(
        config=dict(dense=2000.0, periods=4),
        pretension=net.PRETENSION,
        times=times,
        junctions=np.zeros((times.size, 13, 3)),
        tension=tension,
        still=net.junctions(),
        still_tension=np.ones(4),
        places=dict(zip(s2n.PLACES, range(4))),
        branches={},
        steps=0,
        statics_time=0.0,
        wall_time=0.0,
    )
    assert s.find_snap(run, 19.2, 25.6) == pytest.approx(23.35)
    assert s.find_snap(run, 10.0, 15.0) is None
