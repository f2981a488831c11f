"""The cases of a sweep: its parameters checked, `build` traced once under an eager
`vmap` into the leaves that vary by case and those shared, each case's model and water
checked, and whether the cases' statics differ."""

import inspect
import itertools
from collections.abc import Mapping
from typing import Any

import equinox as eqx
import jax
import jax.core
import jax.numpy as jnp
import numpy as np

from .. import _checks as checks
from .._equations import lagrangian as lag
from .._model.network import CableNetwork, network_conditions
from .._programs import program
from .._sea.environment import Environment
from .._typing import RealLike

# What `build` does with a traced parameter that it cannot do under `vmap`: use its
# value in Python (`float(x)`, `if x > 0`, numpy, a segment count).
_TRACER_ERRORS = (
    jax.errors.ConcretizationTypeError,
    jax.errors.TracerArrayConversionError,
    jax.errors.TracerBoolConversionError,
    jax.errors.TracerIntegerConversionError,
)


def sweep_grid(**axes: RealLike) -> dict[str, np.ndarray]:
    """The Cartesian product of parameter axes, as the flat arrays [`jaxcable.sweep`][]
    takes.

    The first axis varies slowest, as in `itertools.product` (or `numpy.meshgrid` with
    `indexing="ij"`).

    **Arguments:**

    - `**axes`: each parameter's values, a non-empty 1-D array-like.

    **Returns:**

    A dict from each name to a float array of shape `(cases,)`, `cases` being the
    product of the axes' lengths.

    **Raises:**

    `ValueError` naming the axis if it is not 1-D, empty or not finite, or if no axis is
    given.

    For example, `sweep_grid(a=[1.0, 2.0], b=[10.0, 20.0, 30.0])` gives six cases with
    `a = [1, 1, 1, 2, 2, 2]` and `b = [10, 20, 30, 10, 20, 30]`.
    """
    if not axes:
        raise ValueError("sweep_grid: give at least one axis, e.g. sweep_grid(steepness=[0.02, 0.04])")
    values = {name: _parameter_values("sweep_grid", name, value) for name, value in axes.items()}
    product = list(itertools.product(*values.values()))
    return {name: np.array([case[k] for case in product]) for k, name in enumerate(values)}


def each_case(batched, unbatched):
    """Each case's `(model, env)`, concrete, from the batched leaves (leading case
    axis) and the shared ones."""
    n_cases = len(jax.tree.leaves(batched)[0])
    host = jax.tree.map(np.asarray, batched)
    for i in range(n_cases):
        yield eqx.combine(jax.tree.map(lambda x: x[i], host), unbatched)  # noqa: B023 (used within the iteration)


def _parameter_values(where: str, name: str, value: Any) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{where}: parameter {name!r} must be an array of floats, got {value!r}") from e
    if array.ndim != 1 or array.size == 0:
        raise ValueError(f"{where}: parameter {name!r} must be a non-empty 1-D array, got shape {array.shape}")
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        raise ValueError(f"{where}: parameter {name!r} must be finite, got {array[bad[0]]} at index {bad[0]}")
    return array


def check_parameters(parameters) -> dict[str, np.ndarray]:
    if not isinstance(parameters, Mapping):
        raise ValueError(f"sweep: parameters must be a dict from names to 1-D arrays, got {type(parameters).__name__}")
    if not parameters:
        raise ValueError("sweep: parameters must name at least one parameter")
    values = {}
    for name, value in parameters.items():
        if not (isinstance(name, str) and name.isidentifier()):
            raise ValueError(f"sweep: parameter names must be keyword names, got {name!r}")
        values[name] = _parameter_values("sweep", name, value)
    lengths = {name: len(v) for name, v in values.items()}
    if len(set(lengths.values())) > 1:
        raise ValueError(f"sweep: every parameter must have the same number of cases, got lengths {lengths}")
    return values


