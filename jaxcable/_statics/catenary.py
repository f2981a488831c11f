"""Catenaries: a single line's statics in closed form, in numpy.

A line between two supports in still water is a catenary. Two are here:

- The continuous elastic catenary (Jonkman's quasi-static line, FAST v7 and MAP, which
  MoorDyn's `Line::initialize` solves, v2.7 `QSlines.hpp`): [`catenary`][], solved by
  Newton's method on the upper end's tension (H, V) as MoorDyn iterates it, with its
  first guess, damped steps and stop at a relative step of 1e-5 (`TOLERANCE`). It is
  MoorDyn's start shape (`jaxcable.io._initial_shape`) and the first guess below.
- The discrete one, jaxcable's own equilibrium of the polyline (`jaxcable._equations.lagrangian`'s
  static forces, exactly): [`catenary_statics`][], which `jaxcable.solve_statics`
  takes where it applies. Compiling statics' root finder costs seconds; this
  costs milliseconds, and finds the same equilibrium to rounding.

**The discrete catenary.** In still water, with no bodies on the line's inner nodes and
no bending, a free node carries only vertical loads: half of each neighbouring segment's
weight less buoyancy (the potential's `(m − ρF) g L z̄` term), and the seabed's spring
`k A δ` where it presses a depth δ into the bed (a frictionless bed holds nothing
sideways at rest). So each segment's tension vector `T_k τ_k` (pointing from end A
towards end B) has the same horizontal component H, in the vertical plane through the
two supports, and its vertical component steps by each node's load:

    V_k = V_1 − Σ_{j<k} (W_j + R_j),   T_k = √(H² + V_k²),   S_k = L_k (1 + ε(T_k)),

with W_j the node's wet lift, R_j its bed reaction and ε(T) the inverse of the tension
law (closed form above the slack switch's band, a safeguarded Newton inside it). Each
node is its predecessor plus `S_k (H, V_k)/T_k`. Newton's method on (H, V_1) and the
bed nodes' reactions makes the walk end on support B and each reaction the spring's
`k A max(−depth − z_j, 0)`, with the nodes on the bed held fixed while it converges
and then taken afresh (`_solve_chain`). The reactions are unknowns, not computed
along the walk: walked, a chain on a stiff bed is unstable (an error grows by a factor
of about `k A S / H` a node, 675 for the bundled wave_mooring chain), where one linear
system over them all is well posed.

It applies only where it is exact: one chain of segments between the two constrained
nodes, still water (no current, no waves), no bending stiffness, nothing on the inner
nodes, jaxcable's own tension laws, concrete values (not under `jit`, `vmap` or a
derivative), and, with the free surface on, the line wholly below it. Elsewhere, and
where it does not converge, `catenary_statics` returns `None` and statics takes the
compiled root finder.
"""

import functools
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx

from .. import _checks as checks
from .._equations import lagrangian as lag
from .._model.materials import KelvinVoigt, LinearElastic, NonlinearElastic
from .._model.motion import Fixed
from .._model.network import CableNetwork, Topology
from .._model.state import State
from .._programs import RUN_ONCE, program
from .._sea.environment import Environment
from .._typing import RealScalarLike
from .solution import FORCE_TOLERANCE, MAX_REQUIRED_STRAIN, StaticSolution, still_water

# MoorDyn's tolerances: the catenary's relative tolerance, which also marks an end on the
# bed (within 1e-5 of the depth), floors the spans, damps the steps and bounds their
# number (1/TOLERANCE).
TOLERANCE = 1e-5

# The discrete catenary's Newton iterations: at most `MAX_ITERATIONS` for each set of
# nodes on the bed (and as many sets), ending where end B and the bed nodes are within
# `CLOSURE` (m) of where they belong, or where rounding stops the closure from halving
# and it is within `ROUNDING_CLOSURE` of the line's length. Steps are halved at most
# `HALVINGS` times, while the closure grows.
MAX_ITERATIONS = 100
CLOSURE = 1e-10
ROUNDING_CLOSURE = 1e-8
HALVINGS = 30
# A dense solve over the nodes on the bed costs their cube: beyond this many statics
# takes the compiled solver, whose Jacobian is banded.
MOST_ON_BED = 2000
# Iterations that invert the tension law inside the slack switch's band (each at least
# halves the bracket, so 2⁻¹⁰⁰ of the band at worst).
BAND_ITERATIONS = 100

METHOD = "discrete catenary"
"""`StaticSolution.method` of a solution found here."""


