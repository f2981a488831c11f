"""First-order cnoidal waves against independent values.

References:

- The cnoidal-loads paper's notes, §7.4: the (H, d, T) → (m, λ, c, U, crest/trough, u_max/u_min,
  max ∂u/∂t) table, the point values of the H = 2 m, d = 10 m, T = 12 s wave, and the
  Fig. 1 analogue (U → m, crest/H, acceleration ratio), each to one unit of its last
  printed digit.
- A reference solve written here with SciPy: m from the Ursell number U = 16 m K²/3
  by bracketing, λ = d √(U d/H), c from the KdV dispersion relation, T = λ/c; the wave
  built from that T must give back that m (1 − m down to 4e-10).
- SciPy's `ellipj`: the Fourier coefficients of cn² by FFT.
- Limits: m → 0 (small U) gives the sinusoid of linear theory (jaxcable's `Airy` and
  the linear shallow-water formulas; the notes' §7.3 quote the largest difference in
  η: 2.4e-3 H at U = 0.5, 9.5e-3 H at U = 2); m → 1 gives the solitary wave
  H sech²(√(3H/(4d³))(x − ct)) with c → c₀(1 + H/(2d)).
- Exact identities: continuity ∂u/∂x + ∂w/∂z = 0 and w(−d) = 0 by autodiff of the
  velocity in space; the closed-form local acceleration against central differences
  and forward-mode autodiff of the velocity in time; the harmonic series against the
  closed form.
- `jax.grad` through the m-solve against central differences.

Every wave is sampled on one of two grids, `line` (2048 points over a wavelength) and
`column` (192 points in the water), so that the eager evaluations compile for few
shapes.
"""

import contextlib
import math
import warnings

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy import optimize, special

from jaxcable import AbstractWave, Airy, Cnoidal, cnoidal_coefficients

G = 9.81
SAMPLES = 2048


def ursell_warning(ursell):
    """The warning a wave of Ursell number `ursell` gives (U < 5), or none."""
    return pytest.warns(UserWarning, match="Ursell") if ursell < 5 else contextlib.nullcontext()


def reference(ursell, height, depth):
    """(T, m, 1 − m) of the first-order cnoidal wave of Ursell number `ursell`, by
    SciPy: s = −ln(1 − m) bracketed on 16 m K²/3 = U, then λ and c in closed form."""

    def mismatch(s):
        return np.log(16 * -np.expm1(-s) * special.ellipkm1(np.exp(-s)) ** 2 / 3 / ursell)

    s = optimize.brentq(mismatch, 1e-12, 700.0, xtol=1e-15, rtol=1e-15)
    m, m1 = -np.expm1(-s), np.exp(-s)
    k, e = special.ellipkm1(m1), special.ellipe(m)
    length = depth * np.sqrt(ursell * depth / height)
    celerity = np.sqrt(G * depth) * (1 + height / (m * depth) * (1 - m / 2 - 1.5 * e / k))
    return length / celerity, m, m1


def close(actual, printed):
    """`actual` agrees with the string `printed` to within one unit of its last digit
    (the notes mostly round, but truncate some values: u(λ/4) = −0.216454 is printed
    −0.2164)."""
    decimals = len(printed.split(".")[1]) if "." in printed else 0
    assert abs(float(actual) - float(printed)) <= 10.0**-decimals, (float(actual), printed)


def line(wave, z):
    """`SAMPLES` points at height `z` over one wavelength along the heading, from the
    crest at x_β = 0 (at t = 0): θ = 2π j / `SAMPLES`, so the trough is at j = 1024."""
    x = jnp.arange(SAMPLES) / SAMPLES * wave.wavelength
    beta = jnp.deg2rad(wave.heading)
    return jnp.stack([x * jnp.cos(beta), x * jnp.sin(beta), jnp.broadcast_to(z, x.shape)], -1)


