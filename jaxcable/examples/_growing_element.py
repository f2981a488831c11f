"""Zhukov's plane problems: a growing element of a mariculture farm in a regular wave.

Zhukov (2005, ch. 4–5) loads a growing element (a scallop cage, a mussel collector) by
the drag part of Lappo–Morison's formula only, `R = k₀ u² m g` on the velocity u
relative to the water, dropping the inertia term, which his flume tests found small.
Here that is `Environment(fluid_inertia=False)` and a body with no added mass; the
element keeps its own mass, which jaxcable always integrates.

Two scenes, each node 0 the fixed frame point and node 1 the element:

- **Free**: the element on a tether too long ever to tighten. The line
  is tension-only, so it carries nothing, and it is made massless and dragless enough
  (1e-6 kg/m, no drag coefficients) that the element moves as a free body.
- **Tethered**: an element heavier than water hanging from the frame point on a short
  elastic tether (Hooke's law, tension only, as in the thesis).

Zhukov's dimensionless form (eq. 7) writes the tension as `T = (EF/(l ω)) u₀ η(α, ξ, ρ,
τ)`, with u₀ the water's speed, ω the wave's frequency, ξ = l ω/u₀ and τ = ω t. The
abstract defines the weight characteristic ρ only by name; here it is the element's
weight in water over its drag at u₀,

    ρ = W / (k₀ m_o g u₀²),

so `√ρ u₀` is the speed at which drag lifts the element's weight: where the water rises
faster than that, it can lift the element and slacken the tether. u₀ is the amplitude of
the water's horizontal velocity at the element's depth.

The values are this module's choices, stated because the abstract gives none: a 1 m,
4 s wave in 20 m of water (k a = 0.126, deep water), the frame point 2 m down, a 1.5 m
tether of 10 mm rope with EF = 1e5 N, and VerticalTow's scallop cage (25 kg in air,
20 kg of it organisms, k₀ = 0.5 s²/m²).
"""

import jax.numpy as jnp
from jaxtyping import Array, Float

from .._model.materials import LinearElastic
from .._model.motion import Fixed
from .._model.network import Body, CableNetwork, LineType
from .._sea.environment import Environment
from .._sea.waves import Airy
from .._typing import RealLike, RealScalarLike

WATER_DENSITY = 1025.0  # kg/m³
GRAVITY = 9.81  # m/s²
WAVE_HEIGHT = 1.0  # m
WAVE_PERIOD = 4.0  # s
DEPTH = 20.0  # m
WAVE_RAMP = 2 * WAVE_PERIOD  # s: the waves start over two periods, from still water
FRAME_DEPTH = 2.0  # m, below the still-water level
TETHER_LENGTH = 1.5  # m
TETHER_STIFFNESS = 1.0e5  # N, EF
TETHER_DIAMETER = 0.010  # m
TETHER_MASS = 0.07  # kg/m
ELEMENT_MASS = 25.0  # kg, in air
ORGANISM_MASS = 20.0  # kg, the mass k₀ refers to
SPECIFIC_DRAG = 0.5  # s²/m², k₀
# The free element's tether: this many times longer than the element's distance from the
# frame point, so that it never tightens over the drift of a long run.
_FREE_SLACK = 20.0
_FREE_TETHER_MASS = 1e-6  # kg/m
_INITIAL_STRAIN = 1e-4


def growing_element_wave() -> Airy:
    """The regular wave of the growing-element scenes, travelling along +x."""
    return Airy(WAVE_HEIGHT, WAVE_PERIOD, DEPTH, gravity=GRAVITY)


def orbital_speed(wave: Airy, z: RealLike) -> Float[Array, "*z"]:
    """u₀ (m/s): the amplitude of the water's horizontal velocity at depth `z` (m)
    under a linear wave, `(H/2) ω cosh k(z+d) / sinh kd`."""
    k, d = wave.wavenumber, wave.depth
    return 0.5 * wave.height * wave.angular_frequency * jnp.cosh(k * (jnp.asarray(z) + d)) / jnp.sinh(k * d)


def element_depth() -> float:
    """The element's initial depth (m, negative down): hanging a tether's length below the
    frame point, or, free, at that same depth."""
    return -(FRAME_DEPTH + TETHER_LENGTH)


