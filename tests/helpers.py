"""References the tests share, written out independently of jaxcable: one copy each.

- `Irvine`: Irvine's elastic catenary in closed form (H. M. Irvine, *Cable Structures*,
  MIT Press 1981, §2.2), for a linear-elastic cable, with its end's stiffness; `rigid_top_tension` and
  `catenary_parameter` for an inextensible one.
- `ElasticCatenary`: the same continuum for the tension law C_E ε + C_E1 ε², by
  quadrature.
- `hand_forces`, `wet_fraction`: the static force balance of a network's nodes, with
  numpy, independent of jaxcable's Lagrangian.
- `chain_nodes`: the node order of a single branch built by `from_branches`.
- `compilations`: the compilations of one program, counted from JAX's compile log.
- `SCENE`: a small scene file (an anchored line to a coupled float) that the readers'
    and the bad-input tests edit one key at a time.
"""

import contextlib
import logging
import re

import jax
import numpy as np
from scipy.optimize import brentq, fsolve


def wet_fraction(body: dict, z):
    """The submerged share of a body centred at height `z` (m): a floating column of
    height `body["height"]` is wet below the still-water level z = 0; a point body
    (no height) always wholly."""
    height = body.get("height", 0.0)
    if not height:
        return np.ones_like(np.asarray(z, dtype=float))
    return np.clip((height / 2 - np.asarray(z)) / height, 0.0, 1.0)


def hand_forces(model, env, positions, bodies: dict, flow=(0.0, 0.0, 0.0)):
    """`(tension, force)`: the tension (N) of every segment at `positions` (m), and the
    force (N) on every node at rest there in a uniform current `flow` (m/s).

    The tension law is the design notes' `(C_E ε + C_E1 ε²) H(ε)`, H the smoothstep
    `3s² − 2s³` of `s = ε / w` over the law's `slack_width` w (a step where w = 0).
    On each node: the tensions along the segments that meet there; half of each such
    segment's submerged weight, and half of its drag, `C_n |u_n| u_n + C_τ |u_τ| u_τ`
    per stretched length, uniform along the straight segment; for each node in
    `bodies` (node → a body's `mass`, `volume`, `drag_area` and optional `height`, as
    `Body` takes them) its weight, the buoyancy and drag of its wet part. At
    equilibrium the force vanishes on every free node; on a constrained node it is
    minus the support's reaction. With a seabed, each node below it is pushed up by
    `k δ A`, δ its depth below the bed and A half the projected area `d L` of each
    segment that meets there (MoorDyn's `kBot`).
    """
    rho, g = float(env.water_density), float(env.gravity)
    line = model.line
    ends = np.asarray(model.segment_nodes)
    chord = positions[ends[:, 1]] - positions[ends[:, 0]]
    stretched = np.linalg.norm(chord, axis=1)
    tau = chord / stretched[:, None]
    length = np.asarray(model.segment_length)
    law = line.tension_law
    strain = stretched / length - 1
    width = np.asarray(law.slack_width)
    s = np.clip(strain / np.where(width > 0, width, 1.0), 0.0, 1.0)
    switch = np.where(width > 0, s * s * (3 - 2 * s), (strain > 0).astype(float))
    tension = strain * (np.asarray(law.axial_stiffness) + np.asarray(law.quadratic_stiffness()) * strain) * switch

    u = np.asarray(flow, dtype=float)
    diameter = np.asarray(line.diameter)
    c_n = 0.5 * rho * np.asarray(line.normal_drag) * diameter
    c_t = 0.5 * rho * np.asarray(line.tangential_drag) * np.pi * diameter
    u_t = (tau @ u)[:, None] * tau
    u_n = u - u_t
    drag = (c_n * np.linalg.norm(u_n, axis=1))[:, None] * u_n + (c_t * np.linalg.norm(u_t, axis=1))[:, None] * u_t
    per_end = 0.5 * drag * stretched[:, None]
    per_end[:, 2] -= 0.5 * (np.asarray(line.mass_per_length) - rho * np.asarray(line.area)) * g * length

    force = np.zeros_like(positions)
    np.add.at(force, ends[:, 0], tension[:, None] * tau + per_end)
    np.add.at(force, ends[:, 1], -tension[:, None] * tau + per_end)
    for node, body in bodies.items():
        wet = wet_fraction(body, positions[node, 2])
        force[node, 2] -= (body["mass"] - rho * body["volume"] * wet) * g
        force[node] += 0.5 * rho * body["drag_area"] * wet * np.linalg.norm(u) * u
    if env.seabed is not None:
        area = np.zeros(len(positions))
        np.add.at(area, ends[:, 0], 0.5 * diameter * length)
        np.add.at(area, ends[:, 1], 0.5 * diameter * length)
        force[:, 2] += float(env.seabed.stiffness) * area * np.maximum(-float(env.depth) - positions[:, 2], 0.0)
    return tension, force


