"""The moored net: four buoys over four anchors, braced by a horizontal frame.

Bezverkhyy & Korniienko's example A (Bezverkhyy & Korniienko, §3.1; `seed-002-branched-cables.md`):
a net-like buoy–anchor system of 4 anchors, 4 buoys, one horizontal row of cables,
4 vertical branches and 4 diagonal branches, in plane waves of period 6.4 s running
along the main diagonal, through buoys 1 and 3, from the undisturbed static
configuration. Fig. 5 gives the tension at four places on the vertical branch under
buoy 2: just under the buoy, just above the junction with the horizontal row, just
below it, and near the anchor. So a vertical branch runs buoy → junction → anchor.

Frame: x along the waves (from buoy 1 to buoy 3), z up, y completing a right-handed
triad; the origin is on the still-water surface above the net's centre.

Junctions, which keep their indices as nodes (see [`buoy_node`][] and friends):

- 0–3: buoys 1–4, at (−r, 0), (0, −r), (r, 0), (0, r) (counter-clockwise seen from
    above): buoy 1 is the one the waves reach first, buoy 3 the one opposite, and
    buoys 2 and 4 are mirror images in the wave's vertical plane y = 0.
- 4–7: the corners of the horizontal frame, 10 m under buoys 1–4, where each
    vertical branch meets the horizontal row.
- 8–11: the anchors of buoys 1–4, on the seabed.
- 12: the hub at the frame's centre, where the 4 diagonal branches meet.

Branches, in this order (segments are numbered branch by branch): for each buoy
k = 1…4 its vertical branch's upper part (buoy → corner) then lower part (corner →
anchor); the horizontal row, a ring of 4 sides (corner k → corner k+1); the 4
diagonal branches (hub → corner k).

The paper gives the topology and the wave period only; this module's choices, stated
here and in the constants below:

- Water 30 m deep; buoys and corners at r = 15 m from the centre (the buoy square's
    diagonal, 30 m, is about half the 63.6 m wavelength, so the four buoys meet the
    wave at clearly different phases); the corners 10 m down.
- The diagonal branches join the corners to a hub at the centre, across the frame:
    with the ring they make the horizontal frame a braced net, symmetric about the
    wave's plane, which buoys 2 and 4 need to heave in phase (bracing each corner to a
    neighbouring anchor would turn one way round the square and break that symmetry).
- The vertical branches' lower parts lean outward: the anchors lie at 25 m from the
    centre, 10 m further out than the corners (26.6° from the vertical). Nothing else
    holds the corners apart; with plumb lower parts the frame would pull the corners
    in and hang slack. This is the grid mooring of a fish farm: buoys lift, anchor
    lines pull out and down, the frame is pretensioned between them. The upper parts
    (buoy → corner) hang plumb in still water.
- Vertical branches: the anchored-line paper's steel cable (`anchored_line_type`: m = 3 kg/m,
    F = 0.0003 m², C_E = 3 × 10⁷ N), which the branched-systems paper's printed parameters repeat.
    Horizontal row and diagonal branches: a 24 mm polyester rope (`FRAME_ROPE`:
    0.45 kg/m, nearly neutral in water, C_E = 2 × 10⁶ N). The steel cable weighs
    26.5 N/m in water: a steel frame of these spans, pretensioned only by the anchor
    lines' lean, sagged 4–7 m at its hub, and kept the tension under the buoys above
    2.9 kN however little the buoys lifted. Both viscoelastic as in the trawl,
    C_v = 0.02 C_E (a retardation time of 0.02 s).
- Buoys: 100 kg (the trawl buoy's, the paper's only printed buoy mass), floating
    columns 2 m tall of 1 m³ (0.8 m across; `Body.height`), C_D A = 1 m² on the whole
    column (Cd ≈ 0.6 on its 1.6 m² side), C_a = 0.5. A column is wet up to the waves'
    surface η at its (x, y): its buoyancy, drag and Froude–Krylov force act on that
    part (its added mass on the part below z = 0). Its buoyancy is the waves' main
    heave force on it, ρ g A η = 9.6 kN at the wave's amplitude, more than its 7.3 kN
    of reserve buoyancy: at a crest a buoy can go under, in a trough come clear.
- Each upper part is as long as puts its buoy at the draft that carries `PRETENSION` =
    1.5 kN, by a hand estimate; the knob that sets how taut the vertical branches are.
    The statics (at the default segments) settle at 1.67 kN under the buoys and
    1.06 kN at the anchors, 0.20 kN in the row and 0.27 kN in the diagonal branches;
    the hub sags 0.47 m below the corners; each buoy floats with its centre 0.46 m
    above the still water (0.54 m draft), keeping 7.3 kN of reserve buoyancy.
    In the waves (`studies.moored_net.FULL`, 120 s) the segment of buoy 2's vertical
    branch next to its anchor goes slack for 2.07 s of every period, then snaps taut
    (11 kN over 0.02 s); the rest of the branch bottoms at 0.08–0.17 kN without going
    slack, and carries the snap's spike. A design tension of 1.0 kN gave the same
    picture (slack 2.11 s a period next to the anchor, the rest bottoming at
    0.06–0.16 kN; 51 s run), so 1.5 kN stays.
- Waves: Airy, T = 6.4 s, H = 2 A with the anchored-line paper's amplitude law (A = 1.92 m),
    heading along +x (the main diagonal, from buoy 1 to buoy 3), ramped in over two
    periods from t = 0.
- Segments: by default 2 in each upper part (5.3 m), 4 in each lower part (5.6 m),
    4 in each side of the row (5.3 m) and 3 in each diagonal branch (5 m). The lines'
    viscous term caps an explicit solver's step as the shortest steel segment squared:
    120 s of waves took 916,000 steps at these segments, 2.19 million at (3, 6, 5, 4),
    and more than a million before 64 s at (3, 5, 4, 3) or before 120 s at
    (4, 8, 6, 4). Between the first two, the buoys' heave amplitudes agree to 0.3 %,
    their drifts to 2 cm, the mean tensions on buoy 2's branch to 1 %.
"""

