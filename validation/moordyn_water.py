"""jaxcable against MoorDyn on MoorDyn's own wave and current input files.

Two lines in 50 m of water, each from a fixed point at its foot (end A) to a top held
at z = −5 m (end B), in 20 segments, under a sheared current profile (`Currents = 1`,
`current_profile.txt`, 0 on the bed to 0.8 m/s at the surface, along +x) and waves
from each of MoorDyn's wave inputs that jaxcable reads:

- `WaveKin = 7`: three components in `wave_frequencies.txt` (ω = 0.6, 0.8 and
  1.0 rad/s), summed at the nodes;
- `WaveKin = 2`: the same file, on MoorDyn's FFT grid (`water_grid.txt`);
- `WaveKin = 3`: an elevation record (`wave_elevation.txt`, two sines) on the grid.

The lines:

- `taut`: 310 m of 80 kg/m chain (EA 5e8 N) from x = −300 m, nearly straight at
  151 kN: the waves move its tension by about 1 %, a weak check of the waves.
- `slack`: 106 m of a light 80 mm rope (7 kg/m, 1.85 kg/m wet, EA 1e7 N) from a
  point 5 m above the bed at x = −90 m, on a 98.5 m chord: a deep catenary (its
  lowest node 1.5 m above the bed, which it never touches: MoorDyn's bed contact,
  kBot and cBot on this light rope, is unstable at dtM = 2 ms) whose drag in the
  current and waves is comparable to its weight, so that the waves swing its top
  tension by about a fifth of its mean.

Each program starts from its own statics, and they differ: jaxcable's are in the
current, MoorDyn's initial conditions (`TmaxIC`) leave the current out (its fairlead
tension is the same to ten digits with `Currents = 1` and `0`). So the slack line
starts 0.9 m from jaxcable's, and MoorDyn's run begins with it settling in the current,
a transient that jaxcable's does not have. The statics are compared twice: at t = 0 as
each program starts (MoorDyn's still-water shape), and against MoorDyn's line after
`SETTLE` s in the current alone (`WaveKin = 0`), its own equilibrium in the current.
Both step at MoorDyn's dtM = 2 ms where they can: MoorDyn by its RK2, jaxcable by its
fixed-step midpoint rule, or by adaptive Dopri5 where 2 ms is beyond the midpoint
rule's stability limit (the slack line's light segments), as `jaxcable run` does.
Node i of the line is MoorDyn's `GetLineNodePos(line, i)` (from end A, the foot,
i = 0, to end B, the top, i = 20) and jaxcable's `run.built.line_nodes[0][i]` (the
model numbers the points first, then the line's inner nodes). Reported: the static
node positions' largest difference, at t = 0 and settled; the top
tension's RMS and largest difference over the run, relative to the top tension's
range in MoorDyn; and the nodes' largest and RMS position difference over the run
against how far they move.

    python -m validation.moordyn_water [--duration 20] [--cases taut slack] [--modes 7 2 3]

Results are appended to validation/results/moordyn_water.json.
"""

import argparse
import contextlib
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks._results import append_session

DT = 0.002
SEGMENTS = 20
MODES = (7, 2, 3)
SETTLE = 40.0  # s in the current alone: MoorDyn's line settles to within 10 µm a step
COMPONENTS = ((0.6, 1.0, 0.0), (0.8, 0.0, 0.6), (1.0, 0.3, 0.3))  # ω (rad/s), Re Z, Im Z (m)

INPUT = """--------------------- MoorDyn Input File ------------------------------------
A line under MoorDyn's wave and current input files
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
{line_type}
---------------------- POINT PROPERTIES --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (mˆ3)   (m^2)  (-)
1     Fixed     {anchor_x}    0.0     {anchor_z}    0      0       0      0
2     Fixed     0.0     0.0     -5.0     0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     line       1        2         {length}       {segments}      -
---------------------- OPTIONS -----------------------------------------
{dt}         dtM                  time step (s)
1025.0        WtrDnsty             water density (kg/m^3)
50            WtrDpth              water depth (m)
1.0           dtIC                 IC convergence interval (s)
120.0         TmaxIC               max time for IC generation (s)
1.0           CdScaleIC            drag scale during IC (-)
1.0e-4        threshIC             IC convergence threshold (-)
{mode}             WaveKin              wave input mode (-)
0.1           dtWave               wave time step (s)
1             Currents             steady current profile (-)
1             disableOutTime       no time on the console
------------------------- need this line --------------------------------------
"""
CASES = {
    "taut": {
        "line_type": "line       0.12    80         5.0e8      -1.0        0          1.2    1.0    0.2     0.0",
        "anchor_x": -300.0,
        "anchor_z": -50.0,
        "length": 310.0,
    },
    "slack": {
        "line_type": "line       0.08    7          1.0e7      -1.0        0          1.2    1.0    0.2     0.0",
        "anchor_x": -90.0,
        "anchor_z": -45.0,
        "length": 106.0,
    },
}


