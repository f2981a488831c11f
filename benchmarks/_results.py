"""Results shared by the benchmarks: sessions appended to a JSON list, each stamped with
when and where it ran."""

import json
import os
import platform
import subprocess
import time
from pathlib import Path


def append_session(path: str | Path, **fields) -> list[dict]:
    """Append one session to the JSON list at `path` (created if absent) and return the
    whole list.

    The session holds `fields` after a stamp: the local time, the code's git commit
    (with `+` if the tree had changes), the machine and its core count, the platform,
    Python, JAX's devices, the jax and diffrax versions, `XLA_FLAGS` and `PJRT_NPROC`
    (which change how XLA runs a program; see `benchmarks/README.md`).
    """
    import diffrax
    import jax

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    history = json.loads(path.read_text()) if path.exists() else []
    history.append(
        {
            "time": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "commit": _commit(),
            "machine": f"{platform.node()} {platform.machine()} ({os.cpu_count()} cores)",
            "platform": platform.platform(),
            "python": platform.python_version(),
            "cpu_count": os.cpu_count(),
            "devices": [str(d) for d in jax.devices()],
            "jax": jax.__version__,
            "diffrax": diffrax.__version__,
            "xla_flags": os.environ.get("XLA_FLAGS", ""),
            "pjrt_nproc": os.environ.get("PJRT_NPROC", ""),
            **fields,
        }
    )
    path.write_text(json.dumps(history, indent=1))
    return history


def _commit() -> str | None:
    def git(*args):
        return subprocess.run(["git", *args], capture_output=True, text=True, cwd=Path(__file__).parent).stdout

    try:
        head = git("rev-parse", "--short", "HEAD").strip()
        return head + ("+" if git("status", "--porcelain", "--untracked-files=no").strip() else "") or None
    except OSError:
        return None
