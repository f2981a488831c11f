"""Towing tests as simulations: the rigs that calibration fits drag coefficients to.

A rig is the apparatus of a towing test (cable, weights, floats) as an `eqx.Module` of
float leaves. Given a record's inputs (its sample times and, for a horizontal tow, the
tow speed) it builds a [`jaxcable.CableNetwork`][], simulates it, and returns the
observables a towing test measures at those times. The drag coefficients being fitted
are ordinary leaves, replaced by `with_coefficients`, so the whole chain is
differentiable and vmappable over records.

Two rigs are provided:

- [`jaxcable.HorizontalTow`][]: a cable towed near the surface under a speed history,
  with a weight or depressor at its end (the branched-systems paper's towing, speed steps 1 → 3 m/s).
  It pins the cable's drag coefficients K_n and K_τ.
- [`jaxcable.VerticalTow`][]: Zhukov's vertical towing of a growing element by a
  buoyant leader. It pins the element's specific-weight drag coefficient k₀.
"""

import abc
import inspect
from collections.abc import Mapping
from typing import ClassVar

import equinox as eqx
import jax.numpy as jnp
import numpy as np
import optimistix as optx
from jaxtyping import Array, ArrayLike, Bool, Float

from .. import _checks as checks
from .._model.materials import KelvinVoigt
from .._model.motion import Towing
from .._model.network import Body, CableNetwork, LineType
from .._model.state import State
from .._sea.environment import Environment
from .._simulation.simulate import SimulationResult, simulate
from .._solver.config import SolverConfig
from .._statics.solve import solve_statics
from .._typing import RealLike

COEFFICIENTS = {
    "normal_drag": "K_n (–), the cable's normal drag coefficient",
    "tangential_drag": "K_τ (–), the cable's tangential drag coefficient",
    "specific_drag": "k₀ (s²/m²), Zhukov's specific-weight drag coefficient, R = k₀ u² m g",
}
"""The coefficients calibration can fit, by name, with their symbols and units."""


class TowingRun(eqx.Module):
    """A simulated towing test.

    - `observables`: by name, at the requested times (SI), each shape `(samples,)`.
    - `simulation`: the [`jaxcable.SimulationResult`][].
    - `success`: `True` where both the starting equilibrium (if the rig has one) and
        the run succeeded.
    """

    observables: dict[str, Float[Array, " samples"]]
    simulation: SimulationResult
    success: Bool[Array, ""]


RIG_MAX_STEPS = 100_000
"""The rigs' default step limit: a towing test that needs more has gone wrong, and under
calibration's `vmap` one such record would hold every other to its step count."""


def rig_solver(**options) -> SolverConfig:
    """The rigs' default [`jaxcable.SolverConfig`][]: as [`jaxcable.simulate`][]'s
    (Dopri5 at rtol = atol = 1e-6, `RecursiveCheckpointAdjoint`) but with at most
    100,000 steps (`RIG_MAX_STEPS`). `options` are `SolverConfig`'s keyword arguments,
    replacing these defaults: `rig_solver(rtol=1e-8)`."""
    return SolverConfig(**{"max_steps": RIG_MAX_STEPS, **options})


