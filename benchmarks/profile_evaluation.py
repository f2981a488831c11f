"""Where an evaluation's time goes, single and batched, against this CPU's roofline.

On the anchored line (lumped mass, at its static equilibrium with small velocities), for
each segment count N, as `--scene` says: `quadrature` (`anchored_line`'s default,
drag by three Gauss points per segment) or `speed` (the speed table's,
`moordyn_side_by_side.scene`: MoorDyn's nodal hydrodynamics, linear EA), one
evaluation of each part of the equations, timed as 100 evaluations inside one compiled
`fori_loop` (so no dispatch is counted), alone and as a `vmap` over `--batch` cases:

- *geometry*: segment lengths, tangents and strains;
- *conservative*: `−∂Π/∂x` (elastic, weight, buoyancy), written out;
- *non-conservative*: drag at the quadrature points, bodies, seabed;
- *mass*: the lumped blocks' terms `a I + Σ b τ τᵀ`; *mass + solve*: and their solve
  at the free nodes (Woodbury's identity);
- *field*: the whole vector field, which is what an explicit solver evaluates.

Beside the times: XLA's own count of the field's floating-point operations and bytes per
node (`cost_analysis`), its kernels (fusions) per evaluation, and a measured roofline of
this machine: the rate of a long fused multiply–add chain (compute bound) and of a large
copy (memory bound), both through XLA.

    python benchmarks/profile_evaluation.py --segments 20 100
    python benchmarks/profile_evaluation.py --segments 20 100 --scene speed
    python benchmarks/profile_evaluation.py --report

Results are appended to benchmarks/results/profile_evaluation.json.
"""

import argparse
import json
import re
from pathlib import Path

import jax
import jax.numpy as jnp
from _results import append_session
from _timing import timed

import jaxcable as jc
from jaxcable._equations import lagrangian as lag
from jaxcable._model.indexing import take
from jaxcable.examples import anchored_line

RESULTS = Path(__file__).parent / "results" / "profile_evaluation.json"
EVALUATIONS = 100


def parts(model, env):
    """Each part as a function of component-major positions and velocities, (3, nodes)."""

    def free(x):
        # The free nodes by slices, as the solver's state holds them: `x[:, free_nodes]`
        # would time a gather and a transpose that no evaluation does.
        return take(x, model.free_nodes)

    def tangent(x):
        return lag._geometry(model, x)[1]

    return {
        "geometry": lambda x, v: lag._geometry(model, x),
        "conservative": lambda x, v: lag._conservative_forces(model, env, x),
        "non-conservative": lambda x, v: lag._nonconservative_forces(model, env, 0.3, x, v),
        # The terms without their plan (a static numpy index, not an output).
        "mass": lambda x, v: lag._lumped_terms(model, env, x, tangent(x))[:3],
        "mass + solve": lambda x, v: lag._lumped_solve(model, env, x, tangent(x), free(x)),
        "field": lambda x, v: lag._free_accelerations(model, env, 0.3, free(x), free(v), "all")[0],
    }


def looped(part):
    """`EVALUATIONS` evaluations of `part`, each depending on the last."""

    def run(x, v):
        def body(_, carry):
            x, v, total = carry
            out = jax.tree.leaves(part(x, v))
            # A negligible update keeps each evaluation dependent on the last.
            nudge = sum(jnp.sum(o) for o in out)
            return x + 1e-15 * nudge, v, total + nudge

        return jax.lax.fori_loop(0, EVALUATIONS, body, (x, v, 0.0))[2]

    return run


def kernels(compiled_text: str) -> int:
    return len(re.findall(r"^\s*\S+ = \S+ fusion\(", compiled_text, re.M))


def fma_rate(repeats: int, dtype=jnp.float64, size: int = 1 << 16, chain: int = 64) -> float:
    """GFLOP/s of a fused multiply–add chain through XLA on both cores, `chain` steps over
    a vector of `size` elements of `dtype`: long enough to be compute bound."""

    @jax.jit
    def fma(x):
        for _ in range(chain):
            x = x * 0.999999 + 1e-7
        return x

    x = jnp.ones(size, dtype)
    _, _, seconds = timed(lambda: fma(x), repeats)
    return 2 * chain * size / seconds / 1e9


