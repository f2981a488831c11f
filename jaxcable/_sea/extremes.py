"""Extremes over realisations of an irregular sea: the most probable maximum (MPM) of a
response, such as a line's tension, and its distribution.

Each realisation (one seed of the sea) gives one record of the response and its largest
value. Two estimates of the MPM over a duration D come from them:

- **Gumbel, fitted to the maxima** of the realisations: the largest of many roughly
  independent peaks has the distribution F(x) = exp(−exp(−(x − μ)/β)) (Gumbel 1958),
  whose mode μ is the MPM. μ and β are fitted by moments: β = s √6/π and
  μ = x̄ − γ_E β, with x̄ and s the maxima's mean and standard deviation (n − 1) and
  γ_E Euler's constant. This holds for any response, linear or not, and is the
  practice of DNV-OS-E301 (Ch. 2 Sec. 2) for mooring tensions. The maxima over D
  follow from those over a record of length D_r as F^(D/D_r): μ moves by β ln(D/D_r).
  The estimate's standard error is √(1 − c g₁ + c² (κ − 1)/4) · σ/√n ≈ 0.843 σ/√n
  (delta method, c = γ_E √6/π, the Gumbel skewness g₁ = 1.1395 and kurtosis κ = 5.4, σ
  = πβ/√6 the maxima's spread). Over few seeds s is low by about (κ − 1)/8n, so β is
  too and μ high by γ_E β (κ − 1)/8n: at n = 20, 2.8 % of β and a fifteenth of the
  standard error (by Monte Carlo over 4000 batches of Gumbel samples).
- **Rayleigh, from each record's statistics** (the short-term distribution of a
  Gaussian response): a stationary Gaussian process of mean m and standard deviation σ
  crosses its mean upwards ν₀ = σ_ẋ/(2πσ) times a second (Rice 1944); its maximum over
  D has the mode m + σ √(2 ln(ν₀ D)). A linear response to a linear sea is Gaussian,
  and this estimate then needs no more than a record long enough to measure σ and σ_ẋ;
  a non-Gaussian one (slack, snap, drag) makes it unconservative, and the Gumbel fit
  is the one to trust. σ_ẋ comes from the record's differences, which understate it
  by a fraction (ω Δt)²/24 at frequency ω.

Everything is written in JAX: the statistics differentiate with respect to the records
(the maxima through the samples where they occur), and so, through a simulation, with
respect to H_s, T_p and design parameters.
"""

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

EULER_GAMMA = 0.5772156649015329
GUMBEL_SKEWNESS = 1.1395470994046486  # 12 √6 ζ(3) / π³
GUMBEL_KURTOSIS = 5.4
_C = EULER_GAMMA * np.sqrt(6) / np.pi
STANDARD_ERROR_FACTOR = float(np.sqrt(1 - _C * GUMBEL_SKEWNESS + _C**2 * (GUMBEL_KURTOSIS - 1) / 4))
"""The Gumbel MPM's standard error in units of the maxima's spread σ over √n."""


class ExtremeStatistics(eqx.Module):
    """The extremes of a response over realisations (see the module docstring). Values
    are in the response's units (N for a tension); `*batch` is any leading shape of the
    records (sea states, say).

    **Attributes:**

    - `maxima`: each realisation's largest value over its record, shape
        `(*batch, realisations)`.
    - `location`, `scale`: μ and β of the Gumbel distribution of the maximum over
        `duration`, fitted to `maxima`, shape `(*batch,)`.
    - `rayleigh`: each realisation's short-term MPM over `duration`,
        m + σ √(2 ln(ν₀ D)), shape `(*batch, realisations)`.
    - `duration`: D (s), the duration the distribution and the MPMs refer to.
    - `record`: D_r (s), the length of each record.
    """

    maxima: Float[Array, "*batch realisations"]
    location: Float[Array, "*batch"]
    scale: Float[Array, "*batch"]
    rayleigh: Float[Array, "*batch realisations"]
    duration: Float[Array, ""]
    record: Float[Array, ""]

    @property
    def most_probable_maximum(self) -> Float[Array, "*batch"]:
        """The MPM over `duration`: the Gumbel fit's mode μ."""
        return self.location

    @property
    def spread(self) -> Float[Array, "*batch"]:
        """The maximum's standard deviation under the fit, πβ/√6: how far one
        realisation's maximum over `duration` typically falls from the mean."""
        return np.pi / np.sqrt(6) * self.scale

    @property
    def standard_error(self) -> Float[Array, "*batch"]:
        """The standard error of the MPM's estimate from n realisations,
        0.843 · spread/√n (module docstring): more seeds shrink it as 1/√n."""
        return STANDARD_ERROR_FACTOR * self.spread / np.sqrt(self.maxima.shape[-1])

    @property
    def rayleigh_mpm(self) -> Float[Array, "*batch"]:
        """The short-term (Rayleigh) MPM over `duration`, averaged over realisations."""
        return jnp.mean(self.rayleigh, axis=-1)

    def quantile(self, probability: Float[ArrayLike, "*p"]) -> Float[Array, "..."]:
        """The level the maximum over `duration` stays below with `probability` (in
        (0, 1)): μ − β ln(−ln p). At p = e^(−1) ≈ 0.368 it is the MPM; DNV's
        90 % fractile is `quantile(0.9)`."""
        p = jnp.asarray(probability)[(...,) + (None,) * self.location.ndim]
        return self.location - self.scale * jnp.log(-jnp.log(p))

    def exceedance(self, level: Float[ArrayLike, "*level"]) -> Float[Array, "..."]:
        """The probability that the maximum over `duration` exceeds `level`:
        1 − exp(−exp(−(x − μ)/β))."""
        x = jnp.asarray(level)[(...,) + (None,) * self.location.ndim]
        return -jnp.expm1(-jnp.exp(-(x - self.location) / self.scale))


