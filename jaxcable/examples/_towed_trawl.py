"""The towed trawl: a branched cable system towed at a speed that steps.

Bezverkhyy & Korniienko's example B (Bezverkhyy & Korniienko, §3; `seed-002-branched-cables.md`): a
200 m tow cable from the towing vessel to a branch point, two 100 m sweep branches from
there to diverters, which a constant force F₀ spreads to either side, and a 100 m branch
to a 100 kg support buoy. The cable is the anchored-line paper's (m = 3 kg/m, F = 0.0003 m², C_n = 15.6,
C_τ = 0.78 kg/m², C_a = 0.4 kg/m), viscoelastic with C_v = 0.02 C_E (a retardation time of
0.02 s). The towing speed steps at t = 300 s.

Junctions, which keep their indices as nodes: 0 the tow point, 1 the branch point,
2 and 3 the diverters (to +y and −y), 4 the buoy. x points along the tow, z up.

The paper's numbers for F₀, C_E, the bodies and the waves are lost or never given; this
module's choices, stated here and in the constants below:

- C_E = 3 × 10⁷ N, the anchored-line paper's steel cable (`jaxcable/examples/_anchored_line.py` says why).
- F₀ = 5 kN on each diverter, along ±y (perpendicular to the tow, fixed in direction).
- Diverters: 300 kg, 0.1 m³, C_D A = 2 m². A branch-point vehicle (the paper's
  "underwater apparatus"): 500 kg, 0.1 m³, C_D A = 1 m².
- The buoy floats at the surface, as the paper's does: 100 kg (the paper's), a column
  1.5 m tall of 2.5 m³ (`Body.height`), C_D A = 0.5 m² (1 m² frontal area, K = 0.5).
  It holds the branch point about 100 m down at 1 m/s, not the 200 m the paper gives
  for its vehicle, which a 100 m support branch cannot reach (the notes flag this).
- Waves: Airy, T = 5.6 s, H = 2 A with the anchored-line paper's amplitude law (A = 1.57 m), running
  against the tow (the paper's Ox₁ points against the waves), in 1000 m of water.
"""

import equinox as eqx
import jax.numpy as jnp
import numpy as np

from .._model.materials import KelvinVoigt
from .._model.motion import Towing
from .._model.network import Body, Branch, CableNetwork
from .._model.state import State
from .._sea.environment import Environment
from .._sea.waves import Airy, floater_amplitude
from .._statics.solution import StaticSolution
from .._statics.solve import solve_statics
from ._anchored_line import AXIAL_STIFFNESS, WAVE_PERIOD, anchored_line_type

TOW_LENGTH = 200.0  # m
BRANCH_LENGTH = 100.0  # m, each of the three branches
VISCOUS_RATIO = 0.02  # s, C_v / C_E
STEP_TIME = 300.0  # s
# The paper's step is instantaneous. This one takes 0.02 s: well inside the 0.13 s an
# axial wave takes down the tow cable and back, so the tension's stages stay sharp, but
# a few of the cable's fastest periods, so the front is resolved, not a shock.
STEP_DURATION = 0.02  # s, over which the tow's speed changes linearly
DIVERTER_FORCE = 5.0e3  # N, F₀
DIVERTER = dict(mass=300.0, volume=0.1, drag_area=2.0, added_mass=1.0)
VEHICLE = dict(mass=500.0, volume=0.1, drag_area=1.0, added_mass=1.0)
BUOY = dict(mass=100.0, volume=2.5, drag_area=0.5, added_mass=0.5, height=1.5)
WATER_DEPTH = 1000.0  # m


def _guess() -> np.ndarray:
    """First guesses for the junctions (m): each branch straight and stretched by 0.1 %,
    so that statics starts taut, along the directions of the steady tow at 1 m/s."""

    def unit(v):
        return np.asarray(v) / np.linalg.norm(v)

    stretch = 1.001
    branch_point = TOW_LENGTH * stretch * unit([-170.0, 0.0, -100.0])
    diverter = BRANCH_LENGTH * stretch * unit([-40.0, 80.0, -40.0])
    buoy = BRANCH_LENGTH * stretch * unit([-20.0, 0.0, 100.0])
    mirror = np.array([1.0, -1.0, 1.0])
    return np.stack(
        [np.zeros(3), branch_point, branch_point + diverter, branch_point + mirror * diverter, branch_point + buoy]
    )


