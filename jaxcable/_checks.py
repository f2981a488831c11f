"""Input checks, one implementation of each, for concrete, traced and batched values.

A check is a [`Condition`][]: a field's name, the mask of its entries that break it,
their values, and what the field requires. The same conditions serve three places:

- `enforce`: at construction, on concrete values, a `ValueError` naming the field, the
    entry and the value. A model built inside `jit` or `vmap` holds tracers, whose
    values are not known there; their conditions are left to:
- `guard`: `eqx.error_if` on the traced values, naming the field, which
    [`jaxcable.simulate`][] and [`jaxcable.solve_statics`][] apply to their inputs;
- `violations`: in a sweep, whose leaves carry a leading case axis, which condition
    each case breaks first and with which value, so that the sweep reports the case.
"""

import warnings
from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

import equinox as eqx
import jax
import jax.core
import jax.numpy as jnp
import numpy as np
from jax.interpreters.ad import JVPTracer
from jaxtyping import Array, ArrayLike, Bool, Float

from ._typing import RealLike


class Float64Error(RuntimeError):
    """JAX's float64 is off, and jaxcable computes in float64."""


def require_float64() -> None:
    """Raise [`jaxcable.Float64Error`][] unless JAX's float64 is enabled.

    Stiff cables need float64: at float32 a 1e-7 strain on a 3e7 N line is lost to
    rounding. jaxcable does not enable it itself, since a library must not change its
    caller's global configuration, so every constructor checks here instead.
    """
    if not jax.config.read("jax_enable_x64"):
        raise Float64Error(
            "jaxcable computes in float64, but JAX's float64 is off. Enable it once, before "
            'building any model: jax.config.update("jax_enable_x64", True), or set '
            "JAX_ENABLE_X64=1 in the environment"
        )


class Condition(NamedTuple):
    """`name`'s entries must not be `bad`: `value` (shaped like `bad`) has the entries
    shown in messages, and `requirement` says what the field requires ("must be
    positive"). `detail`, if given, makes a fuller message from concrete values (a
    limit that only numpy can compute, say) for `enforce`."""

    name: str
    bad: Bool[ArrayLike, "..."]
    value: ArrayLike
    requirement: str
    detail: Callable[[], str] | None = None


def _on_host(value: ArrayLike) -> tuple[Any, Any]:
    """`value` and the array module to test it with: numpy where it is concrete, jax.numpy
    where it is traced. Each eager jax.numpy operation on a new shape compiles a small XLA
    program (10–30 ms); a scene file's checks made dozens of them on every run."""
    if traced(value):
        return value, jnp
    return np.asarray(value), np


def on_host(value: ArrayLike) -> Any:
    """`value` as a numpy array where it is concrete, as it is where it is traced: for
    arithmetic at construction that must not compile an XLA program of its own for each
    operation and shape (see `_on_host`)."""
    return _on_host(value)[0]


def on_device(value: RealLike, dtype: Any = float) -> Array:
    """`value` as a JAX array of `dtype`, compiling nothing where it is concrete.

    `jnp.asarray` compiles a small program (10–20 ms) for a Python number, or for a numpy
    array without a `dtype` (JAX 0.10); a numpy array of the requested dtype is only
    copied to the device."""
    if traced(value):
        return jnp.asarray(value, dtype=dtype)
    return jnp.asarray(np.asarray(value, dtype=dtype), dtype=dtype)


def finite(name: str, value: ArrayLike) -> Condition:
    value, xp = _on_host(value)
    return Condition(name, ~xp.isfinite(value), value, "must be finite")


def sign(name: str, value: Array | np.ndarray, allow_zero: bool = False) -> Condition:
    """Positive (or, with `allow_zero`, non-negative) entries; NaN breaks it too."""
    value, _ = _on_host(value)
    kept = value >= 0 if allow_zero else value > 0
    return Condition(name, ~kept, value, "must be " + ("non-negative" if allow_zero else "positive"))


def at_least(name: str, value: Array | np.ndarray, minimum: float) -> Condition:
    """Entries of at least `minimum`; NaN breaks it too."""
    value, _ = _on_host(value)
    return Condition(name, ~(value >= minimum), value, f"must be at least {minimum:g}")


def increasing(name: str, values: Float[ArrayLike, " samples"]) -> Condition:
    """Strictly increasing along the last axis: an entry breaks it if it is not above
    the one before."""
    values, xp = _on_host(values)
    values = xp.asarray(values)
    rising = xp.diff(values, axis=-1) > 0
    bad = xp.concatenate([xp.zeros_like(rising[..., :1]), ~rising], axis=-1)
    return Condition(name, bad, values, "must be strictly increasing")


def _traced(condition: Condition) -> bool:
    return traced((condition.bad, condition.value))


def traced_conditions(conditions: Sequence[Condition]) -> list[Condition]:
    """The conditions on traced values: those `enforce` leaves to `guard` or `violations`."""
    return [c for c in conditions if _traced(c)]


def enforce(conditions: Sequence[Condition]) -> None:
    """Raise `ValueError` for the first concrete condition broken, naming the field, the
    entry (for an array) and its value. Traced conditions are `guard`'s."""
    for c in conditions:
        if _traced(c):
            continue
        bad = np.asarray(c.bad)
        if np.any(bad):
            raise ValueError(_message(c))


def warn(conditions: Sequence[Condition], stacklevel: int) -> None:
    """Warn for each concrete condition broken (advice, not an error: a traced value,
    which cannot be inspected, gets none)."""
    for c in conditions:
        if not _traced(c) and np.any(np.asarray(c.bad)):
            warnings.warn(_message(c), stacklevel=stacklevel + 1)