import numpy as np

from .._model.materials import KelvinVoigt
from .._model.motion import Fixed
from .._model.network import Body, Branch, CableNetwork, LineType
from .._sea.environment import Environment
from .._sea.waves import Airy, floater_amplitude
from ._anchored_line import AXIAL_STIFFNESS, anchored_line_type

WAVE_PERIOD = 6.4  # s, T_w (the paper's "64c")
WATER_DEPTH = 30.0  # m, the anchors' depth
RADIUS = 15.0  # m, horizontal distance of the buoys and corners from the centre
CORNER_DEPTH = 10.0  # m, of the frame under the still-water level (design)
ANCHOR_RADIUS = 25.0  # m, horizontal distance of the anchors from the centre
VISCOUS_RATIO = 0.02  # s, C_v / C_E
PRETENSION = 1.5e3  # N, design tension at the buoys, which sets their drafts
# The frame's rope (horizontal row and diagonal branches): 24 mm polyester.
FRAME_ROPE = dict(
    mass_per_length=0.45,  # kg/m, in air
    diameter=0.024,  # m, for drag and added mass
    area=0.45 / 1380.0,  # m², the fibre's own (polyester, 1380 kg/m³), for buoyancy
    axial_stiffness=2.0e6,  # N, C_E
)
BUOY = dict(mass=100.0, volume=1.0, drag_area=1.0, added_mass=0.5, height=2.0)
WATER_DENSITY = 1025.0  # kg/m³
GRAVITY = 9.81  # m/s²

N_BUOYS = 4
HUB = 3 * N_BUOYS  # junction index of the frame's centre


def buoy_node(buoy: int) -> int:
    """The node of buoy `buoy` (1–4, the paper's numbering)."""
    _check_buoy(buoy)
    return buoy - 1


def corner_node(buoy: int) -> int:
    """The node where buoy `buoy`'s vertical branch meets the horizontal row."""
    _check_buoy(buoy)
    return N_BUOYS + buoy - 1