def chain_nodes(n_segments):
    """Node indices along a single branch 0 → 1 built by `from_branches`."""
    return np.concatenate([[0], np.arange(2, n_segments + 1), [1]])


class Irvine:
    """An elastic catenary hanging from A (the origin) to B at horizontal distance
    `span` and height `height` above A, in A's vertical plane.

    `V` is the vertical force of support B on the cable (upwards positive); the vertical
    tension component at unstretched coordinate s (from A) is `V − w (L₀ − s)`.
    """

    def __init__(self, span, height, length, w, ea):
        self.span, self.height, self.length, self.w, self.ea = span, height, length, w, ea

        def closure(p):
            x, z = self.xz(length, np.exp(p[0]), p[1] * w * length)
            return [(x - span) / length, (z - height) / length]

        # Starting point from the shallow parabola: sag d from L ≈ chord + 8 d² / (3 chord).
        chord = np.hypot(span, height)
        sag = np.sqrt(3 * chord * max(length - chord, 1e-3 * length) / 8)
        h0 = w * span**2 / (8 * sag)
        v0 = w * length / 2 + h0 * height / span
        p, info, ier, msg = fsolve(closure, [np.log(h0), v0 / (w * length)], xtol=1e-13, full_output=True)
        assert ier == 1 and np.max(np.abs(closure(p))) < 1e-11, msg
        self.H, self.V = np.exp(p[0]), p[1] * w * length

    def vertical(self, s, v=None):
        return (self.V if v is None else v) - self.w * (self.length - s)

    def xz(self, s, h=None, v=None):
        h = self.H if h is None else h
        w, ea = self.w, self.ea
        va = self.vertical(0.0, v)
        vs = self.vertical(s, v)
        x = h * s / ea + h / w * (np.arcsinh(vs / h) - np.arcsinh(va / h))
        z = va * s / ea + w * s**2 / (2 * ea) + h / w * (np.hypot(1, vs / h) - np.hypot(1, va / h))
        return x, z

    def tension(self, s):
        return np.hypot(self.H, self.vertical(s))

    def support_stiffness(self):
        """The stiffness (N/m) of support B with A held, `∂(reaction of B)/∂(position of
        B)`, shape `(3, 3)`, axes (along the span, across it, up).

        In the cable's plane, the inverse of the flexibility `∂(x_B, z_B)/∂(H, V)`,
        differentiated from `xz` at s = L (T_A, T_B the end tensions, V_A = V − wL):

            ∂x/∂H = L/EA + (asinh(V/H) − asinh(V_A/H))/w − (V/T_B − V_A/T_A)/w
            ∂x/∂V = ∂z/∂H = (H/w)(1/T_B − 1/T_A)
            ∂z/∂V = L/EA + (V/T_B − V_A/T_A)/w

        Across it, H/span: B moved by δy turns the cable's plane about A by δy/span, and
        the horizontal force H with it.
        """
        h, v, w, length = self.H, self.V, self.w, self.length
        va = v - w * length
        tb, ta = np.hypot(h, v), np.hypot(h, va)
        cross = h / w * (1 / tb - 1 / ta)
        flexibility = np.array(
            [
                [length / self.ea + (np.arcsinh(v / h) - np.arcsinh(va / h)) / w - (v / tb - va / ta) / w, cross],
                [cross, length / self.ea + (v / tb - va / ta) / w],
            ]
        )
        (kxx, kxz), (kzx, kzz) = np.linalg.inv(flexibility)
        return np.array([[kxx, 0.0, kxz], [0.0, h / self.span, 0.0], [kzx, 0.0, kzz]])


