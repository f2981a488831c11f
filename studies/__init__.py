"""The papers' studies, reproduced with jaxcable: not part of the installed package.

Each module runs one seed paper's cases through the public API (`jaxcable`,
`jaxcable.examples` for the papers' scenes) and measures what the paper claims, with the
wall time of each run. Used by `notebooks/`, `benchmarks/` and `tests/`, which put the
repository root on `sys.path` (pytest does it through `pythonpath` in `pyproject.toml`).

- `seed001`: the growing element, free and tethered (seed 001).
- `seed002`: the towed trawl's speed steps (seed 002).
- `seed002_net`: the moored net of buoys in waves (seed 002).
- `seed003`: the anchored line's slack and snap loads in waves (seed 003).
- `seed004`: wave loads on a fixed vertical cylinder in shallow water, cnoidal against
  Airy, and the cnoidal wave's harmonic superposition (seed 004).
- `linear_buoy`: a tethered buoy, a linear oscillator, in an irregular sea, and its
  closed form (issue 21).
"""
