"""Motion tables: prescribed positions of coupled points over time, read from a file."""

import re
from pathlib import Path

import numpy as np

from ._parse import is_number, read_text
from ._scene import SceneError


def read_motion_file(path: str | Path, points: int) -> tuple[np.ndarray, np.ndarray]:
    """Read a table of `time x y z` for each of `points` coupled points, in order.

    Columns are separated by whitespace or commas. Lines that are blank or start with
    `#` are skipped, and so is a first line of column names (one with no number in it).

    **Returns:**

    `(times, positions)`: times (s), shape `(samples,)`, and absolute positions (m),
    shape `(samples, points, 3)`.

    **Raises:**

    [`jaxcable.io.SceneError`][] naming the file and line for a non-numeric field, a row
    with the wrong number of columns, fewer than two rows, or times that do not
    strictly increase.
    """
    path = Path(path)
    text = read_text(path, "motion file")
    expected = 1 + 3 * points
    rows, numbers, header = [], [], False
    for number, line in enumerate(text.splitlines(), start=1):
        fields = [f for f in re.split(r"[,\s]+", line.strip()) if f]
        if not fields or fields[0].startswith("#"):
            continue
        try:
            values = [float(f) for f in fields]
        except ValueError:
            if not rows and not header and not any(is_number(f) for f in fields):
                header = True  # a first row of column names, with no numbers in it
                continue
            raise SceneError(f"{path}, line {number}: non-numeric field in {line.strip()!r}") from None
        if len(values) != expected:
            raise SceneError(
                f"{path}, line {number}: expected {expected} columns (time, then x y z for each of "
                f"{points} coupled point(s)), got {len(values)}"
            )
        rows.append(values)
        numbers.append(number)
    if len(rows) < 2:
        raise SceneError(f"{path}: a motion table needs at least 2 rows, got {len(rows)}")
    table = np.asarray(rows)
    if not np.all(np.isfinite(table)):
        i = int(np.argmax(~np.all(np.isfinite(table), axis=1)))
        raise SceneError(f"{path}, line {numbers[i]}: non-finite value")
    steps = np.diff(table[:, 0])
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0)) + 1
        raise SceneError(
            f"{path}, line {numbers[i]}: the time column must increase, but {table[i, 0]:g} s follows "
            f"{table[i - 1, 0]:g} s"
        )
    return table[:, 0], table[:, 1:].reshape(len(rows), points, 3)
