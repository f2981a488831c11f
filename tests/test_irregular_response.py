"""A linear system in an irregular sea against its closed form: a submerged buoy on a
vertical tether, without drag, a linear oscillator (`studies/linear_buoy.py` derives
H_T(ω), the tension per unit wave amplitude, with numpy and scipy alone).

The default test checks the advice's natural periods against the heave, 2π √(M/k), and
the sway, a pendulum 2π √(M S/T₀); a `slow` one the advice's lines on an irregular sea.
The other `slow` ones run one compiled sweep over 8 seeds and compare each seed's tension with the closed form:
its variance over one repeat period with ∫ |H_T|² S dω, its history point by point, its
maximum, and the most probable maximum over the seeds.

The sea is small (H_s = 0.5 m) so that the motions stay small against the waves'
lengths (k x ≪ 1). Over the 8 seeds the variance was 0.996 to 1.003 of the integral and
the record within 0.7 to 1.1 % of σ of the closed form's, point by point (RMS); at
H_s = 2 m, where the buoy heaves by ±1.8 m, 0.95 to 1.02 and 9 to 14 %
(`validation/irregular_response.py`, *Irregular seas* in `benchmarks/README.md`).
"""

import jax.numpy as jnp
import numpy as np
import pytest

import jaxcable as jc
from jaxcable._equations.modes import natural_periods
from jaxcable.io import advice_lines
from studies import linear_buoy as lb

SIGNIFICANT_HEIGHT = 0.5  # m
SEEDS = 8


@pytest.fixture(scope="module")
def statics():
    return jc.solve_statics(lb.tethered_buoy(), lb.still_water())


def test_natural_periods_are_the_heave_and_the_sway():
    """The modes about the equilibrium in closed form: the tether carries the buoy's net
    buoyancy less half its own wet weight, T₀, stretched to S = L₀ (1 + T₀/EA); the buoy
    heaves at 2π √(M/k) and sways in x and y as a pendulum, 2π √(M S/T₀)."""
    tension = (lb.RHO * lb.VOLUME - lb.BUOY_MASS) * lb.G - (lb.LINE_MASS - lb.RHO * 1e-6) * lb.G * lb.LENGTH / 2
    stretched = lb.LENGTH * (1 + tension / (lb.STIFFNESS * lb.LENGTH))
    positions = np.array([[0.0, 0.0, -lb.DEPTH], [0.0, 0.0, stretched - lb.DEPTH]])
    periods = natural_periods(lb.tethered_buoy(), lb.still_water(), positions)
    heave, sway = 2 * np.pi / lb.NATURAL, 2 * np.pi * np.sqrt(lb.MASS * stretched / tension)
    np.testing.assert_allclose(periods, [sway, sway, heave], rtol=1e-9)


@pytest.mark.slow
def test_the_advice_on_an_irregular_sea():
    """The advice's own equilibrium gives the same modes; the sea repeats after 256 s,
    within a 600 s run. (A regular wave near a mode: wave_mooring's, in test_scenes.py.)"""
    sea = lb.sea(0, SIGNIFICANT_HEIGHT)
    water = jc.Environment(lb.RHO, lb.G, depth=lb.DEPTH, waves=sea)
    advice = jc.advise(lb.tethered_buoy(), water, duration=600.0)
    tension = advice.rest_max_tension
    assert tension is not None
    stretched = lb.LENGTH * (1 + tension / (lb.STIFFNESS * lb.LENGTH))
    heave, sway = 2 * np.pi / lb.NATURAL, 2 * np.pi * np.sqrt(lb.MASS * stretched / tension)
    np.testing.assert_allclose(advice.natural_periods, [sway, sway, heave], rtol=1e-9)
    text = " ".join(advice_lines(advice))
    assert f"wave 1 (irregular, H_s = {float(sea.height):.3g} m" in text and "Airy fits, which it uses" in text
    assert "wave 1 repeats after 256 s (2π/Δω), within the run's 600 s" in text
    assert "2.34 times as many here" in text
    assert "near the natural period" not in text and "design check" not in text  # regular waves only
    text = " ".join(advice_lines(jc.advise(lb.tethered_buoy(), water, duration=200.0)))
    assert "beyond the run's 200 s: the record does not repeat" in text


@pytest.fixture(scope="module")
def comparison(statics):
    result, ts = lb.sweep_seeds(SIGNIFICANT_HEIGHT, SEEDS, statics)
    assert bool(np.all(result.success)), result.status
    return result, lb.compare(result, ts, statics, SIGNIFICANT_HEIGHT)


@pytest.mark.slow
def test_response_variance_is_the_transfer_functions(comparison):
    _, numbers = comparison
    for row in numbers["per_seed"]:
        # The band and the midpoint rule: the discrete sum within 3e-5 of the integral.
        assert row["discrete_over_integral"] == pytest.approx(1.0, abs=1e-4)
        # The record's variance over one period is the discrete sum, but for the
        # solver's error, the transient and the terms of second order in the motion
        # (k x ≪ 1), which move it by up to 0.4 % seed by seed.
        assert row["variance_over_integral"] == pytest.approx(1.0, abs=0.01)
        assert abs(row["mean_offset_over_sigma"]) < 0.002
        assert row["rms_error_over_sigma"] < 0.02


@pytest.mark.slow
def test_most_probable_maximum_over_seeds_is_the_linear_ones(comparison, statics):
    """The statistics over the sweep's seeds against the same statistics of the closed
    form's records, and the short-term (Rayleigh) MPM against Rice's σ √(2 ln ν₀ D), σ
    and ν₀ = √(m₂/m₀)/2π from the response spectrum |H_T|² S."""
    result, numbers = comparison
    sigma = numbers["sigma"]
    np.testing.assert_allclose(numbers["maxima"], numbers["linear_maxima"], rtol=0, atol=0.05 * sigma)
    assert numbers["mpm"] == pytest.approx(numbers["linear_mpm"], abs=0.03 * sigma)
    assert numbers["spread"] == pytest.approx(numbers["linear_spread"], rel=0.1)
    assert numbers["rayleigh_mpm"] == pytest.approx(numbers["rice_mpm"], rel=0.003)
    # Extrapolated to a 3-hour storm.
    storm = result.tension_extremes(lb.START, duration=10800.0)
    rest, rate = (
        numbers["rest_tension"],
        lb.response_moment(2, float(statics.state.positions[1, 2]), SIGNIFICANT_HEIGHT),
    )
    rice = rest + sigma * np.sqrt(2 * np.log(np.sqrt(rate) / sigma / (2 * np.pi) * 10800.0))
    assert float(storm.rayleigh_mpm) == pytest.approx(rice, rel=0.003)
    assert float(storm.most_probable_maximum) > numbers["mpm"]
    assert bool(jnp.all(jnp.isfinite(storm.quantile(0.9))))
