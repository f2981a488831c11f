"""Fatigue damage (`jaxcable._campaign.fatigue`): rainflow counting against ASTM E1049-85's
example counted by hand, Miner's damage of a Gaussian narrow-band process against the
closed form (Rayleigh-distributed ranges), the damage-equivalent load of a sine, and the
standards' T–N curves in both forms."""

import math

import numpy as np
import pytest

import jaxcable as jc


def test_rainflow_counts_astm_e1049s_example():
    """ASTM E1049-85, Fig. 6 (its rainflow example): ranges 3, 4, 6, 8, 9 with 0.5, 1.5,
    0.5, 1.0 and 0.5 cycles; Miner's sum under N = a ΔT⁻³ (area 1e-6 m², so s in MPa is
    ΔT in N) is (0.5·27 + 1.5·64 + 0.5·216 + 512 + 0.5·729)/a = 1094/a."""
    series = [-2.0, 1.0, -3.0, 5.0, -1.0, 3.0, -4.0, 4.0, -2.0]
    ranges, _, counts = jc.rainflow_cycles(series)
    tally = {r: 0.0 for r in (3.0, 4.0, 6.0, 8.0, 9.0)}
    for r, c in zip(ranges, counts):
        tally[r] += c
    assert tally == {3.0: 0.5, 4.0: 1.5, 6.0: 0.5, 8.0: 1.0, 9.0: 0.5}
    curve = jc.TNCurve("cube", 3.0, 1.0e4, "stress")
    result = jc.fatigue_damage(series, np.arange(9.0), curve, area=1e-6)
    assert result.damage == pytest.approx(1094.0 / 1.0e4, rel=1e-14)
    assert result.duration == 8.0 and result.life == pytest.approx(
        8.0 / (result.damage * jc._campaign.fatigue.SECONDS_PER_YEAR)
    )


def test_narrow_band_damage_matches_the_rayleigh_closed_form():
    """A stationary Gaussian narrow-band tension (200 components in 0.098-0.102 Hz,
    random phases, σ = 50 kN about 1 MN) over 50,000 s: its ranges are Rayleigh, so
    E[D] = ν₀ T (2√2 σ)^m Γ(1 + m/2) / a, ν₀ the mean up-crossing rate √(m₂/m₀)."""
    rng = np.random.default_rng(7)
    frequencies = np.linspace(0.098, 0.102, 200)
    sigma, m, a = 5.0e4, 3.0, 6.0e10
    amplitude = sigma * np.sqrt(2.0 / frequencies.size)
    t = np.arange(0.0, 50_000.0, 0.125)
    phases = rng.uniform(0, 2 * np.pi, frequencies.size)
    tension = 1.0e6 + amplitude * np.cos(2 * np.pi * np.outer(t, frequencies) + phases).sum(axis=1)
    area = 1e-6  # s in MPa equal to ΔT in N, so a is per N^m
    result = jc.fatigue_damage(tension, t, jc.TNCurve("chain-like", m, a, "stress"), area=area)
    upcrossing = np.sqrt(np.mean(frequencies**2))
    expected = upcrossing * t[-1] * (2 * np.sqrt(2) * sigma) ** m * math.gamma(1 + m / 2) / a
    assert result.damage == pytest.approx(expected, rel=0.05)


def test_the_damage_equivalent_load_of_a_sine_is_its_range():
    """n whole cycles of a cosine from crest to crest: n cycles of range 2A, so the
    damage-equivalent load at n cycles is 2A for any exponent, and Miner's damage is
    n / N(2A)."""
    t = np.linspace(0.0, 20 * 8.0, 20 * 400 + 1)
    tension = 3.0e5 + 4.0e4 * np.cos(2 * np.pi * t / 8.0)
    ranges, _, counts = jc.rainflow_cycles(tension)
    assert counts.sum() == 20 and ranges == pytest.approx(np.full(ranges.size, 8.0e4), rel=1e-12)
    for exponent in (3.0, 5.2):
        assert jc.damage_equivalent_load(tension, exponent, 20) == pytest.approx(8.0e4, rel=1e-12)
    curve = jc.TN_CURVES["api_polyester"]
    result = jc.fatigue_damage(tension, t, curve, breaking_load=2.0e6)
    assert result.damage == pytest.approx(20 / (25000.0 * (8.0e4 / 2.0e6) ** -5.2), rel=1e-12)
    # The same from the damage's own cycles, uncounted again; and 2A × 2^(1/m) at half the cycles.
    assert result.equivalent_load(5.2, 20) == pytest.approx(8.0e4, rel=1e-12)
    assert result.equivalent_load(3.0, 10) == pytest.approx(8.0e4 * 2 ** (1 / 3), rel=1e-12)
    with pytest.raises(ValueError, match="exponent must be a positive number, got -1.0"):
        result.equivalent_load(-1.0, 20)


def test_the_standards_curves_in_both_forms():
    """DNV-OS-E301's studless chain, N = 6e10 s⁻³ with s the range over both bars' area
    in MPa (100 mm chain, a 1 MN range); API RP 2SK's six-strand rope, N = 10^(3.20 −
    2.79 L_m) R^(−4.09), whose K falls with the mean load."""
    chain = jc.TN_CURVES["dnv_studless_chain"]
    area = jc.chain_area(0.1)
    assert area == pytest.approx(2 * math.pi * 0.01 / 4)
    s = 1.0e6 / area / 1e6  # 1 MN over the area, in MPa
    assert chain.cycles(1.0e6, area=area) == pytest.approx(6.0e10 * s**-3.0, rel=1e-12)
    rope = jc.TN_CURVES["api_multistrand_rope"]
    n = rope.cycles(2.0e5, breaking_load=2.0e6, mean_tension=6.0e5)
    assert n == pytest.approx(10 ** (3.20 - 2.79 * 0.3) * 0.1**-4.09, rel=1e-12)
    assert chain.cycles(0.0, area=area) == np.inf


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: jc.fatigue_damage([1.0, 2.0], [0.0, 1.0], "dnv_studless_chain"), "needs area, a positive number"),
        (lambda: jc.fatigue_damage([1.0, 2.0], [0.0, 1.0], "api_polyester", breaking_load=-1), "needs breaking_load"),
        (lambda: jc.fatigue_damage([1.0, 2.0], [0.0, 1.0], "chain"), "unknown T–N curve 'chain'; jaxcable has"),
        (lambda: jc.fatigue_damage([1.0, 2.0, 3.0], [0.0, 1.0], "api_polyester"), r"got \(3,\) and \(2,\)"),
        (lambda: jc.fatigue_damage([1.0, 2.0], [1.0, 1.0], "api_polyester"), "span a positive duration"),
        (lambda: jc.rainflow_cycles([1.0, np.nan]), "non-finite"),
        (lambda: jc.TNCurve("x", -3.0, 1.0, "stress"), r"TNCurve.exponent must be a positive number, got -3.0"),
        (lambda: jc.TNCurve("x", 3.0, 1.0, "range"), "TNCurve.form must be 'stress' or 'ratio'"),
        (lambda: jc.damage_equivalent_load([1.0, 2.0], 3.0, 0.0), "equivalent_cycles must be a positive number"),
    ],
)
def test_bad_fatigue_input_is_refused_naming_it(call, message):
    with pytest.raises(ValueError, match=message):
        call()
