"""Irregular seas: a sum of linear (Airy) wave components, evaluated all at once.

Component i has amplitude a_i, period T_i (ω_i = 2π/T_i), heading β_i and phase θ₀_i:

    η = Σ a_i cos θ_i,   θ_i = k_i x_βi − ω_i t + θ₀_i,   ω_i² = g k_i tanh(k_i d),

and the water's velocity is the sum of each component's Airy velocity
([`jaxcable.Airy`][] with H = 2 a_i). The components are arrays, so one evaluation is
one vectorised sum whatever their number, and every amplitude, period and phase is a
float leaf that a sweep can vmap and a fit can differentiate.

This is the form MoorDyn's wave inputs reduce to (a spectrum of complex amplitudes, or
the FFT of an elevation record), and [`WaveComponents.from_elevation`][] builds it from a
record sampled at equal steps, exactly as an inverse DFT.
"""

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float

from . import _checks as checks
from ._typing import RealLike
from ._waves import AbstractWave, airy_wavenumber


class WaveComponents(AbstractWave):
    """A sea of superposed linear wave components (see the module docstring).

    The regular-wave summaries a wave carries (used by the advice and the breaking
    check) describe the sea as a whole: `height` is the significant height
    H_s = 4 √m₀ with m₀ = Σ a_i²/2 the surface's variance, and `period` and `heading`
    are those of the most energetic component.

    Above the still-water level (under a crest) the kinematics are those at z = 0, or,
    with `wheeler=True`, Wheeler's stretching evaluates them at
    `z' = d (z − η) / (d + η)` with η the whole sea's elevation, as MoorDyn's summed
    components (`WaveKin = 7`) do.

    **Arguments:**

    - `amplitudes`: a_i (m), shape `(components,)`, non-negative.
    - `periods`: T_i (s), shape `(components,)`, positive.
    - `depth`: d (m), still-water depth.
    - `gravity`: g (m/s²).
    - `headings`: β_i (degrees), a scalar for all or shape `(components,)`.
    - `phases`: θ₀_i (rad), shape `(components,)`; 0 by default.
    - `wheeler`: use Wheeler stretching.

    **Raises:**

    `ValueError` naming the field for mismatched shapes, no component, a negative
    amplitude, a non-positive period, depth or gravity, non-finite values, or a
    significant height past the breaking limit at the peak component's wavelength.
    """

    amplitudes: Float[Array, " components"]
    periods: Float[Array, " components"]
    depth: Float[Array, ""]
    gravity: Float[Array, ""]
    headings: Float[Array, " components"]
    phases: Float[Array, " components"]
    wavenumbers: Float[Array, " components"]
    wheeler: bool = eqx.field(static=True)

    def __init__(
        self,
        amplitudes,
        periods,
        depth,
        *,
        gravity=9.81,
        headings: RealLike = 0.0,
        phases: RealLike = 0.0,
        wheeler: bool = False,
    ):
        self.amplitudes = checks.float_array("WaveComponents.amplitudes", amplitudes)
        if self.amplitudes.ndim != 1 or self.amplitudes.shape[0] < 1:
            raise ValueError(
                f"WaveComponents.amplitudes must be 1-D with at least one component, got shape {self.amplitudes.shape}"
            )
        shape = self.amplitudes.shape
        for name, value in (("periods", periods), ("headings", headings), ("phases", phases)):
            array = checks.float_array(f"WaveComponents.{name}", value)
            if array.shape not in ((), shape):
                raise ValueError(f"WaveComponents.{name} must be a scalar or have shape {shape}, got {array.shape}")
            setattr(self, name, jnp.broadcast_to(array, shape))
        self.depth = checks.float_array("WaveComponents.depth", depth, ())
        self.gravity = checks.float_array("WaveComponents.gravity", gravity, ())
        if not isinstance(wheeler, bool):
            raise ValueError(f"WaveComponents.wheeler must be True or False, got {wheeler!r}")
        self.wheeler = wheeler
        self.wavenumbers = airy_wavenumber(self.periods, self.depth, self.gravity)
        checks.enforce(self.conditions())

    @classmethod
    def from_elevation(cls, times, elevation, depth, **kwargs) -> "WaveComponents":
        """The components whose sum passes through an elevation record at x = 0.

        The record's discrete Fourier transform X_j over its N samples (N even; a last,
        odd sample is dropped) gives, for 1 ≤ j ≤ N/2, T_j = N Δt / j,
        a_j = 2|X_j| / N (|X_{N/2}| / N at the Nyquist frequency) and θ₀_j = arg X_j,
        so that the sum equals the record at every sample time. The mean, X₀ / N, is
        a level offset linear waves do not carry; it is left out (see `mean_level`).

        **Arguments:**

        - `times`: t (s), equally spaced, shape `(samples,)`.
        - `elevation`: η (m) at those times, shape `(samples,)`.
        - `depth` and the keyword arguments: as for `WaveComponents`.
        """
        times, elevation = np.asarray(times, dtype=float), np.asarray(elevation, dtype=float)
        if times.ndim != 1 or times.shape != elevation.shape or times.size < 2:
            raise ValueError(
                f"WaveComponents.from_elevation needs times and elevation of one shape (samples,), at least 2, "
                f"got {times.shape} and {elevation.shape}"
            )
        step = np.diff(times)
        if not np.allclose(step, step[0], rtol=1e-6, atol=0.0) or step[0] <= 0:
            raise ValueError("WaveComponents.from_elevation needs equally spaced, increasing times")
        n = times.size - times.size % 2
        spectrum = np.fft.rfft(elevation[:n])[1:]  # drop the mean, X₀
        j = np.arange(1, n // 2 + 1)
        amplitudes = 2 * np.abs(spectrum) / n
        angles = np.angle(spectrum)  # η = Σ a_j cos(ω_j (t − t₀) + arg X_j)
        amplitudes[-1] = np.abs(spectrum[-1].real) / n  # the Nyquist term is real
        angles[-1] = 0.0 if spectrum[-1].real >= 0 else np.pi
        periods = n * step[0] / j
        phases = 2 * np.pi / periods * times[0] - angles
        return cls(amplitudes, periods, depth, phases=phases, **kwargs)

    def conditions(self) -> list[checks.Condition]:
        out = [
            checks.finite(f"WaveComponents.{field}", getattr(self, field))
            for field in ("amplitudes", "periods", "depth", "gravity", "headings", "phases")
        ]
        out += [
            checks.sign("WaveComponents.amplitudes", self.amplitudes, allow_zero=True),
            checks.sign("WaveComponents.periods", self.periods),
            checks.sign("WaveComponents.depth", self.depth),
            checks.sign("WaveComponents.gravity", self.gravity),
        ]
        return out + [self._unbroken()]

    @property
    def variance(self) -> Float[Array, ""]:
        """m₀ = Σ a_i² / 2 (m²), the surface elevation's variance over time."""
        return 0.5 * jnp.sum(jnp.square(self.amplitudes))

    @property
    def height(self) -> Float[Array, ""]:
        """The significant height H_s = 4 √m₀ (m)."""
        return 4 * jnp.sqrt(self.variance)

    @property
    def _peak(self) -> Array:
        return jnp.argmax(self.amplitudes)

    @property
    def period(self) -> Float[Array, ""]:
        """The most energetic component's period (s)."""
        return self.periods[self._peak]

    @property
    def heading(self) -> Float[Array, ""]:
        """The most energetic component's heading (degrees)."""
        return self.headings[self._peak]

    @property
    def phase(self) -> Float[Array, ""]:
        """The most energetic component's phase (rad)."""
        return self.phases[self._peak]

    @property
    def wavelength(self) -> Float[Array, ""]:
        """The most energetic component's wavelength (m)."""
        return 2 * jnp.pi / self.wavenumbers[self._peak]

    @property
    def crest(self) -> Float[Array, ""]:
        """Σ a_i (m): the highest the components can reach together."""
        return jnp.sum(self.amplitudes)

    def _theta(self, x, y):
        """θ_i less −ω_i t, shape `(*batch, components)`, and the unit headings."""
        beta = jnp.deg2rad(self.headings)
        along = jnp.asarray(x)[..., None] * jnp.cos(beta) + jnp.asarray(y)[..., None] * jnp.sin(beta)
        return self.wavenumbers * along + self.phases, beta

    def elevation(self, x, y, t):
        theta, _ = self._theta(x, y)
        omega = 2 * jnp.pi / self.periods
        return jnp.sum(self.amplitudes * jnp.cos(theta - omega * jnp.asarray(t)[..., None]), axis=-1)

    def velocity(self, position, t):
        position = jnp.asarray(position, dtype=float)
        theta, beta = self._theta(position[..., 0], position[..., 1])
        omega = 2 * jnp.pi / self.periods
        theta = theta - omega * jnp.asarray(t)[..., None]
        z = position[..., 2]
        if self.wheeler:
            eta = jnp.sum(self.amplitudes * jnp.cos(theta), axis=-1)
            z = self.depth * (z - eta) / (self.depth + eta)
        k, d = self.wavenumbers, self.depth
        z = jnp.where(z > 0.0, 0.0, jnp.where(z < -d, -d, z))[..., None]
        # As Airy.velocity: decaying exponentials, so that deep water does not overflow.
        decay, image = jnp.exp(k * z), jnp.exp(-k * (z + 2 * d))
        scale = self.amplitudes * omega / (1 - jnp.exp(-2 * k * d))
        u = scale * (decay + image) * jnp.cos(theta)
        w = scale * (decay - image) * jnp.sin(theta)
        return jnp.stack(
            [jnp.sum(u * jnp.cos(beta), axis=-1), jnp.sum(u * jnp.sin(beta), axis=-1), jnp.sum(w, axis=-1)], axis=-1
        )


def moordyn_phase(phase: RealLike, *, sine: bool) -> np.ndarray:
    """θ₀ (rad) for a MoorDyn component of complex amplitude phase φ = arg Z: MoorDyn's
    summed components (`WaveKin = 7`) write η = |Z| sin(ωt − kx + φ), its FFT grids
    (`WaveKin = 2, 3`) η = |Z| cos(ωt − kx + φ); jaxcable's θ = kx − ωt + θ₀."""
    phase = np.asarray(phase, dtype=float)
    return np.pi / 2 - phase if sine else -phase
