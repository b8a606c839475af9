"""hsgeo: geometry of hyperspectral sensors.

A small tested library behind a reproducible research compendium: sensor models, one
least-squares adjustment engine, measurement from pixels, statistics, and the papers' tables.
"""

from __future__ import annotations

from hsgeo.errors import (
    ConvergenceError,
    DatumError,
    HsgeoError,
    InputError,
    ObservationError,
)

__version__ = "0.1.0"

__all__ = [
    "__version__",
    "show_versions",
    "HsgeoError",
    "InputError",
    "ObservationError",
    "DatumError",
    "ConvergenceError",
]


def show_versions() -> str:
    """Return (and print) the versions of hsgeo, Python and the core dependencies."""
    import importlib.metadata as md
    import platform

    lines = [f"hsgeo {__version__}", f"python {platform.python_version()} ({platform.platform()})"]
    for dist in (
        "numpy",
        "scipy",
        "matplotlib",
        "pandas",
        "xarray",
        "dask",
        "h5py",
        "distributed",
        "pyproj",
        "rasterio",
        "rioxarray",
        "spectral",
        "opencv-python-headless",
        "numba",
        "jupyter-book",
    ):
        try:
            lines.append(f"{dist} {md.version(dist)}")
        except md.PackageNotFoundError:
            lines.append(f"{dist} (not installed)")
    text = "\n".join(lines)
    print(text)
    return text
