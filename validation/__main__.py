"""List the validations, or run some in turn with their default options.

    python -m validation                          # each validation, what it checks, its command
    python -m validation stiffness irregular_response

Each named validation runs as its own process (`python -m validation.NAME`), so one that
fails does not stop the others; the summary gives each one's exit status and wall time.
"""

import argparse
import ast
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def validations() -> dict[str, str]:
    """Each validation's name and the first sentence of its docstring."""
    found = {}
    for path in sorted(HERE.glob("*.py")):
        if path.stem.startswith("_"):
            continue
        doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
        found[path.stem] = " ".join(doc.split("\n\n")[0].split())
    return found


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m validation", description=__doc__.split("\n")[0])
    parser.add_argument("names", nargs="*", help="validations to run, in turn (none: list them)")
    args = parser.parse_args(argv)
    known = validations()
    if not args.names:
        for name, summary in known.items():
            print(f"{name}\n    {summary}\n    python -m validation.{name} --help")
        return 0
    unknown = [name for name in args.names if name not in known]
    if unknown:
        parser.error(f"no validation {unknown[0]!r}; there are: {', '.join(known)}")
    outcomes = []
    for name in args.names:
        start = time.perf_counter()
        status = subprocess.run([sys.executable, "-m", f"validation.{name}"], check=False).returncode
        outcomes.append((name, status, time.perf_counter() - start))
    for name, status, seconds in outcomes:
        print(f"{name}: {'passed' if status == 0 else f'exit status {status}'} in {seconds:.0f} s")
    return max(status for _, status, _ in outcomes)


if __name__ == "__main__":
    sys.exit(main())