def column(wave):
    """192 points in the water over one wavelength at heading 0: x from −λ/2 to λ/2 at
    90 % and 50 % of the depth and just below the trough."""
    x = np.linspace(-0.5, 0.5, 64, endpoint=False) * float(wave.wavelength)
    depth = float(wave.depth)
    z = np.repeat([-0.9 * depth, -0.5 * depth, 1.1 * float(wave.trough)], 64)
    return jnp.stack([np.tile(x, 3), np.zeros(192), z], axis=-1)


@pytest.fixture(scope="module")
def wave():
    """The notes' point-value case: H = 2 m, d = 10 m, T = 12 s (m = 0.856, U = 26.5)."""
    return Cnoidal(2.0, 12.0, 10.0)


# ---------------------------------------------------------------------------------------
# The notes' tables.
# ---------------------------------------------------------------------------------------

TABLE = [
    # H, d, T, m, λ, c, U, crest, trough, u_max, u_min, max ∂u/∂t: Yakovlev et al.'s cnoidal-loads paper §7.4.
    ("2", "10", "12", "0.855964", "115.03", "9.586", "26.5", "1.231", "-0.769", "1.219", "-0.761", "0.635"),
    ("1", "10", "8", "0.296966", "68.14", "8.517", "4.6", "0.522", "-0.478", "0.517", "-0.473", "0.393"),
    ("3", "10", "15", "0.988715", "152.44", "10.162", "69.7", "2.185", "-0.815", "2.164", "-0.807", "1.112"),
    ("0.5", "5", "10", "0.747970", "67.99", "6.799", "18.5", "0.292", "-0.208", "0.409", "-0.291", "0.248"),
    ("5", "35", "20", "0.655160", "348.6", "17.43", "14.2", "2.83", "-2.17", "1.50", "-1.15", "0.449"),
    ("8", "35", "20", "0.820648", "353.3", "17.67", "23.3", "4.83", "-3.17", "2.56", "-1.68", "0.787"),
    ("10", "30", "20", "0.950274", "340.5", "17.03", "42.9", "6.69", "-3.31", "3.83", "-1.89", "1.298"),
    ("8", "40", "25", "0.879275", "482.3", "19.29", "29.1", "5.00", "-3.00", "2.48", "-1.49", "0.626"),
]


@pytest.mark.parametrize("row", TABLE, ids=[f"H{r[0]}-d{r[1]}-T{r[2]}" for r in TABLE])
def test_table_of_the_notes(row):
    height, depth, period, m, length, celerity, ursell, crest, trough, u_max, u_min, du_max = row
    with ursell_warning(float(ursell)):
        w = Cnoidal(float(height), float(period), float(depth))
    for actual, printed in [(w.m, m), (w.wavelength, length), (w.celerity, celerity), (w.ursell, ursell)]:
        close(actual, printed)
    # Crest and trough at θ = 0 and π; the largest ∂u/∂t over a wavelength at t = 0 is
    # the largest over a period at a point.
    points = line(w, -1.0)
    eta = w.elevation(points[:, 0], points[:, 1], 0.0)
    u = w.velocity(points, 0.0)[:, 0]
    for actual, printed in [(eta[0], crest), (eta[1024], trough), (u[0], u_max), (u[1024], u_min)]:
        close(actual, printed)
    close(jnp.max(w.acceleration(points, 0.0)[:, 0]), du_max)


def test_point_values_of_the_notes(wave):
    # H = 2, d = 10, T = 12, z = −5, t = 0, at x = 0, λ/4, λ/2.
    close(wave.wavelength, "115.034")
    points = line(wave, -5.0)
    eta = wave.elevation(points[:, 0], points[:, 1], 0.0)
    velocity, acceleration = wave.velocity(points, 0.0), wave.acceleration(points, 0.0)
    expected = [
        (eta, ["1.2312", "-0.2185", "-0.7688"]),
        (velocity[:, 0], ["1.2195", "-0.2164", "-0.7614"]),
        (velocity[:, 2], ["0.0000", "0.2281", "0.0000"]),
        (acceleration[:, 0], ["0.0000", "0.4374", "0.0000"]),
        (acceleration[:, 2], ["-0.3328", "0.1136", "0.0479"]),
    ]
    for actual, printed in expected:
        for value, text in zip(actual[jnp.array([0, 512, 1024])], printed):
            close(value, text)


