"""The moored net as a study: the measures on series built by hand (heave
amplitude and phase from known sines, drift from a known trend, slack spells and snaps
from known spells and spikes, a clipped sine's levels from their closed form), the
verdict's criteria on a run built by hand, and one `SMALL` run, whose buoys 2 and 4 must
mirror each other in the waves' vertical plane."""

import numpy as np
import pytest

from jaxcable.examples import _moored_net as net
from studies import moored_net as s
from studies import towed_trawl as s2

T = net.WAVE_PERIOD
OMEGA = 2 * np.pi / T
BUOYS = s.BUOYS
PLACE_SEGMENTS = dict(zip(s.PLACES, range(4)))


def _still() -> np.ndarray:
    """Junctions at rest: the scene's design positions."""
    return net.junctions()


def _run(times, buoys=None, tension=None, still=None, still_tension=None, periods=3) -> s.NetRun:
    """A run built by hand: buoys' positions `buoys` (buoy → (times, 3); at rest by
    default), the other junctions at rest, and the four places' `tension`, shape
    `(times, 4)`, on segments 0–3, which also make up buoy 2's vertical branch."""
    still = _still() if still is None else still
    junctions = np.broadcast_to(still, (times.size, *still.shape)).copy()
    for b, position in (buoys or {}).items():
        junctions[:, net.buoy_node(b)] = position
    tension = np.ones((times.size, 4)) if tension is None else np.asarray(tension, dtype=float)
    return s.NetRun(
        config=dict(periods=periods),
        pretension=net.PRETENSION,
        times=times,
        junctions=junctions,
        tension=tension,
        still=still,
        still_tension=np.ones(4) if still_tension is None else still_tension,
        places=PLACE_SEGMENTS,
        branches={b: np.arange(4) if b == 2 else np.array([], dtype=int) for b in BUOYS},
        steps=0,
        statics_time=0.0,
        wall_time=0.0,
    )


def _buoys(times, still, offsets, amplitudes, lags, means=(0, 0, 0, 0)):
    """Buoy positions: still + a fixed horizontal offset, and heave
    `mean + A cos(ω t − lag)`."""
    out = {}
    for b, offset, amplitude, lag, mean in zip(BUOYS, offsets, amplitudes, lags, means):
        p = np.broadcast_to(still[net.buoy_node(b)], (times.size, 3)).copy()
        p[:, :2] += offset
        p[:, 2] += mean + amplitude * np.cos(OMEGA * times - lag)
        out[b] = p
    return out


def test_heave_amplitude_and_phase_by_hand():
    t = np.linspace(0.0, 60.0, 6001)
    still = _still()
    lags = np.radians([30.0, 110.0, 215.0, 110.0])  # buoy 3 lags buoy 1 by 185° = leads by 175°
    amplitudes = [1.3, 0.7, 1.0, 0.7]
    means = [-0.3, -0.2, -0.1, -0.2]
    run = _run(t, _buoys(t, still, [(0, 0)] * 4, amplitudes, lags, means), periods=4)
    h = s.heave(run)
    for b, amplitude, mean in zip(BUOYS, amplitudes, means):
        assert h[b].amplitude == pytest.approx(amplitude, rel=1e-9)
        assert h[b].half_range == pytest.approx(amplitude, rel=1e-4)  # the grid's samples
        assert h[b].mean_z == pytest.approx(still[net.buoy_node(b), 2] + mean, abs=1e-9)
        assert h[b].sink == pytest.approx(mean, abs=1e-9)
    assert [h[b].phase for b in BUOYS] == pytest.approx([0.0, -80.0, 175.0, -80.0], abs=1e-7)
    # A second harmonic and a slow sink leave the first harmonic as it was.
    wobble = np.stack([0 * t, 0 * t, 0.2 * np.cos(2 * OMEGA * t) - 0.001 * t], 1)
    extra = {b: run.buoy(b) + wobble for b in BUOYS}
    h2 = s.heave(_run(t, extra, periods=4))
    for b in BUOYS:
        assert h2[b].amplitude == pytest.approx(h[b].amplitude, rel=1e-9)
        assert h2[b].phase == pytest.approx(h[b].phase, abs=1e-7)
    # The wave's own phase at the buoys, −k Δx, with k from ω² = g k tanh k d solved here.
    k = OMEGA**2 / net.GRAVITY
    for _ in range(100):
        k = OMEGA**2 / (net.GRAVITY * np.tanh(k * net.WATER_DEPTH))
    assert s.wave_phase(2, still) == pytest.approx(-np.degrees(k * net.RADIUS), rel=1e-9)
    assert s.wave_phase(3, still) == pytest.approx(-np.degrees(2 * k * net.RADIUS), rel=1e-9)