class BedCatenary:
    """An elastic catenary from an anchor on a frictionless, rigid seabed (the origin)
    to a fairlead at horizontal distance `span` and height `height` above the bed, part
    of it lying on the bed: MoorPy's catenary with seabed contact, in closed form.

    With H the horizontal tension and V the fairlead's vertical force, the suspended
    length is V/w (it leaves the bed tangent, with no vertical tension), the rest lies
    straight on the bed at tension H:

        x = L − V/w + H L/EA + (H/w) asinh(V/H)
        z = (H/w)(√(1 + (V/H)²) − 1) + V²/(2 w EA)
    """

    def __init__(self, span, height, length, w, ea):
        self.span, self.height, self.length, self.w, self.ea = span, height, length, w, ea

        def closure(p):
            x, z = self.xz(np.exp(p[0]), p[1] * w * length)
            return [(x - span) / length, (z - height) / length]

        h0 = w * height
        p, info, ier, msg = fsolve(closure, [np.log(h0), 0.5], xtol=1e-13, full_output=True)
        assert np.max(np.abs(closure(p))) < 1e-11, msg
        self.H, self.V = np.exp(p[0]), p[1] * w * length
        assert 0 < self.V < w * length, "the line must rest on the bed"

    def xz(self, h, v):
        w, ea, length = self.w, self.ea, self.length
        x = length - v / w + h * length / ea + h / w * np.arcsinh(v / h)
        z = h / w * (np.hypot(1, v / h) - 1) + v**2 / (2 * w * ea)
        return x, z

    def support_stiffness(self):
        """The fairlead's stiffness (N/m), `∂(its reaction)/∂(its position)`, shape
        `(3, 3)`, axes (along the span, across it, up): the inverse of the flexibility
        ∂(x, z)/∂(H, V) in the line's plane, T the fairlead's tension,

            ∂x/∂H = L/EA + asinh(V/H)/w − V/(w T)
            ∂x/∂V = ∂z/∂H = (H/T − 1)/w
            ∂z/∂V = V/(w T) + V/(w EA)

        and across it H/span: the line and its plane turn about the anchor."""
        h, v, w, ea, length = self.H, self.V, self.w, self.ea, self.length
        t = np.hypot(h, v)
        cross = (h / t - 1) / w
        flexibility = np.array(
            [[length / ea + np.arcsinh(v / h) / w - v / (w * t), cross], [cross, v / (w * t) + v / (w * ea)]]
        )
        (kxx, kxz), (kzx, kzz) = np.linalg.inv(flexibility)
        return np.array([[kxx, 0.0, kxz], [0.0, h / self.span, 0.0], [kzx, 0.0, kzz]])


def catenary_parameter(span: float, length: float) -> float:
    """a = H/w of the inextensible catenary of `length` between points level `span` apart."""
    return brentq(lambda a: 2 * a * np.sinh(span / (2 * a)) - length, 1.0, 1e4, xtol=1e-14)


