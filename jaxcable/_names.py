"""Names and limits the command line offers and checks before it imports JAX
(`jaxcable --help` answers without it, and a refused input file is answered without
it): the solvers and their tightest tolerance, the mass matrices and hydrodynamic
forms, the motion tables' interpolations, the kinds of physics a MoorDyn file may
ask for that jaxcable leaves out, and the default safety factor on breaking loads.
Plain data, importing nothing; the modules that use them import them from here."""

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

AUTO = "auto"
"""The solver name a scene file and the command line take, besides `SOLVER_NAMES`, for
fixed RK4 steps chosen for the scene's fastest modes ([`jaxcable.fixed_steps`][]): the
default of a scene that names no solver."""

SMALLEST_RTOL = 1e-13
"""The tightest relative tolerance (–) a step-size controller may be given: about 450
float64 epsilons (2.2e-16). A step's error estimate is a difference of two solutions,
each carrying rounding of a few ε |y| from its stage sums, so a tighter tolerance
cannot be met: the controller shrinks the step until it runs out of steps (an rtol of
1e-300 ran on towards `max_steps` with no message)."""

LARGEST_RTOL = 0.1
"""The loosest relative tolerance (–) a step-size controller may be given: a tenth of the
state per step. Looser steps are not a solution: at `--rtol 5` a line held at rest
(6 kN) was written as −43 kN, then 18 MN."""

MASS_MATRICES = ("consistent", "lumped")
"""The mass matrices of [`jaxcable.CableNetwork`][]."""

HYDRODYNAMICS = ("segments", "nodes")
"""Where [`jaxcable.CableNetwork`][] takes drag and added mass: on the segments, or
lumped at the nodes (MoorDyn's form)."""

INTERPOLATIONS = ("cubic", "pchip", "linear")
"""How [`jaxcable.Sampled`][] interpolates between its samples."""

DROPPED_KINDS = ("EI", "waves", "currents", "bathymetry", "friction")
"""What a MoorDyn file can ask for that jaxcable leaves out (`Scene.dropped`): a bending
stiffness table (a constant EI is modelled), waves or currents from MoorDyn's input files, a bathymetry file, and
friction's static-to-dynamic ratio. `jaxcable run` refuses such a file unless
`--allow-ignored` names them."""

DEFAULT_SAFETY_FACTOR = 1.67
"""API RP 2SK's factor of safety for an intact mooring line in a dynamic analysis (–):
the largest tension at most the minimum breaking load / 1.67 (`jaxcable.io._extremes`)."""
