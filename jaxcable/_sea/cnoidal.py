"""First-order cnoidal waves: the Korteweg–de Vries wave of shallow water.

Yakovlev et al.'s cnoidal-loads paper (Yakovlev et al. 2024) recommends cnoidal theory on the shallow shelf, where
its steep crests and flat troughs carry larger particle accelerations than linear
theory's. Its notes (§3.3, §7.2) give the first-order set coded here, with H the wave
height, d the mean depth, m the elliptic parameter, K = K(m), E = E(m), c₀ = √(g d):

    λ = 4K √(m d³ / (3H)),    U = H λ² / d³ = 16 m K² / 3,
    c = c₀ [1 + (H / (m d)) (1 − m/2 − 3E/(2K))],    T = λ / c,

and, with θ = k₀ x_β − ω t + θ₀ (k₀ = 2π/λ, ω = 2π/T) and ψ = Kθ/π,

    η = H [cn²(ψ|m) − (E/K − 1 + m)/m],    u = (c₀/d) η,
    w = (z + d) (c₀/d) H (4K/λ) sn cn dn.

m → 0 gives a sinusoid (linear shallow-water theory); m → 1 the solitary wave
η = H sech²(√(3H/(4d³)) (x − ct)). The Fourier series of cn² writes the same wave as
phase-locked harmonics n k₀, n ω of amplitudes H aₙ ([`jaxcable.cnoidal_coefficients`][]),
the paper's "harmonic superposition" (its eqs. 32–33).
"""

import functools

import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx
from jaxtyping import Array, ArrayLike, Float

from .. import _checks as checks
from .elliptic import ellipj, ellipk, ellipke
from .waves import BREAKING_HEIGHT_RATIO, AbstractWave, _check_wave, airy_wavenumber

# Below this Ursell number the cnoidal wave differs from linear theory by a few per cent
# (crest 0.524 H instead of H/2 at U = 5, Yakovlev et al.'s cnoidal-loads paper §7.4), less than the error of the
# long-wave approximation it rests on, whose (k d)² = 4π² (H/d) / U is then of order 1:
# Airy fits better.
URSELL_MINIMUM = 5.0


def _elliptic_parameter(s):
    """m, m₁ = 1 − m, K and E at s = −ln(1 − m): m₁ = e^{−s} keeps its relative
    precision however near 1 m is."""
    m1 = jnp.exp(-s)
    m = -jnp.expm1(-s)
    k, e = ellipke(m, m1)
    return m, m1, k, e


def _period_number(s, height_ratio):
    """T √(g/d) (–) of the wave of H/d = `height_ratio` and m = 1 − e^{−s}: λ/d over c/c₀."""
    m, _, k, e = _elliptic_parameter(s)
    length = 4 * k * jnp.sqrt(m / (3 * height_ratio))
    speed = 1 + height_ratio / m * (1 - m / 2 - 1.5 * e / k)
    return length / speed


def _given_height(s, height_ratio):
    """H/d, given: the same for every m."""
    return height_ratio


def _height_of_steepness(s, steepness):
    """H/d of the wave of steepness H/λ = `steepness` and m = 1 − e^{−s}: H = S λ and
    λ = 4K √(m d³/(3H)) give H/d = (4 S K √(m/3))^(2/3)."""
    m, _, k, _ = _elliptic_parameter(s)
    return (4 * steepness * k * jnp.sqrt(m / 3)) ** (2 / 3)


def _ursell_to_s(ursell):
    """A start for s from the Ursell number U = 16 m K²/3: its small-m asymptote
    (K → π/2, so s ≈ m ≈ 3U/(4π²)) up to U = 20 (m ≈ 0.8), its m → 1 asymptote
    (K ≈ ln 4 + s/2 ≈ √(3U/16)) beyond."""
    return jnp.where(ursell < 20, 3 * ursell / (4 * jnp.pi**2), 2 * (jnp.sqrt(3 * ursell / 16) - jnp.log(4.0)))