def roofline(repeats: int) -> dict:
    """Measured rates of this machine through XLA, both cores: an FMA chain long enough
    to be compute bound, and a copy of 256 MB."""
    big = jnp.ones(1 << 25)
    copy = jax.jit(lambda y: y + 1.0)
    _, _, seconds = timed(lambda: copy(big), repeats)
    bandwidth = 2 * big.nbytes / seconds / 1e9
    return {"fma_gflops": fma_rate(repeats), "copy_gb_per_s": bandwidth}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--segments", type=int, nargs="+", default=[20, 100])
    parser.add_argument("--scene", choices=["quadrature", "speed"], default="quadrature")
    parser.add_argument("--batch", type=int, default=256)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--out", default=str(RESULTS))
    parser.add_argument("--report", action="store_true")
    args = parser.parse_args()
    if args.report:
        report(Path(args.out))
        return
    jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us
    rows = []
    for n in args.segments:
        if args.scene == "speed":
            from moordyn_side_by_side import scene

            model, env = scene(slack_width=1e-6, segments=n)
        else:
            model, env = anchored_line(n, mass_matrix="lumped")
        state = jc.solve_statics(model, env).state
        x = lag._cm(state.positions)
        v = lag._cm(state.velocities) + 0.01
        xb, vb = (jnp.broadcast_to(a, (args.batch, *a.shape)) + 0.0 for a in (x, v))
        for name, part in parts(model, env).items():
            single = jax.jit(looped(part))
            batched = jax.jit(jax.vmap(looped(part)))
            _, _, t_single = timed(lambda: single(x, v), args.repeats)
            _, _, t_batched = timed(lambda: batched(xb, vb), args.repeats)
            row = {
                "segments": n,
                "part": name,
                "single_us": 1e6 * t_single / EVALUATIONS,
                "batched_ns_per_node": 1e9 * t_batched / EVALUATIONS / args.batch / model.n_nodes,
                "single_ns_per_node": 1e9 * t_single / EVALUATIONS / model.n_nodes,
            }
            if name == "field":
                one = jax.jit(part).lower(x, v).compile()
                cost = one.cost_analysis()
                cost = cost[0] if isinstance(cost, list) else cost
                row["flops_per_node"] = cost["flops"] / model.n_nodes
                row["bytes_per_node"] = cost["bytes accessed"] / model.n_nodes
                row["kernels"] = kernels(one.as_text())
            print(json.dumps(row), flush=True)
            rows.append(row)
        jax.clear_caches()
    machine = roofline(args.repeats)
    print(json.dumps(machine))
    append_session(
        args.out,
        scene=args.scene,
        batch=args.batch,
        repeats=args.repeats,
        roofline=machine,
        rows=rows,
    )
    report(Path(args.out))


def report(path: Path):
    session = json.loads(path.read_text())[-1]
    machine = session["roofline"]
    print(
        f"roofline: {machine['fma_gflops']:.1f} GFLOP/s (FMA chain), {machine['copy_gb_per_s']:.1f} GB/s (copy); "
        f"XLA_FLAGS={session.get('xla_flags') or '(none)'}; PJRT_NPROC={session.get('pjrt_nproc') or '(unset)'}; "
        f"scene {session.get('scene', 'quadrature')}; session {session['time'][:16]}"
    )
    print("| N | part | single (µs) | single (ns/node) | batched (ns/node) |")
    print("|---|---|---|---|---|")
    for r in session["rows"]:
        print(
            f"| {r['segments']} | {r['part']} | {r['single_us']:.2f} | {r['single_ns_per_node']:.0f} | "
            f"{r['batched_ns_per_node']:.1f} |"
        )
    for r in session["rows"]:
        if "flops_per_node" in r:
            print(
                f"N = {r['segments']}: {r['flops_per_node']:.0f} flop and {r['bytes_per_node']:.0f} bytes per node "
                f"(XLA's count), {r['kernels']} kernels per evaluation"
            )


if __name__ == "__main__":
    main()