def _message(c: Condition) -> str:
    if c.detail is not None:
        return c.detail()
    bad = np.asarray(c.bad)
    index = tuple(np.argwhere(bad)[0])
    value = np.broadcast_to(np.asarray(c.value), bad.shape)[index]
    where = f" at index {', '.join(map(str, index))}" if index else ""
    return f"{c.name} {c.requirement}, got {value}{where}"


def guard(x, conditions: Sequence[Condition], hint: str = ""):
    """`x`, with an `eqx.error_if` for each traced condition, raising (at run time)
    `EquinoxRuntimeError` naming the field if any entry breaks it, followed by `hint`."""
    for c in conditions:
        if _traced(c):
            x = eqx.error_if(x, jnp.any(c.bad), f"{c.name} {c.requirement}{hint}")
    return x


def traced(tree) -> bool:
    """Whether any leaf of `tree` is traced: the caller runs under `jit`, `vmap` or a
    derivative, and errors must be raised from inside the program."""
    return any(isinstance(leaf, jax.core.Tracer) for leaf in jax.tree.leaves(tree))


def differentiated(tree) -> bool:
    """Whether any leaf of `tree` carries a derivative's tracer (`jax.grad`, `jax.jvp`,
    `jax.jacfwd`, ...), also beneath `vmap`'s tracer or inside the derivative's `jit`.
    A derivative taken of a function compiled before it (`jax.grad(jax.jit(f))`) is
    taken of the compiled program, whose tracers are `jit`'s alone: not seen."""
    for leaf in jax.tree.leaves(tree):
        while isinstance(leaf, jax.core.Tracer):
            # `jax.grad` linearises with a tracer that JAX does not export; its name is
            # checked, so that a JAX without it only sees fewer derivatives.
            if isinstance(leaf, JVPTracer) or type(leaf).__name__ == "LinearizeTracer":
                return True
            # The value beneath: a derivative's primal, or vmap's batched value.
            leaf = getattr(leaf, "primal", getattr(leaf, "val", None))
    return False


def raise_if(x, failed, message: str):
    """`x`, after raising `equinox.EquinoxRuntimeError(message)` if `failed` holds.

    Where `failed` is concrete the error is raised here, in Python, so the compiled
    program it came out of carries no host callback: JAX's persistent compilation cache
    refuses programs with callbacks, and `eqx.error_if` is one. Where it is traced (the
    caller's own `jit`), `eqx.error_if` raises it when the program runs, as before.
    """
    if traced(failed):
        return eqx.error_if(x, failed, message)
    if np.any(np.asarray(failed)):
        raise eqx.EquinoxRuntimeError(message)
    return x


def check(x, conditions: Sequence[Condition]):
    """`enforce` the concrete conditions now and `guard` `x` with the traced ones."""
    enforce(conditions)
    return guard(x, conditions)


def violations(conditions: Sequence[Condition]) -> tuple[Bool[Array, " conditions"], Float[Array, " conditions"]]:
    """Whether each condition is broken, and its first bad value (NaN where none):
    traceable, for `vmap` over a sweep's cases."""
    broken, first = [], []
    for c in conditions:
        bad = jnp.ravel(jnp.asarray(c.bad))
        value = jnp.ravel(jnp.broadcast_to(jnp.asarray(c.value, dtype=float), jnp.shape(c.bad)))
        broken.append(jnp.any(bad))
        first.append(jnp.where(jnp.any(bad), value[jnp.argmax(bad)], jnp.nan))
    if not conditions:
        return jnp.zeros(0, bool), jnp.zeros(0)
    return jnp.stack(broken), jnp.stack(first)


def first_violation(
    conditions: Sequence[Condition], broken: Bool[np.ndarray, " conditions"], values: Float[np.ndarray, " conditions"]
) -> str | None:
    """The message for the first of `conditions` broken, from `violations`' output for
    one case; `None` if none is."""
    for c, is_broken, value in zip(conditions, broken, values):
        if is_broken:
            return f"{c.name} {c.requirement}, got {value}"
    return None


def float_array(name: str, value: RealLike, shape: tuple[int, ...] | None = None) -> Array:
    """`value` as a float array, checked finite and, if `shape` is given, broadcast to it.

    Raises `ValueError` naming `name` if the value is not numeric, not finite or cannot
    take `shape`, and [`jaxcable.Float64Error`][] if JAX's float64 is off.
    """
    require_float64()
    try:
        if traced(value):
            # A tracer, or a tuple or list holding one (`current=(c, 0.0, 0.0)` under
            # `vmap` or `grad`): numpy cannot hold it, JAX can.
            concrete = value if isinstance(value, jax.core.Tracer) else jnp.asarray(value, dtype=float)
        else:
            concrete = np.asarray(value, dtype=float)
    except (TypeError, ValueError):  # a string, None, a ragged list: numpy's message names no field
        raise ValueError(f"{name} must be a number or an array of numbers, got {value!r}") from None
    enforce([finite(name, concrete)])
    if shape is not None:
        if np.ndim(concrete) != 0 and np.shape(concrete) != shape:
            raise ValueError(f"{name} must have shape {shape} (or be a scalar), got shape {np.shape(concrete)}")
        concrete = (jnp if traced(concrete) else np).broadcast_to(concrete, shape)
    return on_device(concrete)


def positive(name: str, value: Array | np.ndarray, allow_zero: bool = False) -> None:
    """Raise `ValueError` if any concrete entry of `value` is not positive (or
    negative, with `allow_zero`)."""
    enforce([sign(name, value, allow_zero)])


def option(name: str, value: str, allowed: tuple[str, ...]) -> str:
    """Raise `ValueError` unless `value` is one of `allowed`."""
    if value not in allowed:
        raise ValueError(f"{name} must be one of {allowed}, got {value!r}")
    return value