def check_keywords(build, values) -> None:
    """Match the parameters against `build`'s signature, where it has one."""
    if not callable(build):
        raise ValueError(f"sweep: build must be a function build(**case) -> (model, env), got {build!r}")
    try:
        signature = inspect.signature(build)
    except (TypeError, ValueError):
        return
    try:
        signature.bind(**values)
    except TypeError as e:
        accepted = [
            p.name for p in signature.parameters.values() if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)
        ]
        unknown = [k for k in values if k not in accepted]
        if unknown and not any(p.kind == p.VAR_KEYWORD for p in signature.parameters.values()):
            raise ValueError(
                f"sweep: parameter {unknown[0]!r} is not a keyword of build{signature}; it takes {accepted}"
            ) from e
        raise ValueError(f"sweep: build{signature} cannot be called with parameters {list(values)}: {e}") from e


def _check_output(output, where: str) -> None:
    if not (
        isinstance(output, tuple)
        and len(output) == 2
        and isinstance(output[0], CableNetwork)
        and isinstance(output[1], Environment)
    ):
        raise ValueError(f"sweep: build must return (CableNetwork, Environment), got {output!r} {where}")


def build_first(build, values) -> tuple[CableNetwork, Environment]:
    """`build` on the first case's concrete values: constructors check real values
    there (they cannot check tracers), and it is the reference the traced build must
    match."""
    first = {k: float(v[0]) for k, v in values.items()}
    try:
        output = build(**first)
    except Exception as e:
        e.add_note(f"raised by sweep's build(**{first}) (the first case)")
        raise
    _check_output(output, f"for the first case {first}")
    return output


def _culprits(build, values) -> str:
    """Name the parameters that `build` cannot take traced: each is tried alone under
    vmap, the others held at the first case's values."""
    first = {k: float(v[0]) for k, v in values.items()}
    names = []
    for name, value in values.items():

        def alone(x, name=name):
            return jax.tree.leaves(build(**{**first, name: x}))

        try:
            jax.vmap(alone)(jnp.asarray(value))
        except _TRACER_ERRORS:
            names.append(repr(name))
        except Exception:  # another failure says nothing about this parameter
            pass
    if not names:
        return "a swept parameter"
    return ("parameter " if len(names) == 1 else "parameters ") + ", ".join(names)


def invalid_cases(batched, unbatched, reference) -> dict[int, str]:
    """The cases whose values break a condition of their model or water, each with its
    status line naming the case, the field and the value.

    The conditions are the constructors' own (`conditions()` of the model and the
    water), evaluated per case under `vmap` on the batched leaves, which are concrete
    here; the first case's concrete build gives their names and order.
    """
    conditions = network_conditions(*reference)
    broken, first = jax.tree.map(np.asarray, _case_violations(batched, unbatched))
    invalid = {}
    for i in range(broken.shape[0]):
        message = checks.first_violation(conditions, broken[i], first[i])
        if message is not None:
            invalid[i] = f"invalid input: case {i}: {message}"
    return invalid


def statics_differ(batched, unbatched, t0) -> bool:
    """Whether `solve_statics(model, env, t=t0)` would be given different inputs in
    different cases of the batch.

    Statics reads every float leaf of the model and the water (the waves' too, whose
    loads at `t0` it includes) except the motions', which it reads only as the
    constrained nodes' positions at `t0`. So the inputs differ where a batched leaf
    outside the motions, or a constrained node's position at `t0`, is not the same in
    every case: compared exactly, in numpy, on the concrete batch (after invalid cases
    took a valid case's values). A harmonic amplitude with zero phase leaves every
    position at `t0` unchanged (A sin 0 = 0); its phase does not.

    **Arguments:**

    - `batched`, `unbatched`: `build_batch`'s trees, the batched leaves with a
        leading case axis and the shared ones.
    - `t0`: the time (s) at which statics places the constrained nodes.
    """
    motions = (jax.tree_util.SequenceKey(0), jax.tree_util.GetAttrKey("motions"))
    leaves = [x for path, x in jax.tree_util.tree_flatten_with_path(batched)[0] if tuple(path[:2]) != motions]
    leaves.append(_held_at(batched, unbatched, np.asarray(t0, dtype=float)))
    return not all(np.array_equal(x, np.broadcast_to(x[:1], x.shape), equal_nan=True) for x in map(np.asarray, leaves))


