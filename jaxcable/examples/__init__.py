"""Bundled example scenes, as Python builders returning `(model, environment)`."""

from ._seed003 import seed003_amplitude as seed003_amplitude, seed003_line as seed003_line
