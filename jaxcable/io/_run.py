"""Running a scene: statics, then dynamics, with the results as numpy arrays."""

import os
import threading
import time
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import diffrax
import numpy as np

from .. import _programs as programs
from .._advice import STABLE_STEP
from .._equations.modes import stiffest_axial_mode
from .._interrupt import StopRequest
from .._model.motion import Sampled
from .._model.reach import for_run
from .._model.state import State
from .._progress import progress_bar
from .._simulation.blocks import SimulationFailed, simulate_in_blocks, substeps_per_interval
from .._simulation.blocks import prepare as prepare_blocks
from .._simulation.simulate import simulate
from .._solver.config import SolverConfig, describe_stepping
from .._solver.stability import STABLE_GROWTH, STEP_FRACTION, fixed_step_growth, fixed_steps
from .._statics.solution import StaticSolution
from .._statics.solve import prepare as prepare_statics
from .._statics.solve import solve_statics
from . import _channels
from ._extremes import LineExtremes, line_extremes
from ._initial_shape import initial_positions
from ._line_fatigue import LineFatigue, line_fatigue
from ._moordyn import read_moordyn
from ._scene import BuiltScene, Scene, SceneError
from ._scene_file import read_scene
from ._statistics import ChannelStatistics, channel_statistics, from_start

DEFAULT_DT_OUT = 0.1  # s
# A tension history whose spread is below this, relative to its largest value, is
# steady: the ripple of rounding and of a fixed-step solver on a held line, not a peak.
STEADY = 1e-6

# What a run costs on one CPU core, for the estimate that `check_size` gives before any
# work. An explicit Dopri5 step is six force evaluations of 144 ns per node and 13.5 µs
# of diffrax's bookkeeping, for a single run (`benchmarks/step_cost.py` measures both).
STEP_SECONDS, EVALUATION_SECONDS_PER_NODE, EVALUATIONS_PER_STEP = 13.5e-6, 144e-9, 6
# Statics (pseudo-transient continuation on the network's block-tridiagonal Jacobian)
# costs O(F) a step for F free nodes, after a compilation whose time does not grow with
# F. The anchored line cut into 100, 1,000 and 10,000 segments (`python
# benchmarks/statics_cost.py --sizes`, a fresh process each): first calls of 32, 30
# and 37 s, warm calls of 0.11, 2.4 and 2.5 s over 110, 357 and 16 steps (1.0 ms,
# 6.8 ms and 157 ms a step: about 16 µs per free node at 10,000), and peak memory 350,
# 456 and 554 MiB above the built scene's, 350 MiB and about 20 kB per free node more.
# The estimate takes the compilation, 400 steps (the 1,000-segment line's order;
# `benchmarks/statics_fuzz.py`'s random scenes take a median of about 100 and at most
# 7 × 1,000) at 16 µs per free node, and that memory.
STATICS_BASE_BYTES = 350 * 2**20
STATICS_BYTES_PER_FREE_NODE = 20e3
STATICS_COMPILE_SECONDS = 35.0
STATICS_STEPS = 400
STATICS_SECONDS_PER_FREE_NODE_STEP = 16e-6
WARN_SECONDS = 3600.0  # a run estimated to take longer than this is warned of


def load_scene(path: str | Path) -> Scene:
    """Read `path` as a jaxcable scene if it ends in `.toml`, otherwise as a MoorDyn v2
    input file ([`jaxcable.read_scene`][], [`jaxcable.read_moordyn`][])."""
    path = Path(path)
    return read_scene(path) if path.suffix.lower() == ".toml" else read_moordyn(path)


