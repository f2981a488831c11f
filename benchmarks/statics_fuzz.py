"""Statics on random legal scenes: does `solve_statics` find the equilibrium wherever
one exists, and is what it returns an equilibrium?

`scene(seed)` draws one scene: a single line between an anchor and a fairlead (slack or
taut), a riser held up by a buoy, a line hanging from one point with a clump weight,
or a Y of three lines meeting at a free junction (with a buoy or a clump, or neither);
3–100 segments a line, EA 1e4–1e11 N, m 0.1–400 kg/m, a current of 0–2 m/s in any
horizontal direction, sometimes a seabed (the line's anchor on it), and Airy waves
ramped in from t = 0, which statics at t = 0 therefore does not see. Segment counts
come from a short list, and every scene has a seabed (out of reach where none was
drawn), waves and a `NonlinearElastic` law (C_E1 = 0 for Hooke's), so that scenes of
one topology share a compiled program.

`check(built, solution)` judges a solution independently of jaxcable's equations: the
force on every free node, summed with numpy from the positions (tension law, submerged
weight, drag of the uniform current on straight segments and on bodies, the seabed's
penalty spring), relative to the scene's force scale (the largest tension, wet weight
of a segment or body, or drag); and, for a line hanging between two fixed ends
in still water off the bed, the fairlead tension against Irvine's elastic catenary
(`tests/helpers.ElasticCatenary`), which the polyline approaches at O(1/N²).

    OPENBLAS_NUM_THREADS=1 python benchmarks/statics_fuzz.py --scenes 1000
    python benchmarks/statics_fuzz.py --report
    python benchmarks/statics_fuzz.py --failed --records failed.json   # the last session's failures only
    python benchmarks/statics_fuzz.py --seeds 9 220 510 --no-save
    JAX_COMPILATION_CACHE_DIR=$(mktemp -d) python benchmarks/statics_fuzz.py --timings

The tests import `scene` and `check` (`tests/test_statics_fuzz.py`).
"""

import argparse
import json
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # imported where used, after the caller has enabled float64
    import jaxcable as jc

RESULTS = Path(__file__).resolve().parent / "results" / "statics_fuzz.json"
TESTS = Path(__file__).resolve().parents[1] / "tests"

KINDS = ("catenary", "taut", "riser", "hanging", "y")
LINE_SEGMENTS = (3, 10, 40, 100)
Y_SEGMENTS = (3, 12, 30)
RHO, G = 1025.0, 9.81

# A residual force above this share of the scene's force scale is not equilibrium. The
# engine's own tolerance is 1e-6 of its scale; rounding adds EA ε per node.
CHECK_TOLERANCE = 1e-6

# The polyline's fairlead tension approaches the continuum catenary's at O(1/N²); the
# records' `catenary_bound` is 1/N², which most lines meet (0.2 % at N = 10 on
# `tests/test_statics.py`'s line). Tight buoyant arches, coarsely cut, have a larger
# constant: seed 600 (3 segments, arched up over 1.2 times its chord) 6.8/N², falling
# to 4.3/N² at 6 and 0.14/N² at 96 segments; seed 75 (40 segments over twice its
# chord) 2.7/N², its error falling 9 times from 20 to 40 segments. A wrong equation
# misses by far more (a 10 % error in the wet weight moves the tension about 10 %):
# the tests allow `CATENARY_CONSTANT / N²`.
CATENARY_CONSTANT = 10.0


@dataclass(frozen=True)
class FuzzScene:
    """A drawn scene: the model and water, what was drawn (`kind`, `features`), and the
    bodies as `{node: (mass, volume, drag_area)}` for the independent check."""

    seed: int
    kind: str
    model: "jc.CableNetwork"
    env: "jc.Environment"
    bodies: dict
    features: dict


def _log_uniform(rng, low, high):
    return float(np.exp(rng.uniform(np.log(low), np.log(high))))


def _line_type(rng, jc, kind):
    """Mass, diameter and law: EA 1e4–1e11 N, m 0.1–400 kg/m, the displaced mass 10–150 %
    of the line's (buoyant lines too), the anchored-line paper's quadratic term on a third of them."""
    mass = _log_uniform(rng, 0.1, 400.0)
    displaced = mass * rng.uniform(0.1, 1.5) if kind != "riser" else mass * rng.uniform(0.1, 0.9)
    diameter = float(np.sqrt(4 * displaced / (RHO * np.pi)))
    ea = _log_uniform(rng, 1e4, 1e11)
    # One class of law for all (C_E1 = 0 is Hooke's), so that scenes share programs.
    law = jc.NonlinearElastic(ea, rng.uniform(0.05, 0.2) * ea if rng.uniform() < 1 / 3 else 0.0)
    normal, tangential = rng.uniform(0.8, 2.0), rng.uniform(0.0, 0.5)
    line = jc.LineType(mass, diameter, law, normal_drag=normal, tangential_drag=tangential)
    return line, mass, diameter, ea


