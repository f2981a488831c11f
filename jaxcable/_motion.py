"""Boundary conditions: how a constrained node moves.

A constrained node's position is its reference position plus a displacement that is a
known function of time. Its degrees of freedom are removed from the unknowns (seed 003,
eq. 8), and the velocity and acceleration that the equations need are the displacement's
time derivatives, taken here by forward-mode differentiation so that each motion only
has to say where the node is.
"""

import abc

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

from . import _checks as checks
from ._typing import RealLike


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

    def conditions(self) -> list[checks.Condition]:
        """What the fields require: checked at construction on concrete values and, on
        traced or swept ones, by `simulate`, `solve_statics` and `sweep`."""
        return []


def ramp_factor(t: Float[ArrayLike, ""], ramp: Float[ArrayLike, ""]) -> Float[Array, ""]:
    """The smoothstep f = u³(6u² − 15u + 10), u = t / ramp, rising from 0 at t = 0 to 1 at
    `ramp` (s) with zero first and second derivatives at both ends; 1 throughout when
    `ramp` is 0."""
    ramped = jnp.asarray(ramp) > 0
    u = jnp.clip(t / jnp.where(ramped, ramp, 1.0), 0.0, 1.0)
    return jnp.where(ramped, u**3 * (6 * u**2 - 15 * u + 10), 1.0)


class Fixed(AbstractMotion):
    """A node held at its reference position (an anchor)."""

    def displacement(self, t):
        return jnp.zeros(3) * jnp.asarray(t, dtype=float)


class Harmonic(AbstractMotion):
    """`r(t) = f(t) A sin(ω t + φ) e`, seed 003's fairlead motion (eq. 6), optionally
    switched on smoothly.

    Without a ramp (f = 1) a motion that does not start at rest jerks the line at
    t = 0: the velocity jumps to A ω cos φ. Over `ramp` seconds, f rises as the
    smoothstep u³(6u² − 15u + 10), u = t / ramp, whose first and second derivatives
    vanish at both ends, so the velocity and acceleration start from zero (the Low &
    Langley jumper's cases are driven this way over one period).

    **Arguments:**

    - `amplitude`: A (m).
    - `period`: T = 2π/ω (s).
    - `direction`: e, a 3-vector, normalised here.
    - `phase`: φ (rad).
    - `ramp`: the time (s) over which the motion is switched on; 0 for none.
    """

    amplitude: Float[Array, ""]
    period: Float[Array, ""]
    direction: Float[Array, "3"]
    phase: Float[Array, ""]
    ramp: Float[Array, ""]

    def __init__(self, amplitude: RealLike, period: RealLike, direction=(1.0, 0.0, 0.0), phase=0.0, ramp=0.0):
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
        self.ramp = checks.float_array("Harmonic.ramp", ramp, ())
        checks.positive("Harmonic.ramp", self.ramp, allow_zero=True)

    def conditions(self):
        return [
            checks.finite("Harmonic.amplitude", self.amplitude),
            checks.finite("Harmonic.period", self.period),
            checks.sign("Harmonic.period", self.period),
            # A zero direction, normalised under tracing, comes out NaN.
            checks.finite("Harmonic.direction", self.direction),
            checks.finite("Harmonic.phase", self.phase),
            checks.finite("Harmonic.ramp", self.ramp),
            checks.sign("Harmonic.ramp", self.ramp, allow_zero=True),
        ]

    def displacement(self, t):
        omega = 2 * jnp.pi / self.period
        return ramp_factor(t, self.ramp) * self.amplitude * jnp.sin(omega * t + self.phase) * self.direction


class Sampled(AbstractMotion):
    """A displacement given as a time series, interpolated by a natural cubic spline.

    The spline is C², so the velocity and acceleration that the equations need converge
    with the sampling (the acceleration at second order away from the ends; the natural
    end conditions set it to zero at the first and last sample). Outside the sampled
    interval the end values are held.

    **Arguments:**

    - `times`: sample times (s), shape `(samples,)`, strictly increasing.
    - `displacements`: displacements (m), shape `(samples, 3)`.
    """

    times: Float[Array, " samples"]
    displacements: Float[Array, "samples 3"]
    curvatures: Float[Array, "samples 3"]

    def __init__(self, times: RealLike, displacements: RealLike):
        times = checks.float_array("Sampled.times", times)
        displacements = checks.float_array("Sampled.displacements", displacements)
        if times.ndim != 1 or times.shape[0] < 2:
            raise ValueError(f"Sampled.times must be 1-D with at least 2 samples, got shape {times.shape}")
        if displacements.shape != (times.shape[0], 3):
            raise ValueError(
                f"Sampled.displacements must have shape ({times.shape[0]}, 3) to match "
                f"Sampled.times, got {displacements.shape}"
            )
        checks.enforce([checks.increasing("Sampled.times", times)])
        self.times = times
        self.displacements = displacements
        self.curvatures = _natural_spline_curvatures(times, displacements)

    def conditions(self):
        return [
            checks.finite("Sampled.times", self.times),
            checks.increasing("Sampled.times", self.times),
            checks.finite("Sampled.displacements", self.displacements),
        ]

    def displacement(self, t):
        ts, ys, ms = self.times, self.displacements, self.curvatures
        # Not `clip`: its derivative is ½ where t equals an end sample, which would halve
        # the velocity at the last output time. `where` keeps the inside derivative there.
        t = jnp.where(t < ts[0], ts[0], jnp.where(t > ts[-1], ts[-1], t))
        k = jnp.clip(jnp.searchsorted(ts, t, side="right") - 1, 0, ts.shape[0] - 2)
        h = ts[k + 1] - ts[k]
        a, b = (ts[k + 1] - t) / h, (t - ts[k]) / h
        return a * ys[k] + b * ys[k + 1] + ((a**3 - a) * ms[k] + (b**3 - b) * ms[k + 1]) * h**2 / 6