def test_drift_by_hand():
    # Each buoy's horizontal offset grows linearly, with a wave-period surge on top: the
    # mean over the last whole periods is the offset at their middle.
    t = np.linspace(0.0, 64.0, 3201)
    still = _still()
    offsets = {1: (0.8, 0.0), 2: (0.5, 0.1), 3: (0.3, 0.0), 4: (0.5, -0.1)}
    rate = 0.01  # m/s along x
    buoys = {}
    for b, (dx, dy) in offsets.items():
        p = np.broadcast_to(still[net.buoy_node(b)], (t.size, 3)).copy()
        mid = 64.0 - 1.5 * T  # the middle of the last 3 periods
        p[:, 0] += dx + rate * (t - mid) + 0.4 * np.sin(OMEGA * t + b)
        p[:, 1] += dy + 0.05 * np.cos(OMEGA * t)
        buoys[b] = p
    d = s.drift(_run(t, buoys, periods=3))
    # Inward is toward the centre: buoy 1 sits at −x, buoy 3 at +x, buoy 2 at −y, 4 at +y.
    inward = {1: 0.8, 2: 0.1, 3: -0.3, 4: 0.1}
    for b, (dx, dy) in offsets.items():
        assert d[b].along == pytest.approx(dx, abs=1e-9)
        assert d[b].across == pytest.approx(dy, abs=1e-9)
        assert d[b].inward == pytest.approx(inward[b], abs=1e-9)
        assert d[b].rate == pytest.approx(rate * T, rel=1e-9)


def _spiky(t):
    """Slack for 1.95 s of every 6.4 s period, from 1 s into it; on the end of each
    spell a spike to 9 kN (a Gaussian 0.1 s wide, 0.2 s after), and 3 kN otherwise."""
    phase = t % T
    spike = 6e3 * np.exp(-(((phase - 3.15) / 0.1) ** 2))
    return np.where((phase >= 1.0) & (phase < 2.95), -0.5, 3e3 + spike)


def test_snaps_by_hand():
    t = np.round(np.arange(0.0, 40.0, 1e-3), 9)
    tension = np.stack([_spiky(t), 3e3 + 0 * t, _spiky(t - 0.5), _spiky(t)], 1)
    found = s.series_snaps(t, tension, after=20.0)
    # Spells start at 1 + 6.4 n s: n = 3…5 start after 20 s; n = 2's (13.8–15.75) is
    # before. On the series shifted by 0.5 s, n = 3…5 too (20.7, 27.1, 33.5).
    assert sorted({f.segment for f in found}) == [0, 2, 3]
    first = [f for f in found if f.segment == 0]
    assert [f.slack_from for f in first] == pytest.approx([1 + 3 * T, 1 + 4 * T, 1 + 5 * T], abs=2e-3)
    assert [f.slack_to - f.slack_from for f in first] == pytest.approx([1.95] * 3, abs=2e-3)
    assert all(f.peak == pytest.approx(9e3, rel=1e-6) for f in found)
    assert [f.peak_time - f.slack_to for f in first] == pytest.approx([0.2] * 3, abs=2e-3)
    # A spell still going at the end is left out; one going at `after` counts from there.
    late = s.series_snaps(t, tension, [0], after=1 + 3 * T + 1.0)
    assert late[0].slack_from == pytest.approx(1 + 3 * T + 1.0, abs=2e-3)
    assert len(s.series_snaps(t[t < 38.0], tension[t < 38.0], [0], after=30.0)) == 1  # the 33.0 s spell
    # On a trawl run it is the trawl study's `snaps`.
    run = s2.TrawlRun(
        name="by hand",
        speeds=(1.0, 3.0),
        viscous=True,
        waves=False,
        times=t,
        tension=tension,
        junctions=np.zeros((t.size, 5, 3)),
        points={},
        steady=None,
        front_angle=0.0,
        steps=0,
        wall_time=0.0,
    )
    assert s2.snaps(run, after=20.0) == found


def test_places_on_a_clipped_sine():
    # T = max(0, a + b sin ωt) with a < b: slack a share (π − 2 asin(a/b)) / 2π of the
    # time, mean (a (π + 2 asin(a/b)) + 2 √(b² − a²)) / 2π, once a period.
    a, b = 4e3, 5e3
    c = np.arcsin(a / b)
    t = np.linspace(0.0, 10 * T, 200001)
    sine = np.maximum(0.0, a + b * np.sin(OMEGA * t))
    tension = np.stack([sine, sine + 100.0, sine, sine], 1)
    run = _run(t, tension=tension, still_tension=np.array([1.6e3, 1.5e3, 1.4e3, 1.0e3]), periods=5)
    p = s.places(run)
    near = p["near anchor"]
    assert near.still == 1.0e3
    assert near.min == 0.0
    assert near.max == pytest.approx(a + b, rel=1e-9)
    assert near.mean == pytest.approx((a * (np.pi + 2 * c) + 2 * np.sqrt(b * b - a * a)) / (2 * np.pi), rel=1e-4)
    assert near.slack_fraction == pytest.approx((np.pi - 2 * c) / (2 * np.pi), rel=1e-3)
    assert len(near.spells) == 5
    assert near.longest == pytest.approx((np.pi - 2 * c) / OMEGA, abs=1e-3)
    # Each spell ends where a + b sin θ rises through 0; 1 s on, the tension is still
    # rising (to within the 0.3 ms samples).
    assert near.peak == pytest.approx(a + b * np.sin(-c + OMEGA * 1.0), rel=1e-3)
    assert p["above junction"].spells == [] and np.isnan(p["above junction"].peak)
    assert p["above junction"].min == pytest.approx(100.0)
    # The running mean over 0.02 s (n samples) of a slow sine peaks as the sine does; a
    # spike one sample wide adds its height over n to each window that holds it.
    assert near.max_smoothed == pytest.approx(a + b, rel=1e-4)
    spiked = tension.copy()
    j = np.argmin(np.abs(t - 9.5 * T - 0.3))
    spiked[j, 0] += 1e6
    dt = t[1] - t[0]
    n = round(0.02 / dt)
    under = s.places(_run(t, tension=spiked, periods=5))["under buoy"]
    assert under.max == pytest.approx(spiked[j, 0])
    assert under.max_time == pytest.approx(t[j])
    holding = max(sine[k : k + n].mean() for k in range(j - n + 1, j + 1))
    assert under.max_smoothed == pytest.approx(holding + 1e6 / n, rel=1e-9)