# Each one compiled program, kept on disk (`jaxcable._programs`), rather than run as
# eager operations under `vmap`, each of which compiled a program of its own: 2.6 s of
# a 32-case sweep's set-up on the anchored line.
@program
def _case_violations(batched, unbatched):
    """`checks.violations` of each case's model and water: whether each condition is
    broken, and its first bad value, with a leading case axis."""

    def one(case):
        model, env = eqx.combine(case, unbatched)
        return checks.violations(network_conditions(model, env))

    return jax.vmap(one)(batched)


@program
def _held_at(batched, unbatched, t0):
    """Each case's constrained nodes' positions (m) at `t0` (s), shape
    `(cases, constrained, 3)`."""

    def one(case):
        model, _ = eqx.combine(case, unbatched)
        return lag.constrained_motion(model, t0)[0]

    return jax.vmap(one)(batched)


def build_batch(build, values, reference):
    """`build` under an eager `jax.vmap` over the cases.

    Not under `jit`: there, every value is a tracer, and builders that compute with
    numpy on their fixed inputs (`anchored_line` does) would fail. Under an eager vmap
    only what depends on a swept parameter is a tracer, which tells the batched leaves
    from the shared ones.

    Returns two trees shaped like `(model, env)`: the batched leaves, with a leading
    case axis, and the shared leaves, each with `None` in the other's places (as
    `eqx.partition` makes them).
    """
    seen = {}

    def traced(case):
        output = build(**case)
        _check_output(output, "when traced under vmap")
        leaves, seen["treedef"] = jax.tree.flatten(output)
        seen["is_batched"] = [isinstance(x, jax.core.Tracer) for x in leaves]
        seen["shapes"] = [jnp.shape(x) for x in leaves]
        seen["shared"] = [None if b else x for x, b in zip(leaves, seen["is_batched"])]
        return [x for x, b in zip(leaves, seen["is_batched"]) if b]

    try:
        # `device_put`, not `jnp.asarray`, which compiles a program for a numpy array's copy.
        batched = jax.vmap(traced)({k: jax.device_put(np.asarray(v)) for k, v in values.items()})
    except _TRACER_ERRORS as e:
        raise ValueError(
            f"sweep: build used the value of {_culprits(build, values)} in Python (float(), int(), "
            "`if`, numpy, or as a count), which it cannot under vmap. Compute with jax.numpy on "
            "the parameters, or replace float leaves of a prebuilt model with eqx.tree_at; "
            "topology cannot be swept."
        ) from e
    leaves, treedef = jax.tree.flatten(reference)
    if treedef != seen["treedef"] or [jnp.shape(x) for x in leaves] != seen["shapes"]:
        raise ValueError(
            "sweep: build returned a different structure when traced under vmap than for the "
            "first case's values (different static options, node or segment counts, or leaves); "
            "topology must not depend on the swept parameters."
        )
    paths = [jax.tree_util.keystr(p) for p, _ in jax.tree_util.tree_flatten_with_path(reference)[0]]
    for path, leaf, is_batched in zip(paths, leaves, seen["is_batched"]):
        if is_batched and not jnp.issubdtype(jnp.result_type(leaf), jnp.inexact):
            raise ValueError(
                f"sweep: build returned (model, env){path}, an integer or boolean array (topology), "
                "that depends on the swept parameters; only float leaves can be swept. Run one "
                "sweep per topology."
            )
    batched = iter(batched)
    case_leaves = [next(batched) if b else None for b in seen["is_batched"]]
    return jax.tree.unflatten(treedef, case_leaves), jax.tree.unflatten(treedef, seen["shared"])