@dataclass(frozen=True)
class SceneRun:
    """A scene's equilibrium and, unless the duration was 0, its motion.

    Arrays are numpy, indexed by output time first. With a duration of 0 there is one
    output time, 0 s, and the state is the initial one.

    - `built`: the [`jaxcable.io.BuiltScene`][] that ran.
    - `static`: its [`jaxcable.StaticSolution`][], the initial state; `None` where
        statics was skipped and the run started from the file's geometry at rest
        (`jaxcable.io._initial_shape`).
    - `times`: (s), shape `(times,)`.
    - `positions`, `velocities`: (m, m/s), shape `(times, nodes, 3)`.
    - `tension`: (N), shape `(times, segments)`.
    - `reactions`: force (N) of each support on the network, in the order of
        `built.model.constrained_nodes`, shape `(times, constrained, 3)`.
    - `steps`: solver steps taken (0 for statics only).
    - `stepping`: how the motion was integrated, such as `"Midpoint, fixed steps of
        0.001 s"` or `"Dopri5, adaptive (rtol 1e-06, atol 1e-06)"`; empty for statics only.
    - `statics_seconds`, `dynamics_seconds`: wall time (s), compilation included.
    - `statics_compile`, `dynamics_compile`: the part of each spent tracing and
        compiling programs, or loading them from JAX's persistent cache (s), as JAX's
        compile events time it.
    - `cache_hits`, `cache_misses`: programs loaded from, and compiled and missing in,
        the kept programs' folder ([`jaxcable._programs`][]) or JAX's persistent
        compilation cache (both 0 with neither).
    - `notes`: what the user should know about this run (seabed penetration, ...).
    """

    built: BuiltScene
    static: StaticSolution | None
    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    tension: np.ndarray
    reactions: np.ndarray
    steps: int
    stepping: str
    statics_seconds: float
    dynamics_seconds: float
    notes: tuple[str, ...]
    statics_compile: float = 0.0
    dynamics_compile: float = 0.0
    cache_hits: int = 0
    cache_misses: int = 0

    def channels(self, names: tuple[str, ...] = ()) -> dict[str, np.ndarray]:
        """Output channels by MoorDyn name, `Time` first; the scene's own channels, or
        every line's `FairTen<k>` and `AnchTen<k>`, when `names` is empty."""
        return _channels.channels(
            self.built, self.times, self.tension, self.positions, self.velocities, self.net_forces, names
        )

    def net_forces(self) -> np.ndarray:
        """The net force on every node (N), shape `(times, nodes, 3)`: every force but
        the inertial ones (`jaxcable.equations.generalised_forces`), the point force
        of MoorDyn's `Point<k>FX` channels (`jaxcable.io._channels`)."""
        import jax

        from .._equations.lagrangian import generalised_forces

        model, env = self.built.model, self.built.environment
        forces = jax.vmap(generalised_forces, in_axes=(None, None, 0, 0, 0))
        return np.asarray(forces(model, env, self.times, self.positions, self.velocities))

    def line_extremes(self, start: float = 0.0) -> tuple[LineExtremes, ...]:
        """Each line's largest and smallest tension with where and when, its ends' largest,
        and its utilisation where its line type gives a minimum breaking load
        ([`jaxcable.io.LineExtremes`][]), over the outputs from `start` (s) on, in the
        scene's order of lines."""
        keep = from_start(self.times, start)
        return line_extremes(self.built, self.times[keep], self.tension[keep])

    def line_fatigue(self, start: float = 0.0) -> tuple[LineFatigue, ...]:
        """Each line's fatigue damage, at its most damaged segment, and the life at this
        run's rate, over the outputs from `start` (s) on, for the lines whose line type
        names a T–N curve ([`jaxcable.io.LineFatigue`][]), in the scene's order."""
        return line_fatigue(self.built, self.times, self.tension, start)

    def channel_statistics(self, names: tuple[str, ...] = (), start: float = 0.0) -> tuple[ChannelStatistics, ...]:
        """Each output channel's time-averaged mean and standard deviation and its
        extremes with their times, over the outputs from `start` (s) on, which leaves a
        start-up transient out ([`jaxcable.io.ChannelStatistics`][]): the scene's
        channels, or `names`, in their order."""
        values = self.channels(names)
        return channel_statistics(values, {name: _channels.channel_units(name) for name in values}, start)

    def to_dataset(self, names: tuple[str, ...] = (), start: float = 0.0):
        """The run as an `xarray.Dataset`: positions, velocities, tensions and reactions
        against time, node, segment and support, the segments' lines and lengths, each
        line's extremes over the outputs from `start` (s) on, and the output channels (the
        scene's, or `names`), each with its units (`attrs["units"]`). Needs xarray (`pip
        install "jaxcable[xarray]"`)."""
        from ._output import dataset

        return dataset(self, names, start)

    def peak_tension(self) -> tuple[float, int, int, float]:
        """The peak tension: `(tension (N), line index, segment index along the line
        from end A, time (s))`, all indices from 0."""
        t, s = np.unravel_index(np.argmax(self.tension), self.tension.shape)
        for k, segments in enumerate(self.built.line_segments):
            hits = np.flatnonzero(segments == s)
            if hits.size:
                return float(self.tension[t, s]), k, int(hits[0]), float(self.times[t])
        raise AssertionError("every segment belongs to a line")

    def steady(self) -> bool:
        """Whether every segment's tension held constant over the run, to `STEADY` of
        the largest tension: a held line at rest, whose "peak" would be rounding."""
        scale = float(np.max(np.abs(self.tension)))
        spread = np.max(self.tension, axis=0) - np.min(self.tension, axis=0)
        return self.times.size < 2 or float(np.max(spread)) <= STEADY * max(scale, np.finfo(float).tiny)

    def summary(self) -> str:
        """Where and when the peak tension was (or that the tensions held steady), and
        the wall time, split into statics, compiling and running."""
        value, k, j, when = self.peak_tension()
        line = self.built.scene.lines[k]
        n = line.segments
        end = " (end B)" if j == n - 1 else " (end A)" if j == 0 else ""
        where = f"in line {line.name}, segment {j + 1}/{n}{end}"
        if self.steps and self.steady():
            peak = f"tensions steady (constant to {STEADY:g} of the largest), largest {value / 1e3:.3f} kN {where}"
        else:
            peak = f"peak tension {value / 1e3:.3f} kN {where}" + (f", at t = {when:.3f} s" if self.steps else "")
        return f"{self._simulated()}; {peak}\n{self.timing()}"

    def _simulated(self) -> str:
        if self.steps == 0:
            return "statics only" if self.static is not None else "initial state only (statics skipped)"
        start = "from the file's geometry (statics skipped)" if self.static is None else "from equilibrium"
        return f"simulated {self.times[-1] - self.times[0]:.3f} s {start} in {self.steps} steps ({self.stepping})"

    def timing(self) -> str:
        """Wall time in words: statics, then the dynamics' compiling and running, and
        how many programs came from JAX's persistent cache."""
        parts = []
        if self.static is not None:
            # Which way statics went (`StaticSolution.method`): the compiled solver, or the
            # single line's closed form, which compiles at most its supports' motion.
            parts.append(
                f"statics {self.statics_seconds:.1f} s ({self.static.method}, {int(self.static.steps)} iterations; "
                f"compile {self.statics_compile:.1f} s of it)"
            )
        if self.steps:
            run = max(self.dynamics_seconds - self.dynamics_compile, 0.0)
            parts.append(f"compile {self.dynamics_compile:.1f} s, run {run:.1f} s")
        if not parts:
            parts.append(f"the start shape {self.statics_seconds:.1f} s (no statics, no dynamics)")
        total = self.statics_seconds + self.dynamics_seconds
        cache = ""
        if self.cache_hits or self.cache_misses:
            programs = self.cache_hits + self.cache_misses
            cache = f"; {self.cache_hits} of {programs} programs loaded from the compilation cache"
            if not self.cache_misses:
                # Loaded, not compiled; but each was traced first to find it, which is
                # what the compile time above still counts.
                cache = f"; all {self.cache_hits} programs loaded from the compilation cache (compile: tracing)"
        return f"wall time {total:.1f} s: " + ", ".join(parts) + cache