def catenary(
    spread: float, rise: float, length: float, stiffness: float, weight: float, on_bed: bool, arc: np.ndarray
) -> tuple[np.ndarray, np.ndarray] | None:
    """The elastic catenary of a line from end A to end B, `spread` (m) apart
    horizontally and B `rise` (m) above A, of unstretched `length` (m), axial stiffness
    `stiffness` (N) and wet weight `weight` (N/m), resting on a frictionless bed
    through its lower end if `on_bed`; `None` where it has no solution.

    **Returns:**

    The horizontal distance from A towards B and the height above A (m) of the points
    at unstretched arc lengths `arc` (m) from A, each of `arc`'s shape.
    """
    if rise < 0:  # solve with the ends swapped, so that the lower end is at the origin
        solved = catenary(spread, -rise, length, stiffness, weight, on_bed, length - arc)
        if solved is None:
            return None
        horizontal, vertical = solved
        return spread - horizontal, vertical - (-rise)
    if weight == 0:
        return None
    on_bed = on_bed and weight > 0
    # MoorDyn floors both spans at the tolerance, so that neither limit case (vertical,
    # horizontal) needs its own formulas.
    spread, rise = max(spread, TOLERANCE), max(rise, TOLERANCE)
    if on_bed and _doubles_back(spread, rise, length, stiffness, weight):
        return None
    tensions = _fairlead_tension(spread, rise, length, stiffness, weight, on_bed)
    if tensions is None:
        return None
    horizontal_tension, vertical_tension = tensions
    w, h, ea = weight, horizontal_tension, stiffness
    anchor = vertical_tension - w * length  # the vertical tension at A (negative: on the bed)
    if not on_bed or anchor > 0:
        ratio = (anchor + w * arc) / h
        x = h / w * (np.arcsinh(ratio) - np.arcsinh(anchor / h)) + arc * h / ea
        z = h / w * (np.hypot(1, ratio) - np.hypot(1, anchor / h)) + arc / ea * (anchor + w * arc / 2)
        return x, z
    resting = length - vertical_tension / w  # the length on the bed
    ratio = np.maximum(anchor + w * arc, 0.0) / h
    hanging = h / w * np.arcsinh(ratio) + resting
    x = np.where(arc <= resting, arc, hanging) + arc * h / ea
    z = np.where(arc <= resting, 0.0, h / w * (np.hypot(1, ratio) - 1) + arc / ea * (anchor + w * arc / 2))
    z = z + np.where(arc <= resting, 0.0, anchor**2 / (2 * w * ea))
    return x, z


def _doubles_back(spread: float, rise: float, length: float, stiffness: float, weight: float) -> bool:
    """Whether a line resting on the bed through its lower end is longer than the "L"
    along the bed and straight up to its upper end, `spread` and `rise` (m) away, so
    that it would double back on the bed (`catenary`'s arguments)."""
    reach = spread - stiffness / weight + np.sqrt((stiffness / weight) ** 2 + 2 * rise * stiffness / weight)
    return bool(length >= reach)


def _fairlead_tension(
    spread: float, rise: float, length: float, stiffness: float, weight: float, on_bed: bool
) -> tuple[float, float] | None:
    """The horizontal and vertical tension (N) at the upper end that put it `spread`,
    `rise` (m) from the lower: Newton's method on the catenary's closure equations
    from Peyrot and Goulois's first guess, with MoorDyn's damping and stopping rule
    (module docstring); `None` if it does not converge."""
    w, ea, length = weight, stiffness, length
    if length <= np.hypot(spread, rise):
        shape = 0.2  # taut
    else:
        shape = np.sqrt(3 * ((length**2 - rise**2) / spread**2 - 1))
    h = max(abs(0.5 * w * spread / shape), TOLERANCE)
    v = 0.5 * w * (rise / np.tanh(shape) + length)
    for step in range(1, int(round(1 / TOLERANCE)) + 1):
        a, b = v / h, (v - w * length) / h
        ra, rb = np.hypot(1, a), np.hypot(1, b)
        if on_bed and v - w * length <= 0:
            x = h / w * np.arcsinh(a) + length * h / ea + length - v / w - spread
            z = h / w * (ra - 1) + v**2 / (2 * w * ea) - rise
            jacobian = np.array(
                [
                    [(np.arcsinh(a) - a / ra) / w + length / ea, (1 / ra - 1) / w],
                    [(ra - 1 - a**2 / ra) / w, a / ra / w + v / (w * ea)],
                ]
            )
        else:
            x = h / w * (np.arcsinh(a) - np.arcsinh(b)) + length * h / ea - spread
            z = h / w * (ra - rb) + length / ea * (v - w * length / 2) - rise
            jacobian = np.array(
                [
                    [(np.arcsinh(a) - np.arcsinh(b) - a / ra + b / rb) / w + length / ea, (1 / ra - 1 / rb) / w],
                    [(ra - rb - a**2 / ra + b**2 / rb) / w, (a / ra - b / rb) / w + length / ea],
                ]
            )
        try:
            dh, dv = np.linalg.solve(jacobian, [-x, -z])
        except np.linalg.LinAlgError:
            return None
        dh, dv = dh * (1 - TOLERANCE * step), dv * (1 - TOLERANCE * step)
        dh = max(dh, (TOLERANCE - 1) * h)  # keeps the horizontal tension positive
        if not (np.isfinite(dh) and np.isfinite(dv)):
            return None
        if abs(dh) <= TOLERANCE * h and abs(dv) <= TOLERANCE * abs(v):
            return float(h), float(v)
        h, v = h + dh, v + dv
    return None


