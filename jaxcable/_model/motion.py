"""Boundary conditions: how a constrained node moves.

A constrained node's position is its reference position plus a displacement that is a
known function of time. Its degrees of freedom are removed from the unknowns (Bezverkhyy & Korniienko,
eq. 8), and the velocity and acceleration that the equations need are the displacement's
time derivatives, taken here by forward-mode differentiation so that each motion only
has to say where the node is.
"""

import abc

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

from .. import _checks as checks
from .._names import INTERPOLATIONS as INTERPOLATIONS
from .._ramp import ramp_factor
from .._typing import RealLike


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

    def excursion(self, duration: float | None = None) -> tuple[float, float, float]:
        """Bounds on the displacement over `0 ≤ t ≤ duration` (s; every time where
        `None`), from concrete fields: `(down, up, reach)` (m), the most it moves in −z
        and in +z, and the largest |r(t)|. Infinite where a motion cannot bound them:
        the default, for a motion of unknown form. They tell which nodes can reach the
        seabed or the surface (`jaxcable._model.reach`)."""
        return np.inf, np.inf, np.inf


class Fixed(AbstractMotion):
    """A node held at its reference position (an anchor)."""

    def displacement(self, t):
        return jnp.zeros(3) * jnp.asarray(t, dtype=float)

    def excursion(self, duration=None):
        return 0.0, 0.0, 0.0


