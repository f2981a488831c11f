"""The equations of motion: the lumped-mass Lagrangian dynamics, hydrodynamic loads and bending."""
