"""Sea states: the JONSWAP spectrum (Pierson–Moskowitz at γ = 1) and cos-2s spreading.

The spectral density, in angular frequency ω (rad/s), of significant height H_s (m) and
peak period T_p (s), ω_p = 2π/T_p, is

    S(ω) = α(γ) (5/16) H_s² ω_p⁴ ω⁻⁵ exp(−(5/4)(ω_p/ω)⁴) γ^r,
    r = exp(−(ω − ω_p)² / (2 σ² ω_p²)),   σ = 0.07 for ω ≤ ω_p, 0.09 above,

(Hasselmann et al. 1973, in the form of DNV-RP-C205 §3.5.5). At γ = 1 it is the
Pierson–Moskowitz spectrum, whose variance is m₀ = H_s²/16 exactly. DNV approximates
the normalisation as α ≈ 1 − 0.287 ln γ; here α makes m₀ = H_s²/16 exactly for every γ,
from the integral of (γ^r − 1) S_PM, which is zero but within 8σ of the peak (there
γ^r − 1 < 10⁻¹³ ln γ) and is taken by Gauss–Legendre quadrature on either side of it.

The spectral moments m_n = ∫ ω^n S dω are, for Pierson–Moskowitz,
m_n = (H_s²/16) ω_p^n (5/4)^(n/4) Γ(1 − n/4) (n < 4), and for JONSWAP those plus the same
quadrature. Everything is written in JAX: a spectrum built from traced H_s, T_p or γ
differentiates and vmaps.

Directional spreading is Longuet-Higgins' cos-2s form about a mean heading θ̄,
D(θ) ∝ cos^{2s}((θ − θ̄)/2) on |θ − θ̄| ≤ π, whose mean of cos(θ − θ̄) is s/(s + 1)
(a directional spread σ_θ = √(2/(s + 1)) rad).
"""

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

from .. import _checks as checks
from .._typing import RealScalarLike

PEAK_WIDTH_BELOW, PEAK_WIDTH_ABOVE = 0.07, 0.09
"""σ of the JONSWAP peak below and above ω_p (–)."""
# γ^r − 1 is below 1e-13 ln γ beyond 8σ of the peak: the quadrature's panels end there.
_PANEL_WIDTHS = 8.0
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(64)
# The cos-2s spreading's inverse CDF is interpolated on this many cells of [−π, π].
_SPREADING_CELLS = 4096


class Jonswap(eqx.Module):
    """A JONSWAP spectrum, normalised to m₀ = H_s²/16 exactly (see the module docstring);
    `peak_enhancement = 1` is the Pierson–Moskowitz spectrum.

    **Arguments:**

    - `significant_height`: H_s (m), 4 √m₀.
    - `peak_period`: T_p (s), where S(ω) is largest.
    - `peak_enhancement`: γ (–), at least 1; 3.3 is the JONSWAP mean.

    **Raises:**

    `ValueError` naming the field for a non-positive height or period, or γ < 1.
    """

    significant_height: Float[Array, ""]
    peak_period: Float[Array, ""]
    peak_enhancement: Float[Array, ""]

    def __init__(self, significant_height, peak_period, peak_enhancement=3.3):
        self.significant_height = checks.float_array("Jonswap.significant_height", significant_height, ())
        self.peak_period = checks.float_array("Jonswap.peak_period", peak_period, ())
        self.peak_enhancement = checks.float_array("Jonswap.peak_enhancement", peak_enhancement, ())
        checks.enforce(self.conditions())

    @classmethod
    def pierson_moskowitz(cls, significant_height, peak_period) -> "Jonswap":
        """The Pierson–Moskowitz spectrum: JONSWAP at γ = 1."""
        return cls(significant_height, peak_period, 1.0)

    def conditions(self) -> list[checks.Condition]:
        """What the fields require (as the waves' `conditions`)."""
        return [
            checks.sign("Jonswap.significant_height", self.significant_height),
            checks.sign("Jonswap.peak_period", self.peak_period),
            checks.at_least("Jonswap.peak_enhancement", self.peak_enhancement, 1.0),
        ]

    @property
    def peak_frequency(self) -> Float[Array, ""]:
        """ω_p = 2π/T_p (rad/s)."""
        return 2 * jnp.pi / self.peak_period

    @property
    def variance(self) -> Float[Array, ""]:
        """m₀ = H_s²/16 (m²)."""
        return jnp.square(self.significant_height) / 16

    def log_density(self, omega: Float[ArrayLike, "*omega"]) -> Float[Array, "*omega"]:
        """ln S(ω), S in m²·s/rad, at angular frequencies `omega` (rad/s, positive):
        finite where S underflows, so that amplitudes √(2 S Δω) built from it have
        finite derivatives everywhere."""
        x = jnp.asarray(omega) / self.peak_frequency
        log_pm = jnp.log(5 / 16 * self.variance * 16 / self.peak_frequency) - 5 * jnp.log(x) - 1.25 * x**-4
        return log_pm + self._peak_shape(x) * jnp.log(self.peak_enhancement) - jnp.log(self._unnormalised(0))

    def density(self, omega: Float[ArrayLike, "*omega"]) -> Float[Array, "*omega"]:
        """S(ω) (m²·s/rad) at angular frequencies `omega` (rad/s, positive)."""
        return jnp.exp(self.log_density(omega))

    def moment(self, order: int) -> Float[Array, ""]:
        """The spectral moment m_n = ∫₀^∞ ω^n S(ω) dω (m²·(rad/s)^n) of `order` n = 0, 1,
        2 or 3 (higher ones diverge: S falls as ω⁻⁵)."""
        if order not in (0, 1, 2, 3):
            raise ValueError(f"Jonswap.moment: order must be 0, 1, 2 or 3 (m_n diverges from 4), got {order!r}")
        return self.variance * self.peak_frequency**order * self._unnormalised(order) / self._unnormalised(0)

    @property
    def mean_period(self) -> Float[Array, ""]:
        """T_m01 = 2π m₀/m₁ (s); 0.772 T_p for Pierson–Moskowitz."""
        return 2 * jnp.pi * self.moment(0) / self.moment(1)

    @property
    def zero_crossing_period(self) -> Float[Array, ""]:
        """T_z = T_m02 = 2π √(m₀/m₂) (s), the mean zero up-crossing period of the
        surface (Rice); 0.710 T_p for Pierson–Moskowitz."""
        return 2 * jnp.pi * jnp.sqrt(self.moment(0) / self.moment(2))

    def _peak_shape(self, x):
        """r(ω), with x = ω/ω_p."""
        sigma = jnp.where(x <= 1, PEAK_WIDTH_BELOW, PEAK_WIDTH_ABOVE)
        return jnp.exp(-jnp.square(x - 1) / (2 * sigma**2))

    def _unnormalised(self, order: int) -> Float[Array, ""]:
        """∫ x^n s(x) γ^r dx with s(x) = 5 x⁻⁵ exp(−(5/4) x⁻⁴), x = ω/ω_p, whose γ = 1
        part is (5/4)^(n/4) Γ(1 − n/4) in closed form."""
        closed = (5 / 4) ** (order / 4) * math.gamma(1 - order / 4)
        log_gamma = jnp.log(self.peak_enhancement)
        total = jnp.asarray(closed)
        for width, side in ((PEAK_WIDTH_BELOW, -1.0), (PEAK_WIDTH_ABOVE, 1.0)):
            half = 0.5 * _PANEL_WIDTHS * width
            x = 1 + side * half * (1 + _NODES)
            shape = 5 * x ** (order - 5) * np.exp(-1.25 * x**-4)
            peak = np.exp(-np.square(x - 1) / (2 * width**2))
            total = total + half * jnp.sum(_WEIGHTS * shape * jnp.expm1(peak * log_gamma))
        return total


