"""The water the cables sit in: density, gravity, depth, current, waves and seabed.

The environment is a pytree: its floats (density, depth, current speeds, wave heights,
seabed stiffness, ...) are leaves that can be swept or differentiated. What a scene
has is static structure, so a scene without waves compiles no wave code, one without a
seabed no contact code.
"""

import dataclasses

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

from .. import _checks as checks
from .._ramp import ramp_factor
from .._typing import RealLike
from .waves import AbstractWave


class CurrentProfile(eqx.Module):
    """A horizontal current whose speed varies over depth, in one direction.

    The speed is interpolated linearly between the given heights, and held constant
    above the highest and below the lowest.

    **Arguments:**

    - `heights`: z (m) of the profile's points, strictly increasing, shape `(points,)`;
        z = 0 is the still-water level, so these are ≤ 0 in the water.
    - `speeds`: the current speed (m/s) at each height, shape `(points,)`.
    - `heading`: β (degrees), the direction the current flows towards, from +x towards
        +y.

    **Raises:**

    `ValueError` for mismatched shapes, fewer than two points, heights not increasing,
    or non-finite values.
    """

    heights: Float[Array, " points"]
    speeds: Float[Array, " points"]
    heading: Float[Array, ""]

    def __init__(self, heights: RealLike, speeds: RealLike, heading: RealLike = 0.0):
        self.heights = checks.float_array("CurrentProfile.heights", heights)
        self.speeds = checks.float_array("CurrentProfile.speeds", speeds)
        self.heading = checks.float_array("CurrentProfile.heading", heading, ())
        if self.heights.ndim != 1 or self.heights.shape[0] < 2:
            raise ValueError(
                f"CurrentProfile.heights must be 1-D with at least 2 points, got shape {self.heights.shape}"
            )
        if self.speeds.shape != self.heights.shape:
            raise ValueError(
                f"CurrentProfile.speeds must have the shape of heights {self.heights.shape}, got {self.speeds.shape}"
            )
        checks.enforce([checks.increasing("CurrentProfile.heights", self.heights)])

    def conditions(self) -> list[checks.Condition]:
        """What the fields require: checked at construction on concrete values and, on
        traced or swept ones, by `simulate`, `solve_statics` and `sweep`."""
        return [
            checks.finite("CurrentProfile.heights", self.heights),
            checks.increasing("CurrentProfile.heights", self.heights),
            checks.finite("CurrentProfile.speeds", self.speeds),
            checks.finite("CurrentProfile.heading", self.heading),
        ]

    def velocity(self, position: Float[Array | np.ndarray, "*batch 3"]) -> Float[Array, "*batch 3"]:
        """The current velocity (m/s) at `position` (m)."""
        speed = jnp.interp(position[..., 2], self.heights, self.speeds)
        beta = jnp.deg2rad(self.heading)
        return speed[..., None] * jnp.stack([jnp.cos(beta), jnp.sin(beta), 0.0])


