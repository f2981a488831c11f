"""Float32 for the explicit runs: what a float32 state costs in accuracy, and what float32
could buy in speed on this CPU (issue 18, "float32 where a measured error study allows
it").

A float32 run stores its state (the free nodes' positions and velocities) in float32:
every step rounds it to 24 bits. That rounding is the least error any float32 run has,
whatever precision its arithmetic keeps, so this study measures it alone: the speed
table's explicit scheme (the midpoint rule, MoorDyn's RK2) stepped in float64, and the
same steps with the state rounded to float32 after each, on the speed table's scenes.
Two ways of storing it:

- `absolute`: the positions themselves in float32 (what casting a model and its state
  to float32 gives): a node 50 m from the origin is held to about 4 µm;
- `displacement`: the positions as float64 start positions plus a float32 displacement
  from them (a float32 design that keeps the large part exact), and the velocities in
  float32.

Beside them, `representation`: the float64 run's own states rounded to float32 at each
output, the tension error of the rounding alone, without its growth through the
dynamics; and `float32 strain`: the top segment's elastic tension EA ε computed in
float32 arithmetic from the displacement design's float32 state (its chord as the
float32 start chord plus the float32 displacements' difference), against the same
tension in float64: the resolution of a float32 evaluation's strain, which no storage
design removes (about EA · 2⁻²⁴ · S/L). Every error is the top segment's tension against the float64 run's, RMS and
largest, relative to the float64 run's peak, over the run; the speed table matches
engines at an RMS error of 1e-3 of the peak (`speed.py`), so a float32 state whose own
error is near that cannot meet it.

The speed side: this machine's FMA rate in float32 and float64 through XLA (a fused
chain on both cores, as `profile_evaluation.roofline` measures float64), the ceiling of
what float32 could gain on the batched evaluation, which is compute bound.

Scenes: `anchored_line_20` and `anchored_line_100`, the anchored line as the speed table runs it
(`moordyn_side_by_side.scene`: lumped, nodal hydrodynamics, linear EA = 3e7 N) over
the first 3 s (up to its first slack event, where the speed table measures), at
MoorDyn's dtM for 1e-3 there (0.25 ms at N = 20, scaled by 20/N); and `jumper`, the
Low & Langley jumper (68 segments, EA = 5e8 N, its EI) driven as in case 1, the first
10 s at the file's dtM = 1 ms (the speed table's Low & Langley row).

    python benchmarks/float32.py                 # every scene (a few minutes)
    python benchmarks/float32.py --scene jumper --duration 5
    python benchmarks/float32.py --report

Results are appended to benchmarks/results/float32.json.
"""

import argparse
import json
import statistics
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
from _results import append_session

RESULTS = Path(__file__).resolve().parent / "results" / "float32.json"
SCENES = ("anchored_line_20", "anchored_line_100", "jumper")
STORAGE = ("absolute", "displacement")
LEVEL = 1e-3  # the speed table's matched RMS error, of the peak


def build(scene: str):
    """`(model, env, initial state, top segment, duration (s), dt (s))` for a scene."""
    import jaxcable as jc

    if scene.startswith("anchored_line"):
        from moordyn_side_by_side import scene as anchored_line_scene

        n = int(scene.split("_")[1])
        model, env = anchored_line_scene(slack_width=1e-6, segments=n)
        return model, env, jc.solve_statics(model, env).state, n - 1, 3.0, 2.5e-4 * 20 / n
    from work_precision import build as work_precision_scene

    model, env, top = work_precision_scene("jumper")
    return model, env, jc.solve_statics(model, env).state, top, 10.0, 1e-3


