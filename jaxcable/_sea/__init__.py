"""The water: current, seabed, regular waves (Airy, cnoidal and its elliptic functions),
irregular seas (spectra, components) and the extremes of responses to them."""