def output_times(duration: float, dt_out: float) -> np.ndarray:
    """Output times from 0 to `duration` (s) every `dt_out` (s), ending at `duration`."""
    count = int(np.floor(duration / dt_out + 1e-9))
    times = np.arange(count + 1) * dt_out
    return times if np.isclose(times[-1], duration) else np.append(times, duration)


def run_scene(
    scene: Scene,
    *,
    duration: float | None = None,
    dt_out: float | None = None,
    solver: SolverConfig | None = None,
    progress: bool = False,
    statics: bool | None = None,
    stop: StopRequest | None = None,
) -> SceneRun:
    """Solve a scene's statics in still water (with its current, without its waves) and,
    for a positive duration, integrate its motion from that equilibrium; or, without
    statics, from the file's geometry at rest (MoorDyn's `TmaxIC = 0`).

    The motion is integrated interval by interval between output times (see
    `jaxcable._simulation.blocks`), so that its compiled program can stay in JAX's persistent
    cache; the answers agree with one [`jaxcable.simulate`][] call to within the
    solver's tolerance. A solver with a given `dt0` runs one `simulate` call instead.

    **Arguments:**

    - `scene`: the [`jaxcable.io.Scene`][].
    - `duration`: simulated time (s); the scene's `run.duration` by default; 0 solves
        statics only.
    - `dt_out`: output interval (s); the scene's, or 0.1 s.
    - `solver`: a [`jaxcable.SolverConfig`][]; the scene's by default
        (`scene.run.solver_config(...)`: its named solver and tolerances, or for
        `"auto"`, the default, fixed RK4 steps chosen for the scene's fastest modes).
    - `progress`: show a progress bar over simulated time on stderr: redrawn on a
        terminal, and otherwise (a log) a line at most every 20 s of wall time.
    - `statics`: solve statics first (the scene's `run.statics` by default); without,
        lines start as MoorDyn starts them with `TmaxIC = 0`, on their elastic catenary
        between their ends or straight (`jaxcable.io._initial_shape`), at rest.
    - `stop`: a request from another thread to stop at the end of a block of output
        intervals (`jaxcable._interrupt.StopRequest`), raising
        [`jaxcable.SimulationInterrupted`][] with the run so far (`partial`).

    **Raises:**

    [`jaxcable.io.SceneError`][] for a bad duration or interval, an unknown solver
    name in the scene, or a run too large for memory (`check_size`, which also warns
    of one that would take hours);
    `RuntimeError` if statics or the integration fails: a
    [`jaxcable.SimulationFailed`][] where the integration failed part-way, holding the
    run up to its last good output time as a `SceneRun` (`partial`).
    """
    settings = scene.run
    duration = settings.duration if duration is None else duration
    if dt_out is None:  # not `or`: an interval of 0 is an error, not the default
        dt_out = settings.dt_out if settings.dt_out is not None else DEFAULT_DT_OUT
    if not (np.isfinite(duration) and duration >= 0):
        raise SceneError(f"duration must be a non-negative number of seconds, got {duration}")
    if not (np.isfinite(dt_out) and dt_out > 0):
        raise SceneError(f"dt_out must be a positive number of seconds, got {dt_out}")
    named = solver is None
    if named:
        try:
            solver = settings.solver_config()  # checked before the scene is built
        except ValueError as error:  # a scene built in Python with an unknown solver name
            raise SceneError(str(error)) from None
    check_motion_tables(scene, duration)
    built = scene.build()
    for warning in check_size(built, duration, dt_out, solver):  # before any work on the model
        warnings.warn(warning, stacklevel=2)
    if named and duration > 0:  # "auto" chooses its step for the scene
        solver = settings.solver_config(built, duration)
    model = built.model
    env = for_run(model, built.environment, duration)
    statics = settings.statics if statics is None else statics

    ts = output_times(duration, dt_out)
    blocks = False
    if duration > 0:
        solver, stepping_notes = _feasible(solver, built, ts)
        blocks = solver.dt0 is None or isinstance(solver.stepsize_controller, diffrax.ConstantStepSize)
    # Where programs are kept (the command line), the run's programs and then statics'
    # are traced here and compile in the background while the next is traced. The run's
    # first: they trace quickly and compile on a core that statics' trace (Python, one
    # thread) leaves idle, so that statics' compile, which the run waits for, has the
    # cores to itself. Statics first, the two compiles shared the cores and statics'
    # took 1.7 times as long (Low & Langley file).
    start_notes: tuple[str, ...] = ()
    with _compile_meter() as prepare_meter:
        start = time.perf_counter()
        if blocks:
            prepare_blocks(model, env, ts, solver)
        prepare_seconds = time.perf_counter() - start
    with _compile_meter() as statics_meter:
        start = time.perf_counter()
        if statics:
            prepare_statics(model, env.without_waves())
        statics_seconds = time.perf_counter() - start
    with _compile_meter(statics_meter):
        start = time.perf_counter()
        if statics:
            # The run starts from still water (the current only): the waves' drag and
            # inertia at t = 0 are one instant of a cycle, not a load to balance.
            static = solve_statics(model, env.without_waves())
            initial = static.state
        else:
            static = None
            positions, start_notes = initial_positions(built)
            initial = State(positions, np.zeros_like(positions))
        statics_seconds += time.perf_counter() - start
    if duration == 0:
        positions = np.asarray(initial.positions)[None]
        velocities = np.asarray(initial.velocities)[None]
        if static is not None:
            tension, reactions = np.asarray(static.tension)[None], np.asarray(static.reactions)[None]
        else:
            tension, reactions = _at_rest(built, positions[0])
        return SceneRun(
            built,
            static,
            np.zeros(1),
            positions,
            velocities,
            tension,
            reactions,
            0,
            "",
            statics_seconds,
            0.0,
            start_notes + _water_notes(built, positions),
            statics_compile=statics_meter.seconds,
            cache_hits=statics_meter.hits,
            cache_misses=statics_meter.misses,
        )

    def scene_run(result, dynamics_seconds: float, dynamics_meter: _CompileMeter) -> SceneRun:
        positions = np.asarray(result.positions)
        return SceneRun(
            built,
            static,
            np.asarray(result.times),
            positions,
            np.asarray(result.velocities),
            np.asarray(result.tension),
            np.asarray(result.reactions),
            int(result.stats["num_steps"]),
            describe_stepping(solver),
            statics_seconds,
            dynamics_seconds,
            start_notes + stepping_notes + _water_notes(built, positions),
            statics_compile=statics_meter.seconds,
            dynamics_compile=prepare_meter.seconds + dynamics_meter.seconds,
            cache_hits=prepare_meter.hits + statics_meter.hits + dynamics_meter.hits,
            cache_misses=prepare_meter.misses + statics_meter.misses + dynamics_meter.misses,
        )

    with _compile_meter() as dynamics_meter:
        start = time.perf_counter()
        if blocks:
            # Interval by interval, so that the compiled solve has no host callback and
            # a second run loads it from JAX's persistent cache (see `jaxcable._simulation.blocks`).
            try:
                with progress_bar(duration, progress) as bar:
                    result = simulate_in_blocks(model, env, ts, initial, solver, on_block=bar, stop=stop)
            except SimulationFailed as failure:  # the same failure, with the run so far as a scene's
                seconds = prepare_seconds + time.perf_counter() - start
                partial = None if failure.partial is None else scene_run(failure.partial, seconds, dynamics_meter)
                raise type(failure)(str(failure), partial, failure.time) from None
        else:
            # diffrax checks an adaptive solve's given first step with a callback, so
            # this solve is compiled on every run; it is one `simulate` call, with
            # diffrax's own progress bar.
            result = simulate(model, env, duration, ts=ts, initial=initial, solver=solver, progress=progress)
        dynamics_seconds = prepare_seconds + time.perf_counter() - start
    return scene_run(result, dynamics_seconds, dynamics_meter)