class AbstractTowingRig(eqx.Module):
    """A towing test's apparatus: what turns a record's inputs into its observables.

    Subclasses declare, as class variables, the record columns they take as `inputs`,
    the `observables` they predict, and the calibration `coefficients` they depend on
    (names from `jaxcable.COEFFICIENTS`).
    """

    inputs: ClassVar[tuple[str, ...]]
    observables: ClassVar[tuple[str, ...]]
    coefficients: ClassVar[tuple[str, ...]]
    caveats: ClassVar[dict[str, str]] = {}
    """Observables that are easily mistaken for an instrument's reading, by name: a
    sentence saying where the model takes them, which calibration repeats when a record
    measures one of them."""

    @abc.abstractmethod
    def with_coefficients(self, values: Mapping[str, Float[ArrayLike, ""]]) -> "AbstractTowingRig":
        """This rig with the named coefficients replaced; names it does not depend on
        are ignored, so one set of values can serve every rig in a joint fit."""

    @abc.abstractmethod
    def simulate(
        self,
        times: Float[Array, " samples"],
        inputs: Mapping[str, Float[Array, " samples"]],
        solver: SolverConfig | None = None,
    ) -> TowingRun:
        """Simulate the test; its observables are taken at `times` (s).

        `times` must be non-decreasing; repeated final times (padding) are allowed. The
        run starts at `times[0]` and ends at `times[-1]`. `inputs` holds one array per
        name in `inputs`, sampled at `times`. `solver` is how to integrate,
        [`jaxcable.calibration.rig_solver`][]`()` by default.
        """

    @abc.abstractmethod
    def conditions(self) -> dict[str, float | str]:
        """The rig as a record header's conditions: `rig`, its name in
        `jaxcable.RIGS`, and every argument of its constructor (SI), so that
        [`jaxcable.calibration.rig_from_conditions`][] rebuilds it."""

    def predict(self, times, inputs=None, solver: SolverConfig | None = None):
        """The observables alone, `simulate(...).observables`."""
        return self.simulate(jnp.asarray(times, dtype=float), _as_arrays(inputs), solver).observables


def _as_arrays(inputs):
    return {k: jnp.asarray(v, dtype=float) for k, v in (inputs or {}).items()}


def _replace(module, values: Mapping, fields: Mapping[str, str]):
    """`module` with `module.<fields[name]> = values[name]` for each name present."""
    for name, field in fields.items():
        if name in values:
            module = eqx.tree_at(lambda m: getattr(m, field), module, jnp.asarray(values[name], dtype=float))  # noqa: B023 (called within this iteration)
    return module


