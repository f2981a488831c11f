"""Calibration of drag and weight coefficients against towing records: the rigs, the
records and the fit."""
