"""Helpers the file readers share: reading a file's text, telling numbers from words,
and catching a name defined twice. Errors are [`jaxcable.io.SceneError`][]."""

from collections.abc import Sequence
from pathlib import Path

from ._scene import SceneError


def read_text(path: Path, what: str = "") -> str:
    """The text of `path`, or a `SceneError` saying why it cannot be read."""
    try:
        return path.read_text(encoding="utf-8", errors="replace")
    except OSError as error:
        raise SceneError(f"cannot read {what + ' ' if what else ''}{path}: {error.strerror}") from error


def is_number(token: str) -> bool:
    """Whether `token` reads as a float."""
    try:
        float(token)
    except ValueError:
        return False
    return True


def unique_names(items: Sequence, what: str, source: str) -> None:
    """Raise a `SceneError` naming the second definition of a duplicated name."""
    seen = {}
    for item in items:
        if item.name in seen:
            raise SceneError(f"{item.where}: {what} {item.name!r} is already defined at {seen[item.name]}")
        seen[item.name] = item.where or source
