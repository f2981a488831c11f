"""Regular waves: the water's velocity and acceleration below the surface.

A wave is an `eqx.Module` of float parameters (height, period, depth, heading, ...) and
the quantities solved from them at construction (wavenumber, frequency, ...). Build a
new wave to change a parameter: `eqx.tree_at` on `height` alone would leave the solved
quantities stale. Every solve is written in JAX, so a wave built inside `jit`, `vmap`
or `grad` is traced, and a sweep over wave steepness compiles once.

Frame: z up, still-water level z = 0, seabed z = −d. A wave travels towards its
`heading` β (degrees, from +x towards +y); `x_β = x cos β + y sin β`.
"""

import abc

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

from .. import _checks as checks
from .._typing import RealLike, RealScalarLike

BREAKING_HEIGHT_RATIO = 0.78
"""H/d, McCowan's (1894) limit: the highest solitary wave, the shallow-water bound."""
BREAKING_STEEPNESS = 0.142
"""H/λ in deep water, Miche's (1944) limit, which is `0.142 tanh(2π d/λ)` at depth d."""


def breaking_height(wavelength: RealLike, depth: RealLike) -> Array:
    """The height (m) past which a regular wave of `wavelength` λ (m) in water of `depth`
    d (m) breaks: the lesser of Miche's `0.142 λ tanh(2π d/λ)` and McCowan's `0.78 d`.

    Miche's limit holds for periodic waves at any depth; in shallow water it tends to
    0.89 d, and McCowan's solitary-wave bound is the lower there. No regular wave
    theory (Airy, cnoidal, Stokes) describes a wave past it: it has broken.
    """
    wavelength, depth = jnp.asarray(wavelength), jnp.asarray(depth)
    miche = BREAKING_STEEPNESS * wavelength * jnp.tanh(2 * jnp.pi * depth / wavelength)
    return jnp.minimum(miche, BREAKING_HEIGHT_RATIO * depth)


def floater_amplitude(period: RealScalarLike = 5.6, gravity: RealScalarLike = 9.81) -> Float[ArrayLike, ""]:
    """The anchored-line paper's wave amplitude law, `A = 0.085 (g T² / 2π)^0.75` (m).

    Bezverkhyy & Korniienko use it for the amplitude of a floating object's motion
    at wave period `period` T (s), 5.6 s in their study; `g T² / 2π` is the deep-water
    wavelength (m). Concrete values are worked in numpy, which compiles nothing.
    """
    xp = jnp if checks.traced((period, gravity)) else np
    return 0.085 * (xp.square(period) * gravity / (2 * np.pi)) ** 0.75


def _check_wave(name: str, height, period, depth, gravity, heading, phase):
    fields = {}
    for field, value in (
        ("height", height),
        ("period", period),
        ("depth", depth),
        ("gravity", gravity),
        ("heading", heading),
        ("phase", phase),
    ):
        fields[field] = checks.float_array(f"{name}.{field}", value, ())
    for field in ("height", "period", "depth", "gravity"):
        checks.positive(f"{name}.{field}", fields[field])
    return fields


