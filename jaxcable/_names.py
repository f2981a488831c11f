"""Names the command line offers before it imports JAX (`jaxcable --help` answers
without it): the solvers, the motion tables' interpolations, and the kinds of physics
a MoorDyn file may ask for that jaxcable leaves out. Plain data, importing nothing;
the modules that use them import them from here."""

SOLVER_NAMES = (
    "dopri5",
    "tsit5",
    "bosh3",
    "rk4",
    "dopri8",
    "midpoint",
    "heun",
    "euler",
    "kvaerno5",
    "kencarp4",
    "picard",
)
"""The keys of [`jaxcable.SOLVERS`][], in its order (a test holds them equal)."""

INTERPOLATIONS = ("cubic", "pchip", "linear")
"""How [`jaxcable.Sampled`][] interpolates between its samples."""

DROPPED_KINDS = ("EI", "waves", "currents", "bathymetry", "friction")
"""What a MoorDyn file can ask for that jaxcable leaves out (`Scene.dropped`): a bending
stiffness table (a constant EI is modelled), waves or currents from MoorDyn's input files, a bathymetry file, and
friction's static-to-dynamic ratio. `jaxcable run` refuses such a file unless
`--allow-ignored` names them."""
