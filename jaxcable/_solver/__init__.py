"""Time-stepping methods and their configuration: RK4, Picard, implicit steps with the
network's Jacobian, and the stability of a fixed step."""