def write_inputs(folder: Path, case: str, mode: int) -> Path:
    """The input file of `case` for `WaveKin = mode` and its water files, in `folder`."""
    path = folder / "line.txt"
    path.write_text(INPUT.format(segments=SEGMENTS, dt=DT, mode=mode, **CASES[case]))
    z = np.linspace(-50.0, 0.0, 11)
    rows = "\n".join(f"{h:g} {0.8 * (h + 50) / 50:g} 0 0" for h in z)
    (folder / "current_profile.txt").write_text(f"---- MoorDyn steady currents ----\nprofile\nz ux uy uz\n{rows}\n")
    omega = [0.0] + [w for w, _, _ in COMPONENTS]
    spectrum = [(0.0, 0.0)] + [(r, i) for _, r, i in COMPONENTS]
    if mode == 2:  # an even grid of 0.2 rad/s, to 2 rad/s: the FFT grid samples 0.314 s
        even = np.arange(11) * 0.2
        spectrum = [dict(zip(omega, spectrum, strict=True)).get(round(w, 6), (0.0, 0.0)) for w in even]
        omega = list(even)
    (folder / "wave_frequencies.txt").write_text(
        "".join(f"{w:g} {r:g} {i:g}\n" for w, (r, i) in zip(omega, spectrum, strict=True))
    )
    t = np.arange(0.0, 200.0 + 1e-9, 0.05)
    eta = 0.8 * np.sin(2 * np.pi * t / 12.5) + 0.4 * np.cos(2 * np.pi * t / 8.0)
    (folder / "wave_elevation.txt").write_text("".join(f"{a:.6f} {b:.9f}\n" for a, b in zip(t, eta, strict=True)))
    grid = " ".join(f"{x:g}" for x in np.arange(-310.0, 11.0, 2.0))
    zs = " ".join(f"{x:g}" for x in np.arange(-51.0, 2.0, 1.0))
    (folder / "water_grid.txt").write_text(f"grid\nx y z\nblocks\n1\n{grid}\n1\n-1 0 1\n1\n{zs}\n")
    return path


@contextlib.contextmanager
def quiet():
    """Silence MoorDyn's console output (C level)."""
    null = os.open(os.devnull, os.O_WRONLY)
    saved = os.dup(1), os.dup(2)
    os.dup2(null, 1), os.dup2(null, 2)
    try:
        yield
    finally:
        os.dup2(saved[0], 1), os.dup2(saved[1], 2)
        os.close(null)


def run_moordyn(path: Path, duration: float) -> dict:
    """MoorDyn's top tension (N) and every line node's position (m), from end A, every
    0.1 s from t = 0 (the statics)."""
    import moordyn

    with quiet():
        system = moordyn.Create(str(path))
        moordyn.Init(system, [], [])
    line = moordyn.GetLine(system, 1)

    def nodes():
        return [moordyn.GetLineNodePos(line, i) for i in range(SEGMENTS + 1)]

    every, steps = round(0.1 / DT), round(duration / DT)
    tension, positions = [moordyn.GetLineFairTen(line)], [nodes()]
    start = time.perf_counter()
    for k in range(steps):
        moordyn.Step(system, [], [], k * DT, DT)
        if (k + 1) % every == 0:
            tension.append(moordyn.GetLineFairTen(line))
            positions.append(nodes())
    wall = time.perf_counter() - start
    with quiet():
        moordyn.Close(system)
    return {"tension": np.array(tension), "positions": np.array(positions), "wall_s": wall}