def extreme_statistics(
    records: Float[ArrayLike, "*batch realisations times"],
    times: Float[ArrayLike, " times"],
    *,
    start: float | None = None,
    duration: float | None = None,
) -> ExtremeStatistics:
    """The most probable maximum of a response and its distribution, from one record
    per realisation (module docstring).

    **Arguments:**

    - `records`: the response (a tension in N, say) at `times`, one row per
        realisation, shape `(*batch, realisations, times)`, at least 2 realisations.
    - `times`: the sample times (s), equally spaced, shape `(times,)`.
    - `start`: the first time (s) kept, to leave out the start-up transient; the first
        sample's by default.
    - `duration`: D (s), the duration to give the maximum for (a 3-hour storm, say);
        the kept record's length by default.

    **Returns:**

    An [`jaxcable.ExtremeStatistics`][].

    **Raises:**

    `ValueError` for records and times of mismatched shapes, fewer than 2 realisations
    or 3 kept samples, unequal time steps, or a non-positive duration.
    """
    times = np.asarray(times, dtype=float)
    records = jnp.asarray(records, dtype=float)
    if times.ndim != 1 or records.ndim < 2 or records.shape[-1] != times.size:
        raise ValueError(
            f"extreme_statistics: records must have shape (..., realisations, times) with times of shape "
            f"({times.size},) its last axis, got records {records.shape} and times {times.shape}"
        )
    if records.shape[-2] < 2:
        raise ValueError(f"extreme_statistics: at least 2 realisations are needed, got {records.shape[-2]}")
    keep = np.ones(times.size, bool) if start is None else times >= start
    if keep.sum() < 3:
        raise ValueError(f"extreme_statistics: fewer than 3 samples from start = {start} s, of times up to {times[-1]}")
    times, records = times[keep], records[..., keep]
    step = np.diff(times)
    if not np.allclose(step, step[0], rtol=1e-6, atol=0.0) or step[0] <= 0:
        raise ValueError("extreme_statistics: times must be equally spaced and increasing")
    record = float(times[-1] - times[0])
    duration = record if duration is None else float(duration)
    if not duration > 0:
        raise ValueError(f"extreme_statistics: duration must be positive, got {duration}")

    maxima = jnp.max(records, axis=-1)
    scale = jnp.std(maxima, axis=-1, ddof=1) * np.sqrt(6) / np.pi
    location = jnp.mean(maxima, axis=-1) - EULER_GAMMA * scale + scale * np.log(duration / record)

    mean = jnp.mean(records, axis=-1)
    sigma = jnp.std(records, axis=-1)
    rate = jnp.std(jnp.diff(records, axis=-1), axis=-1) / step[0]
    crossings = rate / (2 * np.pi * jnp.maximum(sigma, jnp.finfo(float).tiny)) * duration
    # At most one crossing (or a constant record): the mean is the most probable
    # maximum. Both `where`s keep the derivative finite there.
    log = jnp.log(crossings)
    positive = log > 0
    rayleigh = mean + jnp.where(positive, sigma * jnp.sqrt(2 * jnp.where(positive, log, 1.0)), 0.0)
    return ExtremeStatistics(maxima, location, scale, rayleigh, jnp.asarray(duration), jnp.asarray(record))
