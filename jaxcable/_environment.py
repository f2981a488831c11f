"""The water the cables sit in: density, gravity and the current."""

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

from . import _checks as checks


class Environment(eqx.Module):
    """Still water, or water in a uniform current.

    **Arguments:**

    - `water_density`: ρ (kg/m³); 1025 (sea water) by default.
    - `gravity`: g (m/s²), acting along −z.
    - `current`: V (m/s), the uniform current velocity, shape `(3,)`.
    - `free_surface`: if `True`, lines are in water only below the still-water level
        z = 0: buoyancy, drag and added mass act on the submerged part of each segment.
        If `False` (default), every segment is treated as submerged, which is exact for
        lines that stay below the surface and costs nothing to evaluate. Point bodies
        are always treated as submerged.
    """

    water_density: Float[Array, ""]
    gravity: Float[Array, ""]
    current: Float[Array, "3"]
    free_surface: bool = eqx.field(static=True)

    def __init__(
        self,
        water_density: ArrayLike = 1025.0,
        gravity: ArrayLike = 9.81,
        current=(0.0, 0.0, 0.0),
        free_surface: bool = False,
    ):
        self.water_density = checks.float_array("Environment.water_density", water_density, ())
        self.gravity = checks.float_array("Environment.gravity", gravity, ())
        self.current = checks.float_array("Environment.current", current)
        if self.current.shape != (3,):
            raise ValueError(f"Environment.current must have shape (3,), got {self.current.shape}")
        checks.positive("Environment.water_density", self.water_density)
        checks.positive("Environment.gravity", self.gravity)
        if not isinstance(free_surface, bool):
            raise ValueError(f"Environment.free_surface must be True or False, got {free_surface!r}")
        self.free_surface = free_surface

    def water_velocity(self, position: Float[Array, "*batch 3"], t: Float[ArrayLike, ""]) -> Float[Array, "*batch 3"]:
        """The water velocity V (m/s) at `position` (m) and time `t` (s)."""
        del t
        return jnp.broadcast_to(self.current, jnp.shape(position))
