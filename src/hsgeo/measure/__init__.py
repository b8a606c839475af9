"""Measurement: images → observations (tables of image coordinates and ids)."""