def check_motion_tables(scene: Scene, duration: float) -> None:
    """[`jaxcable.io.SceneError`][] naming the point for a motion table that does not
    cover a run from 0 to `duration` (s)."""
    for point in scene.points:
        motion = point.motion
        if isinstance(motion, Sampled):
            first, last = (float(t) for t in np.asarray(motion.times)[[0, -1]])
            if first > 0 or last < duration:
                raise SceneError(
                    f"{point.where}: point {point.name}'s motion table covers {first:g} to {last:g} s, "
                    f"but the run needs 0 to {duration:g} s"
                )


def _at_rest(built: BuiltScene, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The segment tensions (N, shape `(1, segments)`) and support reactions (N, shape
    `(1, constrained, 3)`) of the network held at `positions` (m), at rest."""
    from .._equations.lagrangian import reactions, tension

    model, env = built.model, built.environment
    rest = np.zeros_like(positions)
    return (
        np.asarray(tension(model, positions, rest))[None],
        np.asarray(reactions(model, env, 0.0, positions, rest, rest))[None],
    )


class _CompileMeter:
    """What JAX's compile events report while it is open: the wall time (s) this thread
    spent tracing, lowering and compiling programs (or loading them from a cache, or
    waiting for their compilation in the background, `jaxcable._programs`), and the
    caches' hits and misses (from every thread).

    The time is the union of the events' spans: a program traced inside another's
    trace reports its own span within the outer one, and summing them would count it
    twice. A background compilation's spans are not this thread's time, except where
    it waits for one."""

    EVENTS = (
        "/jax/core/compile/jaxpr_trace_duration",
        "/jax/core/compile/jaxpr_to_mlir_module_duration",
        "/jax/core/compile/backend_compile_duration",
        programs.WAIT_EVENT,
    )

    def __init__(self):
        self.spans: list[tuple[float, float]] = []
        self.hits, self.misses = 0, 0
        self.thread = threading.get_ident()

    def span(self, event: str, start_time: float, end_time: float, **kwargs: str | int) -> None:
        if event in self.EVENTS and threading.get_ident() == self.thread:
            self.spans.append((start_time, end_time))

    def event(self, event: str, **kwargs: str | int) -> None:
        if event in ("/jax/compilation_cache/cache_hits", programs.LOADED_EVENT):
            self.hits += 1
        elif event in ("/jax/compilation_cache/cache_misses", programs.COMPILED_EVENT):
            self.misses += 1

    @property
    def seconds(self) -> float:
        """The length of the union of the spans (s)."""
        total, reached = 0.0, -np.inf
        for start, end in sorted(self.spans):
            if end > reached:
                total += end - max(start, reached)
                reached = end
        return total


@contextmanager
def _compile_meter(meter: _CompileMeter | None = None) -> Iterator[_CompileMeter]:
    """A [`_CompileMeter`][] (a new one, or `meter` to go on adding to it) listening to
    JAX's monitoring events for the block only (its listeners are removed on the way
    out, so nothing outlives the run)."""
    from jax import monitoring

    meter = _CompileMeter() if meter is None else meter
    monitoring.register_event_time_span_listener(meter.span)
    monitoring.register_event_listener(meter.event)
    try:
        yield meter
    finally:
        monitoring.unregister_event_time_span_listener(meter.span)
        monitoring.unregister_event_listener(meter.event)


def _feasible(solver: SolverConfig, built: BuiltScene, ts: np.ndarray) -> tuple[SolverConfig, tuple[str, ...]]:
    """`solver`, or where its fixed step would fail, RK4 at a step that does not
    ([`jaxcable.fixed_steps`][]): a step beyond its method's stability limit at the
    scene's fastest modes (`jaxcable._solver.stability`), or more steps than its `max_steps`
    (then adaptive steps); with a note that says why."""
    if not isinstance(solver.stepsize_controller, diffrax.ConstantStepSize) or solver.dt0 is None:
        return solver, ()
    dt = float(np.asarray(solver.dt0))
    method = type(solver.solver).__name__
    steps = substeps_per_interval(ts, dt) * (ts.size - 1)
    if steps > solver.max_steps:
        adaptive = SolverConfig(max_steps=solver.max_steps)
        return adaptive, (
            f"fixed steps of {dt:g} s would take {steps} steps, more than max_steps = {solver.max_steps}: "
            f"stepped adaptively with {describe_stepping(adaptive)} instead",
        )
    growth = fixed_step_growth(solver.solver, dt, built, steps=steps)
    if growth is not None and growth > STABLE_GROWTH:
        stable = fixed_steps([(built.model, built.environment)], float(ts[-1] - ts[0]), max_steps=solver.max_steps)
        return stable, (
            f"fixed steps of {dt:g} s are beyond {method}'s stability limit here (the fastest mode grows "
            f"{growth:.3g}× a step: no damping holds it): stepped with {describe_stepping(stable)} instead "
            f"({STEP_FRACTION:g} of RK4's stability limit)",
        )
    return solver, ()


def check_size(built: BuiltScene, duration: float, dt_out: float, solver: SolverConfig) -> tuple[str, ...]:
    """Refuse a run that cannot fit in memory, and say when one would take hours: before
    any work, so that `segments = 1000000` fails at once instead of hanging.

    Memory: statics' (`STATICS_BASE_BYTES + STATICS_BYTES_PER_FREE_NODE × F` for F
    free nodes) and the output (positions and velocities of every node, strain and
    tension of every segment, at every output time, held twice: the solve's and the
    copy returned). Time: statics, `STATICS_COMPILE_SECONDS + STATICS_STEPS ×
    STATICS_SECONDS_PER_FREE_NODE_STEP × F` (O(F): the solver's linear systems are
    block-tridiagonal along the network's graph); and for an
    explicit solver the dynamics, at the stable step Δt = 1.7/|λ| of the stiffest
    axial mode ([`jaxcable.advise`][]'s), each step costing
    `STEP_SECONDS + EVALUATIONS_PER_STEP × EVALUATION_SECONDS_PER_NODE × nodes`. The
    figures are one CPU core's (see the constants): a guide to the order of magnitude,
    not a promise.

    **Returns:**

    Warnings, in words, for a run estimated to take over `WARN_SECONDS`.

    **Raises:**

    [`jaxcable.io.SceneError`][] naming the segment count when the memory estimate
    exceeds the machine's physical memory.
    """
    model = built.model
    nodes, free, segments = model.n_nodes, int(model.free_nodes.size), model.n_segments
    times = 1 if duration == 0 else int(np.floor(duration / dt_out)) + 2
    statics = STATICS_BASE_BYTES + STATICS_BYTES_PER_FREE_NODE * free
    outputs = 2 * times * (6 * nodes + 2 * segments) * 8
    available = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    counts = "/".join(str(line.segments) for line in built.scene.lines)
    if statics + outputs > available:
        raise SceneError(
            f"{built.scene.source}: {segments:,} segments (lines of {counts}) over {duration:g} s need about "
            f"{(statics + outputs) / 2**30:,.1f} GiB ({statics / 2**30:,.1f} GiB for statics of {free:,} free "
            f"nodes, {outputs / 2**30:,.1f} GiB for {times:,} output times every {dt_out:g} s), "
            f"more than this machine's {available / 2**30:,.1f} GiB: use fewer segments (segments in the file, or "
            "--segments), or fewer output times"
        )
    statics_seconds = STATICS_COMPILE_SECONDS + STATICS_STEPS * STATICS_SECONDS_PER_FREE_NODE_STEP * free
    parts = [f"statics some {statics_seconds / 3600:,.2g} h ({free:,} free nodes, O(F))"]
    seconds = statics_seconds
    if duration > 0 and not isinstance(solver.solver, diffrax.AbstractImplicitSolver):
        _, magnitude, _ = stiffest_axial_mode(model, built.environment)
        steps = duration * magnitude / STABLE_STEP
        dynamics_seconds = steps * (STEP_SECONDS + EVALUATIONS_PER_STEP * EVALUATION_SECONDS_PER_NODE * nodes)
        seconds += dynamics_seconds
        parts.append(
            f"dynamics some {dynamics_seconds / 3600:,.2g} h ({duration:g} s at an explicit solver's stable step of "
            f"at most {STABLE_STEP / magnitude:.3g} s, set by the stiffest axial mode, |λ| = {magnitude:.4g} 1/s: "
            f"about {steps:,.0f} steps of {nodes:,} nodes"
            + (
                f", more than max_steps = {solver.max_steps:,}, so the solve would fail"
                if steps > solver.max_steps
                else ""
            )
            + ")"
        )
    if seconds <= WARN_SECONDS:
        return ()
    return (
        f"{segments:,} segments (lines of {counts}) would take some {seconds / 3600:,.2g} h on a 2-core CPU: "
        + "; ".join(parts)
        + "; fewer segments cut both",
    )


def _water_notes(built: BuiltScene, positions: np.ndarray) -> tuple[str, ...]:
    """Where the run left the water the model assumes: above the highest crest without
    the free surface, a point body without a height above it (whose buoyancy the
    surface never changes), or below the bottom without a seabed."""
    scene, env = built.scene, built.environment
    notes = []
    highest = float(positions[..., 2].max())
    crest = sum(float(wave.crest) for wave in env.waves)
    where = "the still-water level" if not env.waves else f"the highest crest, {crest:.2f} m"
    if highest > crest + 1e-6 and not scene.water.free_surface:
        notes.append(
            f"nodes reach z = {highest:.2f} m, above {where}: every segment is treated as "
            "submerged, so buoyancy, drag and added mass act on the emerged part too"
        )
    # A point's node is its index (`Scene.build`). A body without a height is a point:
    # its buoyancy is its whole volume's wherever it is (MoorDyn's points' too).
    for k, point in enumerate(scene.points):
        body = point.body
        if body is None or not np.any(np.asarray(body.volume) > 0) or np.any(np.asarray(body.height) > 0):
            continue
        top = float(positions[..., k, 2].max())
        if top > crest + 1e-6:
            notes.append(
                f"{point.where}: point {point.name}'s body reaches z = {top:.2f} m, above {where}, and keeps the "
                f"buoyancy of its whole volume ({float(np.asarray(body.volume)):g} m³) there: a body without a height "
                "is a point, which the surface does not change (as in MoorDyn); give it a height (m, a scene file "
                "point's `height`) for buoyancy that follows its draft"
            )
    depth = scene.water.depth
    if depth is not None and scene.water.seabed is None and positions[..., 2].min() < -depth:
        notes.append(
            f"nodes reach z = {float(positions[..., 2].min()):.2f} m, below the bottom at z = {-depth:g} m: "
            "the scene has no [seabed], so lines there hang through it"
        )
    return tuple(notes)
