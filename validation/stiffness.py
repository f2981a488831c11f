"""The mooring's stiffness (`jaxcable.stiffness`, `jaxcable.body_stiffness`) against
Irvine's elastic catenary and MoorPy, on the same lines.

- **Convergence**: a suspended line (anchor 300 m along and 100 m below its fairlead,
  350 m of 80 kg/m, d = 0.1 m, EA = 5e8 N) cut into N = 4 ... 128 segments: the
  fairlead's 3 × 3 against the closed form of the continuous line
  (`tests/helpers.Irvine.support_stiffness`), the error relative to the largest entry
  and its order between successive N; the first call of `jc.stiffness` (tracing and
  compiling) and the median of warm calls, beside a warm `jc.solve_statics`.
- **MoorPy** (`--moorpy PYTHON`, an interpreter that has MoorPy): the same line; a line
  lying on the seabed between its anchor and its touchdown (MoorPy's rigid bed against
  jaxcable's penalty bed at MoorDyn's stiffness and 100 times it); and the 6 × 6 of a
  body on a three-line spread (MoorPy's `Body.getStiffnessA`, lines only). MoorPy's
  analytic stiffness (`getCoupledStiffnessA`) and its own central differences
  (`getCoupledStiffness`, default step 0.1 m) side by side with jaxcable's at N = 16 and
  64. MoorPy runs in its interpreter, this script's `--moorpy-side`.
- **Touchdown** (`--touchdown`): the line on the seabed in detail, N = 16 ... 128 (see
  `touchdown`), where the polyline's stiffness converges slowly.

MoorPy is no dependency of jaxcable, not even for its tests: install it apart,

    python -m venv /tmp/moorpy && /tmp/moorpy/bin/pip install moorpy
    OPENBLAS_NUM_THREADS=1 python -m validation.stiffness --moorpy /tmp/moorpy/bin/python
    OPENBLAS_NUM_THREADS=1 python -m validation.stiffness --no-convergence --touchdown

Results go to `validation/results/stiffness.json`.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import timeit
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = Path(__file__).resolve().parent / "results" / "stiffness.json"

LINE = {"mass_per_length": 80.0, "diameter": 0.1, "axial_stiffness": 5e8}
WATER = {"density": 1025.0, "gravity": 9.81}
# Each case: its lines `(attachment point, anchor, unstretched length)` (m), the water
# depth MoorPy needs (m), whether jaxcable's network has a seabed, and for a body its
# reference point. The fairleads sit 5 m down: MoorPy treats a line end above z = 0
# as out of the water, which its differences would cross.
CASES = {
    "suspended": {
        "lines": [([300.0, 0.0, -5.0], [0.0, 0.0, -105.0], 350.0)],
        "depth": 400.0,
        "seabed": False,
    },
    "touchdown": {
        "lines": [([400.0, 0.0, -5.0], [0.0, 0.0, -150.0], 500.0)],
        "depth": 150.0,
        "seabed": True,
    },
    "spread": {
        "lines": [
            (
                [20.0 * c, 20.0 * s, -5.0],
                [320.0 * c, 320.0 * s, -105.0],
                350.0,
            )
            for c, s in [(1.0, 0.0), (-0.5, 0.75**0.5), (-0.5, -(0.75**0.5))]
        ],
        "depth": 400.0,
        "seabed": False,
        "reference": [5.0, -3.0, 10.0],  # off the spread's axis: the lines' moment is not zero
    },
}
SEGMENTS = [4, 8, 16, 32, 64, 128]
SIDE_BY_SIDE = [16, 64]
BED_STIFFNESS = [3e6, 3e8]  # Pa/m: MoorDyn's default, and 100 times it


# --------------------------------------------------------------------------------------
# jaxcable's side


def network(case: dict, segments: int, bed_stiffness: float = BED_STIFFNESS[0]):
    """The case's model and water: attachment points first (nodes 0, 1, ...), then the
    anchors."""
    import numpy as np

    import jaxcable as jc

    lines = case["lines"]
    points = [p for p, _, _ in lines]
    line = jc.LineType(
        mass_per_length=LINE["mass_per_length"],
        diameter=LINE["diameter"],
        tension_law=jc.LinearElastic(LINE["axial_stiffness"]),
    )
    model = jc.CableNetwork.from_branches(
        junctions=np.array(points + [a for _, a, _ in lines]),
        branches=[jc.Branch(len(points) + i, i, line, length, segments) for i, (_, _, length) in enumerate(lines)],
        constraints={k: jc.Fixed() for k in range(2 * len(lines))},
    )
    seabed = jc.Seabed(stiffness=bed_stiffness) if case["seabed"] else None
    env = jc.Environment(
        water_density=WATER["density"],
        gravity=WATER["gravity"],
        depth=case["depth"] if case["seabed"] else None,
        seabed=seabed,
    )
    return model, env


def convergence(repeats: int) -> list[dict]:
    import numpy as np

    import jaxcable as jc

    sys.path.insert(0, str(ROOT / "tests"))
    from helpers import Irvine  # pyright: ignore[reportMissingImports]

    from benchmarks._timing import timed  # pyright: ignore[reportMissingImports]

    case = CASES["suspended"]
    ((fairlead, anchor, length),) = case["lines"]
    w = (LINE["mass_per_length"] - WATER["density"] * np.pi * LINE["diameter"] ** 2 / 4) * WATER["gravity"]
    span, rise = fairlead[0] - anchor[0], fairlead[2] - anchor[2]
    expected = Irvine(span, rise, length, w, LINE["axial_stiffness"]).support_stiffness()
    rows, previous = [], None
    for n in SEGMENTS:
        model, env = network(case, n)
        k, compile_time, warm = timed(lambda: jc.stiffness(model, env, 0), repeats)  # noqa: B023
        _, statics_compile, statics_warm = timed(lambda: jc.solve_statics(model, env), repeats)  # noqa: B023
        error = float(np.abs(np.asarray(k) - expected).max() / np.abs(expected).max())
        rows.append(
            {
                "segments": n,
                "K_N_per_m": np.asarray(k).tolist(),
                "relative_error": error,
                "order": None if previous is None else float(np.log2(previous / error)),
                "stiffness_compile_s": compile_time,
                "stiffness_warm_s": warm,
                "statics_compile_s": statics_compile,
                "statics_warm_s": statics_warm,
            }
        )
        previous = error
        print(json.dumps(rows[-1]), flush=True)
    return [{"irvine_K_N_per_m": expected.tolist()}, *rows]


def jaxcable_side(repeats: int) -> dict:
    """jaxcable's stiffness of each case at each of `SIDE_BY_SIDE`'s segment counts."""
    import numpy as np

    import jaxcable as jc
    from benchmarks._timing import timed  # pyright: ignore[reportMissingImports]

    out = {}
    for name, case in CASES.items():
        for n in SIDE_BY_SIDE:
            for bed in BED_STIFFNESS if case["seabed"] else [None]:
                model, env = network(case, n, *([bed] if bed else []))
                points = list(range(len(case["lines"])))
                if "reference" in case:
                    k, compile_time, warm = timed(
                        lambda: jc.body_stiffness(model, env, points, case["reference"]),  # noqa: B023
                        repeats,
                    )
                else:
                    k, compile_time, warm = timed(lambda: jc.stiffness(model, env, 0), repeats)  # noqa: B023
                key = f"{name} N={n}" + (f" bed={bed:g}" if bed else "")
                out[key] = {"K": np.asarray(k).tolist(), "compile_s": compile_time, "warm_s": warm}
                print(key, json.dumps(out[key]), flush=True)
    return out


def touchdown(repeats: int) -> dict:
    """The line on the seabed, where the polyline's stiffness converges slowly: at each
    N the fairlead's reaction, `jc.stiffness` (or why it failed), and the stiffness by
    the implicit-function formula at the equilibrium, `K = −(J_cc − J_cf J_ff⁻¹ J_fc)`
    with J the dense Jacobian of the generalised forces; at N = 64 also central
    differences of re-solved statics (0.1 m), and the suspended chain alone, pinned at
    its last node on the bed, without a bed."""
    import equinox as eqx
    import jax
    import jax.numpy as jnp
    import numpy as np

    import jaxcable as jc
    from jaxcable._equations import lagrangian as lag

    case = CASES["touchdown"]
    bed = -case["depth"]
    out = {}
    for n in (16, 32, 64, 128):
        model, env = network(case, n)
        solution = jc.solve_statics(model, env)
        x = solution.state.positions
        row: dict = {"reaction_N": np.asarray(solution.reactions)[0].tolist()}
        try:
            row["stiffness"] = np.asarray(jc.stiffness(model, env, 0)).tolist()
        except Exception as error:  # a failure is a result here
            lines = str(error).splitlines()
            row["stiffness_error"] = next((line for line in lines if "linear solver" in line), lines[-1])
        jacobian = np.asarray(
            jax.jacfwd(lambda y: lag.generalised_forces(model, env, 0.0, y, jnp.zeros_like(y)))(x)  # noqa: B023
        )
        free, held = model.free_nodes, model.constrained_nodes
        block = lambda a, b: jacobian[a][:, :, b].reshape(3 * a.size, 3 * b.size)  # noqa: E731
        reduced = -(block(held, held) - block(held, free) @ np.linalg.solve(block(free, free), block(free, held)))
        row["implicit_function"] = reduced.reshape(held.size, 3, held.size, 3)[0, :, 0, :].tolist()
        row["jacobian_condition"] = float(np.linalg.cond(block(free, free)))
        row["touching_nodes"] = int(np.sum(np.asarray(x)[:, 2] < bed))
        if n == 64:
            columns = []
            for axis in range(3):
                shift = np.zeros(3)
                shift[axis] = 0.1
                ends = [
                    jc.solve_statics(
                        eqx.tree_at(lambda m: m.node_positions, model, model.node_positions.at[0].add(s)),  # noqa: B023
                        env,
                        initial=solution.state,
                    ).reactions[0]
                    for s in (shift, -shift)
                ]
                columns.append(np.asarray(ends[0] - ends[1]) / 0.2)
            row["central_differences_0.1m"] = np.stack(columns, axis=1).tolist()
            # Line 1's nodes from the anchor (node 1) to the fairlead (node 0).
            path = np.concatenate([[1], np.arange(2, n + 1), [0]])
            last = max(i for i, node in enumerate(path) if np.asarray(x)[node, 2] < bed or node == 1)
            points = np.asarray(x)[path[last:]]
            count = len(points)
            chain = jc.CableNetwork(
                points,
                np.stack([np.arange(count - 1), np.arange(1, count)], axis=1),
                np.full(count - 1, float(model.segment_length[0])),
                jc.LineType(
                    mass_per_length=LINE["mass_per_length"],
                    diameter=LINE["diameter"],
                    tension_law=jc.LinearElastic(LINE["axial_stiffness"]),
                ),
                {0: jc.Fixed(), count - 1: jc.Fixed()},
            )
            free_water = jc.Environment(water_density=WATER["density"], gravity=WATER["gravity"])
            row["pinned_chain_segments"] = count - 1
            row["pinned_chain_stiffness"] = np.asarray(jc.stiffness(chain, free_water, count - 1)).tolist()
        out[f"N={n}"] = row
        print(n, json.dumps(row), flush=True)
    return out


# --------------------------------------------------------------------------------------
# MoorPy's side, run in MoorPy's interpreter: imports nothing of jaxcable's.


def moorpy_side(repeats: int) -> dict:
    import moorpy as mp
    import numpy as np

    out = {"moorpy": mp.__version__ if hasattr(mp, "__version__") else _version("moorpy")}
    d = LINE["diameter"]
    line_type = {
        "name": "line",
        "m": LINE["mass_per_length"],
        "d_vol": d,
        "EA": LINE["axial_stiffness"],
        "w": (LINE["mass_per_length"] - WATER["density"] * np.pi * d**2 / 4) * WATER["gravity"],
        "MBL": 1e12,
        "Cd": 1.2,
        "CdAx": 0.008,
        "Ca": 1.0,
        "CaAx": 0.0,
        "cost": 0.0,
        "EAd": 0.0,
        "EAd_Lm": 0.0,
    }
    for name, case in CASES.items():
        system = mp.System(depth=case["depth"], rho=WATER["density"], g=WATER["gravity"])
        system.lineTypes["line"] = line_type
        body = "reference" in case
        if body:
            system.addBody(-1, [*case["reference"], 0.0, 0.0, 0.0])
        for fairlead, anchor, length in case["lines"]:
            system.addPoint(1, anchor)
            a = len(system.pointList)
            if body:
                relative = list(np.subtract(fairlead, case["reference"]))
                system.addPoint(1, relative, body=1)
            else:
                system.addPoint(-1, fairlead)
            system.addLine(length, "line", pointA=a, pointB=a + 1)
        system.initialize()
        system.solveEquilibrium()
        if body:
            analytic = lambda: system.bodyList[0].getStiffnessA(lines_only=True)  # noqa: E731
        else:
            analytic = lambda: system.getCoupledStiffnessA(lines_only=True)  # noqa: E731
        differences = lambda: system.getCoupledStiffness(lines_only=True)  # noqa: E731
        out[name] = {
            "analytic": np.asarray(analytic()).tolist(),
            "analytic_s": statistics.median(timeit.repeat(analytic, number=1, repeat=repeats)),
            "differences": np.asarray(differences()).tolist(),
            "differences_s": statistics.median(timeit.repeat(differences, number=1, repeat=repeats)),
        }
    return out


def _version(package: str) -> str:
    from importlib.metadata import version

    return version(package)


def compare(ours: dict, theirs: dict) -> dict:
    """Each jaxcable figure's largest difference from MoorPy's analytic one, relative to
    the largest entry of MoorPy's (per column, for a body's 6 × 6: its columns have
    units of their own)."""
    import numpy as np

    out = {}
    for key, value in ours.items():
        name = key.split()[0]
        reference = np.asarray(theirs[name]["analytic"])
        scale = np.abs(reference).max(axis=0) if name == "spread" else np.abs(reference).max()
        ratio = (np.asarray(value["K"]) - reference) / scale
        out[key] = {
            "jaxcable_vs_moorpy_analytic": float(np.abs(ratio).max()),
            "moorpy_differences_vs_analytic": float(
                np.abs((np.asarray(theirs[name]["differences"]) - reference) / scale).max()
            ),
        }
    return out


def main():
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    parser.add_argument("--moorpy", help="a Python interpreter that has MoorPy, for the side-by-side")
    parser.add_argument("--no-convergence", action="store_true")
    parser.add_argument("--touchdown", action="store_true", help="the line on the seabed, N = 16 to 128, in detail")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--label", default="", help="a name for this session (the code measured)")
    parser.add_argument("--moorpy-side", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.moorpy_side:
        print(json.dumps(moorpy_side(args.repeats)))
        return

    import jax

    jax.config.update("jax_enable_x64", True)
    results: dict = {"load_average_before": os.getloadavg()[0]}
    if not args.no_convergence:
        results["convergence"] = convergence(args.repeats)
    if args.touchdown:
        results["touchdown"] = touchdown(args.repeats)
    if args.moorpy:
        theirs = subprocess.run(
            [args.moorpy, __file__, "--moorpy-side", "--repeats", str(args.repeats)],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
        results["moorpy"] = json.loads(theirs.strip().splitlines()[-1])
        results["jaxcable"] = jaxcable_side(args.repeats)
        results["differences"] = compare(results["jaxcable"], results["moorpy"])
        print(json.dumps(results["differences"], indent=1))
    results["load_average_after"] = os.getloadavg()[0]
    from benchmarks._results import append_session

    append_session(RESULTS, label=args.label, **results)


if __name__ == "__main__":
    main()
