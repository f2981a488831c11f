"""The Yakovlev et al.'s cnoidal-loads paper study's numbers against references computed apart from jaxcable.

- The paper's eq. 33 (the convolution of cn's Fourier coefficients, coded in the study
  with SciPy's elliptic integrals) against jaxcable's closed-form `cnoidal_coefficients`
  and an FFT of SciPy's cn².
- The study's SciPy cnoidal wave (m by bracketing on T = λ/c) against jaxcable's
  `Cnoidal` (optimistix's Newton on the same relation in ln s).
- The held column's loads (jaxcable's generalised forces, Gauss–Legendre along the
  segments, shape functions onto the nodes) against Morison's load integrated over
  depth by `scipy.integrate.quad` from SciPy's kinematics: force and overturning moment,
  on the pile and on the inertia-only column, under both theories, at a cnoidal wave of
  the paper's shelf and a steep one (U = 220, 1 − m = 4e-5).
- Loads under the bound harmonic series (the paper's harmonic superposition) against
  the same quad over the series with eq. 33's coefficients.

One small batch of each kind, so that each program compiles once (a few seconds).
"""

import numpy as np
import pytest

import jaxcable as jc
from studies import cnoidal_loads as s4

# (H, T): the paper's shelf (λ ≈ 350 m, U = 20) and a near-solitary wave (U = 220).
WAVES = [(7.0, 20.0), (14.0, 40.0)]
TIMES = np.linspace(0.0, 40.0, 33)


@pytest.mark.parametrize("m", [0.3936, 0.9119, 0.99996])
def test_paper_eq33_and_fft_give_the_closed_form_coefficients(m):
    closed = np.asarray(jc.cnoidal_coefficients(m, 32))
    np.testing.assert_allclose(s4.paper_coefficients(m, 32), closed, rtol=0, atol=1e-15)
    np.testing.assert_allclose(s4.fft_coefficients(m, 32), closed, rtol=0, atol=1e-14)


@pytest.mark.parametrize("height, period", WAVES + [(20.3, 24.4)])
def test_reference_wave_matches_jaxcable(height, period):
    reference = s4.ReferenceCnoidal.solve(height, period, s4.DEPTH)
    wave = jc.Cnoidal(height, period, s4.DEPTH)
    assert abs(float(wave.m) - reference.m) < 1e-12 * reference.m1
    assert float(wave.wavelength) == pytest.approx(reference.wavelength, rel=1e-13)
    assert float(wave.trough) == pytest.approx(reference.trough, rel=1e-12)
    # The λ̄-series' start: U = 4π² and λ = 500 m give back λ.
    height, period = s4.steepness_series([1.0])
    assert float(jc.Cnoidal(height[0], period[0], s4.DEPTH).wavelength) == pytest.approx(500.0, rel=1e-12)


@pytest.fixture(scope="module")
def cases():
    """Both waves on the pile and on the inertia-only column: (H, T, structure) × 4."""
    rows = [(h, t, name) for h, t in WAVES for name in ("pile", "potential")]
    return {
        "height": np.array([r[0] for r in rows]),
        "period": np.array([r[1] for r in rows]),
        "structure": [r[2] for r in rows],
        "diameter": np.array([s4.STRUCTURES[r[2]][0] for r in rows]),
        "drag": np.array([s4.STRUCTURES[r[2]][1] for r in rows]),
    }


@pytest.mark.parametrize("theory", ["cnoidal", "airy"])
def test_column_loads_match_morison_by_quad(cases, theory):
    parameters = {k: cases[k] for k in ("height", "period", "diameter", "drag")}
    loads = s4.column_loads(s4.WAVES[theory], parameters, TIMES)
    assert loads.success.all()
    for i, (h, t) in enumerate(zip(cases["height"], cases["period"])):
        wave = s4.reference_wave(theory, h, t)
        force, moment = s4.reference_loads(wave, cases["diameter"][i], cases["drag"][i], TIMES)
        # Cnoidal u is depth-uniform, so the three-point rule is exact; Airy's cosh
        # profile over 3.5 m segments is integrated to ~1e-11.
        np.testing.assert_allclose(loads.force[i], force, rtol=0, atol=1e-9 * np.abs(force).max())
        np.testing.assert_allclose(loads.moment[i], moment, rtol=0, atol=1e-9 * np.abs(moment).max())
    if theory == "cnoidal":
        # The steep wave loads the inertia-only column more than twice as hard as
        # linear theory would (the study's headline; Airy's value by quad).
        i = 3
        airy, _ = s4.reference_loads(s4.ReferenceAiry(14.0, 40.0, s4.DEPTH), 8.0, 0.0, np.linspace(0, 40, 81))
        assert loads.force[i].max() / airy.max() > 2


def test_harmonic_series_loads_match_eq33_by_quad(cases):
    # Harmonics 1–4 and harmonic 3 alone of the shelf wave, on the pile.
    parameters = {
        "height": np.full(2, 7.0),
        "period": np.full(2, 20.0),
        "first": np.array([1.0, 3.0]),
        "last": np.array([4.0, 3.0]),
        "diameter": np.full(2, 1.0),
        "drag": np.full(2, 1.0),
    }
    loads = s4.column_loads(
        lambda height, period, first, last: s4.bound_harmonics(height, period, first, last, 8), parameters, TIMES[:17]
    )
    wave = s4.ReferenceCnoidal.solve(7.0, 20.0, s4.DEPTH)
    for i, weights in enumerate([(1, 1, 1, 1, 0, 0, 0, 0), (0, 0, 1, 0, 0, 0, 0, 0)]):
        force, _ = s4.reference_loads(s4.ReferenceSeries(wave, weights), 1.0, 1.0, TIMES[:17], moment=False)
        np.testing.assert_allclose(loads.force[i], force, rtol=0, atol=1e-11 * np.abs(force).max())