def growing_element(
    weight_characteristic: RealScalarLike = 0.5,
    *,
    tethered: bool = True,
    specific_drag: RealScalarLike = SPECIFIC_DRAG,
    wave_height: RealScalarLike = WAVE_HEIGHT,
    tether_stiffness: RealScalarLike = TETHER_STIFFNESS,
    units: tuple[RealScalarLike, RealScalarLike, RealScalarLike] = (1.0, 1.0, 1.0),
    mass_matrix: str = "lumped",
) -> tuple[CableNetwork, Environment]:
    """A growing element in Zhukov's wave: `(model, env)`, node 0 the fixed frame
    point and node 1 the element.

    **Arguments:**

    - `weight_characteristic`: ρ (–), the element's weight in water over its drag at
        u₀ (see the module docstring); it sets the element's displaced volume, its mass
        staying 25 kg. 0 is neutrally buoyant. At most `M g / (k₀ m_o g u₀²)`, where the
        volume reaches 0: 2.36 at k₀ = 5 s²/m².
    - `tethered`: hang the element from the frame point on the 1.5 m tether (default),
        or let it move freely.
    - `specific_drag`: k₀ (s²/m²) of the element.
    - `wave_height`: H (m) of the 4 s wave.
    - `tether_stiffness`: EF (N) of the tether.
    - `units`: `(L, T, M)`, the same scene with every length multiplied by L, every
        time by T and every mass by M (so gravity by L/T², forces by M L/T², k₀ by
        T²/L², the water's density by M/L³; the other arguments are given in the
        scene's own units): a scene similar to the default one, with every
        dimensionless group of the thesis's eq. 7 the same.
    - `mass_matrix`: as for [`jaxcable.CableNetwork`][].

    All numeric arguments may be traced, for [`jaxcable.sweep`][].
    """
    length, time, mass = units
    gravity = GRAVITY * length / time**2
    density = WATER_DENSITY * mass / length**3
    wave = Airy(wave_height * length, WAVE_PERIOD * time, DEPTH * length, gravity=gravity)
    env = Environment(
        water_density=density,
        gravity=gravity,
        depth=DEPTH * length,
        waves=wave,
        wave_ramp=WAVE_RAMP * time,
        fluid_inertia=False,
    )
    z_element = element_depth() * length
    frame = jnp.array([0.0, 0.0, -FRAME_DEPTH * length])
    # Tethered, the element starts a little below the tether's unstretched reach, so that
    # statics begins taut (Newton has no gradient to follow inside the slack band).
    reach = TETHER_LENGTH * length * (_INITIAL_STRAIN if tethered else 0.0)
    element = jnp.array([0.0, 0.0, z_element - reach])
    specific_drag = jnp.asarray(specific_drag, dtype=float) * time**2 / length**2
    u0 = orbital_speed(wave, z_element)
    organisms = ORGANISM_MASS * mass
    weight = weight_characteristic * specific_drag * organisms * gravity * u0**2  # N, in water
    volume = (ELEMENT_MASS * mass * gravity - weight) / (density * gravity)
    stiffness = LinearElastic(tether_stiffness * mass * length / time**2)
    if tethered:
        line = LineType(TETHER_MASS * mass / length, TETHER_DIAMETER * length, stiffness)
        segment = TETHER_LENGTH * length
    else:
        line = LineType(
            _FREE_TETHER_MASS * mass / length,
            TETHER_DIAMETER * length,
            stiffness,
            area=_FREE_TETHER_MASS * mass / length / density,
            normal_drag=0.0,
            tangential_drag=0.0,
            normal_added_mass=0.0,
        )
        segment = _FREE_SLACK * TETHER_LENGTH * length
    body = Body(
        mass=ELEMENT_MASS * mass,
        volume=volume,
        specific_drag=specific_drag,
        organism_mass=organisms,
    )
    model = CableNetwork(
        node_positions=jnp.stack([frame, element]),
        segment_nodes=[[0, 1]],
        segment_length=[segment],
        line=line,
        constraints={0: Fixed()},
        bodies={1: body},
        mass_matrix=mass_matrix,
    )
    return model, env