@functools.partial(jax.jit, static_argnums=0)
def _solve(height_ratio, parameter, period_number, start):
    """s = −ln(1 − m) on the physical branch of T √(g/d) = `period_number`, or NaN.

    T √(g/d) is not monotone in m. Where D = c/c₀ < 0 (small m) first-order theory is
    invalid; on D > 0 it falls from +∞ to a minimum (≈ 6.66 at small H/d, 6.27 at
    H/d = 0.78, at s ≈ 1.5 H/d) and then rises. The physical root is the one on the
    rising side. There (T √(g/d))³ is convex in ln s (checked on a fine grid, for
    0 < H/d ≤ 0.78 and, from the steepness, up to the breaking height), so Newton's
    method in ln s started anywhere on the rising side lands right of the root after at
    most one step and then descends to it monotonically. `start` must be on the rising
    side.

    `height_ratio(s, parameter)` gives H/d: fixed, or from the steepness. The result is
    differentiated implicitly (optimistix's `ImplicitAdjoint`), not through the
    iterations. It is NaN if Newton's method fails or ends where T √(g/d) falls: no
    physical root.
    """

    def residual(v, args):
        parameter, period_number = args
        s = jnp.exp(v)
        return (_period_number(s, height_ratio(s, parameter)) / period_number) ** 3 - 1

    args = (parameter, period_number)
    solver = optx.Newton(rtol=1e-10, atol=1e-10)
    solution = optx.root_find(residual, solver, jnp.log(start), args, max_steps=64, throw=False)
    v = solution.value
    slope = jax.grad(residual)(jax.lax.stop_gradient(v), jax.lax.stop_gradient(args))
    found = (solution.result == optx.RESULTS.successful) & (slope > 0)
    return jnp.where(found, jnp.exp(v), jnp.nan)


def _branch_minimum(height_ratio, parameter, start):
    """The minimum of T √(g/d) over the D > 0 branch, for error messages (concrete
    values only): it lies within [start/2, start] for the starts used here."""
    s = np.geomspace(0.5 * float(start), float(start), 2001)
    tau = np.asarray(_period_number(s, height_ratio(s, parameter)))
    return float(np.min(np.where(tau > 0, tau, np.inf)))


def cnoidal_coefficients(
    m: Float[ArrayLike, "*#batch"], count: int, m1: Float[ArrayLike, "*#batch"] | None = None
) -> Float[Array, "*batch count"]:
    """The Fourier coefficients aₙ, n = 1 … `count`, of cn²(Kθ/π | m) about its mean:

        cn²(Kθ/π | m) = (E/K − 1 + m)/m + Σₙ aₙ cos nθ,
        aₙ = (π² / (m K²)) n / sinh(nπK'/K) = (2π² / (m K²)) n qⁿ / (1 − q²ⁿ),

    where K' = K(1 − m) and q = e^{−πK'/K} is the nome (the cnoidal-loads paper's eq. 33). A cnoidal
    wave's elevation is η = H Σₙ aₙ cos nθ. aₙ → 1/2 for n = 1 (and 0 for the rest) as
    m → 0. The terms fall like qⁿ: about ln(ε)/ln q of them reach a relative error ε,
    that is 20 for m ≤ 0.9 (q ≤ 0.18) and 100 at 1 − m = 1e-12 (q ≈ 0.72).

    **Arguments:**

    - `m`: the elliptic parameter, 0 < m < 1 (–).
    - `count`: the number of coefficients.
    - `m1`: 1 − m (–); give it when m is within rounding of 1.

    **Returns:**

    aₙ (–), shape `(*batch, count)`.
    """
    m = jnp.asarray(m, dtype=float)
    m1 = 1 - m if m1 is None else jnp.asarray(m1, dtype=float)
    k, k_prime = ellipk(m, m1), ellipk(m1, m)
    n = jnp.arange(1, count + 1)
    # qⁿ and 1 − q²ⁿ as exponentials, so that nothing overflows (sinh would, at small m)
    # and 1 − q²ⁿ keeps its precision as q → 1.
    decay = -jnp.pi * k_prime / k
    scale = 2 * jnp.pi**2 / (m * k**2)
    return scale[..., None] * n * jnp.exp(n * decay[..., None]) / -jnp.expm1(2 * n * decay[..., None])