def towed_trawl(
    speeds: tuple[float, float] = (1.0, 3.0),
    *,
    viscous: bool = True,
    waves: bool = False,
    start: float = STEP_TIME - 20.0,
    step_duration: float = STEP_DURATION,
    segments: tuple[int, int] = (20, 10),
    mass_matrix: str = "lumped",
    quadratic_ratio: float = 0.0,
) -> tuple[CableNetwork, Environment]:
    """The towed trawl, `(model, env)`, its tow point moving along +x at `speeds[0]`
    (m/s) until `STEP_TIME` and at `speeds[1]` from `STEP_TIME + step_duration`.

    **Arguments:**

    - `speeds`: the towing speed before and after the step (m/s): (1, 3), (1, 4) or
        (1, 2) in the paper; a decrease is allowed.
    - `viscous`: the cable's viscous term C_v = 0.02 C_E (default), or none.
    - `waves`: the anchored-line paper's 5.6 s Airy wave against the tow, or calm water (default).
    - `start`: the time (s) at which the tow point is at the origin: start the run
        there, from [`steady_tow`][].
    - `step_duration`: the time (s) over which the speed changes linearly.
    - `segments`: segments in the tow cable and in each 100 m branch.
    - `mass_matrix`: as for [`jaxcable.CableNetwork`][].
    - `quadratic_ratio`: C_E1 / C_E, the cable's nonlinear-elastic coefficient (seed
        003's 0.05–0.2); 0 (Hooke's law) by default.
    """
    before, after = speeds
    law = KelvinVoigt(
        AXIAL_STIFFNESS, quadratic_ratio * AXIAL_STIFFNESS, VISCOUS_RATIO * AXIAL_STIFFNESS if viscous else 0.0
    )
    env_waves = ()
    if waves:
        env_waves = Airy(2 * floater_amplitude(WAVE_PERIOD), WAVE_PERIOD, WATER_DEPTH, heading=180.0)
    # The waves ramp in over two periods from the run's start, out of the steady tow.
    env = Environment(
        water_density=1025.0,
        gravity=9.81,
        depth=WATER_DEPTH,
        waves=env_waves,
        wave_ramp=2 * WAVE_PERIOD,
        wave_start=start,
    )
    line = anchored_line_type(law, float(env.water_density))
    tow, branch = segments
    model = CableNetwork.from_branches(
        _guess(),
        [
            Branch(0, 1, line, TOW_LENGTH, tow),
            Branch(1, 2, line, BRANCH_LENGTH, branch),
            Branch(1, 3, line, BRANCH_LENGTH, branch),
            Branch(1, 4, line, BRANCH_LENGTH, branch),
        ],
        constraints={0: Towing([start, STEP_TIME, STEP_TIME + step_duration], [before, before, after])},
        bodies={
            1: Body(**VEHICLE),
            2: Body(**DIVERTER, force=(0.0, DIVERTER_FORCE, 0.0)),
            3: Body(**DIVERTER, force=(0.0, -DIVERTER_FORCE, 0.0)),
            4: Body(**BUOY),
        },
        mass_matrix=mass_matrix,
    )
    return model, env


def steady_tow(
    model: CableNetwork, env: Environment, speed: float, t: float, *, initial: State | None = None
) -> tuple[State, StaticSolution]:
    """The trawl in steady tow at `speed` (m/s) along +x at time `t`, as the initial
    state of a run from `t`: `(state, statics)`.

    Seen from the tow point, steady towing is statics in a uniform current −speed: every
    node then moves at `speed` along +x. Solved with the waves off; a run from `t`
    meets them ramped in over two periods. `initial`: a first guess, the straight
    branches of `model` by default; [`start_tow`][] makes a better one.
    """
    towed = eqx.tree_at(lambda e: (e.current, e.waves), env, (jnp.array([-speed, 0.0, 0.0]), ()))
    # The drag bends the branches far from their straight first guess: allow more
    # steps than the default.
    statics = solve_statics(model, towed, t=t, initial=initial, max_steps=3000)
    positions = statics.state.positions
    velocities = jnp.zeros_like(positions).at[:, 0].set(speed)
    return State(positions, velocities), statics


COARSE_SEGMENTS = (4, 2)


def _branch_nodes(segments: tuple[int, int]) -> list[np.ndarray]:
    """Each branch's nodes in order, junctions included, as `towed_trawl` numbers them."""
    ends = ((0, 1), (1, 2), (1, 3), (1, 4))
    counts = (segments[0],) + 3 * (segments[1],)
    nodes, next_node = [], len(ends) + 1
    for (a, b), n in zip(ends, counts):
        nodes.append(np.array([a, *range(next_node, next_node + n - 1), b]))
        next_node += n - 1
    return nodes


def start_tow(
    speeds: tuple[float, float] = (1.0, 3.0), **options
) -> tuple[CableNetwork, Environment, State, StaticSolution]:
    """The trawl of [`towed_trawl`][]`(speeds, **options)` and its steady tow at
    `speeds[0]` at the run's start: `(model, env, state, statics)`.

    Levenberg–Marquardt from the straight branches takes hundreds of iterations, each
    dear at 20 segments a branch. So the trawl is first solved with `COARSE_SEGMENTS`,
    and the fine nodes start on that solution's polylines, each branch's nodes spaced
    evenly along its length; a few iterations then finish.
    """
    segments = options.pop("segments", (20, 10))
    start = options.get("start", STEP_TIME - 20.0)
    coarse, env = towed_trawl(speeds, segments=COARSE_SEGMENTS, **options)
    coarse_state, _ = steady_tow(coarse, env, speeds[0], start)
    model, env = towed_trawl(speeds, segments=segments, **options)
    guess = np.array(model.node_positions)
    solved = np.asarray(coarse_state.positions)
    for fine_nodes, coarse_nodes in zip(_branch_nodes(segments), _branch_nodes(COARSE_SEGMENTS)):
        polyline = solved[coarse_nodes]
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(polyline, axis=0), axis=1))])
        at = np.linspace(0.0, arc[-1], fine_nodes.size)
        guess[fine_nodes] = np.stack([np.interp(at, arc, polyline[:, k]) for k in range(3)], axis=1)
    state, statics = steady_tow(model, env, speeds[0], start, initial=State(jnp.asarray(guess), jnp.zeros_like(guess)))
    return model, env, state, statics
