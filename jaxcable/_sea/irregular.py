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

[`WaveComponents.from_spectrum`][] realises a sea state ([`jaxcable.Jonswap`][]) with
random phases from a seed.

**Why equal frequency steps.** The components sit at the middles of N equal steps
Δω = (ω_max − ω_min)/N, with a_i = √(2 S(ω_i) Δω) (the midpoint rule for m₀, exact to
O(Δω²)). Such a sea repeats, up to one phase shift common to all components, after
2π/Δω: that is the longest record it supports, and a longer run only repeats its
statistics. Equal-area (equal-energy) steps, each component carrying m₀/N, do not
repeat, but their frequencies move with T_p and γ, and a phase ω_i(T_p) t then moves
by t ∂ω_i/∂T_p: the derivative of a response at time t with respect to the sea state
grows with t, and a gradient of the maximum tension over a long record is noise. On
fixed steps only the amplitudes depend on H_s, T_p and γ, smoothly, and the periods
and wavenumbers are the same for every sea state of a sweep (one dispersion solve, not
one per case). So: equal steps, N ≥ (ω_max − ω_min) D/(2π) components for a record of
D s.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float

from .. import _checks as checks
from .._typing import RealLike, RealScalarLike
from .spectrum import Jonswap, random_key, spreading_angles
from .waves import AbstractWave, airy_wavenumber

VARIANCE_TOLERANCE = 0.01
"""How far the components' variance Σ a_i²/2 may be from the spectrum's m₀ = H_s²/16,
as a fraction of m₀, in [`WaveComponents.from_spectrum`][]."""


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

    @classmethod
    def from_spectrum(
        cls,
        spectrum: Jonswap,
        depth: RealScalarLike,
        *,
        seed,
        components: int,
        frequencies: tuple[RealScalarLike, RealScalarLike],
        heading: RealScalarLike = 0.0,
        spreading: RealScalarLike | None = None,
        gravity: RealScalarLike = 9.81,
        wheeler: bool = False,
    ) -> "WaveComponents":
        """A realisation of a sea state: `components` Airy components on equal steps of
        frequency (see the module docstring for why), with random phases from `seed`.

        Component i has ω_i = ω_min + (i + ½) Δω, Δω = (ω_max − ω_min)/N, amplitude
        a_i = √(2 S(ω_i) Δω) and a phase drawn uniformly from [0, 2π). With
        `spreading` s, its heading is drawn from the cos-2s distribution about
        `heading` (one direction per frequency, the "single summation" that keeps
        the sea ergodic): at the cumulative probability (p_i + v_i)/N, p a random
        permutation of 0 … N − 1 and v_i uniform in [0, 1), so that the N headings
        fill the distribution evenly whatever the seed.

        Every step is JAX: a `vmap` over seeds (and over H_s, T_p, γ, s) builds a batch
        of seas in one program, and the amplitudes differentiate in H_s, T_p, γ (the
        headings in s). The sea repeats after 2π/Δω s
        ([`repeat_period`][jaxcable._sea.irregular.repeat_period]).

        **Arguments:**

        - `spectrum`: a [`jaxcable.Jonswap`][].
        - `depth`: d (m), still-water depth.
        - `seed`: a `jax.random.key`, or an integer from 0 to 2³² − 1 (a float of
            integer value, as [`jaxcable.sweep`][] passes its parameters, too).
        - `components`: N, a positive integer.
        - `frequencies`: (ω_min, ω_max) (rad/s), the band the components cover.
        - `heading`: the mean heading θ̄ (degrees), the direction of travel.
        - `spreading`: s (–), the cos-2s exponent, positive; `None` (default) for a
            long-crested sea, every component at `heading`.
        - `gravity`, `wheeler`: as for `WaveComponents`.

        **Raises:**

        `ValueError` naming the argument for a bad count, band, seed or spreading,
        and, for concrete values, if the components' variance Σ a_i²/2 differs from
        m₀ = H_s²/16 by more than 1 % (`VARIANCE_TOLERANCE`): the band misses part of
        the spectrum, or the steps are too coarse for its peak. A traced spectrum (in a
        sweep, its first case is built concretely and checked) is not checked.
        """
        if not isinstance(spectrum, Jonswap):
            raise ValueError(f"WaveComponents.from_spectrum: spectrum must be a jaxcable.Jonswap, got {spectrum!r}")
        if not (isinstance(components, int | np.integer) and not isinstance(components, bool) and components >= 1):
            raise ValueError(f"WaveComponents.from_spectrum: components must be a positive integer, got {components!r}")
        try:
            low, high = frequencies
        except (TypeError, ValueError):
            raise ValueError(
                f"WaveComponents.from_spectrum: frequencies must be (ω_min, ω_max) in rad/s, got {frequencies!r}"
            ) from None
        low = checks.float_array("WaveComponents.from_spectrum: frequencies[0]", low, ())
        high = checks.float_array("WaveComponents.from_spectrum: frequencies[1]", high, ())
        checks.enforce(
            [
                checks.sign("WaveComponents.from_spectrum: frequencies[0] (ω_min, rad/s)", low),
                checks.sign("WaveComponents.from_spectrum: frequencies[1] − frequencies[0] (rad/s)", high - low),
            ]
        )
        key = random_key(seed, "WaveComponents.from_spectrum: seed")
        name = "WaveComponents.from_spectrum: "
        heading = checks.float_array(name + "heading", heading, ())
        if spreading is not None:
            spreading = checks.float_array(name + "spreading", spreading, ())
            checks.positive(name + "spreading", spreading)
        depth = checks.float_array("WaveComponents.depth", depth, ())
        gravity = checks.float_array("WaveComponents.gravity", gravity, ())
        if not isinstance(wheeler, bool):
            raise ValueError(f"WaveComponents.wheeler must be True or False, got {wheeler!r}")
        # One compiled program per component count (and spreading or not): eagerly,
        # its fifty-odd operations compiled one by one took seconds.
        sea = _realise(cls, spectrum, depth, gravity, key, low, high, heading, spreading, components, wheeler)
        checks.enforce(sea.conditions())
        checks.enforce([_variance_condition(sea, spectrum, low, high, components)])
        return sea

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