class AbstractWave(eqx.Module):
    """A regular wave: its surface and the water's kinematics below it.

    Subclasses set the parameters and implement `elevation` and `velocity`;
    `acceleration` is the exact time derivative of `velocity` at a fixed point, by
    forward-mode differentiation, unless a subclass gives a closed form.
    """

    height: eqx.AbstractVar[Float[Array, ""]]
    period: eqx.AbstractVar[Float[Array, ""]]
    depth: eqx.AbstractVar[Float[Array, ""]]
    gravity: eqx.AbstractVar[Float[Array, ""]]
    heading: eqx.AbstractVar[Float[Array, ""]]

    def conditions(self) -> list[checks.Condition]:
        """What the fields require: checked at construction on concrete values and, on
        traced or swept ones, by `simulate`, `solve_statics` and `sweep`."""
        name = type(self).__name__
        fields = ("height", "period", "depth", "gravity", "heading", "phase")
        out = [checks.finite(f"{name}.{field}", getattr(self, field)) for field in fields]
        return out + [checks.sign(f"{name}.{field}", getattr(self, field)) for field in fields[:4]] + [self._unbroken()]

    def _unbroken(self) -> checks.Condition:
        """The height is at most [`breaking_height`][jaxcable._sea.waves.breaking_height]."""
        name = type(self).__name__
        limit = breaking_height(self.wavelength, self.depth)

        def detail() -> str:
            length, depth, height = float(self.wavelength), float(self.depth), float(self.height)
            miche = BREAKING_STEEPNESS * np.tanh(2 * np.pi * depth / length)
            return (
                f"{name}.height must be at most the breaking height {float(limit):.4g} m, got {height:g} m "
                f"(T = {float(self.period):g} s, λ = {length:.4g} m, d = {depth:g} m): H/λ = {height / length:.3g} "
                f"against Miche's 0.142 tanh(2πd/λ) = {miche:.3g}, and H/d = {height / depth:.3g} against "
                f"McCowan's {BREAKING_HEIGHT_RATIO}; no regular wave of this height and period exists"
            )

        return checks.Condition(
            f"{name}.height", self.height > limit, self.height, "must be at most the breaking height", detail
        )

    @property
    @abc.abstractmethod
    def wavelength(self) -> Float[Array, ""]:
        """λ (m)."""

    @property
    @abc.abstractmethod
    def crest(self) -> Float[Array, ""]:
        """The crest's elevation η_c (m) above the still-water level."""

    @abc.abstractmethod
    def elevation(
        self, x: Float[Array | np.ndarray, "*batch"], y: Float[Array | np.ndarray, "*batch"], t
    ) -> Float[Array, "*batch"]:
        """The surface elevation η (m) above the still-water level at `(x, y)` (m) and
        time `t` (s)."""

    @abc.abstractmethod
    def velocity(self, position: Float[Array | np.ndarray, "*batch 3"], t) -> Float[Array, "*batch 3"]:
        """The water velocity (m/s) at `position` (m), shape `(..., 3)`, and time `t` (s)."""

    def acceleration(self, position: Float[Array | np.ndarray, "*batch 3"], t) -> Float[Array, "*batch 3"]:
        """The local acceleration ∂u/∂t (m/s²) at a fixed `position` (m) and time `t` (s).

        Morison's inertia force uses the local acceleration, as is common practice (and
        MoorDyn's); the convective part is of second order in the wave height."""
        t = jnp.asarray(t, dtype=float)
        return jax.jvp(lambda s: self.velocity(position, s), (t,), (jnp.ones_like(t),))[1]

    @property
    def steepness(self) -> Float[Array, ""]:
        """H / λ (–)."""
        return self.height / self.wavelength

    @property
    def ursell(self) -> Float[Array, ""]:
        """The Ursell number U = H λ² / d³ (–): nonlinearity H/d over dispersion (d/λ)²."""
        return self.height * jnp.square(self.wavelength) / self.depth**3

    def _along(self, x, y):
        """The distance (m) along the heading, x_β."""
        beta = jnp.deg2rad(self.heading)
        return x * jnp.cos(beta) + y * jnp.sin(beta)

    def _horizontal(self, speed, vertical):
        """`(u cos β, u sin β, w)` from the speed u along the heading and w."""
        beta = jnp.deg2rad(self.heading)
        return jnp.stack([speed * jnp.cos(beta), speed * jnp.sin(beta), vertical], axis=-1)


def airy_wavenumber(period: RealLike, depth: RealLike, gravity: RealScalarLike = 9.81) -> Array:
    """The wavenumber k (1/m) of the linear dispersion relation ω² = g k tanh(k d).

    Starts from Guo's (2002) explicit approximation, within 0.75 % everywhere, and
    takes four Newton steps, which converge quadratically to machine precision.
    The steps are differentiated as they stand: at convergence that is the implicit
    derivative.

    **Arguments:**

    - `period`: T (s).
    - `depth`: d (m).
    - `gravity`: g (m/s²).
    """
    omega = 2 * jnp.pi / jnp.asarray(period, dtype=float)
    depth = jnp.asarray(depth, dtype=float)
    deep = omega**2 / gravity
    kd = deep * depth * (1 - jnp.exp(-((omega * jnp.sqrt(depth / gravity)) ** 2.5))) ** -0.4
    for _ in range(4):
        tanh = jnp.tanh(kd)
        residual = kd * tanh - deep * depth
        kd = kd - residual / (tanh + kd * (1 - tanh**2))
    return kd / depth