_NO_ROOT = "must give a first-order cnoidal wave that does not break: use Airy"


class Cnoidal(AbstractWave):
    """A first-order cnoidal wave (Korteweg–de Vries) in shallow water.

    The surface, with θ = k₀ x_β − ω t + θ₀ and ψ = Kθ/π:

        η = H cn²(ψ|m) + η_t,    η_t = H (1 − m − E/K)/m,

    zero-mean, with its crest H + η_t at θ = 0. The velocity is depth-uniform along the
    heading and linear in depth vertically (continuity with w = 0 on the seabed):

        u = (c₀/d) η,    w = (z + d) (c₀/d) H (4K/λ) sn cn dn.

    The parameter m solves T = λ/c for the given height, depth and period, on the branch
    where c > 0 and T grows with m (module docstring). m → 0 is linear shallow-water
    theory; m → 1 the solitary wave. The theory holds for H/d up to the breaking limit
    0.78 and is meant for Ursell numbers U = H λ²/d³ above about 5 (below, Airy fits
    better).

    First-order theory describes the water −d ≤ z ≤ η. Outside it the kinematics are
    those at the nearest end of the column: above the surface, those at the surface;
    below the seabed, those on it (w = 0). The acceleration is the local ∂/∂t of the
    closed form, evaluated there; above the surface it leaves out the term
    (∂w/∂z) ∂η/∂t of the moving surface, which is second order in H/d, like the
    convective acceleration.

    **Arguments:**

    - `height`: H (m), crest to trough.
    - `period`: T (s).
    - `depth`: d (m), the mean (still-water) depth.
    - `gravity`: g (m/s²).
    - `heading`: β (degrees), the direction of travel from +x towards +y.
    - `phase`: θ₀ (rad); 0 puts a crest at x_β = 0 at t = 0.

    Solved at construction: `m`, the elliptic parameter (–); `m1` = 1 − m (–), kept
    apart because a near-solitary wave has m₁ below 1e-12, lost in 1 − m; and the
    complete elliptic integrals `K` = K(m) and `E` = E(m) (–).

    **Raises:**

    `ValueError` for a non-positive height, period, depth or gravity, for H/d above the
    breaking limit 0.78 or H/λ above Miche's 0.142 tanh(2π d/λ)
    ([`breaking_height`][jaxcable._sea.waves.breaking_height]), and for a period too short
    for any first-order cnoidal wave of this H/d (T √(g/d) below the branch minimum,
    about 6.3 to 6.7). Warns (a `UserWarning`) where U < 5. The checks need concrete values: built inside `jit`,
    `vmap` or `grad` with no physical root, m and everything solved from it are NaN.
    """

    height: Float[Array, ""]
    period: Float[Array, ""]
    depth: Float[Array, ""]
    gravity: Float[Array, ""]
    heading: Float[Array, ""]
    phase: Float[Array, ""]
    m: Float[Array, ""]
    m1: Float[Array, ""]
    K: Float[Array, ""]
    E: Float[Array, ""]

    def __init__(self, height, period, depth, *, gravity=9.81, heading=0.0, phase=0.0):
        fields = _check_wave("Cnoidal", height, period, depth, gravity, heading, phase)
        for name, value in fields.items():
            setattr(self, name, value)
        ratio = self.height / self.depth
        # McCowan's half of the breaking limit, before the solve, which has no root past
        # it; Miche's half needs the wavelength, and `conditions()` has both.
        checks.enforce([self._below_mccowan()])
        period_number = self.period * jnp.sqrt(self.gravity / self.depth)
        airy_length = 2 * jnp.pi / airy_wavenumber(self.period, self.depth, self.gravity)
        # Airy's Ursell number is near the root; 1.6 H/d is right of the branch's
        # minimum (at 1.50 to 1.59 H/d for H/d ≤ 2), so the start is on the rising side.
        floor = 1.6 * ratio
        start = jax.lax.stop_gradient(jnp.maximum(_ursell_to_s(ratio * (airy_length / self.depth) ** 2), floor))
        s = _solve(_given_height, ratio, period_number, start)

        def too_short():
            minimum = _branch_minimum(_given_height, ratio, floor)
            return (
                f"Cnoidal.period must give T √(g/d) ≥ {minimum:.4g}, the least of first-order cnoidal "
                f"waves at H/d = {float(ratio):.4g}, got {float(self.period)} s (T √(g/d) = "
                f"{float(period_number):.4g}): use Airy"
            )

        checks.enforce([checks.Condition("Cnoidal.period", jnp.isnan(s), self.period, _NO_ROOT, too_short)])
        self.m, self.m1, self.K, self.E = _elliptic_parameter(s)
        checks.enforce([self._unbroken()])
        ursell = checks.Condition(
            "Cnoidal",
            self.ursell < URSELL_MINIMUM,
            self.ursell,
            "",
            lambda: (
                f"Cnoidal wave of Ursell number {float(self.ursell):.3g} < {URSELL_MINIMUM}: linear (Airy) theory fits "
                "better"
            ),
        )
        checks.warn([ursell], stacklevel=4)  # the caller's line, past equinox's two construction frames

    def _below_mccowan(self) -> checks.Condition:
        ratio = self.height / self.depth
        return checks.Condition(
            "Cnoidal.height",
            ratio > BREAKING_HEIGHT_RATIO,
            self.height,
            f"must be at most {BREAKING_HEIGHT_RATIO} times the depth (the breaking limit)",
            lambda: (
                f"Cnoidal.height must be at most {BREAKING_HEIGHT_RATIO} times the depth (the breaking limit), "
                f"got {float(self.height)} m in {float(self.depth)} m of water (H/d = {float(ratio):.4g})"
            ),
        )

    def conditions(self) -> list[checks.Condition]:
        # A period with no first-order cnoidal wave leaves m NaN.
        return AbstractWave.conditions(self) + [
            checks.Condition("Cnoidal.period", jnp.isnan(self.m), self.period, _NO_ROOT),
        ]

    @classmethod
    def from_steepness(cls, steepness, period, depth, **kwargs) -> "Cnoidal":
        """The cnoidal wave of steepness H/λ = `steepness` (–); the other arguments as
        for `Cnoidal`.

        λ depends on H: H = S λ and λ = 4K √(m d³/(3H)) give H = (4 S K √(m d³/3))^(2/3),
        which leaves one equation, T = λ/c, for m (solved on the physical branch as for
        the height).

        **Raises:**

        `ValueError` as for `Cnoidal`: for a non-positive steepness, a period too short
        for any first-order cnoidal wave of this steepness, or one so long that the wave
        would break.
        """
        gravity = kwargs.get("gravity", 9.81)
        values = {}
        for field, value in (("steepness", steepness), ("period", period), ("depth", depth), ("gravity", gravity)):
            values[field] = checks.float_array(f"Cnoidal.{field}", value, ())
            checks.positive(f"Cnoidal.{field}", values[field])
        steepness, period, depth, gravity = values.values()
        period_number = period * jnp.sqrt(gravity / depth)
        airy_length = 2 * jnp.pi / airy_wavenumber(period, depth, gravity)
        # As in `__init__`; the branch's minimum is at s = 6.7 to 8.1 times the
        # steepness for steepness ≤ 0.16, beyond which every such wave breaks.
        floor = 9 * steepness
        start = jax.lax.stop_gradient(jnp.maximum(_ursell_to_s(steepness * (airy_length / depth) ** 3), floor))
        s = _solve(_height_of_steepness, steepness, period_number, start)
        height = _height_of_steepness(s, steepness) * depth

        def problem():
            if np.isnan(s) and period_number < (minimum := _branch_minimum(_height_of_steepness, steepness, floor)):
                return (
                    f"Cnoidal.period must give T √(g/d) ≥ {minimum:.4g}, the least of first-order cnoidal "
                    f"waves of steepness {float(steepness):.4g}, got {float(period)} s (T √(g/d) = "
                    f"{float(period_number):.4g}): use Airy"
                )
            return (
                f"Cnoidal.steepness {float(steepness):.4g} at a period of {float(period)} s in "
                f"{float(depth)} m of water gives a breaking wave (H/d > {BREAKING_HEIGHT_RATIO})"
            )

        # Past the breaking height, T √(g/d) levels off towards 2/steepness as m → 1,
        # and may have no root at all: either way the wave would break. Traced, the
        # NaN height that no root leaves is caught by the wave's own conditions.
        broken = jnp.isnan(s) | (height / depth > BREAKING_HEIGHT_RATIO)
        checks.enforce([checks.Condition("Cnoidal.steepness", broken, steepness, _NO_ROOT, problem)])
        return cls(height, period, depth, **kwargs)

    @property
    def wavelength(self) -> Float[Array, ""]:
        return 4 * self.K * jnp.sqrt(self.m * self.depth**3 / (3 * self.height))

    @property
    def celerity(self) -> Float[Array, ""]:
        """c = λ/T (m/s), from the KdV dispersion relation."""
        ratio = self.height / self.depth
        shallow = jnp.sqrt(self.gravity * self.depth)
        return shallow * (1 + ratio / self.m * (1 - self.m / 2 - 1.5 * self.E / self.K))

    @property
    def trough(self) -> Float[Array, ""]:
        """η_t = H (1 − m − E/K)/m (m), the trough's elevation (negative)."""
        return self.height * (self.m1 - self.E / self.K) / self.m

    @property
    def crest(self) -> Float[Array, ""]:
        """η_c = H + η_t (m), the crest's elevation."""
        return self.height + self.trough

    @property
    def nome(self) -> Float[Array, ""]:
        """q = e^{−πK'/K} (–), K' = K(1 − m): the ratio by which the harmonics fall."""
        return jnp.exp(-jnp.pi * ellipk(self.m1, self.m) / self.K)

    def _theta(self, x, y, t):
        """θ, reduced to [−π, π]: the wave has period 2π in θ, and a small ψ = Kθ/π keeps
        the Jacobi functions accurate far from the origin."""
        theta = 2 * jnp.pi * (self._along(x, y) / self.wavelength - t / self.period) + self.phase
        return theta - 2 * jnp.pi * jnp.round(theta / (2 * jnp.pi))

    def _jacobi(self, x, y, t):
        return ellipj(self.K * self._theta(x, y, t) / jnp.pi, self.m, self.m1)

    def _column(self, z, eta):
        """z clamped to the water column −d ≤ z ≤ η, plus d: the height above the seabed.
        Written with `where` rather than `clip`, whose derivative is 1/2 at the ends, so
        that the kinematics keep their z-derivative on the surface and the seabed."""
        z = jnp.where(z > eta, eta, z)
        return jnp.where(z < -self.depth, 0.0, z + self.depth)

    def elevation(self, x, y, t):
        _, cn, _ = self._jacobi(x, y, t)
        return self.height * jnp.square(cn) + self.trough

    def velocity(self, position, t):
        x, y, z = position[..., 0], position[..., 1], position[..., 2]
        sn, cn, dn = self._jacobi(x, y, t)
        eta = self.height * jnp.square(cn) + self.trough
        rate = jnp.sqrt(self.gravity / self.depth)  # c₀/d (1/s)
        w = self._column(z, eta) * rate * self.height * (4 * self.K / self.wavelength) * sn * cn * dn
        return self._horizontal(rate * eta, w)

    def acceleration(self, position, t):
        """The local acceleration ∂u/∂t (m/s²) at a fixed `position` (m) and time `t` (s),
        in closed form (Yakovlev et al. §7.2):

            ∂u/∂t = (c₀/d) H (4K/T) sn cn dn,
            ∂w/∂t = −(z + d) (c₀/d) H (4K/λ) (2K/T) [1 − 2(1 + m) sn² + 3m sn⁴].

        Outside the water column as for the velocity (class docstring)."""
        x, y, z = position[..., 0], position[..., 1], position[..., 2]
        sn, cn, dn = self._jacobi(x, y, t)
        eta = self.height * jnp.square(cn) + self.trough
        amplitude = jnp.sqrt(self.gravity / self.depth) * self.height * 4 * self.K  # (c₀/d) H 4K
        du = amplitude / self.period * sn * cn * dn
        sn2 = jnp.square(sn)
        slope = 1 - 2 * (1 + self.m) * sn2 + 3 * self.m * jnp.square(sn2)  # d(sn cn dn)/dψ
        dw = -self._column(z, eta) * amplitude / self.wavelength * (2 * self.K / self.period) * slope
        return self._horizontal(du, dw)

    def harmonic_series(
        self,
        position: Float[Array | np.ndarray, "*batch 3"],
        t,
        count: int,
        weights: Float[ArrayLike, " count"] | None = None,
    ) -> tuple[Float[Array, "*batch"], Float[Array, "*batch 3"], Float[Array, "*batch 3"]]:
        """The elevation, velocity and local acceleration as `count` phase-locked
        harmonics (Yakovlev et al. §7.2), aₙ from [`jaxcable.cnoidal_coefficients`][]:

            η = H Σ aₙ cos nθ,    u = (c₀/d) η,    w = (z + d) (c₀/d) H k₀ Σ n aₙ sin nθ,
            ∂u/∂t = (c₀/d) H ω Σ n aₙ sin nθ,    ∂w/∂t = −(z + d) (c₀/d) H k₀ ω Σ n² aₙ cos nθ.

        The harmonics are bound: all travel at the celerity c, with the depth-uniform
        (and linear) profiles of first-order theory, not each with its own linear
        dispersion. They equal the closed forms to the series' truncation error, qⁿ at
        n = `count` + 1 ([`jaxcable.Cnoidal.nome`][]). Outside the water column as for
        `velocity`, with η the series' own.

        **Arguments:**

        - `position`: (m), shape `(..., 3)`.
        - `t`: time (s).
        - `count`: the number of harmonics.
        - `weights`: a factor on each harmonic's amplitude, shape `(count,)`: 1 for
            the wave, one 1 among 0s for a single harmonic (the paper's harmonic
            superposition takes the harmonics one at a time). All 1 by default.

        **Returns:**

        `(η, velocity, acceleration)`: (m), shape `(...)`; (m/s) and (m/s²), shape
        `(..., 3)`.
        """
        x, y, z = position[..., 0], position[..., 1], position[..., 2]
        n = jnp.arange(1, count + 1)
        phase = n * self._theta(x, y, t)[..., None]
        cos, sin = jnp.cos(phase), jnp.sin(phase)
        a = cnoidal_coefficients(self.m, count, self.m1)
        if weights is not None:
            a = a * jnp.asarray(weights, dtype=float)
        eta = self.height * jnp.sum(a * cos, axis=-1)
        rate = jnp.sqrt(self.gravity / self.depth)  # c₀/d (1/s)
        wavenumber, frequency = 2 * jnp.pi / self.wavelength, 2 * jnp.pi / self.period
        column = self._column(z, eta)
        sines, cosines = jnp.sum(n * a * sin, axis=-1), jnp.sum(n**2 * a * cos, axis=-1)
        velocity = self._horizontal(rate * eta, column * rate * self.height * wavenumber * sines)
        acceleration = self._horizontal(
            rate * self.height * frequency * sines, -column * rate * self.height * wavenumber * frequency * cosines
        )
        return eta, velocity, acceleration
