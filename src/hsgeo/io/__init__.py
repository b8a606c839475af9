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

from hsgeo.io._files import atomic_path, refuse_inputs
from hsgeo.io.boards import Board, read_board
from hsgeo.io.config import Key, load_dataclass, read_dataclass, read_toml
from hsgeo.io.envi import read_envi, write_envi
from hsgeo.io.envi_read import line_times, open_envi
from hsgeo.io.line_cube import open_line_strip, read_line_cube, read_line_strips
from hsgeo.io.lines import read_lines, write_lines
from hsgeo.io.lp_lines import LpStrip, read_lp_lines, write_lp_lines
from hsgeo.io.navigation import (
    NAV_COLUMNS,
    Navigation,
    read_navigation,
    read_trajectory,
    write_trajectory,
)
from hsgeo.io.nist_strd import read_nist_strd
from hsgeo.io.opencv import read_opencv_storage
from hsgeo.io.raster import read_dem, write_raster
from hsgeo.io.sbet import read_sbet
from hsgeo.io.sensor_file import read_sensor
from hsgeo.io.sensors import (
    read_band_split,
    read_camera_toml,
    read_frame_layouts,
    read_pushbroom_camera,
    read_scanning_sensor,
    read_sensor_toml,
)
from hsgeo.io.tables import read_table, write_csv_array, write_csv_lines
from hsgeo.io.terrain import RasterTerrain, read_terrain

__all__ = [
    "atomic_path",
    "LpStrip",
    "read_lp_lines",
    "write_lp_lines",
    "refuse_inputs",
    "read_table",
    "write_csv_array",
    "write_csv_lines",
    "NAV_COLUMNS",
    "read_trajectory",
    "write_trajectory",
    "Navigation",
    "read_navigation",
    "read_sbet",
    "RasterTerrain",
    "read_terrain",
    "Key",
    "read_dataclass",
    "load_dataclass",
    "read_toml",
    "read_sensor",
    "read_sensor_toml",
    "read_camera_toml",
    "read_band_split",
    "read_frame_layouts",
    "read_pushbroom_camera",
    "read_scanning_sensor",
    "Board",
    "read_board",
    "read_lines",
    "write_lines",
    "write_raster",
    "read_dem",
    "read_envi",
    "open_envi",
    "line_times",
    "read_line_cube",
    "open_line_strip",
    "read_line_strips",
    "write_envi",
    "read_opencv_storage",
    "read_nist_strd",
]
