"""A derivative checked against central differences at a ladder of steps.

A derivative through `simulate` is exact for the discretised dynamics, but through
slack and snap loads those dynamics can be exponentially sensitive: on the README's
anchored line the tangent of the top tension with respect to the segment length grows
by one to three orders of magnitude every quarter second once a segment goes slack, while central
differences with fixed steps converge to it only as h shrinks below 1e-9 m
(`benchmarks/derivative_growth.py`). Such a derivative is right and useless: it holds
for changes too small to matter, and a quantity averaged over the window still varies
with the parameter on larger scales, which is what an optimiser needs. This check says
which case a derivative is in before a user optimises on it.
"""

import dataclasses
import functools
import math
import warnings
from collections.abc import Callable, Sequence
from typing import Literal

import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import ArrayLike

Verdict = Literal["agrees", "disagrees", "ill-conditioned"]

DEFAULT_STEPS = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7)
"""The default ladder of steps, as fractions of the parameter's size (`|x| / |direction|`,
or 1 where that is zero): a solve's rounding (about 1e-6 relative at the default
tolerances) swamps differences below the smallest."""


class DerivativeWarning(UserWarning):
    """A derivative that [`jaxcable.check_derivative`][] could not confirm."""


_SLACK_WARNED = [False]  # `warn_of_slack` speaks once a process


def warn_of_slack(times, strain, undamped: bool = False) -> None:
    """Inside a derivative of a run: a [`DerivativeWarning`][] when a segment goes
    slack in it (its strain, shape `(times, segments)` at `times`, turns from positive
    to zero or less between two saved times), naming how many did, the first and when;
    and, where the line is `undamped` (no axial damping), that damping is the remedy.

    Through slack and snap loads a run's sensitivity grows exponentially (the module's
    notes), so its derivative can be exact and of no use to an optimiser; a run that
    stays taut gets no warning. Said once a process, from a host callback when the
    derivative's forward pass runs; slack that begins and ends between saved times is
    not seen, nor any with a single saved time.

    The growth is fastest without axial damping, which every real rope and chain has:
    on the README's anchored line, the derivatives of the mean and RMS top tension over
    10 s in every segment's length were 10²⁷–10²⁸ N/m without it, and agreed with
    central differences (within 0.6 %) with a damping ratio of 0.3 of a segment's axial
    mode (MoorDyn's `BA = −0.3`), which moved the two statistics by 0.3 %; the maximum's
    agreed at 0.8 (`python benchmarks/derivative_growth.py --part damping`)."""
    if strain.shape[0] < 2:  # one saved time: no event to see
        return
    slack = strain <= 0
    starts = slack[1:] & ~slack[:-1]
    count = jnp.sum(starts)
    first = jnp.argmax(jnp.any(starts, axis=1))
    jax.debug.callback(
        functools.partial(_slack_warning, undamped=undamped),
        count,
        times[first + 1],
        jnp.argmax(starts[first]),
        strain.shape[-1],
        ordered=False,
    )


def _slack_warning(count, time, segment, segments, undamped: bool) -> None:
    count = int(np.sum(count))  # summed over a vmap's cases, where the callback sees a batch
    if count == 0 or _SLACK_WARNED[0]:
        return
    _SLACK_WARNED[0] = True
    time, segment = float(np.ravel(time)[0]), int(np.ravel(segment)[0])
    warnings.warn(
        DerivativeWarning(
            f"simulate is differentiated through {count} slack event{'s' if count > 1 else ''} (a segment's "
            f"strain reaching zero; the first at t = {time:.4g} s, segment {segment + 1} of {segments}). Through "
            "slack and snap loads a run's sensitivity grows exponentially, so this derivative may hold only for "
            "changes too small to matter: check it with jaxcable.check_derivative(f, x) before optimising on it"
            + (
                ". The line has no axial damping, without which that growth is fastest; real ropes and chains "
                "have it (a scene's axial_damping_ratio, MoorDyn's BA, jaxcable.KelvinVoigt's axial_damping), and "
                "with a damping ratio of 0.3 (MoorDyn's BA = -0.3) the derivatives of a slack line's mean and RMS "
                "tension over 10 s agreed with central differences"
                if undamped
                else ""
            )
            + " (said once a process)"
        ),
        stacklevel=1,  # called back from JAX's runtime: no caller of the user's to point at
    )