def _natural_spline_curvatures(times: Array, values: Array) -> Array:
    """Second derivatives at the knots of the natural cubic spline through `values`
    (shape `(samples, 3)`): the tridiagonal system of the C² conditions, with zero
    curvature at both ends."""
    if times.shape[0] < 3:
        return jnp.zeros_like(values)
    h = jnp.diff(times)
    slopes = jnp.diff(values, axis=0) / h[:, None]
    rhs = 6 * jnp.diff(slopes, axis=0)
    lower = jnp.concatenate([jnp.zeros(1), h[1:-1]])
    upper = jnp.concatenate([h[1:-1], jnp.zeros(1)])
    interior = jax.lax.linalg.tridiagonal_solve(lower, 2 * (h[:-1] + h[1:]), upper, rhs)
    zero = jnp.zeros((1, values.shape[1]))
    return jnp.concatenate([zero, interior, zero])


class Towing(AbstractMotion):
    """A tow point moving along `direction` at a speed history: the velocity is the
    piecewise-linear interpolation of `speeds` at `times`, and the displacement its
    exact integral, zero at `times[0]`. Before the first and after the last sample the
    speed holds its end value.

    Piecewise-linear, not a spline: a towing record's speed is a measured input, and a
    spline through a speed step (seed 002's 1 → 3 m/s) would overshoot it. The
    acceleration steps at each sample; with the lumped mass matrix it enters only the
    support's reaction, not the free nodes' equations, so the solver does not see the
    steps. Smooth a noisy measured speed before using it: its differences are
    accelerations.

    **Arguments:**

    - `times`: sample times (s), shape `(samples,)`, strictly increasing.
    - `speeds`: the speed (m/s) at each sample, shape `(samples,)`.
    - `direction`: the towing direction, a 3-vector, normalised here; +x by default.
    """

    times: Float[Array, " samples"]
    speeds: Float[Array, " samples"]
    direction: Float[Array, "3"]
    distances: Float[Array, " samples"]

    def __init__(self, times: RealLike, speeds: RealLike, direction=(1.0, 0.0, 0.0)):
        times = checks.float_array("Towing.times", times)
        if times.ndim != 1 or times.shape[0] < 2:
            raise ValueError(f"Towing.times must be 1-D with at least 2 samples, got shape {times.shape}")
        speeds = checks.float_array("Towing.speeds", speeds)
        if speeds.shape != times.shape:
            raise ValueError(f"Towing.speeds must have shape {times.shape} to match Towing.times, got {speeds.shape}")
        checks.enforce([checks.increasing("Towing.times", times)])
        direction = checks.float_array("Towing.direction", direction)
        if direction.shape != (3,):
            raise ValueError(f"Towing.direction must have shape (3,), got {direction.shape}")
        norm = jnp.linalg.norm(direction)
        checks.positive("Towing.direction (its length)", norm)
        self.times = times
        self.speeds = speeds
        self.direction = direction / norm
        # The distance run at each sample: the trapezoid rule is exact for linear speed.
        steps = 0.5 * (speeds[1:] + speeds[:-1]) * jnp.diff(times)
        self.distances = jnp.concatenate([jnp.zeros(1), jnp.cumsum(steps)])

    def conditions(self):
        return [
            checks.finite("Towing.times", self.times),
            checks.increasing("Towing.times", self.times),
            checks.finite("Towing.speeds", self.speeds),
            checks.finite("Towing.direction", self.direction),
        ]

    def displacement(self, t):
        ts, vs = self.times, self.speeds
        k = jnp.clip(jnp.searchsorted(ts, t, side="right") - 1, 0, ts.shape[0] - 2)
        s = t - ts[k]
        slope = (vs[k + 1] - vs[k]) / (ts[k + 1] - ts[k])
        inside = self.distances[k] + vs[k] * s + 0.5 * slope * s**2
        before = vs[0] * (t - ts[0])
        after = self.distances[-1] + vs[-1] * (t - ts[-1])
        distance = jnp.where(t < ts[0], before, jnp.where(t > ts[-1], after, inside))
        return distance * self.direction