def _horizontal(rng):
    angle = rng.uniform(0, 2 * np.pi)
    return np.array([np.cos(angle), np.sin(angle), 0.0])


def scene(seed: int) -> FuzzScene:
    """Scene number `seed`, the same on every call."""
    import jaxcable as jc
    from jaxcable._sea.waves import breaking_height

    rng = np.random.default_rng(seed)
    kind = KINDS[seed % len(KINDS)]
    depth = _log_uniform(rng, 20.0, 1000.0)
    speed = 0.0 if rng.uniform() < 0.25 else rng.uniform(0.0, 2.0)
    current = speed * _horizontal(rng)
    seabed = rng.uniform() < 0.4 and kind != "riser"
    line, mass, diameter, ea = _line_type(rng, jc, kind)
    anchor = np.array([0.0, 0.0, -depth])
    bodies, constraints = {}, {}
    fixed = jc.Fixed()

    if kind in ("catenary", "taut"):
        segments = int(rng.choice(LINE_SEGMENTS))
        height = depth * rng.uniform(0.3, 1.0)
        span = depth * rng.uniform(0.1, 3.0)
        top = anchor + span * _horizontal(rng) + np.array([0.0, 0.0, height])
        chord = float(np.linalg.norm(top - anchor))
        # Slack: up to twice the chord; taut: pre-strained by up to T = 0.1 % of EA or
        # what a strain of 2 % gives, whichever is less tight for a soft line.
        length = chord * rng.uniform(1.001, 2.0) if kind == "catenary" else chord / (1 + _log_uniform(rng, 1e-5, 0.02))
        junctions = np.stack([anchor, top])
        branches = [jc.Branch(0, 1, line, length, segments)]
        constraints = {0: fixed, 1: fixed}
    elif kind == "riser":
        segments = int(rng.choice(LINE_SEGMENTS))
        length = depth * rng.uniform(0.2, 0.95)
        top = anchor + np.array([0.0, 0.0, length])
        wet_weight = (mass - RHO * np.pi * diameter**2 / 4) * G * length
        lift = max(wet_weight, 0.0) + _log_uniform(rng, 10.0, 1e5)
        volume = rng.uniform(0.5, 5.0)
        buoy_mass = RHO * volume - lift / G
        if buoy_mass <= 0:  # too much lift for that volume: a bigger buoy
            volume = 2 * lift / (RHO * G)
            buoy_mass = RHO * volume - lift / G
        bodies = {1: (buoy_mass, volume, rng.uniform(0.1, 3.0))}
        junctions = np.stack([anchor, top])
        branches = [jc.Branch(0, 1, line, length, segments)]
        constraints = {0: fixed}
    elif kind == "hanging":
        segments = int(rng.choice(LINE_SEGMENTS))
        top = np.array([0.0, 0.0, -rng.uniform(0.0, 0.2) * depth])
        length = (depth + top[2]) * rng.uniform(0.2, 1.3 if seabed else 0.95)
        bottom = top - np.array([0.0, 0.0, length])
        if rng.uniform() < 0.7:
            clump = _log_uniform(rng, 1.0, 1e4)
            bodies = {1: (clump, clump / rng.uniform(1500.0, 8000.0), rng.uniform(0.0, 2.0))}
        junctions = np.stack([top, bottom])
        branches = [jc.Branch(0, 1, line, length, segments)]
        constraints = {0: fixed}
    else:  # "y": three anchors around a free junction
        segments = int(rng.choice(Y_SEGMENTS))
        radius = depth * rng.uniform(0.3, 2.0)
        junction = np.array([0.0, 0.0, -depth * rng.uniform(0.2, 0.8)])
        supports = []
        for k in range(3):
            angle = 2 * np.pi * k / 3 + rng.uniform(-0.5, 0.5)
            z = -depth if k < 2 or rng.uniform() < 0.5 else -rng.uniform(0.0, 0.3) * depth
            supports.append([radius * np.cos(angle), radius * np.sin(angle), z])
        junctions = np.vstack([supports, junction])
        branches = []
        for k in range(3):
            chord = float(np.linalg.norm(junctions[k] - junction))
            branches.append(jc.Branch(k, 3, line, chord * rng.uniform(0.95, 1.6), segments))
        choice = rng.uniform()
        if choice < 0.35:
            volume = rng.uniform(0.1, 10.0)
            bodies = {3: (RHO * volume * rng.uniform(0.05, 0.9), volume, rng.uniform(0.1, 3.0))}
        elif choice < 0.7:
            clump = _log_uniform(rng, 1.0, 1e4)
            bodies = {3: (clump, clump / 7800.0, rng.uniform(0.0, 1.0))}
        constraints = {0: fixed, 1: fixed, 2: fixed}

    model = jc.CableNetwork.from_branches(
        junctions,
        branches,
        constraints=constraints,
        bodies={k: jc.Body(mass=m, volume=v, drag_area=a) for k, (m, v, a) in bodies.items()},
        mass_matrix="lumped",
    )
    # Every scene has a seabed and waves, so that all scenes of a topology share one
    # compiled program (compiling took most of the run): a scene drawn without a
    # seabed has it ten depths down, out of reach. The waves are ramped in from t = 0,
    # so statics sees none of them.
    bed = depth if seabed else 10 * depth
    height = min(0.1 * depth, rng.uniform(0.5, 8.0))
    stiffness = _log_uniform(rng, 1e4, 1e7)
    period = rng.uniform(5.0, 15.0)
    # A legal wave: below 90 % of its breaking height (Miche's, at this period).
    wavelength = 2 * np.pi / float(jc.airy_wavenumber(period, bed, G))
    height = min(height, 0.9 * float(breaking_height(wavelength, bed)))
    env = jc.Environment(
        water_density=RHO,
        gravity=G,
        current=current,
        depth=bed,
        seabed=jc.Seabed(stiffness=stiffness),
        waves=jc.Airy(height=height, period=period, depth=bed),
        wave_ramp=rng.uniform(5.0, 30.0),
    )
    features = {
        "segments": segments,
        "EA": ea,
        "mass_per_length": mass,
        "current": speed,
        "seabed": seabed,
        "bodies": len(bodies),
    }
    return FuzzScene(seed, kind, model, env, bodies, features)