def anchor_node(buoy: int) -> int:
    """The anchor of buoy `buoy`'s vertical branch."""
    _check_buoy(buoy)
    return 2 * N_BUOYS + buoy - 1


def _check_buoy(buoy: int) -> None:
    if buoy not in range(1, N_BUOYS + 1):
        raise ValueError(f"buoys are numbered 1 to {N_BUOYS}, got {buoy!r}")


def _angle(buoy: int) -> float:
    """The azimuth (rad) of buoy `buoy` from +x: 180°, 270°, 0°, 90° for 1–4."""
    return np.pi + (buoy - 1) * np.pi / 2


def junctions(pretension: float = PRETENSION) -> np.ndarray:
    """The design positions (m) of the 13 junctions, shape `(13, 3)`: buoys (at the
    draft that carries `pretension`, N), corners, anchors, hub. They are the statics'
    first guess; the anchors stay there."""
    z_buoy = _buoy_design_z(pretension)
    points = np.zeros((HUB + 1, 3))
    for buoy in range(1, N_BUOYS + 1):
        direction = np.array([np.cos(_angle(buoy)), np.sin(_angle(buoy)), 0.0])
        direction[np.abs(direction) < 1e-12] = 0.0  # exact zeros, for exact symmetry
        points[buoy_node(buoy)] = RADIUS * direction + [0.0, 0.0, z_buoy]
        points[corner_node(buoy)] = RADIUS * direction - [0.0, 0.0, CORNER_DEPTH]
        points[anchor_node(buoy)] = ANCHOR_RADIUS * direction - [0.0, 0.0, WATER_DEPTH]
    points[HUB] = [0.0, 0.0, -CORNER_DEPTH]
    return points


def _buoy_design_z(pretension: float) -> float:
    """The height (m) of a buoy's centre above the still-water level at which its
    buoyancy less its weight is `pretension` (N)."""
    wet = (pretension + BUOY["mass"] * GRAVITY) / (WATER_DENSITY * GRAVITY * BUOY["volume"])
    return BUOY["height"] * (0.5 - wet)


def moored_net(
    *,
    waves: bool = True,
    wave_height: float | None = None,
    viscous: bool = True,
    pretension: float = PRETENSION,
    segments: tuple[int, int, int, int] = (2, 4, 4, 3),
    mass_matrix: str = "lumped",
    quadratic_ratio: float = 0.0,
) -> tuple[CableNetwork, Environment]:
    """The moored net, `(model, env)`, its anchors fixed.

    **Arguments:**

    - `waves`: the 6.4 s Airy wave along +x (default), ramped in over two periods
        from t = 0, or still water.
    - `wave_height`: H (m), crest to trough; 2 × `floater_amplitude(6.4)` (3.84 m)
        by default.
    - `viscous`: the lines' viscous term C_v = 0.02 C_E (default), or none.
    - `pretension`: the design tension (N) under each buoy, which sets the upper
        parts' length (the statics settle above it: 1.67 kN for 1.5 kN, 1.38 kN for
        1.0 kN).
    - `segments`: segments in each vertical branch's upper part (buoy → corner,
        10.5 m at the default pretension) and lower part (corner → anchor, 22.4 m), in
        each side of the horizontal row (21.2 m) and in each diagonal branch (15 m).
        Explicit steps shrink as the shortest segment squared (the viscous term's
        stiffness): halving every segment takes four times the steps.
    - `mass_matrix`: as for [`jaxcable.CableNetwork`][].
    - `quadratic_ratio`: C_E1 / C_E on every line, steel and rope (the anchored-line paper's
        0.05–0.2); 0 (Hooke's law) by default.

    **Returns:**

    `(model, env)`. Node indices: [`buoy_node`][], [`corner_node`][],
    [`anchor_node`][], `HUB`; segment indices of Fig. 5's four places:
    [`fig5_segments`][].
    """
    upper, lower, row, diagonal = segments
    law = KelvinVoigt(
        AXIAL_STIFFNESS, quadratic_ratio * AXIAL_STIFFNESS, VISCOUS_RATIO * AXIAL_STIFFNESS if viscous else 0.0
    )
    env_waves = ()
    if waves:
        height = 2 * floater_amplitude(WAVE_PERIOD) if wave_height is None else wave_height
        env_waves = Airy(height, WAVE_PERIOD, WATER_DEPTH, heading=0.0)
    env = Environment(
        water_density=WATER_DENSITY,
        gravity=GRAVITY,
        depth=WATER_DEPTH,
        waves=env_waves,
        wave_ramp=2 * WAVE_PERIOD,
    )
    line = anchored_line_type(law, WATER_DENSITY)
    rope = frame_rope(viscous, quadratic_ratio)
    points = junctions(pretension)

    def chord(a, b):
        return float(np.linalg.norm(points[a] - points[b]))

    branches = []
    for buoy in range(1, N_BUOYS + 1):
        b, c, a = buoy_node(buoy), corner_node(buoy), anchor_node(buoy)
        branches.append(Branch(b, c, line, chord(b, c), upper))
        branches.append(Branch(c, a, line, chord(c, a), lower))
    for buoy in range(1, N_BUOYS + 1):
        c, following = corner_node(buoy), corner_node(buoy % N_BUOYS + 1)
        branches.append(Branch(c, following, rope, chord(c, following), row))
    for buoy in range(1, N_BUOYS + 1):
        c = corner_node(buoy)
        branches.append(Branch(HUB, c, rope, chord(HUB, c), diagonal))
    model = CableNetwork.from_branches(
        points,
        branches,
        constraints={anchor_node(buoy): Fixed() for buoy in range(1, N_BUOYS + 1)},
        bodies={buoy_node(buoy): Body(**BUOY) for buoy in range(1, N_BUOYS + 1)},
        mass_matrix=mass_matrix,
    )
    return model, env


