"""Measurement: images to observations (image coordinates, ids, bands)."""
