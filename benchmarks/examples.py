"""The bundled examples as a user meets them: every scene by `jaxcable run NAME` and the
sample records by `jaxcable calibrate`, each in its own process, timed from start to
exit.

Each command runs twice on one fresh compilation cache (`JAXCABLE_CACHE_DIR`, a new
empty folder): *cold*, a first run that compiles everything, and *warm*, the same
command again, which loads its programs from the cache (tracing and the run itself
remain). Recorded per command and run: wall time (s), exit status, the lines the
command wrote to stderr that start with `warning:` or `note:`, its last line of
output (the run's summary), and the load average before and after (the machine may be
shared). For calibrate, the fitted values against the truth the records were made with
(`jaxcable.examples.make_records.TRUTH`).

    python benchmarks/examples.py                  # every scene and calibrate
    python benchmarks/examples.py --only buoy_net calibrate
    python benchmarks/examples.py --report         # the latest session as a table

Sessions are appended to `benchmarks/results/examples.json`.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _results import append_session

ROOT = Path(__file__).resolve().parents[1]
OUT = Path(__file__).parent / "results" / "examples.json"
FIT = ["--fit", "normal_drag=1.2", "tangential_drag=0.01"]


def commands() -> dict[str, list[str]]:
    """The command line of each example, by name: `run NAME` for each scene, then the
    calibrate example that `jaxcable examples` prints."""
    from jaxcable.examples import record_names, scene_names

    runs = {name: ["run", name, "--no-progress"] for name in scene_names()}
    return {**runs, "calibrate": ["calibrate", *record_names(), *FIT, "--no-progress"]}


def run(arguments: list[str], cache: str) -> dict:
    """One `jaxcable` process: wall time, exit status, warnings and notes, summary."""
    env = {**os.environ, "JAXCABLE_CACHE_DIR": cache, "PYTHONPATH": str(ROOT)}
    before = os.getloadavg()[0]
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "jaxcable", *arguments], capture_output=True, text=True, env=env)
    wall = time.perf_counter() - start
    out = [line for line in done.stdout.splitlines() if line.strip()]
    return {
        "wall_s": round(wall, 2),
        "status": done.returncode,
        "warnings": [line for line in done.stderr.splitlines() if line.startswith(("warning:", "note:"))],
        "stderr_tail": done.stderr.splitlines()[-3:] if done.returncode else [],
        "summary": out[-1] if out else "",
        "output": out,
        "load_before": round(before, 2),
        "load_after": round(os.getloadavg()[0], 2),
    }


def fitted(output: list[str]) -> dict[str, float]:
    """The fitted value of each coefficient from calibrate's table."""
    from jaxcable.calibration import COEFFICIENTS

    values = {}
    for line in output:
        words = line.split()
        if len(words) >= 3 and words[0] in COEFFICIENTS:
            values[words[0]] = float(words[2])
    return values


def report(path: Path) -> None:
    session = json.loads(path.read_text())[-1]
    print(f"session {session['time']}, commit {session['commit']}, {session['machine']}\n")
    print("| example | cold (s) | warm (s) | exit | warnings | load avg (cold → warm) | result |")
    print("|---|---|---|---|---|---|---|")
    for name, entry in session["examples"].items():
        cold, warm = entry["cold"], entry["warm"]
        warnings = len(cold["warnings"]) + len(warm["warnings"])
        if name == "calibrate":
            result = ", ".join(f"{k} {v:.5g} (truth {entry['truth'][k]:g})" for k, v in entry["fitted"].items())
        else:
            # The summary's motion line (its last line splits the wall time since 2026-11-24).
            motion = next((line for line in warm["output"] if line.startswith("simulated")), warm["summary"])
            result = motion.split("; ", 1)[-1]
        status = f"{cold['status']}/{warm['status']}"
        load = f"{cold['load_before']:.1f} → {warm['load_after']:.1f}"
        print(f"| {name} | {cold['wall_s']:.1f} | {warm['wall_s']:.1f} | {status} | {warnings} | {load} | {result} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", nargs="+", help="examples to run (scene names, calibrate)")
    parser.add_argument("--report", action="store_true", help="print the latest session as a markdown table")
    args = parser.parse_args()
    if args.report:
        report(OUT)
        return
    from jaxcable.examples.make_records import TRUTH

    chosen = commands()
    unknown = sorted(set(args.only or ()) - set(chosen))
    if unknown:
        parser.error(f"unknown examples {unknown}; known: {sorted(chosen)}")
    results = {}
    for name, arguments in chosen.items():
        if args.only and name not in args.only:
            continue
        with tempfile.TemporaryDirectory() as cache:
            entry = {"command": "jaxcable " + " ".join(arguments)}
            for kind in ("cold", "warm"):
                entry[kind] = run(arguments, cache)
                print(f"{name} {kind}: {entry[kind]['wall_s']:.1f} s, exit {entry[kind]['status']}", flush=True)
        if name == "calibrate":
            entry["fitted"], entry["truth"] = fitted(entry["warm"]["output"]), TRUTH
        results[name] = entry
    append_session(OUT, examples=results)
    report(OUT)


if __name__ == "__main__":
    main()
