"""Helpers the file readers share: reading a file's text, telling numbers from words,
and catching a name defined twice. Errors are [`jaxcable.io.SceneError`][]."""

import codecs
from collections.abc import Sequence
from pathlib import Path

from ._scene import SceneError


def read_text(path: Path, what: str = "") -> str:
    """The text of `path`, or a `SceneError` saying why it cannot be read.

    UTF-8 (bytes that are not are replaced, as a comment's Latin-1 degree sign);
    UTF-16 and UTF-8 with a byte-order mark, as Windows editors save them, are decoded
    by it. UTF-16 without a mark (zero bytes between the characters) is refused, naming
    the encoding to save the file in. Line ends are LF, whichever the file has, as Python's
    text mode gives them."""
    name = f"{what + ' ' if what else ''}{path}"
    try:
        data = path.read_bytes()
    except OSError as error:
        raise SceneError(f"cannot read {name}: {error.strerror}") from error
    for mark, encoding in (
        (codecs.BOM_UTF8, "utf-8-sig"),
        (codecs.BOM_UTF16_LE, "utf-16"),
        (codecs.BOM_UTF16_BE, "utf-16"),
    ):
        if data.startswith(mark):
            try:
                return _newlines(data.decode(encoding))
            except UnicodeDecodeError as error:
                raise SceneError(
                    f"{name}: not valid {encoding.upper()} after its byte-order mark ({error.reason})"
                ) from None
    if b"\x00" in data[:4096]:
        raise SceneError(
            f"{name}: the file holds zero bytes, as UTF-16 text without a byte-order mark does; save it as UTF-8"
        )
    return _newlines(data.decode("utf-8", errors="replace"))


def _newlines(text: str) -> str:
    """`text` with Windows (CR LF) and classic Mac (CR) line ends as LF."""
    return text.replace("\r\n", "\n").replace("\r", "\n")


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
