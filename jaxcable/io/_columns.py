"""Plain-text tables of a run's results, as `jaxcable run` prints them."""


def aligned(heading: list[str], body: list[list[str]], left: int) -> list[str]:
    """`heading` and the rows of `body` as lines of columns two spaces apart, each as wide
    as its widest cell: the first `left` columns (names) flush left, the rest (numbers)
    flush right, no trailing spaces."""
    rows = [heading, *body]
    widths = [max(len(row[k]) for row in rows) for k in range(len(heading))]
    return [
        "  ".join(c.ljust(w) if k < left else c.rjust(w) for k, (c, w) in enumerate(zip(row, widths))).rstrip()
        for row in rows
    ]