@dataclasses.dataclass(frozen=True)
class DerivativeCheck:
    """A derivative beside central differences of the same function.

    **Fields:**

    - `value`: `f(x)`.
    - `derivative`: the directional derivative `d f(x + s·direction)/ds` at `s = 0`,
        by automatic differentiation.
    - `steps`: the steps `h` tried, largest first, in the units of `x`.
    - `differences`: `(f(x + h·direction) − f(x − h·direction)) / 2h` at each step.
    - `settled`: for each consecutive pair of steps, whether their differences agree
        within `rtol` (one entry fewer than `steps`).
    - `reference`: the settled difference at the smallest step where two agree (the
        slope of `f` at that scale), or `None` where none do.
    - `verdict`: `"agrees"` (the derivative matches a settled difference),
        `"disagrees"` (the differences settle on another value and no smaller step
        leaves it towards the derivative: a wrong derivative), or `"ill-conditioned"`
        (the differences do not settle, or settle at large steps and leave that value
        towards the derivative at smaller ones:
        `f` varies on scales below the steps, and its exact derivative says nothing
        about its slope at the scale of a useful change).
    - `rtol`: the relative tolerance of both comparisons.
    """

    value: float
    derivative: float
    steps: tuple[float, ...]
    differences: tuple[float, ...]
    settled: tuple[bool, ...]
    reference: float | None
    verdict: Verdict
    rtol: float

    @property
    def trusted(self) -> bool:
        """Whether the derivative agrees with a settled central difference."""
        return self.verdict == "agrees"

    def __str__(self) -> str:
        if self.verdict == "agrees":
            head = f"the derivative {self.derivative:.6g} agrees with central differences within {100 * self.rtol:g} %"
        elif self.verdict == "disagrees":
            head = (
                f"the derivative {self.derivative:.6g} disagrees with central differences, which settle on "
                f"{self.reference:.6g} down to the smallest step: the derivative is wrong"
            )
        else:
            largest = max((abs(d) for d in self.differences if math.isfinite(d)), default=0.0)
            ratio = abs(self.derivative) / largest if largest > 0 else math.inf
            size = f" ({ratio:.3g} times the largest central difference)" if ratio > 10 else ""
            scale = (
                f"the differences settle on {self.reference:.6g} at the larger steps (the slope at that scale) and "
                "move towards the derivative at smaller ones"
                if self.reference is not None
                else "the differences change with the step at every step tried"
            )
            head = (
                f"the derivative {self.derivative:.6g} is ill-conditioned{size}: {scale}. The function varies on "
                "scales below the steps: its derivative holds only for changes far below them and says little "
                "about larger ones"
            )
        rows = [f"  {'automatic differentiation':<34}{self.derivative:14.6g}"]
        for i, (h, d) in enumerate(zip(self.steps, self.differences)):
            mark = " settled" if (i > 0 and self.settled[i - 1]) or (i < len(self.settled) and self.settled[i]) else ""
            rows.append(f"  {f'central difference, h = {h:.3g}':<34}{d:14.6g}{mark}")
        return "check_derivative: " + head + "\n" + "\n".join(rows)


