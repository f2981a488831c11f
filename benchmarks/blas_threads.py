"""How OpenBLAS's threads slow JAX's dense factorisations when the cores are shared.

JAX's CPU LU, QR and Cholesky call LAPACK in NumPy's and SciPy's OpenBLAS, whose threads
spin while they wait for each other. This times a jitted `jnp.linalg.solve` (LU) of
n × n systems in fresh processes: with OpenBLAS's default threads and with
`OPENBLAS_NUM_THREADS=1`, each at normal priority and at nice 19. The contrast only
shows while something else holds the cores (CI, another benchmark); the load average is
recorded with each session.

    python benchmarks/blas_threads.py --sizes 150 600 --repeats 7
"""

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

from _results import append_session

RESULTS = Path(__file__).parent / "results" / "blas_threads.json"


def _time_solves(sizes: list[int], repeats: int) -> dict[str, float]:
    """Median warm time (s) of a jitted LU solve for each size, in this process."""
    import jax
    import jax.numpy as jnp
    import numpy as np
    from _timing import timed

    jax.config.update("jax_enable_x64", True)
    solve = jax.jit(jnp.linalg.solve)
    medians = {}
    for n in sizes:
        a = np.random.default_rng(0).normal(size=(n, n))
        _, _, run = timed(lambda: solve(a, np.ones(n)), repeats)
        medians[str(n)] = run
    return medians


def _child(sizes: list[int], repeats: int, threads: str | None, niceness: int) -> dict[str, float]:
    env = dict(os.environ)
    env.pop("OPENBLAS_NUM_THREADS", None)
    if threads is not None:
        env["OPENBLAS_NUM_THREADS"] = threads
    command = [sys.executable, __file__, "--child", "--repeats", str(repeats), "--sizes", *map(str, sizes)]
    output = subprocess.run(
        command, env=env, check=True, capture_output=True, text=True, preexec_fn=lambda: os.nice(niceness)
    ).stdout
    return json.loads(output.splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", type=int, nargs="+", default=[150, 600])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(_time_solves(args.sizes, args.repeats)))
        return
    load_before = os.getloadavg()[0]
    rows = []
    for niceness in (0, 19):
        for threads in (None, "1"):
            medians = _child(args.sizes, args.repeats, threads, niceness)
            rows.append({"nice": niceness, "openblas_threads": threads or "default", "median_s": medians})
            cells = "  ".join(f"n={n}: {1e3 * t:8.3f} ms" for n, t in medians.items())
            print(f"nice {niceness:2d}, OPENBLAS_NUM_THREADS={threads or 'default':7s} {cells}", flush=True)
    append_session(
        RESULTS,
        sizes=args.sizes,
        repeats=args.repeats,
        load_average_before=load_before,
        load_average_after=os.getloadavg()[0],
        rows=rows,
    )


if __name__ == "__main__":
    main()
