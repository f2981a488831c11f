"""Irregular seas as sums of Airy components, against closed forms: one component is an
Airy wave, the surface's variance is Σ a²/2 (Parseval), the field is divergence-free
and meets the linearised kinematic surface condition, and a record's components pass
through its samples.

Sea states realised from a spectrum against independent references: JONSWAP's moments
by scipy's quadrature of DNV-RP-C205's formula, Pierson–Moskowitz's periods in closed
form, DNV's fits for JONSWAP, the cos-2s spreading's mean cosine s/(s + 1). Extremes:
the Gumbel fit against scipy's distribution and a Monte Carlo of its standard error,
and the most probable maximum of the Gaussian surface against Rice's asymptotic mode.
"""

import tomllib

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy import integrate, special, stats

import jaxcable as jc
from jaxcable._sea.extremes import EULER_GAMMA, GUMBEL_KURTOSIS, STANDARD_ERROR_FACTOR
from jaxcable._sea.irregular import WaveComponents, repeat_period

DEPTH = 40.0
POINTS = jnp.array([[0.0, 0.0, -1.0], [13.0, -4.0, -20.0], [-7.0, 30.0, -39.0], [2.0, 1.0, 0.6]])


@pytest.fixture(scope="module")
def sea():
    rng = np.random.default_rng(3)
    periods = np.linspace(5.0, 14.0, 12)
    return WaveComponents(
        rng.uniform(0.05, 0.4, 12), periods, DEPTH, headings=rng.uniform(-40, 40, 12), phases=rng.uniform(0, 6.28, 12)
    )