def check_derivative(
    f: Callable[[jax.Array], ArrayLike],
    x: ArrayLike,
    *,
    direction: ArrayLike | None = None,
    steps: Sequence[float] | None = None,
    rtol: float = 0.02,
    mode: Literal["reverse", "forward"] = "reverse",
    warn: bool = True,
    progress: bool = False,
) -> DerivativeCheck:
    """Check the derivative of a scalar `f` at `x` against central differences.

    `f` is what a user optimises: a loss, or a statistic of a simulation (a mean,
    an RMS, a maximum of tension over a window). Its directional derivative by
    automatic differentiation is compared with central differences at each of a
    ladder of steps, so that a derivative that is wrong, or right but ill-conditioned
    (through slack and snap loads, say), is told apart from one to optimise on.

    **Arguments:**

    - `f`: a function of one array (the parameters) returning a scalar.
    - `x`: where to check, a float or an array.
    - `direction`: the direction of the derivative, the shape of `x`; all ones by
        default (for a scalar `x`, `df/dx`).
    - `steps`: the steps `h` of the differences, in the units of `x`; by default
        `DEFAULT_STEPS` (1e-2 to 1e-7) times `|x| / |direction|` (or 1 where `x` is
        zero).
    - `rtol`: the relative tolerance within which two values agree (2 % by default).
    - `mode`: how to differentiate, `"reverse"` (`jax.grad`, for `simulate`'s default
        adjoint) or `"forward"` (`jax.jvp`, for `SolverConfig(adjoint=
        diffrax.ForwardMode())`).
    - `warn`: issue a [`jaxcable.DerivativeWarning`][] with the report where the
        derivative is not trusted.
    - `progress`: a progress bar over the evaluations of `f`.

    **Returns:**

    A [`jaxcable.DerivativeCheck`][]; `str()` of it is the report, and `trusted`
    says whether to optimise on the derivative.

    **Cost:** one derivative and two evaluations of `f` per step (13 by default).

    **Raises:**

    `ValueError` for a `direction` of another shape or all zero, a step that is not a
    positive finite number, a non-positive `rtol`, an unknown `mode`, or an `f` that does
    not return a scalar.
    """
    x = jnp.asarray(x, dtype=float)
    direction = jnp.ones_like(x) if direction is None else jnp.asarray(direction, dtype=float)
    if direction.shape != x.shape:
        raise ValueError(f"check_derivative: direction must have the shape of x, {x.shape}, got {direction.shape}")
    norm = float(jnp.linalg.norm(direction))
    if not norm > 0 or not math.isfinite(norm):
        raise ValueError("check_derivative: direction must be finite and not all zero")
    if steps is None:
        size = float(jnp.linalg.norm(x)) / norm
        steps = tuple(s * (size if size > 0 else 1.0) for s in DEFAULT_STEPS)
    steps = tuple(sorted((float(h) for h in steps), reverse=True))
    if not steps or any(not (h > 0 and math.isfinite(h)) for h in steps):
        raise ValueError(f"check_derivative: steps must be positive finite numbers, got {steps}")
    if not (rtol > 0):
        raise ValueError(f"check_derivative: rtol must be positive, got {rtol}")
    if mode not in ("reverse", "forward"):
        raise ValueError(f"check_derivative: mode must be 'reverse' or 'forward', got {mode!r}")

    scalar = _scalar(f, "check_derivative")
    bar = _bar(1 + 2 * len(steps), progress, "check_derivative")
    if mode == "reverse":
        value, gradient = jax.value_and_grad(scalar)(x)
        derivative = float(jnp.vdot(gradient, direction))
    else:
        value, tangent = jax.jvp(scalar, (x,), (direction,))
        derivative = float(tangent)
    _tick(bar)
    differences = _differences(scalar, x, direction, steps, bar)
    if bar is not None:
        bar.close()
    check = _judge(float(value), derivative, steps, differences, rtol)
    if warn and not check.trusted:
        warnings.warn(str(check), DerivativeWarning, stacklevel=2)
    return check


