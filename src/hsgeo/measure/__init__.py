"""Measurement from pixels: image → observations."""