class Airy(AbstractWave):
    """A linear (Airy) wave in water of finite depth.

    `η = (H/2) cos θ`, `θ = k x_β − ω t + θ₀`, with k from ω² = g k tanh(k d):

        u = (H/2) ω cosh k(z+d) / sinh kd · cos θ,   w = (H/2) ω sinh k(z+d) / sinh kd · sin θ.

    Linear theory describes the water below z = 0. Above it (under a crest) the
    kinematics are those at z = 0 (constant extrapolation), or, with `wheeler=True`,
    Wheeler's stretching evaluates them at `z' = d (z − η) / (d + η)`, which maps the
    water column −d ≤ z ≤ η onto −d ≤ z' ≤ 0. Above the surface the kinematics are
    those at the surface, and below the seabed those at the seabed.

    **Arguments:**

    - `height`: H (m), crest to trough.
    - `period`: T (s).
    - `depth`: d (m), still-water depth.
    - `gravity`: g (m/s²).
    - `heading`: β (degrees), the direction of travel from +x towards +y.
    - `phase`: θ₀ (rad); 0 puts a crest at x_β = 0 at t = 0.
    - `wheeler`: use Wheeler stretching above and below the still-water level.

    **Raises:**

    `ValueError` for a non-positive height, period, depth or gravity, or a height past
    the breaking limit ([`breaking_height`][jaxcable._sea.waves.breaking_height]: Miche's
    H/λ ≤ 0.142 tanh(2π d/λ), McCowan's H/d ≤ 0.78).
    """

    height: Float[Array, ""]
    period: Float[Array, ""]
    depth: Float[Array, ""]
    gravity: Float[Array, ""]
    heading: Float[Array, ""]
    phase: Float[Array, ""]
    wavenumber: Float[Array, ""]
    wheeler: bool = eqx.field(static=True)

    def __init__(
        self, height, period, depth, *, gravity: RealScalarLike = 9.81, heading=0.0, phase=0.0, wheeler: bool = False
    ):
        fields = _check_wave("Airy", height, period, depth, gravity, heading, phase)
        for name, value in fields.items():
            setattr(self, name, value)
        if not isinstance(wheeler, bool):
            raise ValueError(f"Airy.wheeler must be True or False, got {wheeler!r}")
        self.wheeler = wheeler
        self.wavenumber = airy_wavenumber(self.period, self.depth, self.gravity)
        checks.enforce([self._unbroken()])

    @classmethod
    def from_steepness(cls, steepness, period, depth, **kwargs) -> "Airy":
        """The Airy wave of steepness H/λ = `steepness` (–); the other arguments as
        for `Airy`. λ does not depend on H in linear theory."""
        k = airy_wavenumber(period, depth, kwargs.get("gravity", 9.81))
        return cls(steepness * 2 * jnp.pi / k, period, depth, **kwargs)

    @property
    def angular_frequency(self) -> Float[Array, ""]:
        """ω = 2π / T (rad/s)."""
        return 2 * jnp.pi / self.period

    @property
    def wavelength(self) -> Float[Array, ""]:
        return 2 * jnp.pi / self.wavenumber

    @property
    def crest(self) -> Float[Array, ""]:
        return 0.5 * self.height

    def stokes_drift(self, z: RealLike) -> Float[Array, "*z"]:
        """The Stokes drift (m/s) along the heading at mean depth `z` (m, ≤ 0): the mean
        speed of a water particle, to second order in the steepness,

            u_s = a² ω k cosh 2k(z+d) / (2 sinh² kd),   a = H/2,

        which is `a² ω k e^{2kz}` in deep water (Phillips, *The dynamics of the upper
        ocean*, 1977, §3.3)."""
        k, d = self.wavenumber, self.depth
        a = 0.5 * self.height
        return a**2 * self.angular_frequency * k * jnp.cosh(2 * k * (jnp.asarray(z) + d)) / (2 * jnp.sinh(k * d) ** 2)

    def _theta(self, x, y, t):
        return self.wavenumber * self._along(x, y) - self.angular_frequency * t + self.phase

    def elevation(self, x, y, t):
        return 0.5 * self.height * jnp.cos(self._theta(x, y, t))

    def velocity(self, position, t):
        x, y, z = position[..., 0], position[..., 1], position[..., 2]
        theta = self._theta(x, y, t)
        if self.wheeler:
            eta = 0.5 * self.height * jnp.cos(theta)
            z = self.depth * (z - eta) / (self.depth + eta)
        # Clamp to the water column; `where`, unlike `clip`, keeps the full derivative
        # at its ends.
        k, d = self.wavenumber, self.depth
        z = jnp.where(z > 0.0, 0.0, jnp.where(z < -d, -d, z))
        # cosh k(z+d) / sinh kd and sinh k(z+d) / sinh kd, written with decaying
        # exponentials so that deep water (kd ≫ 1) does not overflow.
        decay, image = jnp.exp(k * z), jnp.exp(-k * (z + 2 * d))
        denominator = 1 - jnp.exp(-2 * k * d)
        scale = 0.5 * self.height * self.angular_frequency
        u = scale * (decay + image) / denominator * jnp.cos(theta)
        w = scale * (decay - image) / denominator * jnp.sin(theta)
        return self._horizontal(u, w)