def check_gradient(
    f: Callable[[jax.Array], ArrayLike],
    x: ArrayLike,
    *,
    steps: Sequence[float] | None = None,
    rtol: float = 0.02,
    warn: bool = True,
    progress: bool = False,
) -> tuple[DerivativeCheck, ...]:
    """Check every component of the gradient of a scalar `f` at `x` against central
    differences: [`jaxcable.check_derivative`][] along each coordinate, from one
    gradient.

    Before a calibration or a design optimisation, each parameter's derivative should
    be one to optimise on; checking them one direction at a time would take a gradient
    per parameter, where one gradient holds them all.

    **Arguments:**

    - `f`: a function of one array (the parameters) returning a scalar.
    - `x`: where to check, a float or an array of any shape.
    - `steps`: the steps `h` of the differences, in the units of `x`, the same for
        every component; by default `DEFAULT_STEPS` (1e-2 to 1e-7) times each
        component's own size `|x[i]|` (or 1 where it is zero).
    - `rtol`, `warn`, `progress`: as [`jaxcable.check_derivative`][]'s; a warning
        names the component (its index in `x` flattened).

    **Returns:**

    One [`jaxcable.DerivativeCheck`][] a component of `x`, in the order of `x`
    flattened (`x.size` of them); `all(c.trusted for c in checks)` says whether the
    gradient is one to optimise on.

    **Cost:** one gradient (`jax.grad`) and two evaluations of `f` per step and
    component (`1 + 2 × steps × x.size`).

    **Raises:**

    `ValueError` for an empty `x`, a step that is not a positive finite number, a
    non-positive `rtol`, or an `f` that does not return a scalar.
    """
    x = jnp.asarray(x, dtype=float)
    if x.size == 0:
        raise ValueError("check_gradient: x must have at least one component, got an empty array")
    if not (rtol > 0):
        raise ValueError(f"check_gradient: rtol must be positive, got {rtol}")
    flat = [abs(float(v)) for v in np.asarray(x).ravel()]
    if steps is None:
        ladders = [tuple(s * (size if size > 0 else 1.0) for s in DEFAULT_STEPS) for size in flat]
    else:
        ladder = tuple(sorted((float(h) for h in steps), reverse=True))
        if not ladder or any(not (h > 0 and math.isfinite(h)) for h in ladder):
            raise ValueError(f"check_gradient: steps must be positive finite numbers, got {steps}")
        ladders = [ladder] * x.size

    scalar = _scalar(f, "check_gradient")
    bar = _bar(1 + 2 * sum(len(ladder) for ladder in ladders), progress, "check_gradient")
    value, gradient = jax.value_and_grad(scalar)(x)
    gradient = np.asarray(gradient).ravel()
    _tick(bar)
    checks = []
    for i, ladder in enumerate(ladders):
        direction = jnp.zeros(x.size).at[i].set(1.0).reshape(x.shape)
        differences = _differences(scalar, x, direction, ladder, bar)
        check = _judge(float(value), float(gradient[i]), ladder, differences, rtol)
        if warn and not check.trusted:
            warnings.warn(f"component {i} of x: {check}", DerivativeWarning, stacklevel=2)
        checks.append(check)
    if bar is not None:
        bar.close()
    return tuple(checks)


def _scalar(f, caller):
    """`f`, refusing a result that is not a scalar."""

    def scalar(x):
        value = jnp.asarray(f(x))
        if value.shape != ():
            raise ValueError(f"{caller}: f must return a scalar, got shape {value.shape}")
        return value

    return scalar


def _differences(scalar, x, direction, steps, bar) -> tuple[float, ...]:
    """The central differences of `scalar` at `x` along `direction`, one a step."""
    differences = []
    for h in steps:
        above = float(scalar(x + h * direction))
        _tick(bar)
        below = float(scalar(x - h * direction))
        _tick(bar)
        differences.append((above - below) / (2 * h))
    return tuple(differences)


def _judge(value, derivative, steps, differences, rtol) -> DerivativeCheck:
    """The verdict on `derivative` from the `differences` at `steps` (largest first)."""

    def close(a, b):
        return math.isfinite(a) and math.isfinite(b) and abs(a - b) <= rtol * max(abs(a), abs(b))

    settled = tuple(close(a, b) for a, b in zip(differences, differences[1:]))
    # A difference counts as settled where it agrees with a neighbour.
    settled_at = [i for i in range(len(differences)) if (i > 0 and settled[i - 1]) or (i < len(settled) and settled[i])]
    reference = differences[settled_at[-1]] if settled_at else None
    if any(close(derivative, differences[i]) for i in settled_at) or (
        len(steps) == 1 and close(derivative, differences[0])
    ):
        verdict: Verdict = "agrees"
    elif reference is None or not math.isfinite(derivative):
        verdict = "ill-conditioned" if math.isfinite(derivative) else "disagrees"
    else:
        # Below the scale where they settle, differences that leave the settled value
        # towards the derivative resolve a structure finer than that scale (the
        # derivative is their limit as h shrinks, however far off: through a snap the
        # 5 s mean's is 1e10 times any difference); differences that stay put leave
        # the derivative wrong.
        finer = differences[settled_at[-1] + 1 :]
        towards = any(
            math.isfinite(d)
            and abs(d - reference) > rtol * abs(reference)
            and math.copysign(1.0, d - reference) == math.copysign(1.0, derivative - reference)
            for d in finer
        )
        verdict = "ill-conditioned" if towards else "disagrees"
    return DerivativeCheck(value, derivative, steps, differences, settled, reference, verdict, rtol)


def _bar(total, progress, caller):
    if not progress:
        return None
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=caller, unit="evaluation")


def _tick(bar):
    if bar is not None:
        bar.update()