class _Law(NamedTuple):
    """A tension law's elastic part `T = (C_E ε + C_E1 ε²) H(ε)` in numpy, per segment:
    C_E (N), C_E1 (N) and the slack switch's width w (–; 0 for the sharp switch), each
    of shape `(segments,)`. The numpy twin of `jaxcable._model.materials`' elastic tension,
    which eager JAX would compile op by op (tens of milliseconds each); tested equal."""

    stiffness: np.ndarray
    quadratic: np.ndarray
    width: np.ndarray

    @classmethod
    def of(cls, law, segments: int) -> "_Law":
        """The elastic part of one of `jaxcable._model.materials`' laws, for `segments`."""
        # A linear law's C_E1 is zero; its `quadratic_stiffness()` builds it on the
        # device, an eager op that compiles (75 ms).
        quadratic = 0.0 if isinstance(law, LinearElastic) else law.quadratic_stiffness()
        coefficients = (law.axial_stiffness, quadratic, law.slack_width)
        return cls(*(np.broadcast_to(np.asarray(x, float), (segments,)) for x in coefficients))

    def tension(self, strain: np.ndarray) -> np.ndarray:
        """T(ε) (N), `strain` of shape `(segments,)`."""
        smooth = self.width > 0
        s = np.clip(strain / np.where(smooth, self.width, 1.0), 0.0, 1.0)
        switch = np.where(smooth, s * s * (3.0 - 2.0 * s), strain > 0)
        return strain * (self.stiffness + self.quadratic * strain) * switch

    def strain(self, tension: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The strain ε (–) at which each segment carries `tension` T > 0 (N, shape
        `(segments,)`), and its compliance dε/dT (1/N); NaN beyond the largest
        tension the law reaches."""
        c_e, c_e1, w = self.stiffness, self.quadratic, self.width
        # Above the band: the root of C_E1 ε² + C_E ε − T on the rising branch, written
        # without the cancellation of (−C_E + √·)/2C_E1 when C_E1 is small.
        with np.errstate(invalid="ignore"):
            above = 2 * tension / (c_e + np.sqrt(c_e**2 + 4 * c_e1 * tension))
        band = (w > 0) & (tension < w * (c_e + c_e1 * w))
        if not np.any(band):
            return above, 1 / (c_e + 2 * c_e1 * above)
        # Inside it, T = w s³ (3 − 2s)(C_E + C_E1 w s) with s = ε/w rises from 0 to 1:
        # Newton's steps, bisection's where they leave the bracket.
        t, c_e, c_e1, w = tension[band], c_e[band], c_e1[band], w[band]

        def law(s):
            cubic, rising = s**3 * (3 - 2 * s), c_e + c_e1 * w * s
            return w * cubic * rising - t, w * ((9 * s**2 - 8 * s**3) * rising + cubic * c_e1 * w)

        low, high = np.zeros_like(t), np.ones_like(t)
        s = np.clip(np.cbrt(t / (3 * c_e * w)), 0.0, 1.0)  # the law's leading term near zero
        for _ in range(BAND_ITERATIONS):
            value, slope = law(s)
            low, high = np.where(value < 0, s, low), np.where(value < 0, high, s)
            with np.errstate(divide="ignore", invalid="ignore"):
                newton = s - value / slope
            inside = (newton > low) & (newton < high)
            stepped = np.where(inside, newton, 0.5 * (low + high))
            settled = np.all(np.abs(stepped - s) <= 4 * np.finfo(float).eps * np.maximum(s, 1e-300))
            s = stepped
            if settled:
                break
        strain, compliance = above.copy(), 1 / (self.stiffness + 2 * self.quadratic * above)
        strain[band], compliance[band] = w * s, w / law(s)[1]
        return strain, compliance


class _Chain(NamedTuple):
    """A network that is one chain of segments from one constrained node to the other."""

    nodes: np.ndarray  # (N + 1,): from constrained node A to constrained node B
    segments: np.ndarray  # (N,): segment k joins nodes[k] and nodes[k + 1]


@functools.lru_cache(maxsize=32)
def _chain(topology: Topology) -> _Chain | None:
    """The network as a chain (`_Chain`), or `None` where it is not one: other than two
    constrained nodes, a junction, a free end, a part apart."""
    constrained = topology.constrained_nodes
    ends = topology.segment_nodes
    degree = np.bincount(ends.reshape(-1), minlength=topology.n_nodes)
    if constrained.size != 2 or np.any(degree > 2) or np.any(degree[constrained] != 1):
        return None
    touching = [[] for _ in range(topology.n_nodes)]
    for s, (i, j) in enumerate(ends):
        touching[i].append(s)
        touching[j].append(s)
    nodes, segments = [int(constrained[0])], []
    while len(segments) < ends.shape[0]:
        following = [s for s in touching[nodes[-1]] if not segments or s != segments[-1]]
        if not following:
            break
        s = following[0]
        i, j = ends[s]
        segments.append(s)
        nodes.append(int(j if i == nodes[-1] else i))
    if nodes[-1] != constrained[1] or len(segments) != ends.shape[0]:
        return None
    return _Chain(np.asarray(nodes), np.asarray(segments))


def applies(model: CableNetwork, env: Environment, t: RealScalarLike = 0.0) -> bool:
    """Whether [`catenary_statics`][] may find the equilibrium of `model` in `env` at
    time `t` (s): what its structure and its values allow, before solving (the module
    docstring lists it). The free surface is judged after solving."""
    if checks.traced((model, env, t)) or _chain(model.topology) is None:
        return False
    if model.line.bending_stiffness is not None or not still_water(env):
        return False
    if type(model.line.tension_law) not in (LinearElastic, NonlinearElastic, KelvinVoigt):
        return False  # another law may define its own elastic tension
    free, body = model.free_nodes, model.body
    assert body is not None  # statics take a built model, which carries its bodies (zeros where none)
    loaded = [np.asarray(body.mass)[free], np.asarray(body.volume)[free], np.asarray(body.force)[free]]
    return not any(np.any(x != 0) for x in loaded)


@functools.partial(program, compiler_options=RUN_ONCE)
def _displacements(motions, t):
    """The constrained nodes' displacements (m) at time `t` (s), shape `(constrained, 3)`."""
    return jnp.stack([motion.displacement(t) for motion in motions])


def _supports(model: CableNetwork, t) -> np.ndarray:
    """The constrained nodes' positions (m) at time `t` (s), shape `(constrained, 3)`,
    as `jaxcable._equations.lagrangian.constrained_motion` places them: where they are all fixed,
    their given positions; otherwise displaced by a small compiled program (0.07 s for
    a harmonic motion; eager JAX, op by op, took 0.3 s, and the motions' kinematics
    0.1 s compiled)."""
    reference = np.asarray(model.node_positions)[model.constrained_nodes]
    if all(isinstance(motion, Fixed) for motion in model.motions):
        return reference
    return reference + np.asarray(_displacements(model.motions, np.asarray(t, dtype=float)))


class _Walk(NamedTuple):
    """The chain walked from end A (`_walk`): per segment (shape `(N,)`) the derivatives
    of its step (Δx, Δz) = S (H, V)/T in H and V, `dx_dh`, `dx_dv` (= `dz_dh`) and
    `dz_dv` (m/N); per node after A (shape `(N,)`, B last) its distance from A along
    the heading and height above A (m)."""

    dx_dh: np.ndarray
    dx_dv: np.ndarray
    dz_dv: np.ndarray
    x: np.ndarray
    z: np.ndarray


def _walk(law: _Law, length, lift, horizontal, first, reactions) -> _Walk:
    """The chain from end A under horizontal tension `horizontal` (N) and vertical
    tension `first` (N) in its first segment, with free nodes' loads `lift` and bed
    reactions `reactions` (N, upward, shape `(N − 1,)`); segments' unstretched `length`
    (m, shape `(N,)`)."""
    h = horizontal
    v = first - np.concatenate([[0.0], np.cumsum(lift + reactions)])
    tension = np.hypot(h, v)
    strain, compliance = law.strain(tension)
    stretched = length * (1 + strain)
    give = length * compliance  # dS/dT
    # d(S h/T) and d(S v/T) in h and v, with dT = (h dh + v dv)/T.
    cross = h * v * (give / tension**2 - stretched / tension**3)
    dx_dh = give * h**2 / tension**2 + stretched * v**2 / tension**3
    dz_dv = give * v**2 / tension**2 + stretched * h**2 / tension**3
    x = np.cumsum(stretched * h / tension)
    z = np.cumsum(stretched * v / tension)
    return _Walk(dx_dh, cross, dz_dv, x, z)


def _closure(walk: _Walk, reactions, on_bed, spread, rise, bed_height, spring) -> np.ndarray:
    """How far `walk` misses (m): end B's miss along the heading and upward, then, for
    each free node `on_bed` (a mask, shape `(N − 1,)`), its reaction over its spring
    k A (N/m) less its penetration of the bed `bed_height` (m) below A."""
    nodes = np.flatnonzero(on_bed)
    penetration = bed_height - walk.z[nodes]
    return np.concatenate([[walk.x[-1] - spread, walk.z[-1] - rise], reactions[nodes] / spring[nodes] - penetration])


def _newton_step(walk: _Walk, closure, on_bed, spring) -> tuple[float, float, np.ndarray]:
    """Newton's step (δH, δV₁, δR) (N, δR of shape `(N − 1,)`) on `_closure`'s equations,
    in H, V₁ and the reactions of the nodes `on_bed` (the others carry none).

    A change δR_i of node i's reaction changes V by −δR_i in every segment after it,
    so node j's height by −Σ_{i<k≤j} ∂Δz_k/∂V, a difference of cumulative sums.

    **Raises:**

    `_NoClosedForm` for more than `MOST_ON_BED` nodes on the bed or a singular system."""
    nodes = np.flatnonzero(on_bed)
    if nodes.size > MOST_ON_BED:
        raise _NoClosedForm
    # The steps' derivatives summed up to each node after A (node j + 1 at index j);
    # ∂Δz/∂H equals ∂Δx/∂V.
    by_v_x, by_v_z = np.cumsum(walk.dx_dv), np.cumsum(walk.dz_dv)
    size = 2 + nodes.size
    jacobian = np.zeros((size, size))
    jacobian[0, :2] = np.sum(walk.dx_dh), by_v_x[-1]
    jacobian[1, :2] = by_v_x[-1], by_v_z[-1]
    jacobian[0, 2:] = by_v_x[nodes] - by_v_x[-1]
    jacobian[1, 2:] = by_v_z[nodes] - by_v_z[-1]
    jacobian[2:, 0] = by_v_x[nodes]
    jacobian[2:, 1] = by_v_z[nodes]
    later = nodes[:, None] > nodes[None, :]
    jacobian[2:, 2:] = np.where(later, by_v_z[nodes][None, :] - by_v_z[nodes][:, None], 0.0)
    jacobian[2:, 2:] += np.diag(1 / spring[nodes])
    try:
        step = np.linalg.solve(jacobian, -closure)
    except np.linalg.LinAlgError:
        raise _NoClosedForm from None
    change = np.zeros(on_bed.shape)
    change[nodes] = step[2:]
    return float(step[0]), float(step[1]), change


class _NoClosedForm(Exception):
    """The discrete catenary has no solution from its start, or is not worth solving."""


class _Line(NamedTuple):
    """The chain's line in chain order (`_Chain`): its law, segments' unstretched
    lengths L (m) and net lifts (ρF − m) g L (N), shape `(N,)`; its free nodes' loads
    (half of each neighbouring segment's lift, N) and bed springs k A (N/m; zero
    without a bed), shape `(N − 1,)`."""

    law: _Law
    length: np.ndarray
    segment_lift: np.ndarray
    lift: np.ndarray
    spring: np.ndarray


def _start(line: _Line, spread, rise, on_bed) -> tuple[float, float, np.ndarray] | None:
    """(H, V₁, R) (N) for the discrete chain from the continuous elastic catenary
    (`_fairlead_tension`) of a uniform line with its total length, wet weight and series
    stiffness, from end A to B `spread` (m) along the heading and `rise` (m) above A,
    lying on the bed through its lower end if `on_bed`; the nodes it rests on the bed
    start carrying their weight there. `None` where that catenary has no solution."""
    total = float(np.sum(line.length))
    weight = -float(np.sum(line.segment_lift)) / total  # wet weight per length, sinking > 0
    stiffness = total / float(np.sum(line.length / line.law.stiffness))
    if weight == 0:
        return None
    # A buoyant line is a heavy one upside down.
    sign = 1.0 if weight > 0 else -1.0
    rise, weight, on_bed = sign * rise, abs(weight), on_bed and weight > 0
    spread, height = max(spread, TOLERANCE), max(abs(rise), TOLERANCE)  # as `catenary` floors them
    if on_bed and _doubles_back(spread, height, total, stiffness, weight):
        return None  # slack on a frictionless bed: H = 0, and the line rests in any layout
    tensions = _fairlead_tension(spread, height, total, stiffness, weight, on_bed)
    if tensions is None:
        return None
    horizontal, top = tensions
    reactions = np.zeros_like(line.lift)
    arc = np.cumsum(line.length)[:-1]  # each free node's from A
    if rise < 0:  # B is the lower end
        arc = total - arc
    if on_bed:
        resting = arc < total - top / weight
        reactions[resting] = np.maximum(-line.lift[resting], 0.0)
    if rise >= 0:  # the last segment rises to the upper end B with the top's tension
        first = sign * top + float(np.sum(line.lift + reactions))
    else:  # the first falls from the upper end A
        first = -sign * top
    return horizontal, first, reactions


def _solve_chain(line: _Line, spread, rise, bed_height, start) -> tuple[_Walk, int]:
    """The chain's equilibrium from `start` (`_start`), for end B `spread` (m) along the
    heading and `rise` (m) above A and a bed `bed_height` (m) below A (`−inf` for none):
    the walk there and Newton's iterations taken.

    The bed makes the equations piecewise smooth: a node's spring acts only below it.
    So, as a primal–dual active-set method does, the nodes on the bed are held fixed
    while Newton's method solves the smooth equations they give, then taken afresh as
    the nodes below the bed there, until they are the same (to `CLOSURE` of the bed).
    Newton's steps on the nonsmooth equations, with the set taken at each iterate,
    instead moved a node at the touchdown on and off the bed from step to step: on the
    tests' 30-segment chain they took 19 steps, most of them halved, where these take 4.

    **Raises:**

    `_NoClosedForm` where it does not converge."""
    h, first, reactions = start
    on_bed = reactions > 0
    taken = 0
    for _ in range(MAX_ITERATIONS):
        solved = _smooth_solve(line, spread, rise, bed_height, on_bed, h, first, reactions)
        h, first, reactions, walk, iterations = solved
        taken += iterations
        penetration = bed_height - walk.z[:-1]
        if np.all(((penetration > 0) == on_bed) | (np.abs(penetration) <= CLOSURE)):
            return walk, taken
        on_bed = penetration > 0
        # A node new to the bed starts with the spring's reaction at its penetration.
        reactions = np.where(on_bed, np.maximum(reactions, line.spring * penetration), 0.0)
    raise _NoClosedForm


def _smooth_solve(line: _Line, spread, rise, bed_height, on_bed, h, first, reactions):
    """Newton's method for `_closure`'s equations with the nodes `on_bed` fixed, from
    (H, V₁, R) = (`h`, `first`, `reactions`) (N): those at the solution, its walk and
    the iterations taken. Each step is halved while H would not stay positive (a line
    under no horizontal tension is no catenary) or the closure would grow.

    **Raises:**

    `_NoClosedForm` where it does not converge."""

    def evaluate(h, first, reactions):
        walk = _walk(line.law, line.length, line.lift, h, first, reactions)
        closure = _closure(walk, reactions, on_bed, spread, rise, bed_height, line.spring)
        return walk, closure, float(np.max(np.abs(closure)))

    walk, closure, size = evaluate(h, first, reactions)
    rounding = ROUNDING_CLOSURE * float(np.sum(line.length))
    for iteration in range(MAX_ITERATIONS + 1):
        if not np.isfinite(size):
            raise _NoClosedForm
        if size <= CLOSURE:
            return h, first, reactions, walk, iteration
        dh, dv, dr = _newton_step(walk, closure, on_bed, line.spring)
        fraction = 1.0
        for _ in range(HALVINGS):
            if h + fraction * dh > 0:
                trial = h + fraction * dh, first + fraction * dv, reactions + fraction * dr
                trial_walk, trial_closure, trial_size = evaluate(*trial)
                if trial_size < size:
                    break
            fraction /= 2
        else:
            if size <= rounding:  # rounding's floor, reached before the target
                return h, first, reactions, walk, iteration
            raise _NoClosedForm
        (h, first, reactions), walk, closure = trial, trial_walk, trial_closure
        # Rounding's floor: the closure stopped halving, close to the target.
        if trial_size > 0.5 * size and trial_size <= rounding:
            return h, first, reactions, walk, iteration + 1
        size = trial_size
    raise _NoClosedForm


def _forces(model: CableNetwork, env: Environment, law: _Law, positions) -> tuple[np.ndarray, ...]:
    """`jaxcable._equations.lagrangian.static_forces` in still water, with the line wholly
    submerged, in numpy: the forces (N, shape `(nodes, 3)`) on every node at
    `positions` (m, shape `(nodes, 3)`), and each segment's strain (–) and tension (N)."""
    line, body = model.line, model.body
    assert body is not None  # statics take a built model, which carries its bodies (zeros where none)
    g, rho = float(env.gravity), float(env.water_density)
    ends, length = model.segment_nodes, np.asarray(model.segment_length)
    chord = positions[ends[:, 1]] - positions[ends[:, 0]]
    stretched = np.linalg.norm(chord, axis=1)
    strain = stretched / length - 1
    tension = law.tension(strain)
    pull = (tension / stretched)[:, None] * chord
    forces = np.zeros_like(positions)
    np.add.at(forces, ends[:, 0], pull)
    np.add.at(forces, ends[:, 1], -pull)
    lift = np.zeros(model.n_nodes)
    half = 0.5 * (rho * np.asarray(line.area) - np.asarray(line.mass_per_length)) * g * length
    np.add.at(lift, ends.reshape(-1), np.repeat(half, 2))
    height = np.asarray(body.height)
    # Eager JAX only where a body can pierce the surface: the fraction is 1 otherwise.
    wet = np.asarray(lag.column_submerged_fraction(positions[:, 2], height)) if np.any(height > 0) else 1.0
    lift += (rho * np.asarray(body.volume) * wet - np.asarray(body.mass)) * g
    if env.seabed is not None and env.depth is not None:
        penetration = np.maximum(-float(env.depth) - positions[:, 2], 0.0)
        lift += float(env.seabed.stiffness) * _contact_area(model) * penetration
    forces[:, 2] += lift
    return forces + np.asarray(body.force), strain, tension


def _contact_area(model: CableNetwork) -> np.ndarray:
    """`jaxcable._equations.lagrangian.contact_area` in numpy (m², shape `(nodes,)`)."""
    half = 0.5 * np.asarray(model.line.diameter) * np.asarray(model.segment_length)
    area = np.zeros(model.n_nodes)
    np.add.at(area, model.segment_nodes.reshape(-1), np.repeat(half, 2))
    return area


def catenary_statics(
    model: CableNetwork, env: Environment, t: RealScalarLike = 0.0, force_tolerance: float = FORCE_TOLERANCE
) -> StaticSolution | None:
    """The static equilibrium of `model` in `env` at time `t` (s) as the discrete
    catenary (module docstring), where it [`applies`][] and converges; `None` otherwise.

    **Arguments:**

    - `model`, `env`: the network and the water, as for [`jaxcable.solve_statics`][].
    - `t`: the time (s) at which the constrained nodes are placed.
    - `force_tolerance`: the largest residual force on a free node that counts as
        equilibrium, relative to the scene's force scale (–), as `solve_statics`'.

    **Returns:**

    A [`jaxcable.StaticSolution`][] as `solve_statics` reports one, its `method`
    `"discrete catenary"` and its `steps` Newton's iterations; or `None` where the
    scene is not a single line in still water (see `applies`), the catenary finds no
    equilibrium from its start (a line under no horizontal tension, one that would
    double back on the bed, more than `MOST_ON_BED` nodes on the bed), the line
    breaks the free surface, or the forces left are above the tolerance. Then
    `solve_statics`' compiled solver takes the scene, and reports its errors.
    """
    chain = _chain(model.topology)
    if chain is None or not applies(model, env, t):
        return None
    law = _Law.of(model.line.tension_law, model.n_segments)
    found = _discrete_catenary(model, env, t, chain, law)
    if found is None:
        return None
    positions, iterations = found
    if env.free_surface and np.any(positions[:, 2] > 0):
        return None  # a segment out of the water has less buoyancy than the walk gave it
    return _solution(model, env, law, positions, iterations, force_tolerance)


def _discrete_catenary(
    model: CableNetwork, env: Environment, t, chain: _Chain, law: _Law
) -> tuple[np.ndarray, int] | None:
    """The node positions (m, shape `(nodes, 3)`) of the discrete catenary along
    `chain`, with the constrained nodes where their motions put them at `t` (s), and
    Newton's iterations taken; `None` where it has none (see `catenary_statics`)."""
    a, b = held = _supports(model, t)  # `_chain` runs from the first constrained node to the second
    heading = (b - a) * [1.0, 1.0, 0.0]
    spread, rise = float(np.linalg.norm(heading)), float(b[2] - a[2])
    segment_length = np.asarray(model.segment_length)
    total = float(np.sum(segment_length))
    if np.linalg.norm(b - a) / total - 1 > MAX_REQUIRED_STRAIN:
        return None  # a line far too short for its ends: the solver's to refuse, saying why
    positions = np.array(model.node_positions, dtype=float)
    positions[model.constrained_nodes] = held
    if chain.nodes.size == 2:
        return positions, 0  # one segment between its supports: nothing to solve
    if spread <= 1e-9 * total:
        return None  # a vertical line has no plane
    heading /= spread

    segments = chain.segments
    length = segment_length[segments]
    line_type, g = model.line, float(env.gravity)
    lift = (float(env.water_density) * np.asarray(line_type.area) - np.asarray(line_type.mass_per_length)) * g
    lift = lift[segments] * length
    spring, bed_height, on_bed = np.zeros(model.n_segments - 1), -np.inf, False
    if env.seabed is not None and env.depth is not None:
        depth = float(env.depth)
        spring = float(env.seabed.stiffness) * _contact_area(model)[chain.nodes[1:-1]]
        bed_height = -depth - float(a[2])
        on_bed = min(float(a[2]), float(b[2])) <= -depth * (1 - TOLERANCE)  # as MoorDyn marks it
    line = _Line(_Law(*(x[segments] for x in law)), length, lift, 0.5 * (lift[:-1] + lift[1:]), spring)
    # A trial step may overflow or leave the law's range: its closure is then not
    # finite and the step is halved, so numpy's warnings would only be noise.
    with np.errstate(all="ignore"):
        start = _start(line, spread, rise, on_bed)
        if start is None:
            return None
        try:
            walk, iterations = _solve_chain(line, spread, rise, bed_height, start)
        except _NoClosedForm:
            return None
    positions[chain.nodes[1:-1]] = a + walk.x[:-1, None] * heading + walk.z[:-1, None] * [0.0, 0.0, 1.0]
    return positions, iterations


def _solution(model: CableNetwork, env: Environment, law: _Law, positions, iterations, force_tolerance):
    """The `StaticSolution` at `positions` (m, shape `(nodes, 3)`), reported as
    `jaxcable._statics.solve._equilibrium` reports its own, from the same equations in
    numpy; `None` where the force left on a free node is above `force_tolerance`
    times the force scale, plus rounding."""
    forces, strain, tension = _forces(model, env, law, positions)
    free = model.free_nodes
    left = np.max(np.abs(forces[free]), axis=1)
    residual = float(np.max(left, initial=0.0))
    # `_statics._force_scale`: the largest tension, wet weight of a segment or a body, or
    # body's force (no drag in still water); and `_statics._rounding`.
    line_type, body = model.line, model.body
    assert body is not None  # statics take a built model, which carries its bodies (zeros where none)
    g, rho = float(env.gravity), float(env.water_density)
    wet_segment = (np.asarray(line_type.mass_per_length) - rho * np.asarray(line_type.area)) * g
    wet_body = (np.asarray(body.mass) - rho * np.asarray(body.volume)) * g
    loads = (tension, wet_segment * np.asarray(model.segment_length), wet_body, np.linalg.norm(body.force, axis=-1))
    scale = max(float(np.max(np.abs(x))) for x in loads)
    rounding = 16 * np.finfo(float).eps * float(np.max(law.stiffness))
    if not residual <= force_tolerance * scale + rounding:
        return None
    worst = int(free[np.argmax(left)]) if free.size else 0  # as `_statics._equilibrium` names none
    at_worst = np.any(model.segment_nodes == worst, axis=1)
    on_seabed = env.seabed is not None and env.depth is not None and positions[worst, 2] < -float(env.depth)
    ends = positions[model.constrained_nodes]
    required = np.linalg.norm(ends[1] - ends[0]) / float(np.sum(np.asarray(model.segment_length))) - 1
    # `jax.device_put`, not `jnp.asarray`, which compiles a copy for each shape (10 ms).
    put = jax.device_put
    return StaticSolution(
        state=State(put(positions), put(np.zeros_like(positions))),
        strain=put(strain),
        tension=put(tension),
        reactions=put(-forces[model.constrained_nodes]),
        residual=put(np.float64(residual)),
        force_scale=put(np.float64(scale)),
        worst_node=put(np.int32(worst)),
        worst_tension=put(np.max(np.abs(tension[at_worst]))),
        worst_drag=put(np.float64(0.0)),  # still water
        worst_on_seabed=put(np.bool_(on_seabed)),
        required_strain=put(np.float64(required)),
        result=optx.RESULTS.successful,
        steps=put(np.int32(iterations)),
        invalid_input=put(np.int32(-1)),
        invalid_value=put(np.float64(np.nan)),
        method=METHOD,
    )