def describe(fuzz: FuzzScene) -> str:
    """One line: the scene's seed, kind and what was drawn."""
    drawn = ", ".join(f"{k} {v:.3g}" if isinstance(v, float) else f"{k} {v}" for k, v in fuzz.features.items())
    return f"scene {fuzz.seed} ({fuzz.kind}): {drawn}"


def node_forces(fuzz: FuzzScene, positions: np.ndarray) -> tuple[np.ndarray, float]:
    """The force (N) on every node at rest at `positions` (m), shape `(nodes, 3)`, by
    `tests/helpers.hand_forces` (numpy, from the laws as the design notes state them,
    not from jaxcable's code), and the scene's force scale (N): the largest tension,
    wet weight of a segment or body, or drag on a node (the change in its force when
    the current is switched off)."""
    sys.path.insert(0, str(TESTS))
    from helpers import hand_forces  # pyright: ignore[reportMissingImports]

    model, env = fuzz.model, fuzz.env
    bodies = {k: {"mass": m, "volume": v, "drag_area": a} for k, (m, v, a) in fuzz.bodies.items()}
    tension, force = hand_forces(model, env, positions, bodies, np.asarray(env.current))
    _, still = hand_forces(model, env, positions, bodies)
    line = model.line
    wet = np.abs(np.asarray(line.mass_per_length) - RHO * np.asarray(line.area)) * G * np.asarray(model.segment_length)
    loads = [np.abs(tension), wet, np.linalg.norm(force - still, axis=1)]
    loads += [np.array([abs(m - RHO * v) * G]) for m, v, _ in fuzz.bodies.values()]
    return force, float(max(np.max(part) for part in loads))


