"""What `solve_statics` costs: on the files a user runs, and against the node count.

- `--scenes`: statics of the Low & Langley file (`tests/data/lowe_and_langley_2006/line.txt`,
  the MoorDyn input) and of every bundled scene (`jaxcable/examples/scenes/*.toml`), as
  `jaxcable run` solves it (`env.without_waves()`): the first call (tracing, compiling,
  solving) and the median of warm calls (s), each file in a fresh process with an empty
  persistent compilation cache, so that the first call compiles.
- `--sizes`: the anchored line (`anchored_line.toml`) cut into 100, 1,000 and 10,000
  segments, one fresh process each: the first call's wall time, a warm call's, the
  steps, and the process's peak resident memory above what it held after building the
  scene (MiB). `jaxcable.io._run.check_size` estimates statics from these figures.

    python benchmarks/statics_cost.py --scenes [--repeats 5]
    python benchmarks/statics_cost.py --sizes [--segments 100 1000 10000]

Run both with the code to compare on `PYTHONPATH`; results go to
`benchmarks/results/statics_cost.json`.
"""

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results" / "statics_cost.json"
LOWE_LANGLEY = ROOT / "tests" / "data" / "lowe_and_langley_2006" / "line.txt"
SCENES = sorted((ROOT / "jaxcable" / "examples" / "scenes").glob("*.toml"))


def _peak_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # Linux: KiB


def measure(path: str, segments: int | None, repeats: int) -> dict:
    """Statics of the scene at `path` (with `segments` a line, if given) in this process."""
    import jax

    jax.config.update("jax_enable_x64", True)
    import jaxcable as jc

    scene = jc.load_scene(path)
    if segments is not None:
        scene = scene.with_segments(segments)
    built = scene.build()
    model, env = built.model, built.environment.without_waves()
    before = _peak_mib()
    start = time.perf_counter()
    solution = jax.block_until_ready(jc.solve_statics(model, env))
    first = time.perf_counter() - start
    warm = []
    for _ in range(repeats):
        start = time.perf_counter()
        solution = jax.block_until_ready(jc.solve_statics(model, env))
        warm.append(time.perf_counter() - start)
    return {
        "file": Path(path).name,
        "free_nodes": int(model.free_nodes.size),
        "first_call_s": first,
        "warm_median_s": statistics.median(warm) if warm else None,
        "steps": int(solution.steps),
        "residual_N": float(solution.residual),
        "peak_above_built_MiB": _peak_mib() - before,
    }


def fresh(path: Path, segments: int | None, repeats: int) -> dict:
    """`measure` in a new process with an empty persistent compilation cache."""
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "JAX_COMPILATION_CACHE_DIR": cache, "OPENBLAS_NUM_THREADS": "1"}
        args = [sys.executable, __file__, "--one", str(path), "--repeats", str(repeats)]
        if segments is not None:
            args += ["--one-segments", str(segments)]
        out = subprocess.run(args, env=env, capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    parser.add_argument("--scenes", action="store_true")
    parser.add_argument("--sizes", action="store_true")
    parser.add_argument("--segments", type=int, nargs="+", default=[100, 1000, 10000])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--label", default="", help="a name for this session (the code measured)")
    parser.add_argument("--one", help=argparse.SUPPRESS)
    parser.add_argument("--one-segments", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        print(json.dumps(measure(args.one, args.one_segments, args.repeats)))
        return
    results = {}
    if args.scenes:
        results["scenes"] = []
        for path in [LOWE_LANGLEY, *SCENES]:
            results["scenes"].append(fresh(path, None, args.repeats))
            print(json.dumps(results["scenes"][-1]), flush=True)
    if args.sizes:
        results["sizes"] = []
        for n in args.segments:
            results["sizes"].append(fresh(SCENES[[p.name for p in SCENES].index("anchored_line.toml")], n, 1))
            print(json.dumps(results["sizes"][-1]), flush=True)
    sys.path.insert(0, str(Path(__file__).parent))
    from _results import append_session

    append_session(RESULTS, label=args.label, **results)


if __name__ == "__main__":
    main()
