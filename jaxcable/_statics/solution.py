"""What a static solve returns, its defaults, and what both ways of solving (the
compiled pseudo-transient continuation and the discrete catenary) share."""

import functools
from typing import Any

import equinox as eqx
import jax
import numpy as np
import optimistix as optx
from jaxtyping import Array, Bool, Float, Int

from .. import _checks as checks
from .._model.state import State
from .._sea.environment import CurrentProfile, Environment

# The largest mean strain that a chain of segments between two constrained nodes may
# need to reach from one to the other. Above it the scene is taken to be a mistake (a
# length in the wrong unit, a line between the wrong points), said before solving, and
# not a load: 100 % is beyond any rope's breaking strain.
MAX_REQUIRED_STRAIN = 1.0

# `solve_statics`'s defaults, which a sweep's statics use.
MAX_STEPS = 1000
FORCE_TOLERANCE = 1e-6

# Failure's causes (`failure_message`), relative to the force scale: a node off the bed
# whose segments carry less than `SLACK_SHARE` of it is on slack line, and a force left
# below `STALL_SHARE` of it is close to the equilibrium.
SLACK_SHARE = 1e-3
STALL_SHARE = 1e-3


class StaticSolution(eqx.Module):
    """The equilibrium of a network.

    **Attributes:**

    - `state`: node positions (m) and zero velocities, usable as the initial state of
        [`jaxcable.simulate`][].
    - `strain`: ε (–), shape `(segments,)`.
    - `tension`: T (N), shape `(segments,)`.
    - `reactions`: force (N) of each support on the network, shape `(constrained, 3)`.
    - `residual`: the largest remaining force (N) on a free node (any component).
    - `force_scale`: the scene's force scale (N) that `residual` is judged against: the
        largest segment tension, wet weight of a segment or body, body's constant force,
        or drag on a node at rest.
    - `worst_node`: the node that `residual` is on.
    - `worst_tension`: the largest tension (N) in a segment at `worst_node`; about zero
        where that node is on slack line.
    - `worst_drag`: the drag (N) of the current on `worst_node` at rest.
    - `worst_on_seabed`: whether `worst_node` rests on the seabed.
    - `required_strain`: the largest mean strain (–) that a chain of segments between
        two constrained nodes needs to reach from one to the other; above
        `MAX_REQUIRED_STRAIN` (100 %) the solve counts as failed.
    - `result`: optimistix's result code; `result == optimistix.RESULTS.successful` on
        success.
    - `steps`: pseudo-time steps taken, all stages together; Newton's iterations for
        the discrete catenary.
    - `invalid_input`: which of `input_requirements` the inputs break, the first one;
        −1 where they break none. Only a traced input (a model built or batched inside
        `jax.vmap` or `jit`) solved with `throw=False` can break one: a concrete one is
        refused before solving, and `throw=True` raises. Such a case's `result` is
        `optimistix.RESULTS.nonfinite_input` (as a sweep marks one), its free nodes
        are NaN and its other fields mean nothing.
    - `invalid_value`: the first entry of that field that breaks it; NaN where none.
    - `input_requirements`: what the model's and the water's fields require, as
        `"LineType.tension_law.axial_stiffness must be positive"`, where the inputs
        were traced and `throw=False`; empty otherwise.
    - `method`: how it was found: `"pseudo-transient continuation"`, the compiled
        solver, or `"discrete catenary"`, a single line in still water in closed form
        (numpy, `jaxcable._statics.catenary`).
    """

    state: State
    strain: Float[Array, " segments"]
    tension: Float[Array, " segments"]
    reactions: Float[Array, "constrained 3"]
    residual: Float[Array, ""]
    force_scale: Float[Array, ""]
    worst_node: Int[Array, ""]
    worst_tension: Float[Array, ""]
    worst_drag: Float[Array, ""]
    worst_on_seabed: Bool[Array, ""]
    required_strain: Float[Array, ""]
    result: optx.RESULTS
    steps: Int[Array, ""]
    invalid_input: Int[Array, ""]
    invalid_value: Float[Array, ""]
    input_requirements: tuple[str, ...] = eqx.field(static=True, default=())
    method: str = eqx.field(static=True, default="pseudo-transient continuation")

    def failures(self, force_tolerance: float = FORCE_TOLERANCE, max_steps: int = MAX_STEPS) -> dict[Any, str]:
        """Why each case found no equilibrium, for a concrete solution: a batch from
        `jax.vmap(lambda m: solve_statics(m, env, throw=False))`, say, whose leaves carry
        leading case axes.

        **Arguments:**

        - `force_tolerance`, `max_steps`: those the solve was given, which the messages
            quote.

        **Returns:**

        `{case: message}` for each case that failed, none for those that succeeded:
        the case's index along the batch's axis (an int), a tuple of indices for
        nested batches, `()` for a single solution. A case whose inputs break a
        requirement names the field and the value (`invalid_input`).
        """
        if checks.traced(self.residual):
            raise ValueError("StaticSolution.failures: the solution is traced; call it on the concrete result")
        failed = ~np.asarray(self.result == optx.RESULTS.successful)
        out = {}
        for index in np.argwhere(failed):
            index = tuple(int(i) for i in index)
            case = jax.tree.map(functools.partial(_entry, index=index), self)
            out[index[0] if len(index) == 1 else index] = failure_message(case, force_tolerance, max_steps)
        return out