class Harmonic(AbstractMotion):
    """`r(t) = f(t) A sin(ω t + φ) e`, the anchored-line paper's fairlead motion (eq. 6), optionally
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
        # On the host where concrete: eagerly, the norm and the division were programs
        # of their own, compiled in every process that built a motion.
        direction = checks.on_host(direction)
        norm = jnp.linalg.norm(direction) if checks.traced(direction) else np.asarray(np.linalg.norm(direction))
        checks.positive("Harmonic.direction (its length)", norm)
        self.amplitude = checks.float_array("Harmonic.amplitude", amplitude, ())
        self.period = checks.float_array("Harmonic.period", period, ())
        checks.positive("Harmonic.period", self.period)
        self.direction = checks.on_device(direction / norm)
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

    def excursion(self, duration=None):
        # The ramp factor and the sine both stay within [0, 1] and [−1, 1] in magnitude.
        amplitude = abs(float(self.amplitude))
        vertical = amplitude * abs(float(self.direction[2]))
        return vertical, vertical, amplitude


OVERSHOOT_FRACTION = 0.1
"""How far (as a fraction of a coordinate's range over the table) a cubic spline may
stray outside the two samples of an interval before [`jaxcable.Sampled`][] warns. A
sine sampled at 8 points a period strays by up to 4.2 % of its range between samples
(by SciPy's natural spline, over the sampling's phase); a step strays further (a table
stepping from 0 to 100 m can give a spline that runs to −89 and +167 m)."""


class Sampled(AbstractMotion):
    """A displacement given as a time series, interpolated between the samples.

    - `"cubic"` (default): the natural cubic spline. It is C², so the velocity and
        acceleration that the equations need converge with the sampling (the
        acceleration at second order away from the ends; the natural end conditions
        set it to zero at the first and last sample). Between samples it may stray
        outside them: through a step it overshoots and rings, and it warns where it
        strays by more than `OVERSHOOT_FRACTION` of a coordinate's range.
    - `"pchip"`: the monotone piecewise cubic Hermite interpolant (Fritsch & Carlson
        1980, as SciPy's `PchipInterpolator`): C¹, never outside the samples of an
        interval, flat where the samples turn. Its acceleration jumps at the samples.
    - `"linear"`: straight lines between samples; the velocity jumps at each sample
        and the acceleration is zero between them.

    Outside the sampled interval the end values are held. With a `ramp`, the
    displacement is scaled by the smoothstep of [`jaxcable.Harmonic`][]'s ramp, rising
    from 0 at t = 0 to 1 at `ramp`: a table that starts moving (a vessel's record taken
    mid-motion) then starts the support from rest instead of jolting the line.

    **Arguments:**

    - `times`: sample times (s), shape `(samples,)`, strictly increasing.
    - `displacements`: displacements (m), shape `(samples, 3)`.
    - `interpolation`: `"cubic"`, `"pchip"` or `"linear"`.
    - `ramp`: the time (s) over which the motion is switched on; 0 (the default) for
        none.

    **Raises:**

    `ValueError` naming the field for non-finite values, mismatched shapes, fewer than
    two samples, times that do not increase, or an unknown interpolation. Warns (a
    `UserWarning`) where the cubic spline overshoots.
    """

    times: Float[Array, " samples"]
    displacements: Float[Array, "samples 3"]
    slopes: Float[Array, "samples 3"]
    ramp: Float[Array, ""]
    interpolation: str = eqx.field(static=True)

    def __init__(self, times: RealLike, displacements: RealLike, interpolation: str = "cubic", ramp: RealLike = 0.0):
        self.interpolation = checks.option("Sampled.interpolation", interpolation, INTERPOLATIONS)
        self.ramp = checks.float_array("Sampled.ramp", ramp, ())
        checks.positive("Sampled.ramp", self.ramp, allow_zero=True)
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
        if interpolation == "cubic":
            self.slopes = _natural_spline_slopes(times, displacements)
            if not checks.traced((times, displacements)):
                checks.warn([self._overshoot()], stacklevel=3)  # the caller's line, past equinox's frames
        elif interpolation == "pchip":
            self.slopes = _monotone_slopes(times, displacements)
        else:
            self.slopes = jnp.zeros_like(displacements)  # unused: the pieces are straight

    def conditions(self):
        return [
            checks.finite("Sampled.times", self.times),
            checks.increasing("Sampled.times", self.times),
            checks.finite("Sampled.displacements", self.displacements),
            checks.finite("Sampled.ramp", self.ramp),
            checks.sign("Sampled.ramp", self.ramp, allow_zero=True),
        ]

    def displacement(self, t):
        return ramp_factor(t, self.ramp) * self._interpolate(t, derivatives=False)[0]

    def start_velocity(self) -> np.ndarray:
        """The velocity (m/s) at which the table starts, at its first time, before any
        ramp: shape `(3,)`. In numpy: the first piece's velocity at its left end is its
        slope there, or for straight pieces its secant (eagerly, `_interpolate`'s
        operations were a program each, 0.4 s of a first `jaxcable run`)."""
        if self.interpolation == "linear":
            ts, ys = np.asarray(self.times), np.asarray(self.displacements)
            return (ys[1] - ys[0]) / (ts[1] - ts[0])
        return np.asarray(self.slopes)[0]

    def excursion(self, duration=None):
        # Over the whole table, each piece's exact extremes (the end values hold outside
        # it): a bound for any duration. Linear pieces have zero slopes here, a Hermite
        # cubic that stays between its samples as the straight piece does.
        lowest, highest, _ = _hermite_extremes(self.times, self.displacements, self.slopes)
        down, up = max(0.0, -float(np.min(lowest[:, 2]))), max(0.0, float(np.max(highest[:, 2])))
        largest = np.maximum(np.abs(np.min(lowest, axis=0)), np.abs(np.max(highest, axis=0)))
        return down, up, float(np.linalg.norm(largest))

    def kinematics(self, t) -> tuple[Array, Array, Array]:
        # The pieces' derivatives in closed form, from one interval lookup: forward-mode
        # derivatives of `displacement` traced the lookup (a loop) and its
        # polynomial three times over, 25 ms a call, and a Low & Langley run traces the
        # kinematics 11 times. Equal to `AbstractMotion.kinematics` to rounding (tested).
        t = jnp.asarray(t, dtype=float)
        r, v, a = self._interpolate(t, derivatives=True)

        # The ramp's product rule, with the smoothstep's own derivatives (scalars).
        def rate(s):
            return jax.jvp(lambda u: ramp_factor(u, self.ramp), (s,), (jnp.ones_like(s),))[1]

        f, (df, d2f) = ramp_factor(t, self.ramp), jax.jvp(rate, (t,), (jnp.ones_like(t),))
        return f * r, df * r + f * v, d2f * r + 2 * df * v + f * a

    def _interpolate(self, t, derivatives: bool) -> tuple[Array, ...]:
        """The displacement (m) at time `t` (s) and, if `derivatives`, its velocity (m/s)
        and acceleration (m/s²): zero outside the table, the interval's own at its ends."""
        ts, ys, ds = self.times, self.displacements, self.slopes
        # Not `clip`: its derivative is ½ where t equals an end sample, which would halve
        # the velocity at the last output time. `where` keeps the inside derivative there.
        outside = (t < ts[0]) | (t > ts[-1])
        t = jnp.where(t < ts[0], ts[0], jnp.where(t > ts[-1], ts[-1], t))
        k = jnp.clip(jnp.searchsorted(ts, t, side="right") - 1, 0, ts.shape[0] - 2)
        h = ts[k + 1] - ts[k]
        s = (t - ts[k]) / h
        if self.interpolation == "linear":
            r = (1 - s) * ys[k] + s * ys[k + 1]
            if not derivatives:
                return (r,)
            v = (ys[k + 1] - ys[k]) / h
            return r, jnp.where(outside, 0.0, v), jnp.zeros_like(r)
        # Cubic Hermite: the values y and slopes d at both ends of the interval, each
        # with its basis polynomial in s and that polynomial's first two derivatives.
        y0, y1, d0, d1 = ys[k], ys[k + 1], h * ds[k], h * ds[k + 1]
        r = (1 + 2 * s) * (1 - s) ** 2 * y0 + s * (1 - s) ** 2 * d0 + s**2 * (3 - 2 * s) * y1 - s**2 * (1 - s) * d1
        if not derivatives:
            return (r,)
        v = (6 * s * (s - 1) * (y0 - y1) + (3 * s**2 - 4 * s + 1) * d0 + (3 * s**2 - 2 * s) * d1) / h
        a = (6 * (2 * s - 1) * (y0 - y1) + (6 * s - 4) * d0 + (6 * s - 2) * d1) / h**2
        return r, jnp.where(outside, 0.0, v), jnp.where(outside, 0.0, a)

    def _overshoot(self) -> checks.Condition:
        """The cubic strays outside an interval's two samples by more than
        `OVERSHOOT_FRACTION` of the coordinate's range over the table."""
        lowest, highest, excess = _hermite_extremes(self.times, self.displacements, self.slopes)
        ys = np.asarray(self.displacements)
        span = ys.max(axis=0) - ys.min(axis=0)
        bad = excess > OVERSHOOT_FRACTION * span

        def detail() -> str:
            k, axis = (int(i) for i in np.argwhere(bad)[0])
            ts = np.asarray(self.times)
            return (
                f"Sampled: the cubic spline through the table strays from {lowest[k, axis]:.4g} to "
                f"{highest[k, axis]:.4g} m in {'xyz'[axis]} between t = {ts[k]:g} and {ts[k + 1]:g} s, where the "
                f"samples are {ys[k, axis]:g} and {ys[k + 1, axis]:g} m (the table spans {ys[:, axis].min():g} to "
                f"{ys[:, axis].max():g} m): the motion and its accelerations there are the spline's, not the "
                "table's; interpolation='pchip' (monotone) or 'linear' stays within the samples"
            )

        return checks.Condition("Sampled.displacements", bad, excess, "overshoots", detail)


@jax.jit  # one program, not a few dozen eager operations, for a table given eagerly
def _natural_spline_slopes(times: Array, values: Array) -> Array:
    """First derivatives at the knots of the natural cubic spline through `values`
    (shape `(samples, 3)`): the curvatures M from the tridiagonal system of the C²
    conditions, M = 0 at both ends; then, with δ_k the secant over interval k of
    length h_k, y'_k = δ_k − h_k (2 M_k + M_{k+1}) / 6 at each interval's left end,
    and at the last knot δ + h (M_{n−1} + 2 M_n) / 6 of the last interval."""
    h = jnp.diff(times)
    secants = jnp.diff(values, axis=0) / h[:, None]
    if times.shape[0] < 3:
        return jnp.concatenate([secants, secants])
    rhs = 6 * jnp.diff(secants, axis=0)
    lower = jnp.concatenate([jnp.zeros(1), h[1:-1]])
    upper = jnp.concatenate([h[1:-1], jnp.zeros(1)])
    interior = _tridiagonal_solve(lower, 2 * (h[:-1] + h[1:]), upper, rhs)
    zero = jnp.zeros((1, values.shape[1]))
    m = jnp.concatenate([zero, interior, zero])
    left = secants - h[:, None] * (2 * m[:-1] + m[1:]) / 6
    last = secants[-1:] + h[-1] * (m[-2:-1] + 2 * m[-1:]) / 6
    return jnp.concatenate([left, last])


def _tridiagonal_solve(lower: Array, diagonal: Array, upper: Array, rhs: Array) -> Array:
    """x with `lower[k] x[k-1] + diagonal[k] x[k] + upper[k] x[k+1] = rhs[k]` (`lower[0]`
    and `upper[-1]` unused, as `jax.lax.linalg.tridiagonal_solve` takes them), by the
    Thomas algorithm: elimination down the rows, substitution back up, each a `scan`.
    Without pivoting, which a diagonally dominant system (the natural spline's) needs
    none of. Not LAPACK's gtsv (`tridiagonal_solve`), whose lowering took 0.4 s of
    every process that read a motion table, eight times its whole solve of a 6,001-row
    table."""

    def eliminate(carry, row):
        upper_before, rhs_before = carry
        a, b, c, d = row
        pivot = b - a * upper_before
        reduced = (c / pivot, (d - a * rhs_before) / pivot)
        return reduced, reduced

    start = (jnp.zeros((), diagonal.dtype), jnp.zeros(rhs.shape[1:], rhs.dtype))
    _, (reduced_upper, reduced_rhs) = jax.lax.scan(eliminate, start, (lower, diagonal, upper, rhs))

    def substitute(after, row):
        c, d = row
        x = d - c * after
        return x, x

    _, x = jax.lax.scan(substitute, jnp.zeros(rhs.shape[1:], rhs.dtype), (reduced_upper, reduced_rhs), reverse=True)
    return x


@jax.jit
def _monotone_slopes(times: Array, values: Array) -> Array:
    """Fritsch–Carlson slopes at the knots (SciPy's `PchipInterpolator`): zero where the
    secants on either side differ in sign, their weighted harmonic mean otherwise; at
    the ends the one-sided three-point estimate, kept to the sign of the end secant and
    within three times it."""
    h = jnp.diff(times)[:, None]
    secants = jnp.diff(values, axis=0) / h
    if times.shape[0] < 3:
        return jnp.concatenate([secants, secants])
    before, after = secants[:-1], secants[1:]
    w1, w2 = 2 * h[1:] + h[:-1], h[1:] + 2 * h[:-1]
    same = before * after > 0
    # Double `where`: the harmonic mean is never formed from a zero secant.
    safe_before, safe_after = jnp.where(same, before, 1.0), jnp.where(same, after, 1.0)
    interior = jnp.where(same, (w1 + w2) / (w1 / safe_before + w2 / safe_after), 0.0)

    def end(h0, h1, d0, d1):
        d = ((2 * h0 + h1) * d0 - h0 * d1) / (h0 + h1)
        d = jnp.where(jnp.sign(d) != jnp.sign(d0), 0.0, d)
        return jnp.where((jnp.sign(d0) != jnp.sign(d1)) & (jnp.abs(d) > 3 * jnp.abs(d0)), 3 * d0, d)

    first = end(h[0], h[1], secants[0], secants[1])
    last = end(h[-1], h[-2], secants[-1], secants[-2])
    return jnp.concatenate([first[None], interior, last[None]])


def _hermite_extremes(times, values, slopes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The lowest and highest values of the cubic Hermite pieces, shape `(samples − 1,
    3)` each, and how far each piece strays outside its two samples: exact, from the
    roots of the derivative, a quadratic in s = (t − t_k)/h."""
    ts, ys, ds = np.asarray(times), np.asarray(values), np.asarray(slopes)
    h = np.diff(ts)[:, None]
    y0, y1, m0, m1 = ys[:-1], ys[1:], h * ds[:-1], h * ds[1:]
    # p(s) = a s³ + b s² + c s + y0 on 0 ≤ s ≤ 1.
    a, b, c = 2 * (y0 - y1) + m0 + m1, 3 * (y1 - y0) - 2 * m0 - m1, m0
    discriminant = np.maximum(b * b - 3 * a * c, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        cubic = np.abs(a) > 1e-12 * (np.abs(b) + np.abs(c) + 1e-300)
        roots = [
            np.where(cubic, (-b + np.sqrt(discriminant)) / (3 * a), -c / (2 * b)),
            np.where(cubic, (-b - np.sqrt(discriminant)) / (3 * a), -c / (2 * b)),
        ]
    candidates = [y0, y1]
    for s in roots:
        inside = np.isfinite(s) & (s > 0) & (s < 1)
        s = np.where(inside, s, 0.0)
        candidates.append(np.where(inside, ((a * s + b) * s + c) * s + y0, y0))
    lowest, highest = np.min(candidates, axis=0), np.max(candidates, axis=0)
    excess = np.maximum(np.minimum(y0, y1) - lowest, highest - np.maximum(y0, y1))
    return lowest, highest, excess


class Towing(AbstractMotion):
    """A tow point moving along `direction` at a speed history: the velocity is the
    piecewise-linear interpolation of `speeds` at `times`, and the displacement its
    exact integral, zero at `times[0]`. Before the first and after the last sample the
    speed holds its end value.

    Piecewise-linear, not a spline: a towing record's speed is a measured input, and a
    spline through a speed step (the branched-systems paper's 1 → 3 m/s) would overshoot it. The
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

    def excursion(self, duration=None):
        if duration is None:
            return np.inf, np.inf, np.inf
        # The distance is zero at times[0] and changes no faster than the fastest speed.
        reach = float(np.max(np.abs(np.asarray(self.speeds)))) * (abs(float(self.times[0])) + float(duration))
        vertical = reach * abs(float(self.direction[2]))
        return vertical, vertical, reach
