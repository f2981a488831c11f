"""Bundled examples: scene files in `scenes/`, sample towing records for `jaxcable
calibrate` in `records/` (made by `make_records.py`), and the seed papers' scenes as
Python builders returning `(model, environment)`.

The builders are re-exported here; each paper's constants (its cable, bodies and sea) live in
its module: `jaxcable.examples.seed001` (growing elements), `.seed002` (the towed trawl),
`.seed002_net` (the moored net of buoys) and `.seed003` (the anchored line). The studies that
reproduce the papers are not part of the package: they are in the repository's `studies/`."""

import tomllib
from pathlib import Path

from .._waves import seed003_amplitude as seed003_amplitude
from .seed001 import seed001_element as seed001_element
from .seed002 import start_tow as start_tow
from .seed002 import towed_trawl as towed_trawl
from .seed002_net import moored_net as moored_net
from .seed003 import seed003_line as seed003_line

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
