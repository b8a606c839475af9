"""Measurement from pixels: images → observations (tables of image coordinates and ids)."""

__all__: list[str] = []
