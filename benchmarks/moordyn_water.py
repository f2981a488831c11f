"""jaxcable against MoorDyn on MoorDyn's own wave and current input files.

One chain catenary in 50 m of water (anchor at x = −300 m on the bed, the top held at
z = −5 m, 310 m of chain in 20 segments) under a sheared current profile
(`Currents = 1`, `current_profile.txt`, 0 on the bed to 0.8 m/s at the surface, along
+x) and waves from each of MoorDyn's wave inputs that jaxcable reads:

- `WaveKin = 7`: three components in `wave_frequencies.txt`, summed at the nodes;
- `WaveKin = 2`: the same file, on MoorDyn's FFT grid (`water_grid.txt`);
- `WaveKin = 3`: an elevation record (`wave_elevation.txt`, two sines) on the grid.

Both start from the statics in the current (MoorDyn's `TmaxIC`, jaxcable's statics), and
step at MoorDyn's dtM = 2 ms: MoorDyn by its RK2, jaxcable by its fixed-step midpoint
rule. Reported: the top tension's RMS and largest difference over the run, relative
to the top tension's range in MoorDyn, and the mid node's position difference.

    python benchmarks/moordyn_water.py [--duration 30]

Results are appended to benchmarks/results/moordyn_water.json.
"""

import argparse
import contextlib
import os
import tempfile
import time
from pathlib import Path

import numpy as np
from _results import append_session

DT = 0.002
SEGMENTS = 20
MODES = (7, 2, 3)
COMPONENTS = ((0.6, 1.0, 0.0), (0.8, 0.0, 0.6), (1.0, 0.3, 0.3))  # ω (rad/s), Re Z, Im Z (m)

INPUT = """--------------------- MoorDyn Input File ------------------------------------
A chain catenary under MoorDyn's wave and current input files
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
chain      0.12    80         5.0e8      -1.0        0          1.2    1.0    0.2     0.0
---------------------- POINT PROPERTIES --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (mˆ3)   (m^2)  (-)
1     Fixed     -300    0.0     -50.0    0      0       0      0
2     Fixed     0.0     0.0     -5.0     0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     chain      1        2         310       {segments}      -
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


def write_inputs(folder: Path, mode: int) -> Path:
    """The input file for `WaveKin = mode` and its water files, in `folder`."""
    path = folder / "chain.txt"
    path.write_text(INPUT.format(segments=SEGMENTS, dt=DT, mode=mode))
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
    """MoorDyn's top tension and mid-node position every 0.1 s from t = 0."""
    import moordyn

    with quiet():
        system = moordyn.Create(str(path))
        moordyn.Init(system, [], [])
    line = moordyn.GetLine(system, 1)
    every, steps = round(0.1 / DT), round(duration / DT)
    tension, mid = [moordyn.GetLineFairTen(line)], [moordyn.GetLineNodePos(line, SEGMENTS // 2)]
    start = time.perf_counter()
    for k in range(steps):
        moordyn.Step(system, [], [], k * DT, DT)
        if (k + 1) % every == 0:
            tension.append(moordyn.GetLineFairTen(line))
            mid.append(moordyn.GetLineNodePos(line, SEGMENTS // 2))
    wall = time.perf_counter() - start
    with quiet():
        moordyn.Close(system)
    return {"tension": np.array(tension), "mid": np.array(mid), "wall_s": wall}


def run_jaxcable(path: Path, duration: float) -> dict:
    """jaxcable's, from the same file, at MoorDyn's dtM."""
    from jaxcable.io._run import load_scene, run_scene

    scene = load_scene(path)
    start = time.perf_counter()
    run = run_scene(scene, duration=duration, dt_out=0.1)
    wall = time.perf_counter() - start
    top = run.channels(("FairTen1",))["FairTen1"]
    return {"tension": top, "mid": run.positions[:, SEGMENTS // 2], "wall_s": wall, "stepping": run.stepping}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--duration", type=float, default=30.0)
    args = parser.parse_args()
    import jax

    jax.config.update("jax_enable_x64", True)
    results = []
    for mode in MODES:
        with tempfile.TemporaryDirectory() as folder:
            path = write_inputs(Path(folder), mode)
            md, jc = run_moordyn(path, args.duration), run_jaxcable(path, args.duration)
        n = min(len(md["tension"]), len(jc["tension"]))
        dt, dm = jc["tension"][:n] - md["tension"][:n], jc["mid"][:n] - md["mid"][:n]
        span = float(np.ptp(md["tension"][:n]))
        row = {
            "wavekin": mode,
            "duration_s": args.duration,
            "top_tension_mean_kN": float(md["tension"][:n].mean() / 1e3),
            "top_tension_range_kN": span / 1e3,
            "start_difference_percent": float(100 * abs(dt[0]) / md["tension"][0]),
            "rms_difference_of_range_percent": float(100 * np.sqrt(np.mean(dt**2)) / span),
            "max_difference_of_range_percent": float(100 * np.max(np.abs(dt)) / span),
            "mid_node_max_difference_m": float(np.max(np.linalg.norm(dm, axis=1))),
            "mid_node_motion_m": float(np.max(np.linalg.norm(md["mid"][:n] - md["mid"][0], axis=1))),
            "moordyn_wall_s": md["wall_s"],
            "jaxcable_wall_s": jc["wall_s"],
            "jaxcable_stepping": jc["stepping"],
        }
        results.append(row)
        print(row, flush=True)
    append_session(Path(__file__).parent / "results" / "moordyn_water.json", cases=results)


if __name__ == "__main__":
    main()