def check(fuzz: FuzzScene, solution) -> dict:
    """The independent verdict on `solution` (a `StaticSolution`) for `fuzz`:
    `relative_residual` (the largest force on a free node over the scene's force scale),
    `equilibrium` (whether that is within `CHECK_TOLERANCE` plus rounding, `16 ε EA /
    scale`), and, where the elastic catenary applies, `catenary_error` (the relative
    fairlead tension error) and `catenary_bound` (`1/N²`, from the O(1/N²) convergence
    of the polyline: 0.2 % at N = 10 on `tests/test_statics.py`'s line)."""
    positions = np.asarray(solution.state.positions)
    force, scale = node_forces(fuzz, positions)
    free = np.asarray(fuzz.model.free_nodes)
    residual = float(np.max(np.abs(force[free]))) / scale if free.size else 0.0
    rounding = 16 * np.finfo(float).eps * float(np.max(np.asarray(fuzz.model.line.tension_law.axial_stiffness))) / scale
    out = {
        "relative_residual": residual,
        "equilibrium": bool(np.isfinite(residual) and residual <= CHECK_TOLERANCE + rounding),
    }
    if fuzz.kind == "catenary" and not fuzz.features["current"] and not _touches(fuzz, positions):
        out.update(_catenary(fuzz, solution))
    return out


def _touches(fuzz, positions):
    return fuzz.env.seabed is not None and bool(np.any(positions[:, 2] < -float(fuzz.env.depth)))


def _catenary(fuzz, solution) -> dict:
    """The fairlead tension against the continuum elastic catenary through the same
    ends (guessed from the solution's anchor reaction, solved by `fsolve`)."""
    sys.path.insert(0, str(TESTS))
    from helpers import ElasticCatenary  # pyright: ignore[reportMissingImports]

    model = fuzz.model
    positions = np.asarray(model.node_positions)
    chord = positions[1] - positions[0]
    span = float(np.hypot(chord[0], chord[1]))
    law = model.line.tension_law
    w = float((model.line.mass_per_length[0] - RHO * model.line.area[0]) * G)
    reaction = np.asarray(solution.reactions)[0]  # the anchor's force on the line
    heading = chord[:2] / span
    guess = [float(reaction[:2] @ heading), float(reaction[2])]
    length = float(np.sum(model.segment_length))
    try:
        exact = ElasticCatenary(
            length,
            w,
            float(law.axial_stiffness[0]),
            float(law.quadratic_stiffness()[0]),
            span,
            float(chord[2]),
            guess,
        )
    except AssertionError:  # fsolve missed; no verdict rather than a wrong one
        return {}
    top = float(exact.tension(length))
    error = abs(float(np.linalg.norm(np.asarray(solution.reactions)[1])) / top - 1)
    n = fuzz.features["segments"]
    return {"catenary_error": error, "catenary_bound": 1.0 / n**2}


def run(seeds, max_steps=None, progress=False, save=None) -> list[dict]:
    """Solve every scene in `seeds` with `solve_statics(..., throw=False)` and check it;
    one record a scene (its features, the verdicts, the engine's result and steps,
    the wall time of the call, compilations included). `save`: a path that the records
    so far are written to (JSON) after each scene, so that a long run interrupted keeps
    them."""
    import jax
    import optimistix as optx

    import jaxcable as jc
    from jaxcable._statics.solution import MAX_STEPS
    from jaxcable._statics.solve import failure_message

    jax.config.update("jax_enable_x64", True)
    records = []
    for seed in seeds:
        record = {"seed": seed}
        try:
            fuzz = scene(seed)
        except ValueError as error:  # not a legal scene after all: a generator bug
            records.append({**record, "error": f"scene: {error}"})
            continue
        record.update(kind=fuzz.kind, **fuzz.features)
        start = time.perf_counter()
        try:
            options = {} if max_steps is None else {"max_steps": max_steps}
            solution = jc.solve_statics(fuzz.model, fuzz.env, throw=False, **options)
            jax.block_until_ready(solution)
        except (ValueError, RuntimeError) as error:
            record.update(error=str(error), seconds=time.perf_counter() - start)
            records.append(record)
            continue
        record["seconds"] = time.perf_counter() - start
        record["converged"] = bool(solution.result == optx.RESULTS.successful)
        record["steps"] = int(solution.steps)
        record["engine_residual"] = float(solution.residual)
        record.update(check(fuzz, solution))
        record["largest_strain"] = float(np.max(np.asarray(solution.strain)))
        if not record["converged"]:
            record["message"] = failure_message(solution, max_steps=max_steps or MAX_STEPS)
        records.append(record)
        if save is not None:
            Path(save).write_text(json.dumps(records))
        if progress:
            verdict = "ok" if record["equilibrium"] else "NOT IN EQUILIBRIUM: " + record.get("message", "")
            print(f"{describe(fuzz)}: {verdict}, {record['steps']} steps, {record['seconds']:.2f} s", flush=True)
    return records