def _entry(leaf, index: tuple[int, ...]):
    """One case's entry of a batched leaf."""
    return leaf[index]


def still_water(env: Environment) -> bool:
    """Whether the water is known to be still before tracing: no waves, and a current
    (or a profile's speeds) that is concrete and exactly zero. Statics then leaves out
    the water's loads on nodes at rest, which are exactly zero there: for the Low &
    Langley jumper they were half of statics' program (10,526 lines of StableHLO
    against 5,052) and 0.9 s of its trace and compile. A traced current (a sweep over
    it, a derivative with respect to it) takes the general path."""
    if env.waves:
        return False
    current = env.current.speeds if isinstance(env.current, CurrentProfile) else env.current
    return not checks.traced(current) and not np.any(np.asarray(current))


def failure_message(
    solution: StaticSolution, force_tolerance: float = FORCE_TOLERANCE, max_steps: int = MAX_STEPS
) -> str:
    """Why `solution` (concrete, one case) is not an equilibrium, and what to try."""
    if int(solution.invalid_input) >= 0:
        requirement = solution.input_requirements[int(solution.invalid_input)]
        return f"solve_statics: invalid input: {requirement}, got {float(solution.invalid_value):g}"
    result = solution.result
    if solution.required_strain > MAX_REQUIRED_STRAIN:
        return (
            "solve_statics: the segments between two constrained nodes must stretch "
            f"{100 * float(solution.required_strain):.3g} % to reach from one to the other, more than the "
            f"{100 * MAX_REQUIRED_STRAIN:.0f} % allowed. Is a line's length or an end's position wrong?"
        )
    stretch = float(np.max(np.asarray(solution.strain)))
    if not np.isfinite(stretch) or stretch > MAX_REQUIRED_STRAIN:
        return (
            f"solve_statics found no equilibrium: segments were stretched by up to {100 * stretch:.3g} % and "
            "still stretching. Loads that grow as a line stretches (the drag on a soft line, which grows with "
            "its length) can outgrow its stiffness, and then there is no equilibrium: check the line's EA "
            "against its drag and weight."
        )
    if result == optx.RESULTS.nonlinear_max_steps_reached:
        why = f"its {max_steps} steps (max_steps) ran out"
    elif result == optx.RESULTS.nonfinite:
        why = "the forces became non-finite"
    else:
        why = "its steps stalled (every larger pseudo-time step raised the force)"
    node = int(solution.worst_node)
    position = np.array2string(np.asarray(solution.state.positions)[node], precision=4)
    residual, scale = float(solution.residual), float(solution.force_scale)
    tension, drag = float(solution.worst_tension), float(solution.worst_drag)
    left = (
        f"The largest force left is {residual:.4g} N, on node {node} at {position} m, against force_tolerance "
        f"({force_tolerance}) times the scene's force scale ({scale:.4g} N)."
    )
    if solution.worst_on_seabed:
        cause = (
            f"node {node} lies on the seabed, which holds nothing sideways (statics has no friction): only the "
            f"current's drag there ({drag:.3g} N, a fraction {drag / scale:.2g} of the force scale) and the line's "
            f"tension ({tension:.3g} N) move it, and they were still laying the line out along the bed when {why}. "
            f"{left} Start from a shape with the line laid out along the bed (initial=), or check the line's "
            "length; in still water, slack line on the bed rests in any layout"
        )
    elif tension <= SLACK_SHARE * scale:
        cause = (
            f"node {node} is on slack line (its segments carry {tension:.3g} N), which has no stiffness to hold it, "
            f"and it was still moving under its weight, buoyancy or drag ({drag:.3g} N) when {why}. {left} Check "
            "that this stretch can rest (a line floating up, a buoy that cannot lift its line) or start from a "
            "shape closer to its rest (initial=)"
        )
    elif residual <= STALL_SHARE * scale:
        cause = (
            f"{why} close to it, the force left a fraction {residual / scale:.2g} of the force scale, on taut line "
            f"({tension:.4g} N) at node {node}. {left} Stiff segments whose stretch is far smaller than their turn "
            "can stall there: start from a shape closer to the equilibrium (initial=)"
        )
    else:
        cause = (
            f"{why} far from it. {left} Check that this part of the network can rest (a line that must carry its "
            "load nearly straight, a buoy that cannot lift its line), or start from a shape closer to the "
            "equilibrium (initial=)"
        )
    return f"solve_statics found no equilibrium: {cause}; from Python, max_steps allows more steps."
