"""Input checks shared by every constructor.

They run on concrete values only: a model built inside `jax.grad` or `jax.vmap` holds
tracers, whose values cannot be inspected, and was checked when it was built eagerly.
Each message names the field and the offending value.
"""

import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike


def is_concrete(value) -> bool:
    return not isinstance(value, jax.core.Tracer)


def float_array(name: str, value: ArrayLike, shape: tuple[int, ...] | None = None) -> Array:
    """`value` as a float array, checked finite and, if `shape` is given, broadcast to it.

    Raises `ValueError` naming `name` if the value is not finite or cannot take `shape`.
    """
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