def summary(records: list[dict]) -> dict:
    """Counts by kind; the share in equilibrium by the independent check; steps."""
    solved = [r for r in records if "error" not in r]
    ok = [r for r in solved if r["equilibrium"]]
    by_kind = {}
    for kind in KINDS:
        mine = [r for r in records if r.get("kind") == kind]
        by_kind[kind] = {"scenes": len(mine), "equilibrium": sum(r.get("equilibrium", False) for r in mine)}
    catenary = [r for r in solved if "catenary_error" in r]
    return {
        "scenes": len(records),
        "equilibrium": len(ok),
        "share": len(ok) / max(len(records), 1),
        "engine_says_converged": sum(r["converged"] for r in solved),
        "engine_and_check_disagree": sum(r["converged"] != r["equilibrium"] for r in solved),
        "errors": sum("error" in r for r in records),
        "by_kind": by_kind,
        "steps_median": float(np.median([r["steps"] for r in solved])) if solved else None,
        "steps_max": int(max(r["steps"] for r in solved)) if solved else None,
        "catenary_checked": len(catenary),
        "catenary_within_bound": sum(r["catenary_error"] <= r["catenary_bound"] for r in catenary),
        "catenary_error_times_n2_max": max((r["catenary_error"] * r["segments"] ** 2 for r in catenary), default=None),
        "seconds_total": float(sum(r.get("seconds", 0.0) for r in records)),
    }


def timings(repeats: int = 5) -> dict:
    """`solve_statics` on the Low & Langley file and on the anchored line: the first call
    (tracing, compiling or loading from the persistent cache, solving) and the median of
    `repeats` warm calls (s), with the steps and the force left (N). Run it in a fresh
    process with an empty `JAX_COMPILATION_CACHE_DIR` to time compiling."""
    import statistics

    import jax

    import jaxcable as jc
    from jaxcable.examples import anchored_line

    jax.config.update("jax_enable_x64", True)
    built = jc.load_scene(TESTS / "data" / "lowe_and_langley_2006" / "line.txt").build()
    out = {}
    for name, (model, env) in {
        "lowe_langley": (built.model, built.environment.without_waves()),
        "anchored_line": anchored_line(),
    }.items():
        start = time.perf_counter()
        solution = jax.block_until_ready(jc.solve_statics(model, env))
        first = time.perf_counter() - start
        warm = []
        for _ in range(repeats):
            start = time.perf_counter()
            solution = jax.block_until_ready(jc.solve_statics(model, env))
            warm.append(time.perf_counter() - start)
        out[name] = {
            "first_call_s": first,
            "warm_median_s": statistics.median(warm),
            "steps": int(solution.steps),
            "residual_N": float(solution.residual),
        }
    return out


def main():
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    parser.add_argument("--scenes", type=int, default=1000)
    parser.add_argument("--first", type=int, default=0)
    parser.add_argument("--seeds", type=int, nargs="+", help="solve these scenes only (instead of --first/--scenes)")
    parser.add_argument(
        "--failed", action="store_true", help="solve only the scenes that the last saved session did not find"
    )
    parser.add_argument("--max-steps", type=int, default=None)
    parser.add_argument("--report", action="store_true")
    parser.add_argument(
        "--timings",
        action="store_true",
        help="time statics on the Low & Langley file and Bezverkhyy & Korniienko's anchored-line paper",
    )
    parser.add_argument("--no-save", action="store_true")
    parser.add_argument("--records", type=Path, help="write this run's records here instead of saving a session")
    parser.add_argument("--merge", type=Path, nargs="+", help="save one session from these records files")
    args = parser.parse_args()
    if args.report:
        print(json.dumps({k: v for k, v in json.loads(RESULTS.read_text())[-1].items() if k != "records"}, indent=1))
        return
    if args.timings:
        print(json.dumps(timings(), indent=1))
        return
    if args.merge:
        records = [r for path in args.merge for r in json.loads(path.read_text())]
    else:
        seeds = args.seeds or range(args.first, args.first + args.scenes)
        if args.failed:
            seeds = [r["seed"] for r in json.loads(RESULTS.read_text())[-1]["records"] if not r.get("equilibrium")]
        records = run(seeds, args.max_steps, progress=True, save=args.records)
    if args.records:
        return
    result = summary(records)
    print(json.dumps(result, indent=1))
    for r in records:
        if not r.get("equilibrium", False):
            print("FAILED", json.dumps(r))
    if not args.no_save:
        sys.path.insert(0, str(Path(__file__).parent))
        from _results import append_session

        append_session(RESULTS, **result, records=records)


if __name__ == "__main__":
    main()
