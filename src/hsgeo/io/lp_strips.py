"""LP line files as the orthomosaic reads them, and the adjustment JSON of ``adjust-pushbroom``.

An LP line file (NetCDF, one flight strip): the variable ``lines(line, column, band)`` (radiance),
``t_s(line)`` (exposure time of each line on the navigation's time scale, s),
``wavelength_nm(band)``, and the attributes ``col0`` (the detector column of the file's first
column) and ``strip_id``. **Adapter**: this reader follows that description;
:func:`open_lp_strip` is the one place to swap for ``hsgeo.io.lp_lines`` (being written at the
same time) when both meet — the mosaic needs only :class:`LpStrip`. The pixel coordinate of the
camera (x in px from the line centre) of column ``j`` is ``col0 + j − (n_detector − 1) / 2``
with ``n_detector`` the attribute ``n_detector_px`` (default: the file's own column count and
``col0 = 0``, i.e. a full line).

:func:`read_adjustment` reads what ``hsgeo adjust-pushbroom --json`` prints
(``workflows.pushbroom_ba.summary``): the camera parameters with σ̂ and the node corrections.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path, check_outputs, read_text

__all__ = ["LpStrip", "open_lp_strip", "write_lp_strip", "read_adjustment"]


@dataclass(frozen=True)
class LpStrip:
    """One LP strip, its cube lazily (Dask).

    Attributes
    ----------
    values : dask.array.Array
        ``(line, column, band)`` radiance, read chunk by chunk.
    t_s : (n_lines,) ndarray, s
    wavelength_nm : (n_bands,) ndarray, nm
    x_px : (n_columns,) ndarray, px
        Each column's x from the line centre (the camera's pixel coordinate).
    strip_id : str
    path : str
    """

    values: object
    t_s: np.ndarray
    wavelength_nm: np.ndarray
    x_px: np.ndarray
    strip_id: str
    path: str


def open_lp_strip(path, lines_per_chunk: int = 256) -> LpStrip:
    """Open an LP line file lazily (module docstring); one InputError per problem."""
    from hsgeo.io.lines import open_netcdf

    ds = open_netcdf(path, "lines", "LP LINES ", "it needs lines(line, column, band)")
    name = str(path)
    for var, dims in (
        ("lines", ("line", "column", "band")),
        ("t_s", ("line",)),
        ("wavelength_nm", ("band",)),
    ):
        if var not in ds:
            raise InputError(
                f"LINES {name!r}: no variable {var!r}; an LP line file has {var}{dims}"
            )
        if ds[var].dims != dims:
            raise InputError(
                f"LINES {name!r}: {var} must have dimensions {dims}, got {ds[var].dims}"
            )
    t = np.asarray(ds["t_s"].values, dtype=float)
    if t.size < 2 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise InputError(f"LINES {name!r}: t_s must be at least two finite, increasing times (s)")
    wl = np.asarray(ds["wavelength_nm"].values, dtype=float)
    n_col = ds.sizes["column"]
    col0 = float(ds.attrs.get("col0", 0))
    n_det = float(ds.attrs.get("n_detector_px", n_col if col0 == 0 else np.nan))
    if not np.isfinite(n_det):
        raise InputError(
            f"LINES {name!r}: col0 = {col0:g} needs the attribute n_detector_px (the detector's "
            "column count) to place the columns on the line"
        )
    x_px = col0 + np.arange(n_col) - (n_det - 1) / 2
    values = ds["lines"].chunk({"line": lines_per_chunk, "column": -1, "band": -1}).data
    return LpStrip(values, t, wl, x_px, str(ds.attrs.get("strip_id", name)), name)


def write_lp_strip(
    path,
    values,
    t_s,
    wavelength_nm,
    *,
    strip_id: str,
    col0: int = 0,
    n_detector_px: int | None = None,
    overwrite: bool = False,
) -> None:
    """Write an LP line file (NetCDF-4), atomically; ``values`` ``(line, column, band)`` may be
    a Dask array (written chunk by chunk).
    """
    import xarray as xr

    check_outputs([(path, "LINES", {".nc": "NetCDF"})], overwrite=overwrite)
    ds = xr.Dataset(
        {
            "lines": (("line", "column", "band"), values),
            "t_s": (("line",), np.asarray(t_s, float)),
            "wavelength_nm": (("band",), np.asarray(wavelength_nm, float)),
        },
        attrs={
            "col0": int(col0),
            "strip_id": str(strip_id),
            "n_detector_px": int(n_detector_px or np.shape(values)[1]),
        },
    )
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf")


def read_adjustment(path) -> dict:
    """Camera parameters and node corrections from ``hsgeo adjust-pushbroom --json``.

    Returns
    -------
    dict
        ``boresight_rad`` (3,), ``lever_arm_m`` (3,), ``distortion`` (4,), ``c_mm`` (n,),
        ``t_nodes_s`` (n_nodes,), ``nodes`` (n_nodes, 6) in m and rad, ``node_columns``.
    """
    text = read_text(path, "--adjustment file", "JSON")
    try:
        d = json.loads(text)
        par, nodes = d["parameters"], d["nodes"]
        out = {
            "boresight_rad": np.radians(np.asarray(par["boresight_deg"]["value"], float)),
            "lever_arm_m": np.asarray(par["lever_arm_m"]["value"], float),
            "distortion": np.asarray(par["distortion"]["value"], float),
            "c_mm": np.atleast_1d(np.asarray(par["c_mm"]["value"], float)),
            "t_nodes_s": np.asarray(nodes["t_s"], float),
            "nodes": np.asarray(nodes["value"], float),
            "node_columns": tuple(nodes["columns"]),
        }
    except (ValueError, KeyError, TypeError) as exc:
        raise InputError(
            f"--adjustment {str(path)!r}: not the JSON of `hsgeo adjust-pushbroom --json` "
            f"({type(exc).__name__}: {exc}); give that command's output"
        ) from None
    shapes = {"boresight_rad": (3,), "lever_arm_m": (3,), "distortion": (4,)}
    for k, shp in shapes.items():
        if out[k].shape != shp:
            raise InputError(f"--adjustment {str(path)!r}: {k} must have {shp[0]} values")
    n = out["t_nodes_s"].size
    if n < 4 or out["nodes"].shape != (n, len(out["node_columns"])):
        raise InputError(
            f"--adjustment {str(path)!r}: nodes.value must be ({n}, "
            f"{len(out['node_columns'])}) for {n} node times"
        )
    return out
