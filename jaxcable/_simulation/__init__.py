"""Time integration of a network from its state: the public simulate and its interval-by-
interval blocks for cached programs."""
