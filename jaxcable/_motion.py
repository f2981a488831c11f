"""Boundary conditions: how a constrained node moves.

A constrained node's position is its reference position plus a displacement that is a
known function of time. Its degrees of freedom are removed from the unknowns (seed 003,
eq. 8), and the velocity and acceleration that the equations need are the displacement's
time derivatives, taken here by forward-mode differentiation so that each motion only
has to say where the node is.
"""

import abc

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

from . import _checks as checks


class AbstractMotion(eqx.Module):
    """A prescribed displacement `r(t)` of a node from its reference position."""

    @abc.abstractmethod
    def displacement(self, t: Float[ArrayLike, ""]) -> Float[Array, "3"]:
        """The displacement (m) at time `t` (s)."""

    def kinematics(self, t: Float[ArrayLike, ""]) -> tuple[Array, Array, Array]:
        """Displacement (m), velocity (m/s) and acceleration (m/s²) at time `t` (s)."""
        t = jnp.asarray(t, dtype=float)

        def velocity(time):
            return jax.jvp(self.displacement, (time,), (jnp.ones_like(time),))

        (r, v), (_, a) = jax.jvp(velocity, (t,), (jnp.ones_like(t),))
        return r, v, a


class Fixed(AbstractMotion):
    """A node held at its reference position (an anchor)."""

    def displacement(self, t):
        return jnp.zeros(3) * jnp.asarray(t, dtype=float)


class Harmonic(AbstractMotion):
    """`r(t) = A sin(ω t + φ) e`, seed 003's fairlead motion (eq. 6).

    **Arguments:**

    - `amplitude`: A (m).
    - `period`: T = 2π/ω (s).
    - `direction`: e, a 3-vector, normalised here.
    - `phase`: φ (rad).
    """

    amplitude: Float[Array, ""]
    period: Float[Array, ""]
    direction: Float[Array, "3"]
    phase: Float[Array, ""]

    def __init__(self, amplitude: ArrayLike, period: ArrayLike, direction=(1.0, 0.0, 0.0), phase=0.0):
        direction = checks.float_array("Harmonic.direction", direction)
        if direction.shape != (3,):
            raise ValueError(f"Harmonic.direction must have shape (3,), got {direction.shape}")
        norm = jnp.linalg.norm(direction)
        checks.positive("Harmonic.direction (its length)", norm)
        self.amplitude = checks.float_array("Harmonic.amplitude", amplitude, ())
        self.period = checks.float_array("Harmonic.period", period, ())
        checks.positive("Harmonic.period", self.period)
        self.direction = direction / norm
        self.phase = checks.float_array("Harmonic.phase", phase, ())

    def displacement(self, t):
        omega = 2 * jnp.pi / self.period
        return self.amplitude * jnp.sin(omega * t + self.phase) * self.direction


class Sampled(AbstractMotion):
    """A displacement given as a time series, interpolated by piecewise cubic Hermite
    polynomials (C¹, so the velocity is continuous and the acceleration piecewise
    continuous). Outside the sampled interval the end values are held.

    **Arguments:**

    - `times`: sample times (s), shape `(samples,)`, strictly increasing.
    - `displacements`: displacements (m), shape `(samples, 3)`.
    """

    interpolation: diffrax.CubicInterpolation

    def __init__(self, times: ArrayLike, displacements: ArrayLike):
        times = checks.float_array("Sampled.times", times)
        displacements = checks.float_array("Sampled.displacements", displacements)
        if times.ndim != 1 or times.shape[0] < 2:
            raise ValueError(f"Sampled.times must be 1-D with at least 2 samples, got shape {times.shape}")
        if displacements.shape != (times.shape[0], 3):
            raise ValueError(
                f"Sampled.displacements must have shape ({times.shape[0]}, 3) to match "
                f"Sampled.times, got {displacements.shape}"
            )
        if checks.is_concrete(times) and not bool(jnp.all(jnp.diff(times) > 0)):
            raise ValueError("Sampled.times must be strictly increasing")
        coefficients = diffrax.backward_hermite_coefficients(times, displacements)
        self.interpolation = diffrax.CubicInterpolation(times, coefficients)

    def displacement(self, t):
        ts = self.interpolation.ts
        return self.interpolation.evaluate(jnp.clip(t, ts[0], ts[-1]))

