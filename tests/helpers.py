"""The static force balance of a cable network written out by hand with numpy,
independent of jaxcable's Lagrangian, for the statics tests of the example scenes."""

import numpy as np


def wet_fraction(body: dict, z):
    """The submerged share of a body centred at height `z` (m): a floating column of
    height `body["height"]` is wet below the still-water level z = 0; a point body
    (no height) always wholly."""
    height = body.get("height", 0.0)
    if not height:
        return np.ones_like(np.asarray(z, dtype=float))
    return np.clip((height / 2 - np.asarray(z)) / height, 0.0, 1.0)


def hand_forces(model, env, positions, bodies: dict, flow=(0.0, 0.0, 0.0)):
    """`(tension, force)`: Hooke's-law tension (N) of every segment at `positions` (m),
    and the force (N) on every node at rest there in a uniform current `flow` (m/s).

    On each node: the tensions along the segments that meet there; half of each such
    segment's submerged weight, and half of its drag, `C_n |u_n| u_n + C_τ |u_τ| u_τ`
    per stretched length, uniform along the straight segment; for each node in
    `bodies` (node → a body's `mass`, `volume`, `drag_area` and optional `height`, as
    `Body` takes them) its weight, the buoyancy and drag of its wet part. At
    equilibrium the force vanishes on every free node; on a constrained node it is
    minus the support's reaction.
    """
    rho, g = float(env.water_density), float(env.gravity)
    line = model.line
    ends = np.asarray(model.segment_nodes)
    chord = positions[ends[:, 1]] - positions[ends[:, 0]]
    stretched = np.linalg.norm(chord, axis=1)
    tau = chord / stretched[:, None]
    length = np.asarray(model.segment_length)
    tension = np.asarray(line.tension_law.axial_stiffness) * (stretched / length - 1)

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
    return tension, force