def frame_rope(viscous: bool = True, quadratic_ratio: float = 0.0) -> LineType:
    """The frame's rope, `FRAME_ROPE`: drag and added mass on its 24 mm diameter
    (LineType's defaults K_n = 1.2, K_τ = 0.008, C_a = 1), buoyancy on its fibre's
    area, viscoelastic with C_v = 0.02 C_E like the steel cable (or elastic), with
    C_E1 = `quadratic_ratio` × C_E."""
    stiffness = FRAME_ROPE["axial_stiffness"]
    law = KelvinVoigt(stiffness, quadratic_ratio * stiffness, VISCOUS_RATIO * stiffness if viscous else 0.0)
    return LineType(
        mass_per_length=FRAME_ROPE["mass_per_length"],
        diameter=FRAME_ROPE["diameter"],
        area=FRAME_ROPE["area"],
        tension_law=law,
    )


def branch_segments(model: CableNetwork, start: int, end: int) -> np.ndarray:
    """The segments (indices, in order from `start`) of the branch from junction
    `start` to junction `end` of a model from [`moored_net`][], whose branches
    `CableNetwork.from_branches` numbers consecutively. Raises `ValueError` if there
    is none."""
    ends = np.asarray(model.segment_nodes)
    n_junctions = HUB + 1
    for first in np.flatnonzero(ends[:, 0] == start):
        chain = [int(first)]
        while ends[chain[-1], 1] >= n_junctions:  # an interior node: the branch goes on
            chain.append(chain[-1] + 1)
        if ends[chain[-1], 1] == end:
            return np.asarray(chain)
    raise ValueError(f"no branch from junction {start} to junction {end}")


def fig5_segments(model: CableNetwork, buoy: int = 2) -> dict[str, int]:
    """The segments at Fig. 5's four places on buoy `buoy`'s vertical branch, by name:
    `"under buoy"` (the upper part's top segment), `"above junction"` (its bottom
    one), `"below junction"` (the lower part's top segment) and `"near anchor"` (its
    bottom one)."""
    upper = branch_segments(model, buoy_node(buoy), corner_node(buoy))
    lower = branch_segments(model, corner_node(buoy), anchor_node(buoy))
    return {
        "under buoy": int(upper[0]),
        "above junction": int(upper[-1]),
        "below junction": int(lower[0]),
        "near anchor": int(lower[-1]),
    }
