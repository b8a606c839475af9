"""Every file hsgeo reads or writes, in one place, checked at the boundary.

One module per format:

* :mod:`hsgeo.io.tables` — CSV / Parquet tables with required columns (units in the names);
* :mod:`hsgeo.io.config` — TOML with a schema (unknown keys are errors with a suggestion);
* :mod:`hsgeo.io.sensor_file` — the one sensor file (``[sensor] model = ...``) of every
  command, through a registry of models (:func:`read_sensor`);
* :mod:`hsgeo.io.sensors` — the former per-command formats (the 000 sensor TOML of ``hsgeo
  geocode``, the 002 camera TOML of ``hsgeo adjust-pushbroom``), the adjustment JSON and the
  instrument files;
* :mod:`hsgeo.io.boards` — the calibration-board description (:class:`Board`, mm) and the
  board TOML of ``hsgeo calibrate-frame``;
* :mod:`hsgeo.io.navigation` — the one navigation file of every command (GNSS/INS
  trajectory, :class:`~hsgeo.trajectory.Trajectory`), and navigation as delivered
  (:func:`read_navigation`: geodetic or geocentric CSV on a named datum, the Applanix SBET of
  :mod:`hsgeo.io.sbet`) into a local frame chosen from the data;
* :mod:`hsgeo.io.terrain` — a DSM/DEM GDAL reads, in any CRS and vertical datum, into the local
  frame (:func:`read_terrain`);
* :mod:`hsgeo.io.lines` — recorded flight lines (NetCDF);
* :mod:`hsgeo.io.lp_lines` — the LP image lines of one strip (:class:`LpStrip`, NetCDF-4) of
  ``hsgeo lp-observations``;
* :mod:`hsgeo.io.raster` — the one writer of orthoimages and mosaics (:func:`write_raster`:
  COG, CF-1.8 NetCDF or ENVI by the suffix) and DEMs (NetCDF);
* :mod:`hsgeo.io.envi` — ENVI BSQ/BIL/BIP + ``.hdr``, also written in blocks of lines;
* :mod:`hsgeo.io.envi_read` — ENVI cubes as line scanners write them (``name.hdr`` or
  ``name.ext.hdr``, memory-mapped) and their line times;
* :mod:`hsgeo.io.line_cube` — recorded lines of either format (ENVI or NetCDF, by suffix);
* :mod:`hsgeo.io.view_angles` — the per-pixel view-angle table of a line scanner;
* :mod:`hsgeo.io.frames` — folders of raw ImSpector frames (16-bit TIFF or ``.npy``) with their
  exposure times and wavelengths (``hsgeo cube``);
* :mod:`hsgeo.io.cube` — reflectance cubes, NetCDF-4 or ENVI, written chunk by chunk;
* :mod:`hsgeo.io.opencv` — OpenCV FileStorage YAML/XML;
* :mod:`hsgeo.io.nist_strd` — NIST StRD nonlinear-regression files (certified values).

Writers replace their file atomically (temporary file, then :func:`os.replace`) and, given the
command's input files, refuse to write over one of them. Errors are
:class:`~hsgeo.InputError` naming the file, the line / column / key, and the remedy.
"""

from __future__ import annotations

import importlib
import importlib.util

#: every public name of the package, by the module that defines it: each module loads on the
#: first use of one of its names (PEP 562), so that ``hsgeo --help``, ``hsgeo --version`` and a
#: usage error do not load numba, scipy.stats and pandas (2.4 s before, 0.3 s now) for readers
#: they never call
_MODULES = {
    "hsgeo.io._files": ("atomic_path", "refuse_inputs"),
    "hsgeo.io.boards": ("Board", "read_board"),
    "hsgeo.io.config": ("Key", "load_dataclass", "read_dataclass", "read_toml"),
    "hsgeo.io.envi": ("read_envi", "write_envi"),
    "hsgeo.io.envi_read": ("line_times", "open_envi"),
    "hsgeo.io.line_cube": ("open_line_strip", "read_line_cube", "read_line_strips"),
    "hsgeo.io.lines": ("read_lines", "write_lines"),
    "hsgeo.io.lp_lines": ("LpStrip", "read_lp_lines", "write_lp_lines"),
    "hsgeo.io.navigation": (
        "NAV_COLUMNS",
        "Navigation",
        "read_navigation",
        "read_trajectory",
        "write_trajectory",
    ),
    "hsgeo.io.nist_strd": ("read_nist_strd",),
    "hsgeo.io.opencv": ("read_opencv_storage",),
    "hsgeo.io.raster": ("read_dem", "write_raster"),
    "hsgeo.io.sbet": ("read_sbet",),
    "hsgeo.io.sensor_file": ("read_sensor",),
    "hsgeo.io.sensors": (
        "read_band_split",
        "read_camera_toml",
        "read_frame_layouts",
        "read_pushbroom_camera",
        "read_scanning_sensor",
        "read_sensor_toml",
    ),
    "hsgeo.io.tables": ("read_table", "write_csv_array", "write_csv_lines"),
    "hsgeo.io.terrain": ("RasterTerrain", "read_terrain"),
}
_LAZY = {name: module for module, names in _MODULES.items() for name in names}
__all__ = list(_LAZY)


def __getattr__(name: str):
    """``hsgeo.io.NAME``: the name from its module, imported on first use; ``hsgeo.io.MODULE``
    (``hsgeo.io.tables``, as when the package imported its modules itself): the module.
    """
    module = _LAZY.get(name)
    if module is None:
        if name.startswith("__") or importlib.util.find_spec(f"{__name__}.{name}") is None:
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
        return importlib.import_module(f"{__name__}.{name}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # found directly from now on
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
