"""Static equilibrium of a network: the solver, the catenary start and closed forms, and
the stiffness of supports and bodies."""