def settle_moordyn(folder: Path, case: str, duration: float = SETTLE) -> dict:
    """MoorDyn's line after `duration` (s) in the current alone (`WaveKin = 0`), from its
    initial conditions, which it solves without the current: its own static
    equilibrium in the current, top tension (N) and node positions (m)."""
    import moordyn

    with quiet():
        system = moordyn.Create(str(write_inputs(folder, case, 0)))
        moordyn.Init(system, [], [])
    line = moordyn.GetLine(system, 1)
    for k in range(round(duration / DT)):
        moordyn.Step(system, [], [], k * DT, DT)
    result = {
        "tension": moordyn.GetLineFairTen(line),
        "positions": np.array([moordyn.GetLineNodePos(line, i) for i in range(SEGMENTS + 1)]),
    }
    with quiet():
        moordyn.Close(system)
    return result


def run_jaxcable(path: Path, duration: float) -> dict:
    """jaxcable's, from the same file, at MoorDyn's dtM; the line's nodes in its own
    order, from end A."""
    from jaxcable.io._run import load_scene, run_scene

    scene = load_scene(path)
    start = time.perf_counter()
    run = run_scene(scene, duration=duration, dt_out=0.1)
    wall = time.perf_counter() - start
    top = run.channels(("FairTen1",))["FairTen1"]
    nodes = np.asarray(run.built.line_nodes[0])
    return {"tension": top, "positions": run.positions[:, nodes], "wall_s": wall, "stepping": run.stepping}


def compare(md: dict, jc: dict) -> dict:
    """The differences, relative where a scale is given."""
    n = min(len(md["tension"]), len(jc["tension"]))
    dt = jc["tension"][:n] - md["tension"][:n]
    dx = np.linalg.norm(jc["positions"][:n] - md["positions"][:n], axis=-1)  # (times, nodes)
    motion = np.linalg.norm(md["positions"][:n] - md["positions"][0], axis=-1)
    span = float(np.ptp(md["tension"][:n]))
    return {
        "static_top_tension_kN": float(md["tension"][0] / 1e3),
        "static_top_tension_difference_percent": float(100 * abs(dt[0]) / md["tension"][0]),
        "static_node_max_difference_m": float(dx[0].max()),
        "top_tension_min_kN": float(md["tension"][:n].min() / 1e3),
        "top_tension_max_kN": float(md["tension"][:n].max() / 1e3),
        "top_tension_range_of_mean_percent": float(100 * span / md["tension"][:n].mean()),
        "rms_difference_of_range_percent": float(100 * np.sqrt(np.mean(dt**2)) / span),
        "max_difference_of_range_percent": float(100 * np.max(np.abs(dt)) / span),
        "node_max_difference_m": float(dx.max()),
        "node_rms_difference_m": float(np.sqrt(np.mean(dx**2))),
        "node_max_motion_m": float(motion.max()),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--duration", type=float, default=20.0)
    parser.add_argument("--cases", nargs="+", choices=tuple(CASES), default=list(CASES))
    parser.add_argument("--modes", nargs="+", type=int, choices=MODES, default=list(MODES))
    args = parser.parse_args()
    import jax

    jax.config.update("jax_enable_x64", True)
    results = []
    for case in args.cases:
        for mode in args.modes:
            with tempfile.TemporaryDirectory() as folder:
                path = write_inputs(Path(folder), case, mode)
                md, jc = run_moordyn(path, args.duration), run_jaxcable(path, args.duration)
                settled = settle_moordyn(Path(folder), case)
            row = {
                "case": case,
                "wavekin": mode,
                "duration_s": args.duration,
                **compare(md, jc),
                "settled_top_tension_difference_percent": float(
                    100 * abs(jc["tension"][0] - settled["tension"]) / settled["tension"]
                ),
                "settled_node_max_difference_m": float(
                    np.linalg.norm(jc["positions"][0] - settled["positions"], axis=1).max()
                ),
                "moordyn_wall_s": md["wall_s"],
                "jaxcable_wall_s": jc["wall_s"],
                "jaxcable_stepping": jc["stepping"],
            }
            results.append(row)
            print(row, flush=True)
    append_session(Path(__file__).parent / "results" / "moordyn_water.json", cases=results)


if __name__ == "__main__":
    main()