def midpoint_run(model, env, state, duration: float, dt: float, every: int, storage: str | None):
    """The explicit midpoint rule at fixed `dt` over `duration`, its free state rounded
    to float32 after each step as `storage` says (`None`: kept in float64). Returns the
    full node positions and velocities every `every` steps, shapes `(outputs, nodes, 3)`,
    and the output times. Written out, not diffrax's `Midpoint`, because the rounding
    falls between steps, where a diffrax solver keeps its state to itself."""
    from jaxcable import equations
    from jaxcable._equations.lagrangian import full_state

    free = model.free_nodes
    x0 = state.positions[free]

    def rounded(y):
        x, v = y
        if storage is None:
            return y
        v = v.astype(jnp.float32).astype(x.dtype)
        if storage == "absolute":
            return x.astype(jnp.float32).astype(x.dtype), v
        return x0 + (x - x0).astype(jnp.float32).astype(x.dtype), v

    def step(y, t):
        f = equations.vector_field(t, y, (model, env))
        half = jax.tree.map(lambda a, b: a + 0.5 * dt * b, y, f)
        g = equations.vector_field(t + 0.5 * dt, half, (model, env))
        return rounded(jax.tree.map(lambda a, b: a + dt * b, y, g))

    outputs = int(round(duration / dt)) // every

    @jax.jit
    def run(y):
        def chunk(y, k):
            t0 = k * every * dt
            y = jax.lax.fori_loop(0, every, lambda i, y: step(y, t0 + i * dt), y)
            return y, y

        _, ys = jax.lax.scan(chunk, y, jnp.arange(outputs))
        times = (jnp.arange(outputs) + 1) * every * dt
        positions, velocities = jax.vmap(lambda t, x, v: full_state(model, t, x, v))(times, *ys)
        return positions, velocities, times

    return run(rounded((state.positions[free], state.velocities[free])))


def top_tension(model, positions, velocities, top: int) -> np.ndarray:
    from jaxcable import equations

    tension = jax.jit(jax.vmap(lambda x, v: equations.tension(model, x, v)))(positions, velocities)
    return np.asarray(tension)[:, top]


def strain_tension(model, state, positions, top: int, dtype) -> np.ndarray:
    """The top segment's elastic tension EA ε (N) at each output, in `dtype` arithmetic
    from a displacement-stored state: its chord as the start chord plus the difference
    of the two nodes' displacements, each in `dtype`. `positions`: `(outputs, nodes, 3)`,
    float64."""
    i, j = (int(k) for k in np.asarray(model.segment_nodes)[top])
    x0 = np.asarray(state.positions)
    d = (np.asarray(positions) - x0).astype(dtype)
    chord = (x0[j] - x0[i]).astype(dtype) + (d[:, j] - d[:, i])
    rest = dtype(np.asarray(model.segment_length)[top])
    stiffness = dtype(np.asarray(model.line.tension_law.axial_stiffness).ravel()[0])
    return (stiffness * (np.linalg.norm(chord, axis=-1) / rest - dtype(1))).astype(np.float64)


def errors(tension: np.ndarray, reference: np.ndarray) -> dict:
    peak = float(np.max(reference))
    diff = tension - reference
    return {"rms_err": float(np.sqrt(np.mean(diff**2)) / peak), "max_err": float(np.max(np.abs(diff)) / peak)}


def study(scene: str, duration: float | None) -> dict:
    model, env, state, top, default_duration, dt = build(scene)
    duration = duration or default_duration
    every = max(1, int(round(0.05 / dt)))  # 20 Hz
    start = time.perf_counter()
    x, v, _ = midpoint_run(model, env, state, duration, dt, every, None)
    reference = top_tension(model, x, v, top)
    row = {
        "scene": scene,
        "duration_s": duration,
        "dt_s": dt,
        "steps": int(round(duration / dt)),
        "segments": model.n_segments,
        "axial_stiffness_N": float(np.max(np.asarray(model.line.tension_law.axial_stiffness))),
        "peak_N": float(np.max(reference)),
        "largest_coordinate_m": float(np.max(np.abs(np.asarray(x)))),
        "float64_wall_s": time.perf_counter() - start,
    }
    f32 = lambda a: a.astype(jnp.float32).astype(a.dtype)  # noqa: E731
    row["representation"] = errors(top_tension(model, f32(x), f32(v), top), reference)
    # The elastic tension's float32 rounding, added to the float64 run's tension.
    rounding = strain_tension(model, state, x, top, np.float32) - strain_tension(model, state, x, top, np.float64)
    row["float32 strain"] = errors(reference + rounding, reference)
    for storage in STORAGE:
        xs, vs, _ = midpoint_run(model, env, state, duration, dt, every, storage)
        row[storage] = errors(top_tension(model, xs, vs, top), reference)
    return row