@eqx.filter_jit
def _realise(cls, spectrum, depth, gravity, key, low, high, heading, spreading, components, wheeler):
    """The components of `WaveComponents.from_spectrum`, from checked arguments."""
    step = (high - low) / components
    omega = low + step * (jnp.arange(components) + 0.5)
    amplitudes = jnp.exp(0.5 * (jnp.log(2 * step) + spectrum.log_density(omega)))
    phase_key, direction_key = jax.random.split(key)
    phases = jax.random.uniform(phase_key, (components,), maxval=2 * jnp.pi)
    headings = heading
    if spreading is not None:
        order_key, jitter_key = jax.random.split(direction_key)
        strata = jax.random.permutation(order_key, components)
        probabilities = (strata + jax.random.uniform(jitter_key, (components,))) / components
        headings = heading + jnp.rad2deg(spreading_angles(spreading, probabilities))
    return cls(
        amplitudes, 2 * jnp.pi / omega, depth, gravity=gravity, headings=headings, phases=phases, wheeler=wheeler
    )


def repeat_period(sea: WaveComponents) -> float:
    """The time (s) after which `sea` repeats, up to one phase shift common to all its
    components: 2π/Δω when its frequencies are equally spaced by Δω (as
    [`WaveComponents.from_spectrum`][] and MoorDyn's FFT grids make them), `inf`
    otherwise (and for one component)."""
    omega = np.unique(2 * np.pi / np.asarray(sea.periods))
    if omega.size < 2:
        return float("inf")
    steps = np.diff(omega)
    if np.ptp(steps) > 1e-9 * omega[-1]:
        return float("inf")
    return float(2 * np.pi / steps.mean())


def _variance_condition(sea, spectrum, low, high, components) -> checks.Condition:
    """Σ a_i²/2 within `VARIANCE_TOLERANCE` of H_s²/16."""
    ratio = sea.variance / spectrum.variance
    if not checks.traced(ratio):
        ratio = np.asarray(ratio)

    def detail() -> str:
        return (
            f"WaveComponents.from_spectrum: the {components} components between {float(low):.4g} and "
            f"{float(high):.4g} rad/s hold {100 * float(ratio):.2f} % of the spectrum's m₀ = H_s²/16 "
            f"(H_s = {float(spectrum.significant_height):g} m, T_p = {float(spectrum.peak_period):g} s, "
            f"γ = {float(spectrum.peak_enhancement):g}, ω_p = {float(spectrum.peak_frequency):.4g} rad/s), "
            f"not within {100 * VARIANCE_TOLERANCE:g} %: widen frequencies (a Pierson–Moskowitz sea has 99.6 % "
            "of m₀ between 0.65 and 4.5 ω_p) or, if the peak is coarsely stepped, add components"
        )

    return checks.Condition(
        "WaveComponents.from_spectrum: frequencies",
        abs(ratio - 1) > VARIANCE_TOLERANCE,
        ratio,
        f"must hold the spectrum's m₀ within {100 * VARIANCE_TOLERANCE:g} %",
        detail,
    )