class HorizontalTow(AbstractTowingRig):
    """A cable towed near the surface under a speed history, with a body at its end.

    The tow point moves along +x at the record's speed ([`jaxcable.Towing`][]); the
    cable streams aft and down to the end body (a clump weight or a depressor). The run
    starts in steady tow at the first speed: the equilibrium in a current of that speed
    against the tow, with every node moving at it. The mass matrix is lumped, so the
    speed history's steps in acceleration do not reach the free nodes' equations.

    Observables:

    - `tow_load`: the load at the tow point (N), what a load cell between the towing
      vessel and the cable reads: the magnitude of the support's reaction on the
      cable's end node, `|M a − Q|` there. It carries the whole cable, the tow node's
      half segment included (its wet weight, drag and inertia).
    - `tension`: the first segment's axial tension (N), `EA ε + C_v ε̇` of its mean
      strain: the tension half a segment (`cable_length / (2 segments)`) below the tow
      point. It reads below `tow_load` by about that half segment's wet weight and
      drag (1-2 % for the default rig), and the gap shrinks as `segments` grows: fit a
      load cell's record as `tow_load`, never as `tension`.
    - `depth`: of the end body's node below the still-water level (m);
    - `layback`: the horizontal distance along the tow from the tow point back to the
      end body's node (m).

    Coefficients: `normal_drag` (K_n) and `tangential_drag` (K_τ) of the cable.

    **Arguments:**

    - `cable_length`: unstretched length (m).
    - `cable_diameter`: d (m), for drag; the displaced area is π d²/4.
    - `cable_mass_per_length`: m (kg/m), in air.
    - `cable_axial_stiffness`: EA (N).
    - `cable_axial_damping`: C_v (N·s), in `T = EA ε + C_v ε̇`. It settles the axial
      ringing of the segments, which otherwise sets the step size for the whole run.
    - `normal_drag`, `tangential_drag`: K_n, K_τ (–).
    - `cable_added_mass`: C_a (–), normal to the cable.
    - `end_mass`: the end body's mass in air (kg).
    - `end_volume`: its displaced volume (m³).
    - `end_drag_area`: its C_D A (m²).
    - `end_added_mass`: its C_a (–) on the displaced volume.
    - `tow_depth`: the tow point's depth below the still-water level (m).
    - `water_density`: ρ (kg/m³).
    - `gravity`: g (m/s²).
    - `segments`: the number of equal segments.

    The defaults are the armoured tow cable and depressor of the bundled `towed_line`
    scene (17.3 mm cable, EA = 1.4e7 N, C_v = 2.1e4 N·s, a 400 kg depressor with
    C_D A = 0.4 m²).

    **Raises:**

    `ValueError` naming the field for a non-finite or non-positive value.
    """

    inputs: ClassVar[tuple[str, ...]] = ("speed",)
    observables: ClassVar[tuple[str, ...]] = ("tow_load", "tension", "depth", "layback")
    coefficients: ClassVar[tuple[str, ...]] = ("normal_drag", "tangential_drag")
    caveats: ClassVar[dict[str, str]] = {
        "tension": (
            "HorizontalTow's 'tension' is the first segment's tension, half a segment below the tow point, "
            "not a load cell's reading at the tow point: it misses that half segment's wet weight and drag, "
            "and a fit shifts the drag coefficients to make up for it. If the column was measured at the tow "
            "point, name it 'tow_load'."
        )
    }

    cable: LineType
    cable_length: Float[Array, ""]
    end_body: Body
    tow_depth: Float[Array, ""]
    water_density: Float[Array, ""]
    gravity: Float[Array, ""]
    segments: int = eqx.field(static=True)

    def __init__(
        self,
        cable_length: RealLike = 200.0,
        cable_diameter: RealLike = 0.0173,
        cable_mass_per_length: RealLike = 1.21,
        cable_axial_stiffness: RealLike = 1.4e7,
        cable_axial_damping: RealLike = 2.1e4,
        normal_drag: RealLike = 1.2,
        tangential_drag: RealLike = 0.01,
        cable_added_mass: RealLike = 1.0,
        end_mass: RealLike = 400.0,
        end_volume: RealLike = 0.06,
        end_drag_area: RealLike = 0.4,
        end_added_mass: RealLike = 1.0,
        tow_depth: RealLike = 0.0,
        water_density: RealLike = 1025.0,
        gravity: RealLike = 9.81,
        segments: int = 10,
    ):
        if not (isinstance(segments, int) and segments >= 1):
            raise ValueError(f"HorizontalTow.segments must be a positive integer, got {segments!r}")
        self.segments = segments
        self.cable = LineType(
            mass_per_length=cable_mass_per_length,
            diameter=cable_diameter,
            tension_law=KelvinVoigt(cable_axial_stiffness, 0.0, cable_axial_damping),
            normal_drag=normal_drag,
            tangential_drag=tangential_drag,
            normal_added_mass=cable_added_mass,
        )
        self.cable_length = checks.float_array("HorizontalTow.cable_length", cable_length, ())
        checks.positive("HorizontalTow.cable_length", self.cable_length)
        self.end_body = Body(mass=end_mass, volume=end_volume, drag_area=end_drag_area, added_mass=end_added_mass)
        self.tow_depth = checks.float_array("HorizontalTow.tow_depth", tow_depth, ())
        checks.positive("HorizontalTow.tow_depth", self.tow_depth, allow_zero=True)
        self.water_density = checks.float_array("HorizontalTow.water_density", water_density, ())
        checks.positive("HorizontalTow.water_density", self.water_density)
        self.gravity = checks.float_array("HorizontalTow.gravity", gravity, ())
        checks.positive("HorizontalTow.gravity", self.gravity)

    def conditions(self):
        cable, body = self.cable, self.end_body
        return _floats(
            rig="horizontal_tow",
            cable_length=self.cable_length,
            cable_diameter=cable.diameter,
            cable_mass_per_length=cable.mass_per_length,
            cable_axial_stiffness=cable.tension_law.axial_stiffness,
            cable_axial_damping=cable.tension_law.damping(),
            normal_drag=cable.normal_drag,
            tangential_drag=cable.tangential_drag,
            cable_added_mass=cable.normal_added_mass,
            end_mass=body.mass,
            end_volume=body.volume,
            end_drag_area=body.drag_area,
            end_added_mass=body.added_mass,
            tow_depth=self.tow_depth,
            water_density=self.water_density,
            gravity=self.gravity,
            segments=self.segments,
        )

    def with_coefficients(self, values):
        fields = {"normal_drag": "normal_drag", "tangential_drag": "tangential_drag"}
        return eqx.tree_at(lambda rig: rig.cable, self, _replace(self.cable, values, fields))

    def network(self, times, speeds) -> CableNetwork:
        """The network at `times[0]`, with the tow point following `speeds` and the
        cable on a straight first guess for the steady-tow statics."""
        n = self.segments
        tow_point = jnp.array([0.0, 0.0, -1.0]) * self.tow_depth
        positions = tow_point + jnp.linspace(0.0, 1.0, n + 1)[:, None] * self._guess_chord(speeds[0])
        edges = np.stack([np.arange(n), np.arange(1, n + 1)], axis=1)  # topology: concrete, never traced
        return CableNetwork(
            node_positions=positions,
            segment_nodes=edges,
            segment_length=jnp.full(n, self.cable_length / n),
            line=self.cable,
            constraints={0: Towing(times, speeds)},
            bodies={n: self.end_body},
            mass_matrix="lumped",
        )

    def _guess_chord(self, speed):
        """A straight, slightly stretched chord from the tow point to the end body, at
        the angle φ below the horizontal where the chord, as a rigid rod pinned at the
        tow point, balances its moments: wet weight against drag, the cable's normal
        drag C_n u² sin²φ per length and the body's drag. Close enough for
        Levenberg–Marquardt from a taut start; a guess from force ratios alone, which
        takes all the cable's drag as normal, left a light cable towed nearly along
        the flow 936 iterations from equilibrium."""
        rho, g, cable, body = self.water_density, self.gravity, self.cable, self.end_body
        length = self.cable_length
        body_weight = (body.mass - rho * body.volume) * g
        cable_weight = (cable.mass_per_length - rho * cable.area) * g * length
        body_drag = 0.5 * rho * body.drag_area * speed**2
        cable_drag = 0.5 * rho * cable.normal_drag * cable.diameter * speed**2 * length

        def excess(angle):  # weight's moment less drag's, over the length; falls with angle
            return (body_weight + 0.5 * cable_weight) * jnp.cos(angle) - (
                body_drag * jnp.sin(angle) + 0.5 * cable_drag * jnp.sin(angle) ** 2
            )

        low, high = jnp.zeros(()), jnp.full((), 0.5 * jnp.pi)
        for _ in range(40):  # bisection to 1e-12 rad
            middle = 0.5 * (low + high)
            heavier = excess(middle) > 0
            low, high = jnp.where(heavier, middle, low), jnp.where(heavier, high, middle)
        angle = 0.5 * (low + high)
        return length * (1 + 1e-3) * jnp.stack([-jnp.cos(angle), 0.0, -jnp.sin(angle)])

    def simulate(self, times, inputs, solver=None):
        speeds = inputs["speed"]
        model = self.network(times, speeds)
        direction = jnp.array([1.0, 0.0, 0.0])
        # Steady tow is equilibrium in the frame of the tow point, where the water flows
        # past at the tow speed.
        towed = Environment(self.water_density, self.gravity, current=-speeds[0] * direction)
        # Statics' steps are cheap next to the run: allow plenty, since a light cable
        # streaming nearly along the flow has weak restoring forces.
        steady = solve_statics(model, towed, t=times[0], max_steps=5000, throw=False)
        initial = State(steady.state.positions, jnp.broadcast_to(speeds[0] * direction, model.node_positions.shape))
        result = _run(model, Environment(self.water_density, self.gravity), times, initial, solver)
        end = self.segments
        observables = {
            # The tow point is the network's only constrained node.
            "tow_load": jnp.linalg.norm(result.reactions[:, 0, :], axis=-1),
            "tension": result.tension[:, 0],
            "depth": -result.positions[:, end, 2],
            "layback": result.positions[:, 0, 0] - result.positions[:, end, 0],
        }
        return TowingRun(observables, result, result.success & (steady.result == optx.RESULTS.successful))