def fma_rates(repeats: int, rounds: int = 5) -> dict:
    """GFLOP/s of a fused multiply–add chain through XLA on both cores, float32 and
    float64 (`profile_evaluation.fma_rate`, on a longer vector and chain), in `rounds` turns of
    the two: the median rate of each and every turn's ratio, since on this shared
    machine one turn's ratio moved between 1.2 and 2.3."""
    from profile_evaluation import fma_rate

    dtypes = (jnp.float32, jnp.float64)
    turns = [{jnp.dtype(d).name: fma_rate(repeats, d, size=1 << 18, chain=256) for d in dtypes} for _ in range(rounds)]
    median = {name: statistics.median(t[name] for t in turns) for name in turns[0]}
    return {**median, "ratios": [t["float32"] / t["float64"] for t in turns]}


def report(path: Path) -> None:
    sessions = json.loads(path.read_text())
    session = sessions[-1]
    rates = session["fma_gflops"]
    print(
        f"FMA chain through XLA, both cores: float32 {rates['float32']:.1f} GFLOP/s, "
        f"float64 {rates['float64']:.1f} GFLOP/s (medians of {len(rates['ratios'])} turns; float32 over "
        f"float64 {statistics.median(rates['ratios']):.2f}× at the median turn, "
        f"{min(rates['ratios']):.2f}–{max(rates['ratios']):.2f}× over them); "
        f"{session['time']}, {session['commit']}, load {session['load'][0]:.2f}\n"
    )
    print("| scene | EA (N) | steps (dt) | peak (kN) | largest |x| (m) | float32 state | RMS err / peak | largest |")
    print("|---|---|---|---|---|---|---|---|")
    for row in session["rows"]:
        head = (
            f"| {row['scene']} | {row['axial_stiffness_N']:.0e} | {row['steps']:,} ({1e3 * row['dt_s']:g} ms) "
            f"| {row['peak_N'] / 1e3:.1f} | {row['largest_coordinate_m']:.1f} "
        )
        for kind in ("representation", *STORAGE, "float32 strain"):
            e = row[kind]
            verdict = "over" if e["rms_err"] > LEVEL else "under"
            print(f"{head}| {kind} | {e['rms_err']:.1e} ({verdict} {LEVEL:g}) | {e['max_err']:.1e} |")
            head = "| | | | | "


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scene", nargs="+", default=list(SCENES), choices=SCENES)
    parser.add_argument("--duration", type=float, default=None, help="simulated time (s); per scene by default")
    parser.add_argument("--repeats", type=int, default=5, help="timed calls of the FMA chain")
    parser.add_argument("--out", type=Path, default=RESULTS)
    parser.add_argument("--report", action="store_true")
    args = parser.parse_args()
    if args.report:
        report(args.out)
        return
    jax.config.update("jax_enable_x64", True)  # the float64 run, and float32 only where asked
    import os

    load = list(os.getloadavg())
    rows = []
    for scene in args.scene:
        row = study(scene, args.duration)
        print(json.dumps(row), flush=True)
        rows.append(row)
    append_session(args.out, rows=rows, fma_gflops=fma_rates(args.repeats), load=load + list(os.getloadavg()))
    report(args.out)


if __name__ == "__main__":
    main()
