"""A package's public names, imported on first use (PEP 562) and listed once: as the
imports under its `if TYPE_CHECKING:`, which type checkers and editors read as they
are, and which [`attach`][] reads for the running package. So `import jaxcable` and the
command line's `--help` import no JAX, and `from jaxcable import X` works as usual."""

import ast
import importlib
from collections.abc import Callable
from pathlib import Path
from typing import Any


def public_names(init_file: str) -> dict[str, tuple[str, str]]:
    """Each public name of the package whose `__init__.py` is `init_file`: the module
    it comes from, relative as written there (`._network`, `.` for a submodule), and
    its name in that module, from the imports under `if TYPE_CHECKING:`."""
    tree = ast.parse(Path(init_file).read_text(encoding="utf-8"))
    (block,) = (
        node
        for node in tree.body
        if isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING"
    )
    names = {}
    for node in block.body:
        if not isinstance(node, ast.ImportFrom):
            raise TypeError(f"{init_file}, line {node.lineno}: only `from ... import ...` under TYPE_CHECKING")
        module = "." * node.level + (node.module or "")
        for alias in node.names:
            names[alias.asname or alias.name] = (module, alias.name)
    return names


def attach(package: str, init_file: str, namespace: dict[str, Any]) -> tuple[Callable, Callable]:
    """`(__getattr__, __dir__)` for the package `package` (its `__name__`), whose
    `__init__.py` is `init_file` and whose globals are `namespace`: each public name
    imported on first use and kept in `namespace`."""
    names = public_names(init_file)

    def __getattr__(name: str):
        """Import a public name or module on first use, and keep it."""
        if name not in names:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, original = names[name]
        if module == ".":
            value = importlib.import_module(f".{original}", package)
        else:
            value = getattr(importlib.import_module(module, package), original)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted(set(namespace) | set(names))

    return __getattr__, __dir__
