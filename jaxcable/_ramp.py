"""A smooth start in time, shared by prescribed motions and waves."""

import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float


def ramp_factor(t: Float[ArrayLike, ""], ramp: Float[ArrayLike, ""]) -> Float[Array, ""]:
    """The smoothstep f = u³(6u² − 15u + 10), u = t / ramp, rising from 0 at t = 0 to 1 at
    `ramp` (s) with zero first and second derivatives at both ends; 1 throughout when
    `ramp` is 0."""
    ramped = jnp.asarray(ramp) > 0
    u = jnp.clip(t / jnp.where(ramped, ramp, 1.0), 0.0, 1.0)
    return jnp.where(ramped, u**3 * (6 * u**2 - 15 * u + 10), 1.0)
