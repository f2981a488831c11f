"""Bundled examples: scene files in `scenes/`, sample towing records for `jaxcable
calibrate` in `records/` (made by `make_records.py`), and the source papers' scenes as
Python builders returning `(model, environment)`.

The builders are re-exported here; each paper's constants (its cable, bodies and sea) live in
its module: `jaxcable.examples._growing_element` (growing elements), `._towed_trawl` (the towed trawl),
`._moored_net` (the moored net of buoys) and `._anchored_line` (the anchored line, and
the README's line in a current). The studies that
reproduce the papers are not part of the package: they are in the repository's `studies/`."""

import importlib
import tomllib
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .._sea.waves import floater_amplitude as floater_amplitude
    from ._anchored_line import anchored_line as anchored_line
    from ._anchored_line import anchored_line_in_current as anchored_line_in_current
    from ._growing_element import growing_element as growing_element
    from ._moored_net import moored_net as moored_net
    from ._towed_trawl import start_tow as start_tow
    from ._towed_trawl import towed_trawl as towed_trawl

# The builders import JAX: they are imported on first use (PEP 562), so that listing
# the bundled scenes (`jaxcable examples`) does not.
_BUILDERS = {
    "anchored_line_in_current": "._anchored_line",
    "floater_amplitude": ".._sea.waves",
    "growing_element": "._growing_element",
    "start_tow": "._towed_trawl",
    "towed_trawl": "._towed_trawl",
    "moored_net": "._moored_net",
    "anchored_line": "._anchored_line",
}


def __getattr__(name: str):
    """Import a builder on first use, and keep it."""
    if name not in _BUILDERS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_BUILDERS[name], __name__), name)
    globals()[name] = value
    return value


_SCENES = Path(__file__).parent / "scenes"
_RECORDS = Path(__file__).parent / "records"


def scene_names() -> list[str]:
    """Names of the bundled example scenes, for `jaxcable run NAME`."""
    return sorted(p.stem for p in _SCENES.glob("*.toml"))


def scene_path(name: str) -> Path:
    """The path of the bundled example scene `name`."""
    path = _SCENES / f"{name}.toml"
    if not path.exists():
        raise ValueError(f"no bundled example scene {name!r}; bundled: {scene_names()}")
    return path


def scene_title(name: str) -> str:
    """The bundled example scene `name`'s one-line description, its `title`."""
    with scene_path(name).open("rb") as file:
        return str(tomllib.load(file).get("title", ""))


def record_names() -> list[str]:
    """Names of the bundled sample towing records, for `jaxcable calibrate NAME ...`."""
    return sorted(p.stem for p in _RECORDS.glob("*.csv"))


def record_path(name: str) -> Path:
    """The path of the bundled sample towing record `name`."""
    path = _RECORDS / f"{name}.csv"
    if not path.exists():
        raise ValueError(f"no bundled towing record {name!r}; bundled: {record_names()}")
    return path