@pytest.mark.parametrize("wheeler", [False, True])
def test_one_component_is_an_airy_wave(wheeler):
    airy = jc.Airy(1.6, 9.0, DEPTH, heading=25.0, phase=0.7, wheeler=wheeler)
    one = WaveComponents([0.8], [9.0], DEPTH, headings=25.0, phases=0.7, wheeler=wheeler)
    for t in (0.0, 3.3, 11.1):
        np.testing.assert_allclose(one.velocity(POINTS, t), airy.velocity(POINTS, t), rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(one.acceleration(POINTS, t), airy.acceleration(POINTS, t), rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(
            one.elevation(POINTS[:, 0], POINTS[:, 1], t), airy.elevation(POINTS[:, 0], POINTS[:, 1], t), atol=1e-14
        )
    assert float(one.height) == pytest.approx(1.6 * np.sqrt(2), rel=1e-12)  # H_s = 4 √(a²/2) = √2 H


def test_surface_variance_is_half_the_sum_of_squared_amplitudes(sea):
    # Over a long record the time average of η² tends to m₀ = Σ a²/2 (the cross terms
    # average out as 1/(Δω t)).
    times = jnp.linspace(0.0, 20000.0, 400001)
    eta = jax.vmap(lambda t: sea.elevation(3.0, -2.0, t))(times)
    assert float(jnp.mean(eta**2)) == pytest.approx(float(sea.variance), rel=5e-3)
    assert float(sea.variance) == pytest.approx(0.5 * float(jnp.sum(sea.amplitudes**2)), rel=1e-14)


def test_the_field_is_divergence_free_and_meets_the_surface_condition(sea):
    inside = jnp.array([[1.0, 2.0, -5.0], [40.0, -8.0, -30.0]])
    for t in (0.0, 4.2):
        jacobian = jax.vmap(jax.jacfwd(sea.velocity), in_axes=(0, None))(inside, t)
        divergence = jnp.trace(jacobian, axis1=1, axis2=2)
        assert float(jnp.max(jnp.abs(divergence))) < 1e-12
    # Linearised kinematic condition: w(z = 0) = ∂η/∂t.
    for t in (1.0, 7.5):
        w = sea.velocity(jnp.array([5.0, 3.0, 0.0]), t)[2]
        deta = jax.grad(lambda s: sea.elevation(5.0, 3.0, s))(t)
        assert float(w) == pytest.approx(float(deta), rel=1e-12)
    # No flow through the bed.
    assert abs(float(sea.velocity(jnp.array([5.0, 3.0, -DEPTH]), 2.0)[2])) < 1e-14


def test_components_of_a_record_pass_through_its_samples():
    rng = np.random.default_rng(0)
    times = 10.0 + 0.25 * np.arange(64)
    record = rng.normal(size=64)
    record -= record.mean()
    sea = WaveComponents.from_elevation(times, record, DEPTH)
    eta = jax.vmap(lambda t: sea.elevation(0.0, 0.0, t))(jnp.asarray(times))
    np.testing.assert_allclose(eta, record, atol=1e-12)
    # A sine record gives one component of its amplitude and period.
    times = 0.15 * np.arange(100)
    sine = WaveComponents.from_elevation(times, np.sin(2 * np.pi * times / 3.75), DEPTH)
    peak = int(np.argmax(sine.amplitudes))
    assert float(sine.amplitudes[peak]) == pytest.approx(1.0, rel=1e-12)
    assert float(sine.period) == pytest.approx(3.75, rel=1e-12)
    assert float(jnp.sum(sine.amplitudes) - sine.amplitudes[peak]) < 1e-12


def test_gradients_match_finite_differences(sea):
    def speed(amplitudes):
        wave = WaveComponents(amplitudes, sea.periods, DEPTH, headings=sea.headings, phases=sea.phases)
        return jnp.sum(wave.velocity(POINTS[:3], 2.0) ** 2)

    grad = jax.grad(speed)(sea.amplitudes)
    h = 1e-6
    step = jnp.zeros_like(sea.amplitudes).at[4].set(h)
    fd = (speed(sea.amplitudes + step) - speed(sea.amplitudes - step)) / (2 * h)
    assert float(grad[4]) == pytest.approx(float(fd), rel=1e-7)


def test_it_loads_an_environment_and_vmaps(sea):
    env = jc.Environment(depth=DEPTH, waves=sea)
    u = env.water_velocity(POINTS[:3], 1.0)
    np.testing.assert_allclose(u, sea.velocity(POINTS[:3], 1.0), rtol=1e-14)
    scaled = jax.vmap(
        lambda s: jnp.sum(WaveComponents(s * sea.amplitudes, sea.periods, DEPTH).velocity(POINTS[0], 0.0))
    )(jnp.array([1.0, 2.0]))
    assert float(scaled[1]) == pytest.approx(2 * float(scaled[0]), rel=1e-12)


def test_bad_components_are_named():
    with pytest.raises(ValueError, match="WaveComponents.amplitudes"):
        WaveComponents([-0.1], [5.0], DEPTH)
    with pytest.raises(ValueError, match="WaveComponents.periods"):
        WaveComponents([0.1, 0.2], [5.0, 0.0], DEPTH)
    with pytest.raises(ValueError, match="WaveComponents.headings must be a scalar or have shape"):
        WaveComponents([0.1, 0.2], [5.0, 6.0], DEPTH, headings=[0.0, 1.0, 2.0])
    with pytest.raises(ValueError, match="breaking"):
        WaveComponents([30.0], [5.0], DEPTH)


# --------------------------------------------------------------------------------------
# Sea states: the JONSWAP spectrum and its realisations


def jonswap_reference(hs, tp, gamma):
    """JONSWAP as DNV-RP-C205 §3.5.5 writes it, normalised here by scipy's quad so that
    m₀ = H_s²/16 (independent of jaxcable's quadrature): its density S(ω) and the
    normalisation α."""
    wp = 2 * np.pi / tp

    def shape(w):
        sigma = np.where(w <= wp, 0.07, 0.09)
        r = np.exp(-((w - wp) ** 2) / (2 * sigma**2 * wp**2))
        return 5 / 16 * hs**2 * wp**4 * w**-5 * np.exp(-1.25 * (wp / w) ** 4) * gamma**r

    total = integrate.quad(shape, 0, wp, epsrel=1e-13, limit=400)[0]
    total += integrate.quad(shape, wp, np.inf, epsrel=1e-13, limit=400)[0]
    alpha = hs**2 / 16 / total
    return (lambda w: alpha * shape(np.asarray(w))), alpha


def test_spectrum_moments_against_scipy():
    for gamma in (1.0, 3.3, 7.0):
        spectrum = jc.Jonswap(2.5, 8.0, gamma)
        density, _ = jonswap_reference(2.5, 8.0, gamma)
        wp = 2 * np.pi / 8.0
        for n in range(4):
            moment = integrate.quad(lambda w, n=n, s=density: w**n * s(w), 0, wp, epsrel=1e-12, limit=400)[0]
            moment += integrate.quad(lambda w, n=n, s=density: w**n * s(w), wp, np.inf, limit=400)[0]
            assert float(spectrum.moment(n)) == pytest.approx(moment, rel=1e-9)
        omega = np.linspace(0.3, 3.0, 7)
        np.testing.assert_allclose(spectrum.density(omega), density(omega), rtol=1e-9)
        # The peak is at ω_p = 2π/T_p.
        fine = np.linspace(0.6, 1.0, 40001)
        assert fine[np.argmax(np.asarray(spectrum.density(fine)))] == pytest.approx(wp, abs=2e-5)


def test_spectral_periods_against_closed_forms_and_dnv():
    # Pierson–Moskowitz: m_n = m₀ ω_p^n (5/4)^(n/4) Γ(1 − n/4).
    pm = jc.Jonswap.pierson_moskowitz(2.0, 10.0)
    wp = 2 * np.pi / 10.0
    t01 = 2 * np.pi / (wp * 1.25**0.25 * special.gamma(0.75))
    t02 = 2 * np.pi / (wp * np.sqrt(1.25**0.5 * special.gamma(0.5)))
    assert float(pm.mean_period) == pytest.approx(t01, rel=1e-12)  # 0.772 T_p
    assert float(pm.zero_crossing_period) == pytest.approx(t02, rel=1e-12)  # 0.710 T_p
    assert float(pm.moment(0)) == pytest.approx(2.0**2 / 16, rel=1e-14)
    # JONSWAP: DNV-RP-C205's fits, T_z/T_p = 0.6673 + 0.05037γ − 0.006230γ² + 0.0003341γ³
    # and the normalisation 1 − 0.287 ln γ, both within their stated accuracy.
    for gamma in (2.0, 3.3, 5.0):
        spectrum = jc.Jonswap(2.0, 10.0, gamma)
        fit = 0.6673 + 0.05037 * gamma - 0.006230 * gamma**2 + 0.0003341 * gamma**3
        assert float(spectrum.zero_crossing_period) / 10.0 == pytest.approx(fit, rel=2e-3)
        _, alpha = jonswap_reference(2.0, 10.0, gamma)
        assert alpha == pytest.approx(1 - 0.287 * np.log(gamma), rel=5e-3)


@pytest.fixture(scope="module")
def realised():
    """A JONSWAP sea on multiples of Δω = 2π/256 s: it repeats exactly after 256 s."""
    step = 2 * np.pi / 256.0
    spectrum = jc.Jonswap(2.0, 7.0, 3.3)
    sea = WaveComponents.from_spectrum(spectrum, DEPTH, seed=5, components=160, frequencies=(19.5 * step, 179.5 * step))
    return spectrum, sea


def test_a_realisation_holds_the_spectrum(realised):
    spectrum, sea = realised
    omega = 2 * np.pi / np.asarray(sea.periods)
    a = np.asarray(sea.amplitudes)
    moments = [np.sum(omega**n * a**2 / 2) for n in range(3)]
    assert moments[0] == pytest.approx(2.0**2 / 16, rel=0.01)  # the check
    # Within the band the components are the midpoint rule for every moment, to
    # O(Δω²); the band's edges cut m₂ by 4 % (S falls as ω⁻⁵, ω² S as ω⁻³).
    step = omega[1] - omega[0]
    band = (omega[0] - step / 2, omega[-1] + step / 2)
    density, _ = jonswap_reference(2.0, 7.0, 3.3)
    for n in range(3):
        within = integrate.quad(lambda w, n=n: w**n * density(w), *band, limit=400)[0]
        assert moments[n] == pytest.approx(within, rel=2e-3)
    assert moments[2] == pytest.approx(float(spectrum.moment(2)), rel=0.05)
    assert abs(omega[np.argmax(a)] - 2 * np.pi / 7.0) <= step / 2  # the peak, T_p
    assert repeat_period(sea) == pytest.approx(256.0, rel=1e-12)
    # Over one repeat period the record's mean square is Σ a²/2 (Parseval) and the
    # record repeats; its zero up-crossings come at the rate 1/T_z of the components.
    times = np.arange(0.0, 256.0, 0.125)
    eta = np.asarray(sea.elevation(3.0, -1.0, times))
    assert np.mean(eta**2) == pytest.approx(moments[0], rel=1e-10)
    np.testing.assert_allclose(np.asarray(sea.elevation(3.0, -1.0, times[:50] + 256.0)), eta[:50], atol=1e-9)
    crossings = np.sum((eta[:-1] < 0) & (eta[1:] >= 0))
    assert crossings == pytest.approx(256.0 * np.sqrt(moments[2] / moments[0]) / (2 * np.pi), abs=3)


def test_a_band_that_misses_the_spectrum_is_refused():
    spectrum = jc.Jonswap(2.0, 8.0, 3.3)
    with pytest.raises(ValueError, match=r"hold 95\.[0-9]+ % of the spectrum's m₀.*widen frequencies"):
        WaveComponents.from_spectrum(spectrum, DEPTH, seed=0, components=160, frequencies=(0.5, 1.6))
    with pytest.raises(ValueError, match="components must be a positive integer"):
        WaveComponents.from_spectrum(spectrum, DEPTH, seed=0, components=0, frequencies=(0.4, 3.5))
    with pytest.raises(ValueError, match=r"frequencies\[1\] − frequencies\[0\]"):
        WaveComponents.from_spectrum(spectrum, DEPTH, seed=0, components=10, frequencies=(2.0, 1.0))
    with pytest.raises(ValueError, match="seed must be an integer"):
        WaveComponents.from_spectrum(spectrum, DEPTH, seed=1.5, components=10, frequencies=(0.4, 3.5))
    with pytest.raises(ValueError, match="Jonswap.peak_enhancement must be at least 1"):
        jc.Jonswap(2.0, 8.0, 0.5)
    with pytest.raises(ValueError, match="spreading must be positive"):
        WaveComponents.from_spectrum(spectrum, DEPTH, seed=0, components=128, frequencies=(0.4, 3.5), spreading=0.0)


def test_seeds_vmap_in_one_program():
    spectrum = jc.Jonswap(2.0, 8.0, 3.3)

    def sea(seed):
        return WaveComponents.from_spectrum(
            spectrum, DEPTH, seed=seed, components=128, frequencies=(0.4, 3.5), spreading=8.0
        )

    batch = jax.jit(jax.vmap(lambda seed: (sea(seed).phases, sea(seed).headings)))(jnp.arange(4.0))
    for seed in range(4):
        one = sea(seed)  # an int here, a traced float above: the same sea
        np.testing.assert_array_equal(batch[0][seed], one.phases)
        np.testing.assert_allclose(batch[1][seed], one.headings, rtol=1e-13)
    assert float(jnp.std(batch[0][0] - batch[0][1])) > 1.0  # different seeds, different phases
    # Phases uniform on [0, 2π): their mean resultant length is of order 1/√N.
    assert float(jnp.abs(jnp.mean(jnp.exp(1j * batch[0])))) < 0.2
    # The amplitudes depend on the sea state only.
    np.testing.assert_array_equal(sea(0).amplitudes, sea(3).amplitudes)


@pytest.mark.parametrize("spreading", [2.0, 10.0, 75.0])
def test_headings_follow_the_cos2s_spreading(spreading):
    sea = WaveComponents.from_spectrum(
        jc.Jonswap(2.0, 8.0), DEPTH, seed=1, components=128, frequencies=(0.4, 3.5), heading=30.0, spreading=spreading
    )
    theta = np.radians(np.asarray(sea.headings) - 30.0)
    # D ∝ cos^{2s}(θ/2) has E[cos θ] = s/(s + 1) and is symmetric (Longuet-Higgins et al.);
    # the stratified draw puts 128 headings within 2e-3 of it.
    assert np.mean(np.cos(theta)) == pytest.approx(spreading / (spreading + 1), rel=5e-3)
    assert abs(np.mean(np.sin(theta))) < 0.02 * np.sqrt(2 / (spreading + 1))
    long_crested = WaveComponents.from_spectrum(
        jc.Jonswap(2.0, 8.0), DEPTH, seed=1, components=160, frequencies=(0.4, 3.5), heading=30.0
    )
    np.testing.assert_array_equal(long_crested.headings, 30.0)


def test_sea_state_gradients_match_finite_differences():
    point = jnp.array([[4.0, 2.0, -6.0], [-10.0, 3.0, -20.0]])

    def energy(x):
        hs, tp, gamma, spreading = x
        sea = WaveComponents.from_spectrum(
            jc.Jonswap(hs, tp, gamma), DEPTH, seed=2, components=60, frequencies=(0.05, 4.0), spreading=spreading
        )
        return jnp.sum(sea.velocity(point, 7.0) ** 2) + sea.elevation(1.0, 2.0, 3.0)

    x = jnp.array([2.0, 8.0, 3.3, 6.0])
    # The headings interpolate the spreading's inverse distribution linearly between
    # 4096 cells: a step small enough not to cross a cell's edge. One program gives the
    # value and gradient at x and the values at x ± h.
    steps = 1e-6 * jnp.diag(x)
    values, grads = jax.jit(jax.vmap(lambda x: (energy(x), jax.jacfwd(energy)(x))))(
        jnp.concatenate([x[None], x + steps, x - steps])
    )
    assert bool(jnp.all(jnp.isfinite(grads[0])))  # S underflows at 0.05 rad/s: still finite
    np.testing.assert_allclose(grads[0], (values[1:5] - values[5:]) / (2e-6 * x), rtol=1e-6)


# --------------------------------------------------------------------------------------
# Extremes over realisations


def maxima_records(maxima):
    """Records whose largest sample is `maxima` (shape (..., n)): three samples each."""
    maxima = np.asarray(maxima)
    return np.stack([maxima - 1.0, maxima, maxima - 2.0], axis=-1)


def test_gumbel_fit_against_scipy_and_its_standard_error():
    """The method-of-moments fit over 4000 batches of n = 20 maxima drawn by scipy: its
    mean against the truth, its scatter against the standard error's formula, and each
    fit's distribution against scipy's with the same parameters."""
    rng = np.random.default_rng(11)
    batches = stats.gumbel_r.rvs(loc=100.0, scale=7.0, size=(4000, 20), random_state=rng)
    fits = jc.extreme_statistics(maxima_records(batches), np.arange(3.0))
    error = STANDARD_ERROR_FACTOR * 7 * np.pi / np.sqrt(6 * 20)  # of one fit's location
    assert float(jnp.std(fits.location)) == pytest.approx(error, rel=0.05)
    assert float(jnp.mean(fits.standard_error)) == pytest.approx(error, rel=0.05)
    # s² (n − 1) is unbiased, s itself low by about (κ − 1)/8n = 2.8 % at n = 20, and μ
    # high by γ_E times that of β (a fifteenth of one fit's standard error).
    bias = (GUMBEL_KURTOSIS - 1) / (8 * 20)
    assert float(jnp.mean(fits.scale)) == pytest.approx(7.0 * (1 - bias), rel=0.01)
    assert float(jnp.mean(fits.location)) == pytest.approx(
        100.0 + EULER_GAMMA * 7.0 * bias, abs=3 * error / np.sqrt(4000)
    )
    frozen = stats.gumbel_r(loc=float(fits.location[0]), scale=float(fits.scale[0]))
    np.testing.assert_allclose(fits.quantile(np.array([0.1, 0.5, 0.9]))[:, 0], frozen.ppf([0.1, 0.5, 0.9]), rtol=1e-12)
    np.testing.assert_allclose(fits.exceedance(np.array([95.0, 120.0]))[:, 0], frozen.sf([95.0, 120.0]), rtol=1e-12)
    assert float(fits.quantile(np.exp(-1.0))[0]) == pytest.approx(float(fits.most_probable_maximum[0]), rel=1e-14)
    # Over n records the maximum is the largest of the records' maxima: μ moves by β ln n.
    longer = jc.extreme_statistics(maxima_records(batches), np.arange(3.0), duration=20.0)
    np.testing.assert_allclose(longer.location - fits.location, fits.scale * np.log(10.0), rtol=1e-12)


@pytest.fixture(scope="module")
def sea_records():
    """The surface elevation at one point over 300 s, for 200 seeds of one sea."""
    spectrum = jc.Jonswap(2.0, 8.0, 3.3)
    times = np.arange(0.0, 300.0, 0.2)

    def record(seed, hs=2.0):
        sea = WaveComponents.from_spectrum(
            jc.Jonswap(hs, 8.0, 3.3), DEPTH, seed=seed, components=160, frequencies=(0.45, 3.6)
        )
        return sea.elevation(0.0, 0.0, times)

    records = jax.jit(lambda seeds: jax.lax.map(record, seeds, batch_size=25))(jnp.arange(200))
    sea = WaveComponents.from_spectrum(spectrum, DEPTH, seed=0, components=160, frequencies=(0.45, 3.6))
    return times, records, sea, record


def test_most_probable_maximum_of_a_gaussian_sea_is_rices(sea_records):
    """The surface is a Gaussian process: its maximum over D has the mode
    σ √(2 ln(ν₀ D)), ν₀ = √(m₂/m₀)/2π (Rice 1944; Cartwright & Longuet-Higgins 1956)."""
    times, records, sea, _ = sea_records
    fit = jc.extreme_statistics(records, times)
    omega = 2 * np.pi / np.asarray(sea.periods)
    m0, m2 = (float(np.sum(omega**n * np.asarray(sea.amplitudes) ** 2 / 2)) for n in (0, 2))
    rice = np.sqrt(m0) * np.sqrt(2 * np.log(np.sqrt(m2 / m0) / (2 * np.pi) * (times[-1] - times[0])))
    # The asymptotic mode against the fit's, within three standard errors.
    assert float(fit.most_probable_maximum) == pytest.approx(rice, abs=3 * float(fit.standard_error))
    # Each record's short-term (Rayleigh) estimate measures σ and ν₀ from the record.
    assert float(fit.rayleigh_mpm) == pytest.approx(rice, rel=0.01)


def test_the_most_probable_maximum_differentiates(sea_records):
    """η is proportional to H_s seed by seed, so every statistic is: d MPM/d H_s = MPM/H_s."""
    times, _, _, record = sea_records
    seeds = jnp.arange(8)

    def mpm(hs):
        records = jax.vmap(lambda seed: record(seed, hs))(seeds)
        return jc.extreme_statistics(records, times, duration=3600.0).most_probable_maximum

    value, slope = jax.jit(jax.value_and_grad(mpm))(2.0)
    assert float(slope) == pytest.approx(float(value) / 2.0, rel=1e-10)


def test_the_bundled_irregular_scene_holds_its_sea():
    """irregular_buoy.toml's sea, against what its header says from the file's numbers."""
    path = jc.examples.scene_path("irregular_buoy")
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    (wave,) = data["waves"]
    (spec,) = jc.read_scene(path).water.waves
    sea = spec.wave(data["water"]["depth"], data["water"]["gravity"])
    hs, (low, high), n = wave["significant_height"], wave["frequencies"], wave["components"]
    assert float(sea.variance) / (hs**2 / 16) == pytest.approx(0.995, abs=0.0005)
    assert repeat_period(sea) == pytest.approx(2 * np.pi * n / (high - low), rel=1e-12)
    assert data["simulation"]["duration"] < repeat_period(sea) == pytest.approx(374.1, abs=0.05)