class VerticalTow(AbstractTowingRig):
    """Zhukov's vertical towing: a buoyant leader pulls a growing element up.

    The leader is a float whose net lift in water is set by lead inserts; on a tether
    below it hangs the element, a cage or collector holding organisms of mass m_o,
    whose drag is Zhukov's `R = k₀ u² m_o g` plus any form drag. Released from rest with
    the element hanging (the tether stretched by the element's wet weight), the pair
    rises and settles at the speed where the lift balances the drag. Nothing is
    constrained: the network moves freely.

    Observables:

    - `speed`: the element's rise speed (m/s), the vertical velocity of its node;
    - `tension`: the lowest tether segment's axial tension (N), `EA ε + C_v ε̇` of its
      mean strain: with the default single segment, the tension at the tether's
      middle, which differs from a load cell at the element by half the tether's wet
      weight and drag (under 1 N for the default 8 mm rope).

    Coefficients: `specific_drag` (k₀) of the element. The tether's drag, from its
    own K_n and K_τ, is a known part of the rig.

    **Arguments:**

    - `leader_lift`: the leader's net lift in water, buoyancy less weight (N).
    - `leader_mass`: its mass in air, inserts included (kg).
    - `leader_drag_area`: its C_D A (m²).
    - `leader_added_mass`: its C_a (–) on its displaced volume.
    - `element_mass`: the element's mass in air (kg), organisms included.
    - `element_volume`: its displaced volume (m³).
    - `organism_mass`: m_o (kg), the mass k₀ refers to.
    - `specific_drag`: k₀ (s²/m²).
    - `element_drag_area`: its form drag C_D A (m²), apart from k₀; 0 by default.
    - `element_added_mass`: its C_a (–) on the displaced volume.
    - `tether_length`, `tether_diameter` (m), `tether_mass_per_length` (kg/m),
      `tether_axial_stiffness` (EA, N), `tether_axial_damping` (C_v, N·s): the tether.
      The damping settles the axial ringing that the release starts.
    - `tether_normal_drag`, `tether_tangential_drag`: its K_n, K_τ (–).
    - `start_depth`: the element's depth at release (m).
    - `water_density`: ρ (kg/m³).
    - `gravity`: g (m/s²).
    - `segments`: the tether's segments.

    The defaults describe a scallop cage (25 kg in air, 20 kg of it organisms, k₀ =
    0.5 s²/m²) on 3 m of 8 mm rope below a streamlined leader. Zhukov's growing-element thesis gives no values
    of k₀ in its text (its figures plot R/(m g) against speed), so these are
    illustrative.

    **Raises:**

    `ValueError` naming the field for a non-finite or non-positive value, and if the
    lift does not exceed the element's and the tether's weight in water.
    """

    inputs: ClassVar[tuple[str, ...]] = ()
    observables: ClassVar[tuple[str, ...]] = ("speed", "tension")
    coefficients: ClassVar[tuple[str, ...]] = ("specific_drag",)

    leader: Body
    element: Body
    tether: LineType
    tether_length: Float[Array, ""]
    start_depth: Float[Array, ""]
    water_density: Float[Array, ""]
    gravity: Float[Array, ""]
    segments: int = eqx.field(static=True)

    def __init__(
        self,
        leader_lift: RealLike = 200.0,
        leader_mass: RealLike = 10.0,
        leader_drag_area: RealLike = 0.02,
        leader_added_mass: RealLike = 0.2,
        element_mass: RealLike = 25.0,
        element_volume: RealLike = 0.012,
        organism_mass: RealLike = 20.0,
        specific_drag: RealLike = 0.5,
        element_drag_area: RealLike = 0.0,
        element_added_mass: RealLike = 1.0,
        tether_length: RealLike = 3.0,
        tether_diameter: RealLike = 0.008,
        tether_mass_per_length: RealLike = 0.05,
        tether_axial_stiffness: RealLike = 2.0e5,
        tether_axial_damping: RealLike = 5.0e3,
        tether_normal_drag: RealLike = 1.2,
        tether_tangential_drag: RealLike = 0.01,
        start_depth: RealLike = 30.0,
        water_density: RealLike = 1025.0,
        gravity: RealLike = 9.81,
        segments: int = 1,
    ):
        if not (isinstance(segments, int) and segments >= 1):
            raise ValueError(f"VerticalTow.segments must be a positive integer, got {segments!r}")
        self.segments = segments
        self.water_density = checks.float_array("VerticalTow.water_density", water_density, ())
        checks.positive("VerticalTow.water_density", self.water_density)
        self.gravity = checks.float_array("VerticalTow.gravity", gravity, ())
        checks.positive("VerticalTow.gravity", self.gravity)
        lift = checks.float_array("VerticalTow.leader_lift", leader_lift, ())
        checks.positive("VerticalTow.leader_lift", lift)
        mass = checks.float_array("VerticalTow.leader_mass", leader_mass, ())
        checks.positive("VerticalTow.leader_mass", mass)
        self.leader = Body(
            mass=mass,
            volume=(lift + mass * self.gravity) / (self.water_density * self.gravity),
            drag_area=leader_drag_area,
            added_mass=leader_added_mass,
        )
        self.element = Body(
            mass=element_mass,
            volume=element_volume,
            drag_area=element_drag_area,
            specific_drag=specific_drag,
            organism_mass=organism_mass,
            added_mass=element_added_mass,
        )
        self.tether = LineType(
            mass_per_length=tether_mass_per_length,
            diameter=tether_diameter,
            tension_law=KelvinVoigt(tether_axial_stiffness, 0.0, tether_axial_damping),
            normal_drag=tether_normal_drag,
            tangential_drag=tether_tangential_drag,
        )
        self.tether_length = checks.float_array("VerticalTow.tether_length", tether_length, ())
        checks.positive("VerticalTow.tether_length", self.tether_length)
        self.start_depth = checks.float_array("VerticalTow.start_depth", start_depth, ())
        checks.positive("VerticalTow.start_depth", self.start_depth)
        hanging = self.hanging_weight()
        rises = checks.Condition(
            "VerticalTow.leader_lift",
            lift <= hanging,
            lift,
            "must exceed the weight in water of the element and tether, or nothing rises",
            lambda: (
                f"VerticalTow.leader_lift = {float(lift)} N must exceed the weight in water of the "
                f"element and tether, {float(hanging):.6g} N, or nothing rises"
            ),
        )
        # Traced (a rig built inside `jit`), the check rides on the leader, which every
        # model of the rig holds.
        self.leader = checks.check(self.leader, [rises])

    def hanging_weight(self) -> Float[Array, ""]:
        """The element's and the tether's weight in water (N)."""
        rho, g = self.water_density, self.gravity
        element = (self.element.mass - rho * self.element.volume) * g
        tether = (self.tether.mass_per_length - rho * self.tether.area) * g * self.tether_length
        return element + tether

    def leader_lift(self) -> Float[Array, ""]:
        """The leader's net lift in water (N)."""
        return (self.water_density * self.leader.volume - self.leader.mass) * self.gravity

    def conditions(self):
        leader, element, tether = self.leader, self.element, self.tether
        return _floats(
            rig="vertical_tow",
            leader_lift=self.leader_lift(),
            leader_mass=leader.mass,
            leader_drag_area=leader.drag_area,
            leader_added_mass=leader.added_mass,
            element_mass=element.mass,
            element_volume=element.volume,
            organism_mass=element.organism_mass,
            specific_drag=element.specific_drag,
            element_drag_area=element.drag_area,
            element_added_mass=element.added_mass,
            tether_length=self.tether_length,
            tether_diameter=tether.diameter,
            tether_mass_per_length=tether.mass_per_length,
            tether_axial_stiffness=tether.tension_law.axial_stiffness,
            tether_axial_damping=tether.tension_law.damping(),
            tether_normal_drag=tether.normal_drag,
            tether_tangential_drag=tether.tangential_drag,
            start_depth=self.start_depth,
            water_density=self.water_density,
            gravity=self.gravity,
            segments=self.segments,
        )

    def with_coefficients(self, values):
        return eqx.tree_at(
            lambda rig: rig.element, self, _replace(self.element, values, {"specific_drag": "specific_drag"})
        )

    def network(self) -> CableNetwork:
        """The free network at release: the element at node 0, the leader at the top
        node, and the tether straight up between them, stretched by the element's wet
        weight."""
        n = self.segments
        rho, g = self.water_density, self.gravity
        stretch = (self.element.mass - rho * self.element.volume) * g / self.tether.tension_law.axial_stiffness
        element = jnp.array([0.0, 0.0, -1.0]) * self.start_depth
        rise = jnp.linspace(0.0, 1.0, n + 1) * self.tether_length * (1 + stretch)
        positions = element + rise[:, None] * jnp.array([0.0, 0.0, 1.0])
        edges = np.stack([np.arange(n), np.arange(1, n + 1)], axis=1)  # topology: concrete, never traced
        return CableNetwork(
            node_positions=positions,
            segment_nodes=edges,
            segment_length=jnp.full(n, self.tether_length / n),
            line=self.tether,
            constraints={},
            bodies={0: self.element, n: self.leader},
            mass_matrix="lumped",
        )

    def simulate(self, times, inputs=None, solver=None):
        model = self.network()
        initial = State(model.node_positions, jnp.zeros_like(model.node_positions))
        result = _run(model, Environment(self.water_density, self.gravity), times, initial, solver)
        observables = {"speed": result.velocities[:, 0, 2], "tension": result.tension[:, 0]}
        return TowingRun(observables, result, result.success)

    def steady_speed(self) -> Float[Array, ""]:
        """The rise speed (m/s) at which the lift balances the drag, in closed form: the
        leader's and the element's form drag, the element's k₀ drag and the tether's
        tangential drag (the tether hangs straight along the flow), all quadratic in
        the speed."""
        rho, g = self.water_density, self.gravity
        quadratic = (
            0.5 * rho * (self.leader.drag_area + self.element.drag_area)
            + self.element.specific_drag * self.element.organism_mass * g
            + 0.5 * rho * self.tether.tangential_drag * jnp.pi * self.tether.diameter * self.tether_length
        )
        return jnp.sqrt((self.leader_lift() - self.hanging_weight()) / quadratic)


