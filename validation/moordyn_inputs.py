"""Read every MoorDyn input file under a directory, solve its statics with jaxcable and
with MoorDyn, and compare the end tensions.

MoorDyn's public repository has dozens of example inputs; they are not part of
jaxcable (fetch MoorDyn and point this script at its `tests/Mooring` and `example`
folders). For each file the script reports whether jaxcable reads it (or the error it
gives for a feature it does not model), its static `FairTen<k>` and `AnchTen<k>`, and
MoorDyn's after its own initial-condition solve (`moordyn.Init`): the largest
difference over lines' ends, relative to the largest tension in the file. Both model
seabed contact (jaxcable with MoorDyn's kBot and cBot); MoorDyn models bending where the
file asks for it and jaxcable does not: rows where jaxcable notes bending are marked, and
differences there are expected.

    python -m validation.moordyn_inputs DIR [DIR ...] [--max-segments 300] [--out results/moordyn_inputs.json]
"""

import argparse
import contextlib
import json
import os
import time
import warnings
from pathlib import Path

import jax
import numpy as np

import jaxcable as jc

jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us


def jaxcable_statics(path: Path, max_segments: int) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            scene = jc.read_moordyn(path)
        except jc.io.SceneError as error:
            return {"status": "rejected", "message": str(error).split(": ", 1)[-1]}
    segments = sum(line.segments for line in scene.lines)
    notes = " ".join(scene.notes)
    record = {
        "segments": segments,
        "bending_ignored": "bending" in notes,
    }
    if segments > max_segments:
        return {**record, "status": "skipped", "message": f"{segments} segments"}
    start = time.perf_counter()
    try:
        run = jc.run_scene(scene, duration=0)
    except RuntimeError as error:
        return {**record, "status": "statics failed", "message": str(error)[:160]}
    names = [f"{kind}{k}" for k in range(1, len(scene.lines) + 1) for kind in ("FairTen", "AnchTen")]
    values = run.channels(tuple(names))
    record |= {
        "status": "ok",
        "seconds": time.perf_counter() - start,
        "tensions": {name: float(values[name][0]) for name in names},
    }
    return record


def moordyn_statics(path: Path) -> dict:
    import moordyn

    with open(os.devnull, "w") as sink, contextlib.redirect_stdout(sink):
        system = moordyn.Create(str(path))
        coupled = []
        for k in range(1, moordyn.GetNumberPoints(system) + 1):
            point = moordyn.GetPoint(system, k)
            if moordyn.GetPointType(point) == moordyn.POINT_TYPE_COUPLED:
                coupled += list(moordyn.GetPointPos(point))
        moordyn.Init(system, coupled, [0.0] * len(coupled))
        tensions = {}
        for k in range(1, moordyn.GetNumberLines(system) + 1):
            line = moordyn.GetLine(system, k)
            n = moordyn.GetLineN(line)
            tensions[f"FairTen{k}"] = float(np.linalg.norm(moordyn.GetLineNodeTen(line, n)))
            tensions[f"AnchTen{k}"] = float(np.linalg.norm(moordyn.GetLineNodeTen(line, 0)))
        moordyn.Close(system)
    return tensions


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folders", type=Path, nargs="+")
    parser.add_argument("--max-segments", type=int, default=300)
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "moordyn_inputs.json")
    parser.add_argument("--no-moordyn", action="store_true")
    args = parser.parse_args()
    files = [
        (folder, path)
        for folder in args.folders
        for path in sorted(folder.rglob("*"))
        if path.suffix in (".txt", ".dat") and _is_moordyn_input(path)
    ]
    results = {}
    for folder, path in files:
        name = f"{folder.name}/{path.relative_to(folder)}"
        record = jaxcable_statics(path, args.max_segments)
        if record["status"] == "ok" and not args.no_moordyn:
            # MoorDyn resolves side files relative to the working directory.
            cwd = os.getcwd()
            try:
                os.chdir(path.parent)
                reference = moordyn_statics(path)
                record["moordyn"] = reference
                # Relative to the largest tension in the file: an end that MoorDyn
                # leaves at rest or slack has ~0 tension, and a ratio to it means nothing.
                largest = max(max(reference.values()), 1e-9)
                record["largest_relative_difference"] = (
                    max(abs(record["tensions"][k] - v) for k, v in reference.items()) / largest
                )
            except Exception as error:  # MoorDyn itself may reject or fail on a file
                record["moordyn_error"] = str(error)[:160]
            finally:
                os.chdir(cwd)
        results[name] = record
        summary = record.get("largest_relative_difference")
        print(
            f"{name}: {record['status']}"
            + (f", max |Δ| / max T = {summary:.2%}" if summary is not None else "")
            + (f" ({record.get('message', '')})" if record["status"] != "ok" else ""),
            flush=True,
        )
    args.out.parent.mkdir(exist_ok=True)
    args.out.write_text(json.dumps(results, indent=1))
    print(f"wrote {args.out}")


def _is_moordyn_input(path: Path) -> bool:
    text = path.read_text(errors="replace").upper()
    return ("LINE TYPES" in text or "LINE DICTIONARY" in text) and "---" in text


if __name__ == "__main__":
    main()
