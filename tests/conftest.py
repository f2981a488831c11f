import jaxcable  # noqa: F401  (enables float64 before any test builds an array)
