"""What a static solve returns, its defaults, and what both ways of solving (the
compiled pseudo-transient continuation and the discrete catenary) share."""

import equinox as eqx
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
    method: str = eqx.field(static=True, default="pseudo-transient continuation")


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
