"""The papers' studies, reproduced with jaxcable: not part of the installed package.

Each module runs one source paper's cases through the public API (`jaxcable`,
`jaxcable.examples` for the papers' scenes) and measures what the paper claims, with the
wall time of each run. Used by `notebooks/`, `benchmarks/` and `tests/`, which put the
repository root on `sys.path` (pytest does it through `pythonpath` in `pyproject.toml`).

- `growing_elements`: the growing element, free and tethered (Zhukov's growing-element thesis).
- `towed_trawl`: the towed trawl's speed steps (Bezverkhyy & Korniienko).
- `moored_net`: the moored net of buoys in waves (Bezverkhyy & Korniienko).
- `anchored_line`: the anchored line's slack and snap loads in waves (Bezverkhyy & Korniienko).
- `cnoidal_loads`: wave loads on a fixed vertical cylinder in shallow water, cnoidal against
  Airy, and the cnoidal wave's harmonic superposition (Yakovlev et al.).
- `linear_buoy`: a tethered buoy, a linear oscillator, in an irregular sea, and its
  closed form (issue 21).
"""