FIGURE_1 = [
    # U, m (or 1 − m), crest/H, max ∂u/∂t over linear theory's: Yakovlev et al.'s cnoidal-loads paper §7.4.
    (5, "0.3157", "0.524", "1.011"),
    (26, "0.8513", "0.614", "1.218"),
    (50, "0.9673", "0.688", "1.538"),
    (100, "0.99725", "0.770", "2.126"),
    (200, "0.999923", "0.837", "3.001"),
    (400, "4.8e-7", "0.885", "4.244"),
    (800, "4e-10", "0.918", "6.002"),
]


@pytest.mark.filterwarnings("ignore:Cnoidal wave of Ursell number")  # U = 5 is the threshold
@pytest.mark.parametrize("ursell, m, crest, ratio", FIGURE_1)
def test_ursell_series_of_the_notes(ursell, m, crest, ratio):
    # At H/d = 0.01, where c ≈ c₀: built from SciPy's period for this U, the wave has
    # SciPy's m (relative 1e-9 in 1 − m), and the notes' crest and the ratio of its
    # largest ∂u/∂t to linear shallow-water theory's (H/2)(c₀/d) ω.
    depth, height = 10.0, 0.1
    period, _, m1 = reference(ursell, height, depth)
    w = Cnoidal(height, period, depth)
    np.testing.assert_allclose(w.m1, m1, rtol=1e-9)
    close(w.m if m.startswith("0.") else w.m1, m)
    close(w.crest / height, crest)
    largest = jnp.max(w.acceleration(line(w, -5.0), 0.0)[:, 0])
    close(largest / (0.5 * height * math.sqrt(G / depth) * 2 * math.pi / period), ratio)


# ---------------------------------------------------------------------------------------
# The harmonic series.
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("m", [0.5, 0.9, 0.99, 1 - 1e-6])
def test_coefficients_match_an_fft_of_cn_squared(m):
    # aₙ = (2/N) Σⱼ cn²(K θⱼ/π) cos nθⱼ over N equally spaced θⱼ, exact up to aliasing
    # of q^N.
    count = 40
    theta = 2 * np.pi * np.arange(SAMPLES) / SAMPLES
    cn = special.ellipj(special.ellipk(m) * theta / np.pi, m)[1]
    spectrum = 2 * np.real(np.fft.rfft(cn**2))[1 : count + 1] / SAMPLES
    np.testing.assert_allclose(cnoidal_coefficients(m, count, 1 - m), spectrum, rtol=0, atol=2e-15)


def test_coefficients_tend_to_a_cosine():
    # m → 0: cn²(θ/2) → (1 + cos θ)/2, so a₁ → 1/2 and the rest → 0 (a₂ ≈ m/16).
    np.testing.assert_allclose(cnoidal_coefficients(1e-9, 3), [0.5, 0.0, 0.0], rtol=0, atol=1e-9)


@pytest.mark.parametrize(
    "height, period", [(1.0, 8.0), (2.0, 12.0), (3.0, 15.0), (1.0, 120.0)], ids=["m0.30", "m0.86", "m0.989", "m1-3e-14"]
)
def test_series_equals_closed_form(height, period):
    # 256 harmonics for every wave (one compilation): n² qⁿ falls below 1e-19 by then
    # even at the largest q here, 0.86 (1 − m = 3e-14).
    with ursell_warning(4.6 if period == 8.0 else 100.0):
        w = Cnoidal(height, period, 10.0)
    count = 256
    assert count**2 * float(w.nome) ** count < 1e-19
    points = column(w)
    eta, velocity, acceleration = w.harmonic_series(points, 0.3, count)
    scale = float(w.height) * np.sqrt(G / 10.0) * 4 * float(w.K)
    np.testing.assert_allclose(eta, w.elevation(points[:, 0], points[:, 1], 0.3), rtol=0, atol=1e-13 * height)
    np.testing.assert_allclose(velocity, w.velocity(points, 0.3), rtol=0, atol=1e-13 * scale)
    np.testing.assert_allclose(acceleration, w.acceleration(points, 0.3), rtol=0, atol=1e-13 * scale)


