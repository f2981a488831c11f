"""The README's Python builds what `jaxcable.examples` builds for it, so that the
benchmarks and tests that quote the README's line run the README's line."""

from pathlib import Path

import equinox as eqx
import jax
import numpy as np

import jaxcable as jc

README = Path(__file__).resolve().parents[1] / "README.md"


def _use_from_python() -> str:
    """The first Python block under *Use from Python*, up to its statics (the runs after
    it are the reader's to wait for)."""
    text = README.read_text(encoding="utf-8")
    section = text[text.index("## Use from Python") :]
    start = section.index("```python") + len("```python")
    block = section[start : section.index("```", start)]
    return block[: block.index("static = ")]


def test_the_readme_line_is_the_examples_anchored_line_in_current():
    namespace: dict = {}
    exec(_use_from_python(), namespace)  # noqa: S102 (the README's own code)
    ours = (namespace["model"], namespace["env"])
    theirs = jc.examples.anchored_line_in_current()
    assert jax.tree.structure(eqx.filter(ours, eqx.is_array)) == jax.tree.structure(eqx.filter(theirs, eqx.is_array))
    for a, b in zip(jax.tree.leaves(eqx.filter(ours, eqx.is_array)), jax.tree.leaves(eqx.filter(theirs, eqx.is_array))):
        np.testing.assert_array_equal(a, b)
    assert eqx.tree_equal(eqx.filter(ours, eqx.is_array, inverse=True), eqx.filter(theirs, eqx.is_array, inverse=True))