def _verdict_run(along=(0.8, 0.5, 0.3, 0.5), inward_24=0.1, slack_upper=True):
    """A run built by hand whose buoys heave like the paper's and drift by `along` (m,
    buoys 1–4) and `inward_24` (m, buoys 2 and 4 toward the centre); buoy 2's branch
    snaps at all four places, or only on the lower part (`slack_upper=False`), with a
    spike 0.8 times as high on the upper part."""
    t = np.linspace(0.0, 64.0, 32001)
    still = _still()
    offsets = [(along[0], 0), (along[1], inward_24), (along[2], 0), (along[3], -inward_24)]
    buoys = _buoys(t, still, offsets, [1.3, 0.7, 1.0, 0.7], np.radians([0, 90, 180, 90]))
    upper = 0.8 * _spiky(t) + 600.0 * (not slack_upper)
    tension = np.stack([upper, upper, _spiky(t), _spiky(t)], 1)
    return _run(t, buoys, tension=tension, still_tension=np.array([1.6e3, 1.5e3, 1.4e3, 1.0e3]), periods=3)


def test_verdict_criteria_by_hand():
    grades = [row[2] for row in s.verdict_rows(_verdict_run())]
    assert grades == ["yes"] * 7
    rows = s.verdict_rows(_verdict_run(along=(-0.8, -0.5, -0.3, -0.5), inward_24=0.0, slack_upper=False))
    assert [row[2] for row in rows] == ["yes", "yes", "partly", "no", "partly", "partly", "yes"]
    # Numbers in the results are the run's.
    assert "−0.80" in rows[2][1].replace("-", "−")
    assert "2 of the 4 places" in rows[4][3]
    # Buoy 1 not the largest drift, buoys 2 and 4 downwave but not inward.
    rows = s.verdict_rows(_verdict_run(along=(0.3, 0.5, 0.8, 0.5), inward_24=-0.1))
    assert [row[2] for row in rows[2:4]] == ["partly", "partly"]
    # No slack anywhere: no snaps.
    run = _verdict_run()
    run.tension = np.abs(run.tension) + 10.0
    assert [row[2] for row in s.verdict_rows(run)[4:]] == ["no", "partly", "no"]


@pytest.fixture(scope="module")
def small():
    return s.run_net(s.SMALL)


@pytest.mark.slow
def test_small_run_is_mirror_symmetric(small):
    # The scene is its own mirror image in the waves' vertical plane y = 0 (buoys 2 ↔ 4),
    # and the Airy wave along +x is too; so must the motion be, to rounding: the still
    # state is mirror-symmetric to 1e-15 m, and the damped motion (the lines' viscous
    # term) does not amplify rounding. Measured: 3e-12 m over the run, while the buoys
    # heave by 2.3 m, the slack segments snap, and a one-sided error in the waves, the
    # buoys or the lines would part them by centimetres.
    b2, b4 = small.buoy(2), small.buoy(4)
    np.testing.assert_allclose(b2 * [1, -1, 1], b4, atol=1e-9)
    assert np.ptp(b2[:, 2]) > 1.0
    # Buoys 1 and 3, on the plane, stay on it; so does the hub.
    for node in (net.buoy_node(1), net.buoy_node(3), net.HUB):
        np.testing.assert_allclose(small.junctions[:, node, 1], 0.0, atol=1e-9)
    # The tensions agree to the solver's tolerance, not to rounding: the explicit solver
    # holds the stiff viscous mode's velocity to its atol, 1e-6 m/s, which the viscous
    # term turns into C_v / L × 1e-6 m/s = 0.06 N on the 10.5 m upper part (0.025 N
    # measured), independently on either side.
    steel = np.asarray(small.tension[:, small.branches[2]])
    np.testing.assert_allclose(steel, small.tension[:, small.branches[4]], rtol=0, atol=0.25)
    assert np.ptp(steel) > 1e4
    h = s.heave(small)
    assert h[2].amplitude == pytest.approx(h[4].amplitude, rel=1e-9)
    assert h[2].phase == pytest.approx(h[4].phase, abs=1e-7)