def test_series_weights_take_harmonics_one_at_a_time():
    # The sum is linear in the aₙ: the single harmonics' kinematics add up to the
    # series' (below the trough, where no single harmonic's own surface clamps w), and
    # weights of 1 are no weights.
    w = Cnoidal(2.0, 12.0, 10.0)
    count = 24
    points = column(w)[:128]  # 90 % and 50 % of the depth
    whole = w.harmonic_series(points, 0.3, count)
    ones = w.harmonic_series(points, 0.3, count, jnp.ones(count))
    singles = [w.harmonic_series(points, 0.3, count, jnp.eye(count)[n]) for n in range(count)]
    scale = float(w.height) * np.sqrt(G / 10.0) * 4 * float(w.K)
    for k, part in enumerate(whole):
        atol = 1e-14 * (float(w.height) if k == 0 else scale)
        np.testing.assert_array_equal(ones[k], part)
        np.testing.assert_allclose(sum(s[k] for s in singles), part, rtol=0, atol=atol)


# ---------------------------------------------------------------------------------------
# The surface and the limits.
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("height, period", [(2.0, 12.0), (3.0, 15.0), (1.0, 120.0)])
def test_zero_mean_and_height(height, period):
    # The mean over a wavelength by the rectangle rule (spectrally accurate for a
    # periodic function); the crest (θ = 0) and trough (θ = π) are among the samples.
    w = Cnoidal(height, period, 10.0)
    points = line(w, 0.0)
    eta = w.elevation(points[:, 0], points[:, 1], 0.0)
    assert abs(float(jnp.mean(eta))) < 1e-14 * height
    np.testing.assert_allclose(jnp.max(eta) - jnp.min(eta), height, rtol=1e-14)
    np.testing.assert_allclose([eta[0], eta[1024]], [w.crest, w.trough], rtol=1e-14)


@pytest.mark.parametrize("ursell, difference", [(0.5, "2.4e-3"), (2.0, "9.5e-3")])
def test_small_ursell_number_gives_linear_theory(ursell, difference):
    # H/d = 1e-4 in 10 m of water, so that λ/d = 71 and 141 (k d = 0.09, 0.04).
    depth, height = 10.0, 1e-3
    period, _, _ = reference(ursell, height, depth)
    with pytest.warns(UserWarning, match="Ursell"):
        w = Cnoidal(height, period, depth)
    airy = Airy(height, period, depth)
    kd = 2 * np.pi * depth / float(w.wavelength)
    # Dispersion: both phase speeds are c₀ (1 − (kd)²/6), Airy's to O((kd)⁴) and the
    # cnoidal's to O(m H/d); the wavelengths agree to the sum.
    c0, m, ratio = math.sqrt(G * depth), float(w.m), height / depth
    assert abs(float(w.celerity) / c0 - (1 - kd**2 / 6)) < m * ratio / 4
    assert abs(float(w.wavelength / airy.wavelength) - 1) < kd**4 + m * ratio
    # The surface, each on its own phase θ: the notes' largest difference, in H.
    points = line(w, -0.3 * depth)
    theta = 2 * jnp.pi * jnp.arange(SAMPLES) / SAMPLES
    cnoidal = w.elevation(points[:, 0], points[:, 1], 0.0)
    linear = airy.elevation(theta / (2 * np.pi) * airy.wavelength, 0 * theta, 0.0)
    close(jnp.max(jnp.abs(cnoidal - linear)) / height * 1e3, str(float(difference) * 1e3))
    # The difference is the second harmonic, a₂/a₁ ≈ 2q (q the nome, 2.4e-3 and 9.5e-3
    # here): q H in η, 2q in u and, as w weights the n-th harmonic by n, 4q in w, relative
    # to linear shallow-water theory's u = (H/2)√(g/d) cos θ, w = ((z + d)/d)(H/2) ω sin θ.
    q = float(w.nome)
    velocity = w.velocity(points, 0.0)
    amplitude = 0.5 * height * math.sqrt(G / depth)
    np.testing.assert_allclose(velocity[:, 0], amplitude * jnp.cos(theta), rtol=0, atol=2.2 * q * amplitude)
    vertical = 0.7 * 0.5 * height * 2 * np.pi / period
    np.testing.assert_allclose(velocity[:, 2], vertical * jnp.sin(theta), rtol=0, atol=4.5 * q * vertical)


