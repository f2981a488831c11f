"""Batched simulations over parameter values (vmapped sweeps)."""