class Seabed(eqx.Module):
    """A flat seabed at z = −depth: a penalty spring-damper with smooth Coulomb friction.

    Each node below the bed is pushed up by `(k δ − c ż) A` over its contact area A =
    Σ ½ d L of the segments that meet there (d the diameter, L the unstretched length),
    with δ the penetration (m). These are MoorDyn's `kBot` and `cBot`, on the same
    area. The spring is conservative (its energy ½ k δ² A is part of the potential, so
    statics sees it); the damper acts in dynamics only.

    Friction opposes a touching node's horizontal velocity v with `μ N v / √(|v|² + v_s²)`,
    N = k δ A: Coulomb's μ N once sliding is faster than v_s, and a viscous drag below
    it, so that the force is smooth at rest. It acts in dynamics only: in statics a
    frictionless bed carries no horizontal load.

    **Arguments:**

    - `stiffness`: k (Pa/m), the bed's stiffness per unit contact area; 3e6 by default
        (MoorDyn's default).
    - `damping`: c (Pa·s/m); 3e5 by default (MoorDyn's default).
    - `friction`: μ (–), the Coulomb coefficient; 0 by default.
    - `friction_speed`: v_s (m/s), where friction approaches its Coulomb value; 0.01 by
        default. Smaller is closer to dry friction and stiffer to integrate: the
        viscous rate μ k δ A / (v_s m) limits an explicit step.
    - `friction_damping`: c_f (N·s/m), to use MoorDyn's friction instead of the smooth
        one: `μ c_f |v|` per node, opposite v, until it exceeds μ N, then μ N, with N
        the bed's whole reaction `|k δ − c ż| A` (MoorDyn's `FricDamp`, Line.cpp). It
        is per node, whatever the node's length, and its kink at μ N is not smooth;
        `friction_speed` is then unused. `None` (default) for the smooth friction.

    **Raises:**

    `ValueError` for a non-positive stiffness or friction speed, or a negative damping
    or friction coefficient.
    """

    stiffness: Float[Array, ""]
    damping: Float[Array, ""]
    friction: Float[Array, ""]
    friction_speed: Float[Array, ""]
    friction_damping: Float[Array, ""] | None

    def __init__(self, stiffness=3.0e6, damping=3.0e5, friction=0.0, friction_speed=0.01, friction_damping=None):
        self.stiffness = checks.float_array("Seabed.stiffness", stiffness, ())
        self.damping = checks.float_array("Seabed.damping", damping, ())
        self.friction = checks.float_array("Seabed.friction", friction, ())
        self.friction_speed = checks.float_array("Seabed.friction_speed", friction_speed, ())
        checks.positive("Seabed.stiffness", self.stiffness)
        checks.positive("Seabed.damping", self.damping, allow_zero=True)
        checks.positive("Seabed.friction", self.friction, allow_zero=True)
        checks.positive("Seabed.friction_speed", self.friction_speed)
        self.friction_damping = None
        if friction_damping is not None:
            self.friction_damping = checks.float_array("Seabed.friction_damping", friction_damping, ())
            checks.positive("Seabed.friction_damping", self.friction_damping)

    def conditions(self) -> list[checks.Condition]:
        """What the fields require (see [`jaxcable.Environment`][]'s)."""
        out = [
            checks.finite(f"Seabed.{f}", getattr(self, f))
            for f in ("stiffness", "damping", "friction", "friction_speed")
        ]
        out += [
            checks.sign("Seabed.stiffness", self.stiffness),
            checks.sign("Seabed.damping", self.damping, allow_zero=True),
            checks.sign("Seabed.friction", self.friction, allow_zero=True),
            checks.sign("Seabed.friction_speed", self.friction_speed),
        ]
        if self.friction_damping is not None:
            out += [
                checks.finite("Seabed.friction_damping", self.friction_damping),
                checks.sign("Seabed.friction_damping", self.friction_damping),
            ]
        return out


