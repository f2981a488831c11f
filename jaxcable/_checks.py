"""Input checks shared by every constructor.

They run on concrete values only: a model built inside `jax.grad` or `jax.vmap` holds
tracers, whose values cannot be inspected, and was checked when it was built eagerly.
Each message names the field and the offending value.
"""

import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike


class Float64Error(RuntimeError):
    """JAX's float64 is off, and jaxcable computes in float64."""


def require_float64() -> None:
    """Raise [`jaxcable.Float64Error`][] unless JAX's float64 is enabled.

    Stiff cables need float64: at float32 a 1e-7 strain on a 3e7 N line is lost to
    rounding. jaxcable does not enable it itself, since a library must not change its
    caller's global configuration, so every constructor checks here instead.
    """
    if not jax.config.jax_enable_x64:
        raise Float64Error(
            "jaxcable computes in float64, but JAX's float64 is off. Enable it once, before "
            'building any model: jax.config.update("jax_enable_x64", True), or set '
            "JAX_ENABLE_X64=1 in the environment"
        )


def is_concrete(value) -> bool:
    return not isinstance(value, jax.core.Tracer)


def float_array(name: str, value: ArrayLike, shape: tuple[int, ...] | None = None) -> Array:
    """`value` as a float array, checked finite and, if `shape` is given, broadcast to it.

    Raises `ValueError` naming `name` if the value is not finite or cannot take `shape`,
    and [`jaxcable.Float64Error`][] if JAX's float64 is off.
    """
    require_float64()
    if is_concrete(value):
        array = np.asarray(value, dtype=float)
        if not np.all(np.isfinite(array)):
            bad = array[~np.isfinite(array)].ravel()[0] if array.ndim else array
            raise ValueError(f"{name} must be finite, got {bad}")
    array = jnp.asarray(value, dtype=float)
    if shape is not None:
        if array.ndim != 0 and array.shape != shape:
            raise ValueError(f"{name} must have shape {shape} (or be a scalar), got shape {array.shape}")
        array = jnp.broadcast_to(array, shape)
    return array


def positive(name: str, value: Array, allow_zero: bool = False) -> None:
    """Raise `ValueError` if any entry of `value` is not positive (or negative)."""
    if not is_concrete(value):
        return
    array = np.asarray(value)
    bad = array < 0 if allow_zero else array <= 0
    if np.any(bad):
        index = np.argwhere(bad)[0]
        where = f"[{', '.join(map(str, index))}]" if array.ndim else ""
        kind = "non-negative" if allow_zero else "positive"
        raise ValueError(f"{name}{where} must be {kind}, got {array[tuple(index)]}")


def option(name: str, value: str, allowed: tuple[str, ...]) -> str:
    """Raise `ValueError` unless `value` is one of `allowed`."""
    if value not in allowed:
        raise ValueError(f"{name} must be one of {allowed}, got {value!r}")
    return value