def rigid_top_tension(span, height, length, w):
    """The inextensible catenary's top tension, to show that elasticity matters."""

    def closure(p):
        h, v = p
        va, vb = v - w * length, v
        x = h / w * (np.arcsinh(vb / h) - np.arcsinh(va / h))
        z = h / w * (np.hypot(1, vb / h) - np.hypot(1, va / h))
        return [(x - span) / length, (z - height) / length]

    h, v = fsolve(closure, [w * length, w * length / 2], xtol=1e-12)
    return np.hypot(h, v)


class ElasticCatenary:
    """Irvine's elastic catenary from A to B (unstretched length L, wet weight w per
    unstretched length, tension law C_E ε + C_E1 ε²), in the vertical plane of A and B.

    With H the horizontal tension and V_A the vertical component at A (upwards along
    the line from A), the tension at arc s from A has components (H, V_A + w s), and
    the position is `∫₀ˢ (1 + ε(T)) (H, V) / T ds'`. The integrals are done by
    Gauss–Legendre on 64 points, exact for these smooth integrands to rounding.
    """

    def __init__(self, length, w, ea, ea1, span, rise, guess):
        self.length, self.w, self.ea, self.ea1 = length, w, ea, ea1
        self.nodes, self.weights = np.polynomial.legendre.leggauss(64)
        solution, info, ok, message = fsolve(
            lambda p: np.array(self.position(self.length, *p)) - [span, rise], guess, full_output=True, xtol=1e-13
        )
        # The end point's miss decides, not fsolve's flag: from a guess already at the
        # solution to rounding (an engine's equilibrium), xtol = 1e-13 can be out of
        # reach and fsolve reports "not making good progress" at a miss of 1e-14 m.
        miss = np.max(np.abs(info["fvec"]))
        assert miss <= 1e-10 * length, f"{message} (end point misses by {miss} m)"
        self.horizontal, self.vertical = solution

    def tension(self, s, horizontal=None, vertical=None):
        h = self.horizontal if horizontal is None else horizontal
        v = self.vertical if vertical is None else vertical
        return np.hypot(h, v + self.w * s)

    def strain(self, tension):
        if self.ea1 == 0:
            return tension / self.ea
        return (-self.ea + np.sqrt(self.ea**2 + 4 * self.ea1 * tension)) / (2 * self.ea1)

    def position(self, s, horizontal=None, vertical=None):
        h = self.horizontal if horizontal is None else horizontal
        v = self.vertical if vertical is None else vertical
        arc = 0.5 * s * (self.nodes + 1)
        t = self.tension(arc, h, v)
        stretch = 1 + self.strain(t)
        x = 0.5 * s * np.sum(self.weights * stretch * h / t)
        z = 0.5 * s * np.sum(self.weights * stretch * (v + self.w * arc) / t)
        return x, z


@contextlib.contextmanager
def compilations(program: str):
    """Collect, in the list this yields, JAX's "Compiling ..." log messages for the
    program named `program` ("Compiling jit(_simulate) ..."; older JAX: "Compiling
    _simulate ...") while the block runs."""
    compiled = []

    class Compiles(logging.Handler):
        def emit(self, record):
            if re.match(rf"Compiling (jit\()?{program}\b", record.getMessage()):
                compiled.append(record.getMessage())

    handler = Compiles()
    logging.getLogger("jax").addHandler(handler)
    try:
        with jax.log_compiles():
            yield compiled
    finally:
        logging.getLogger("jax").removeHandler(handler)


SCENE = """\
title = "reader test"

[water]
density = 1025.0
depth = 150.0

[simulation]
duration = 10.0
dt_out = 0.5

[line_types.rope]
mass_per_length = 3.0
diameter = 0.02
axial_stiffness = 3.0e7
axial_damping_ratio = 0.2

[points.anchor]
type = "fixed"
position = [0.0, 0.0, -100.0]

[points.float]
type = "coupled"
position = [150.0, 0.0, 0.0]

[[lines]]
type = "rope"
from = "anchor"
to = "float"
length = 190.0
segments = 10
"""