class Environment(eqx.Module):
    """The water: still, or with a current, waves and a seabed.

    **Arguments:**

    - `water_density`: ρ (kg/m³); 1025 (sea water) by default.
    - `gravity`: g (m/s²), acting along −z.
    - `current`: a uniform current velocity V (m/s), shape `(3,)`, or a
        [`jaxcable.CurrentProfile`][] over depth.
    - `depth`: d (m), the still-water depth; the seabed, if any, is at z = −d. `None`
        (default) for water without a bottom, which is allowed only without waves and
        seabed.
    - `waves`: regular waves ([`jaxcable.Airy`][], [`jaxcable.Cnoidal`][]), superposed;
        none by default. Each must have this depth and gravity.
    - `wave_ramp`: the time (s) over which the waves are switched on, by the same
        smoothstep as [`jaxcable.Harmonic`][]'s ramp, so that a run can start from
        still-water equilibrium without a jolt; 0 (default) for none.
    - `wave_start`: the time (s) at which that ramp begins, for a run that starts
        later than t = 0 (from a steady tow at t = 280 s, say); 0 by default. Before
        it the water has no waves; with no ramp it has no effect.
    - `seabed`: a [`jaxcable.Seabed`][] at z = −d; `None` (default) for none.
    - `fluid_inertia`: with waves, whether the water's acceleration loads the lines and
        bodies (Froude–Krylov plus added mass, Morison's inertia term). `True` by
        default; `False` leaves only drag, which Zhukov's growing-element thesis found sufficient for
        mariculture's growing elements. The added mass on a line's or body's own
        acceleration is set by its `C_a`, not by this switch.
    - `free_surface`: if `True`, lines are in water only below the still-water level
        z = 0: buoyancy, drag, fluid inertia and added mass act on the submerged part of
        each segment. If `False` (default), every segment is treated as submerged, which
        is exact for lines that stay below the surface and costs nothing to evaluate.
        Bodies are treated as submerged unless they have a `height` (see
        [`jaxcable.Body`][]), whatever this switch. Buoyancy is hydrostatic to z = 0
        either way; the waves' dynamic pressure enters through the Froude–Krylov force.

    **Raises:**

    `ValueError` naming the field for a non-positive density, gravity or depth, a
    current of the wrong shape, waves or a seabed without a depth, or a wave whose depth
    or gravity differs from the environment's.
    """

    water_density: Float[Array, ""]
    gravity: Float[Array, ""]
    current: Float[Array, "3"] | CurrentProfile
    depth: Float[Array, ""] | None
    waves: tuple[AbstractWave, ...]
    wave_ramp: Float[Array, ""]
    wave_start: Float[Array, ""]
    seabed: Seabed | None
    fluid_inertia: bool = eqx.field(static=True)
    free_surface: bool = eqx.field(static=True)

    def __init__(
        self,
        water_density: RealLike = 1025.0,
        gravity: RealLike = 9.81,
        current=(0.0, 0.0, 0.0),
        free_surface: bool = False,
        *,
        depth: RealLike | None = None,
        waves=(),
        wave_ramp: RealLike = 0.0,
        wave_start: RealLike = 0.0,
        seabed: Seabed | None = None,
        fluid_inertia: bool = True,
    ):
        self.water_density = checks.float_array("Environment.water_density", water_density, ())
        self.gravity = checks.float_array("Environment.gravity", gravity, ())
        checks.positive("Environment.water_density", self.water_density)
        checks.positive("Environment.gravity", self.gravity)
        if isinstance(current, CurrentProfile):
            self.current = current
        else:
            self.current = checks.float_array("Environment.current", current)
            if self.current.shape != (3,):
                raise ValueError(f"Environment.current must have shape (3,), got {self.current.shape}")
        for name, flag in (("free_surface", free_surface), ("fluid_inertia", fluid_inertia)):
            if not isinstance(flag, bool):
                raise ValueError(f"Environment.{name} must be True or False, got {flag!r}")
        self.free_surface = free_surface
        self.fluid_inertia = fluid_inertia

        if depth is None:
            self.depth = None
        else:
            self.depth = checks.float_array("Environment.depth", depth, ())
            checks.positive("Environment.depth", self.depth)
        waves = (waves,) if isinstance(waves, AbstractWave) else tuple(waves)
        for i, wave in enumerate(waves):
            if not isinstance(wave, AbstractWave):
                raise ValueError(f"Environment.waves[{i}] must be a wave (Airy, Cnoidal), got {type(wave).__name__}")
            if self.depth is None:
                raise ValueError("Environment.waves need the water depth: give Environment.depth")
        self.waves = waves
        checks.enforce(self._wave_conditions())
        self.wave_ramp = checks.float_array("Environment.wave_ramp", wave_ramp, ())
        checks.positive("Environment.wave_ramp", self.wave_ramp, allow_zero=True)
        self.wave_start = checks.float_array("Environment.wave_start", wave_start, ())
        if seabed is not None and not isinstance(seabed, Seabed):
            raise ValueError(f"Environment.seabed must be a Seabed or None, got {type(seabed).__name__}")
        if seabed is not None and self.depth is None:
            raise ValueError("Environment.seabed needs the water depth: give Environment.depth")
        self.seabed = seabed

    def _wave_conditions(self) -> list[checks.Condition]:
        """Each wave's depth and gravity are the environment's."""
        out = []
        for i, wave in enumerate(self.waves):
            for field in ("depth", "gravity"):
                mine, theirs = getattr(self, field), getattr(wave, field)
                differ = ~jnp.isclose(mine, theirs, rtol=1e-12, atol=0.0)
                out.append(
                    checks.Condition(
                        f"Environment.waves[{i}].{field}", differ, theirs, f"must equal Environment.{field}"
                    )
                )
        return out

    def conditions(self) -> list[checks.Condition]:
        """Every float field's requirements, its current's, waves' and seabed's: checked
        at construction on concrete values; [`jaxcable.simulate`][] and
        [`jaxcable.solve_statics`][] guard traced ones, and [`jaxcable.sweep`][] checks
        each case's."""
        out = [
            checks.finite("Environment.water_density", self.water_density),
            checks.sign("Environment.water_density", self.water_density),
            checks.finite("Environment.gravity", self.gravity),
            checks.sign("Environment.gravity", self.gravity),
            checks.finite("Environment.wave_ramp", self.wave_ramp),
            checks.sign("Environment.wave_ramp", self.wave_ramp, allow_zero=True),
            checks.finite("Environment.wave_start", self.wave_start),
        ]
        if isinstance(self.current, CurrentProfile):
            out += self.current.conditions()
        else:
            out.append(checks.finite("Environment.current", self.current))
        if self.depth is not None:
            out += [checks.finite("Environment.depth", self.depth), checks.sign("Environment.depth", self.depth)]
        for wave in self.waves:
            out += wave.conditions()
        out += self._wave_conditions()
        if self.seabed is not None:
            out += self.seabed.conditions()
        return out

    def without_waves(self) -> "Environment":
        """The same water without its waves: still, or with the current alone."""
        return dataclasses.replace(self, waves=())

    def without_seabed(self) -> "Environment":
        """The same water without its seabed (its depth kept, for the waves)."""
        return dataclasses.replace(self, seabed=None)

    @property
    def has_fluid_acceleration(self) -> bool:
        """Whether the water accelerates and that loads the network: waves, with
        `fluid_inertia`. A steady current does not accelerate."""
        return bool(self.waves) and self.fluid_inertia

    def water_velocity(
        self, position: Float[Array | np.ndarray, "*batch 3"], t: Float[ArrayLike, ""]
    ) -> Float[Array, "*batch 3"]:
        """The water velocity (m/s), current plus waves, at `position` (m) and time `t` (s)."""
        if isinstance(self.current, CurrentProfile):
            velocity = self.current.velocity(position)
        else:
            velocity = jnp.broadcast_to(self.current, jnp.shape(position))
        if not self.waves:
            return velocity
        return velocity + ramp_factor(t - self.wave_start, self.wave_ramp) * self._wave_velocity(position, t)

    def _wave_velocity(self, position, t):
        velocity = jnp.zeros(jnp.shape(position))
        for wave in self.waves:
            velocity = velocity + wave.velocity(position, t)
        return velocity

    def water_acceleration(
        self, position: Float[Array | np.ndarray, "*batch 3"], t: Float[ArrayLike, ""]
    ) -> Float[Array, "*batch 3"]:
        """The water's local acceleration ∂u/∂t (m/s²) at `position` (m) and time `t` (s):
        the waves', through their ramp; the current is steady."""
        acceleration = jnp.zeros(jnp.shape(position))
        for wave in self.waves:
            acceleration = acceleration + wave.acceleration(position, t)
        t = jnp.asarray(t, dtype=float)
        ramp, rate = jax.jvp(lambda s: ramp_factor(s - self.wave_start, self.wave_ramp), (t,), (jnp.ones_like(t),))
        return ramp * acceleration + rate * self._wave_velocity(position, t)

    def surface_elevation(
        self, x: Float[Array | np.ndarray, "*batch"], y: Float[Array | np.ndarray, "*batch"], t
    ) -> Float[Array, "*batch"]:
        """The surface elevation η (m) above the still-water level at `(x, y)` (m) and time
        `t` (s): the waves' sum, through their ramp."""
        eta = jnp.zeros(jnp.broadcast_shapes(jnp.shape(x), jnp.shape(y)))
        for wave in self.waves:
            eta = eta + wave.elevation(x, y, t)
        return ramp_factor(t - self.wave_start, self.wave_ramp) * eta