@pytest.mark.parametrize("period", [120.0, 200.0])
def test_large_ursell_number_gives_the_solitary_wave(period):
    # 1 − m = 3e-14 and 4e-24. Above the trough, η − η_t = H cn² → H sech²(κ(x − ct)),
    # κ = √(3H/(4d³)), to O((1 − m) e^{2κ|x|}); the trough and the celerity approach the
    # solitary wave's 0 and c₀(1 + H/(2d)) like 1/K: η_t K/H → −E → −1, and
    # (c/c₀ − 1 − H/(2d)) K d/H → −(3/2) E/m → −3/2.
    depth, height, t = 10.0, 1.0, 7.0
    w = Cnoidal(height, period, depth)
    assert float(w.m1) < 1e-13
    kappa = math.sqrt(3 * height / (4 * depth**3))
    x = w.celerity * t + jnp.linspace(-5, 5, SAMPLES) / kappa
    solitary = height / jnp.cosh(kappa * (x - w.celerity * t)) ** 2
    np.testing.assert_allclose(w.elevation(x, 0 * x, t) - w.trough, solitary, rtol=0, atol=1e-8 * height)
    np.testing.assert_allclose(w.trough * w.K / height, -1, rtol=1e-12)
    c0 = math.sqrt(G * depth)
    np.testing.assert_allclose((w.celerity / c0 - 1 - height / (2 * depth)) * w.K * depth / height, -1.5, rtol=1e-12)


# ---------------------------------------------------------------------------------------
# The kinematics.
# ---------------------------------------------------------------------------------------


@jax.jit
def _divergence_and_rise(w, points, t):
    """∇·v and ∂v/∂z at `points`, and ∂η/∂t there, by forward-mode autodiff."""
    jacobian = jax.vmap(jax.jacfwd(lambda p: w.velocity(p, t)))(points)
    rise = jax.jvp(lambda t: w.elevation(points[:, 0], points[:, 1], t), (t,), (jnp.ones_like(t),))[1]
    return jnp.trace(jacobian, axis1=-2, axis2=-1), jacobian[:, :2, 2], rise


def test_continuity_and_the_seabed():
    # At heading 30°: the velocity's divergence is 0 in the water, u is depth-uniform,
    # w(−d) = 0; on the surface, w matches ∂η/∂t to O(H/d).
    w = Cnoidal(3.0, 15.0, 10.0, heading=30.0)
    beta = np.deg2rad(30.0)
    rotation = jnp.array([[np.cos(beta), -np.sin(beta), 0], [np.sin(beta), np.cos(beta), 0], [0, 0, 1.0]])
    points = column(w) @ rotation.T
    divergence, shear, _ = _divergence_and_rise(w, points, jnp.array(0.4))
    scale = float(w.height) * math.sqrt(G / 10.0) * 4 * float(w.K) / float(w.wavelength)  # ∂u/∂x's
    np.testing.assert_allclose(divergence, 0.0, rtol=0, atol=1e-14 * scale)
    np.testing.assert_array_equal(shear, 0.0)
    x, y = points[:, 0], points[:, 1]
    np.testing.assert_array_equal(w.velocity(jnp.stack([x, y, jnp.full_like(x, -10.0)], -1), 0.4)[:, 2], 0.0)
    surface = jnp.stack([x, y, w.elevation(x, y, 0.4)], -1)
    _, _, rise = _divergence_and_rise(w, surface, jnp.array(0.4))
    difference = jnp.max(jnp.abs(w.velocity(surface, 0.4)[:, 2] - rise))
    assert 0 < float(difference) < float(w.height / w.depth * jnp.max(jnp.abs(rise)))