def _floats(rig: str, segments: int, **values) -> dict[str, float | str]:
    return {"rig": rig, **{k: float(v) for k, v in values.items()}, "segments": segments}


def _run(model, env, times, initial, solver: SolverConfig | None) -> SimulationResult:
    solver = rig_solver() if solver is None else solver
    return simulate(model, env, times[-1], t0=times[0], ts=times, initial=initial, solver=solver, throw=False)


RIGS: dict[str, type[AbstractTowingRig]] = {"horizontal_tow": HorizontalTow, "vertical_tow": VerticalTow}
"""The rigs by the names a record's `rig` condition uses."""


def rig_from_conditions(conditions: Mapping[str, float | str], name: str = "record") -> AbstractTowingRig:
    """Build the rig a record's header describes: `rig = horizontal_tow` or
    `vertical_tow`, and any of that rig's arguments as numeric conditions (SI); the
    rest take their defaults.

    **Raises:**

    `ValueError` naming the record and the key for a missing or unknown rig, an unknown
    condition, or a bad value.
    """
    if "rig" not in conditions:
        raise ValueError(f"{name}: no 'rig' in the header; say '# rig = horizontal_tow' or '# rig = vertical_tow'")
    kind = conditions["rig"]
    if kind not in RIGS:
        raise ValueError(f"{name}: unknown rig {kind!r}; known rigs: {', '.join(RIGS)}")
    cls = RIGS[kind]
    known = set(_arguments(cls))
    arguments = {}
    for key, value in conditions.items():
        if key == "rig":
            continue
        if key not in known:
            raise ValueError(f"{name}: unknown condition {key!r} for rig {kind}; known: {', '.join(sorted(known))}")
        if isinstance(value, str):
            raise ValueError(f"{name}: condition {key!r} must be a number, got {value!r}")
        arguments[key] = int(value) if key == "segments" and float(value).is_integer() else value
    try:
        return cls(**arguments)
    except ValueError as error:
        raise ValueError(f"{name}: {error}") from None


def _arguments(cls) -> list[str]:
    return [p for p in inspect.signature(cls.__init__).parameters if p != "self"]