def spreading_angles(spreading: RealScalarLike, probabilities: Float[ArrayLike, " n"]) -> Float[Array, " n"]:
    """Angles θ − θ̄ (rad) from the mean heading at the cumulative `probabilities` (in
    (0, 1)) of the cos-2s spreading D(θ) ∝ cos^{2s}((θ − θ̄)/2) of exponent `spreading`
    s > 0: its inverse distribution, interpolated linearly between the cumulative sums
    of D over 4096 cells of [−π, π] (the narrowest spread, σ_θ = √(2/(s + 1)), is ten
    cells at s ≈ 8000). Differentiable in s."""
    cells = _SPREADING_CELLS
    edges = np.linspace(-np.pi, np.pi, cells + 1)
    middle = 0.5 * (edges[1:] + edges[:-1])
    # cos(θ/2) > 0 at the cells' middles: its log and derivative in s stay finite.
    weight = jnp.exp(2 * jnp.asarray(spreading) * jnp.log(np.cos(middle / 2)))
    cumulative = jnp.concatenate([jnp.zeros(1), jnp.cumsum(weight)])
    cumulative = cumulative / cumulative[-1]
    u = jnp.asarray(probabilities)
    i = jnp.clip(jnp.searchsorted(cumulative, u), 1, cells)
    low, high = cumulative[i - 1], cumulative[i]
    # u lies in (low, high], a cell that carries probability: the division is safe.
    fraction = (u - low) / jnp.maximum(high - low, jnp.finfo(float).tiny)
    return jnp.asarray(edges)[i - 1] + fraction * (edges[1] - edges[0])


def random_key(seed, name: str) -> Array:
    """A typed `jax.random` key from `seed`: a key already, or an integer from 0 to
    2³² − 1 (a float of integer value too, as a sweep passes its parameters), concrete
    or traced."""
    if isinstance(seed, jax.Array) and jnp.issubdtype(seed.dtype, jax.dtypes.prng_key):
        return seed
    if not checks.traced(seed):
        try:
            value = np.asarray(seed, dtype=float)
        except (TypeError, ValueError):
            value = np.asarray(np.nan)
        if value.shape != () or not (np.isfinite(value) and value == np.round(value) and 0 <= value < 2**32):
            raise ValueError(
                f"{name} must be an integer from 0 to 2**32 - 1 or a jax.random.key, got {seed!r}"
                + (" (a raw uint32[2] key: wrap it with jax.random.wrap_key_data)" if value.shape == (2,) else "")
            )
    return jax.random.key(jnp.asarray(seed).astype(jnp.uint32))