@pytest.mark.parametrize("height, period", [(2.0, 12.0), (1.0, 120.0)])
def test_time_derivatives(height, period):
    # The closed-form ∂u/∂t, ∂w/∂t against central differences (step 1e-4 s, error
    # O(1e-8) relative) and against forward-mode autodiff of the velocity, which is what
    # `AbstractWave.acceleration` computes.
    w = Cnoidal(height, period, 10.0)
    points = column(w)
    t, step = 1.7, 1e-4
    closed = w.acceleration(points, t)
    central = (w.velocity(points, t + step) - w.velocity(points, t - step)) / (2 * step)
    scale = float(jnp.max(jnp.abs(closed)))
    np.testing.assert_allclose(closed, central, rtol=0, atol=1e-7 * scale)
    np.testing.assert_allclose(closed, AbstractWave.acceleration(w, points, t), rtol=0, atol=1e-14 * scale)


def test_heading_and_phase(wave):
    # The wave at heading 40° is the wave at 0° turned by 40° about z: its velocity at
    # R p is R times the velocity at p, and so are the elevation and acceleration. A
    # phase θ₀ moves the wave back by θ₀ λ/(2π).
    turned = Cnoidal(2.0, 12.0, 10.0, heading=40.0)
    beta = np.deg2rad(40.0)
    rotation = jnp.array([[np.cos(beta), -np.sin(beta), 0], [np.sin(beta), np.cos(beta), 0], [0, 0, 1.0]])
    points = column(wave) + jnp.array([0.0, 23.0, 0.0])
    moved = points @ rotation.T
    np.testing.assert_allclose(turned.velocity(moved, 2.0), wave.velocity(points, 2.0) @ rotation.T, atol=1e-14)
    np.testing.assert_allclose(turned.acceleration(moved, 2.0), wave.acceleration(points, 2.0) @ rotation.T, atol=1e-14)
    np.testing.assert_allclose(
        turned.elevation(moved[:, 0], moved[:, 1], 2.0), wave.elevation(points[:, 0], points[:, 1], 2.0), atol=1e-14
    )
    shifted = Cnoidal(2.0, 12.0, 10.0, phase=1.0)
    ahead = points + jnp.array([1.0 / (2 * np.pi), 0.0, 0.0]) * wave.wavelength
    np.testing.assert_allclose(shifted.velocity(points, 2.0), wave.velocity(ahead, 2.0), atol=1e-13)


def test_outside_the_water_column(wave):
    # Above the surface, the kinematics at the surface; below the seabed, those on it.
    x = column(wave)[:, 0]
    eta = wave.elevation(x, 0 * x, 0.5)

    def at(z):
        position = jnp.stack([x, 0 * x, z], -1)
        return jnp.concatenate([wave.velocity(position, 0.5), wave.acceleration(position, 0.5)], -1)

    np.testing.assert_array_equal(at(eta + 3.0), at(eta))
    np.testing.assert_array_equal(at(jnp.full_like(x, -13.0)), at(jnp.full_like(x, -10.0)))
    assert float(jnp.max(jnp.abs(at(eta)[:, 2]))) > 0.1  # w does not vanish at the surface


# ---------------------------------------------------------------------------------------
# Transformations and construction.
# ---------------------------------------------------------------------------------------


def test_gradient_through_the_solve():
    # jax.grad (reverse mode, through the implicit derivative of the m-solve) of λ and of
    # w at a point, with respect to H, T and d, against central differences (relative
    # step 1e-5, error O(1e-10)).
    point = jnp.array([30.0, 0.0, -4.0])

    def wavelength(p):
        return Cnoidal(p[0], p[1], p[2]).wavelength

    def vertical(p):
        return Cnoidal(p[0], p[1], p[2]).velocity(point, 1.3)[2]

    p0 = np.array([2.0, 12.0, 10.0])
    gradients = jax.jit(lambda p: (jax.grad(wavelength)(p), jax.grad(vertical)(p)))(p0)
    for f, gradient in zip((wavelength, vertical), gradients):
        central = [(f(p0 + e) - f(p0 - e)) / (2 * e.sum()) for e in np.diag(1e-5 * p0)]
        np.testing.assert_allclose(gradient, central, rtol=1e-7)


def test_vmap_over_height_and_traced_failure():
    # Built under jit and vmap: the same waves as built one by one; and where there is
    # no physical root (T = 6 s), m is NaN, as the checks need concrete values.
    heights, periods = [1.5, 2.0, 3.0, 2.0], [12.0, 12.0, 12.0, 6.0]
    point = jnp.array([12.0, 3.0, -4.0])

    @jax.jit
    @jax.vmap
    def build(height, period):
        w = Cnoidal(height, period, 10.0)
        return w.m1, w.velocity(point, 0.8)

    m1, velocity = build(jnp.array(heights), jnp.array(periods))
    for i, height in enumerate(heights[:3]):
        w = Cnoidal(height, 12.0, 10.0)
        np.testing.assert_allclose(m1[i], w.m1, rtol=1e-12)
        np.testing.assert_allclose(velocity[i], w.velocity(point, 0.8), rtol=1e-12)
    assert np.isnan(m1[3]) and np.all(np.isnan(velocity[3]))


def test_from_steepness(wave):
    # The wave of the steepness of the 2 m wave is the 2 m wave.
    w = Cnoidal.from_steepness(wave.steepness, 12.0, 10.0)
    np.testing.assert_allclose([w.height, w.m1], [2.0, wave.m1], rtol=1e-12)
    np.testing.assert_allclose(w.steepness, wave.steepness, rtol=1e-14)


@pytest.mark.parametrize(
    "build, message",
    [
        (lambda: Cnoidal(9.0, 12.0, 10.0), r"Cnoidal.height must be at most 0.78 times the depth .* \(H/d = 0.9\)"),
        (lambda: Cnoidal(2.0, 6.0, 10.0), r"Cnoidal.period must give T √\(g/d\) ≥ 6.636, .* H/d = 0.2, got 6.0 s"),
        (lambda: Cnoidal(2.0, 12.0, -10.0), r"Cnoidal.depth must be positive, got -10.0"),
        (lambda: Cnoidal(0.0, 12.0, 10.0), r"Cnoidal.height must be positive, got 0.0"),
        (lambda: Cnoidal.from_steepness(-0.01, 12.0, 10.0), r"Cnoidal.steepness must be positive"),
        (lambda: Cnoidal.from_steepness(0.02, 5.0, 10.0), r"T √\(g/d\) ≥ 6.659, .* steepness 0.02, got 5.0 s"),
        (lambda: Cnoidal.from_steepness(0.1, 20.0, 10.0), r"Cnoidal.steepness 0.1 .* breaking wave"),
    ],
)
def test_bad_input_is_named(build, message):
    with pytest.raises(ValueError, match=message):
        build()


def test_small_ursell_number_warns():
    # U = 4.6 (the notes' sanity row): Airy fits better; U = 26.5 does not warn.
    with pytest.warns(UserWarning, match=r"Ursell number 4.64 < 5"):
        Cnoidal(1.0, 8.0, 10.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Cnoidal(2.0, 12.0, 10.0)
