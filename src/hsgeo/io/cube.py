"""Reflectance cubes: NetCDF (xarray, h5netcdf) and ENVI (BSQ/BIL/BIP + ``.hdr``), streamed.

A cube is an :class:`xarray.Dataset` with ``reflectance(line, sample, band)`` (float32, NaN
where a pixel has no value), the coordinates ``band`` with ``wavelength_nm`` and ``fwhm_nm``,
and the acquisition settings as attributes (:mod:`hsgeo.workflows.cube`). Its data may be a
Dask array: both writers compute and write it one chunk of lines at a time, so a cube larger
than the memory is written with about one chunk in memory.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import atomic_path
from hsgeo.io.envi import EnviWriter

__all__ = ["write_cube", "read_cube", "ENVI_IGNORE_VALUE", "cube_format", "cube_outputs"]

#: The ENVI ``data ignore value`` written for pixels without a value (NaN in the Dataset).
ENVI_IGNORE_VALUE = -9999.0

_ENVI_SUFFIX = {".hdr": "bsq", ".bsq": "bsq", ".bil": "bil", ".bip": "bip"}


def cube_format(path) -> str:
    """``"netcdf"`` for ``.nc``, else the ENVI interleave of the suffix (``.hdr`` → BSQ)."""
    suffix = Path(path).suffix.lower()
    if suffix == ".nc":
        return "netcdf"
    if suffix in _ENVI_SUFFIX:
        return _ENVI_SUFFIX[suffix]
    raise InputError(
        f"-o {path}: unknown cube format {suffix or '(no suffix)'!r}; use .nc (NetCDF) or "
        ".hdr / .bsq / .bil / .bip (ENVI)"
    )


def _envi_paths(path: Path, interleave: str) -> Path:
    """The ENVI data file for ``-o``: ``cube.hdr`` → ``cube``; ``cube.bil`` → itself."""
    return path.with_suffix("") if path.suffix.lower() == ".hdr" else path


def cube_outputs(path) -> list[Path]:
    """The files :func:`write_cube` writes for ``path`` (ENVI: the data file and its header)."""
    path = Path(path)
    fmt = cube_format(path)
    if fmt == "netcdf":
        return [path]
    data = _envi_paths(path, fmt)
    return [data, data.with_name(data.name + ".hdr")]


def _default_bands(wavelength_nm) -> list[int]:
    """Bands nearest 850, 650, 550 nm (001 Fig. 10's colour composite)."""
    lam = np.asarray(wavelength_nm, dtype=float)
    return [int(np.argmin(np.abs(lam - w))) for w in (850.0, 650.0, 550.0)]


def write_cube(ds, path, *, inputs=(), progress=None) -> list[Path]:
    """Write a cube to ``path``: NetCDF (``.nc``) or ENVI (``.hdr``, ``.bsq``, ``.bil``, ``.bip``).

    Parameters
    ----------
    ds : xarray.Dataset
        With ``reflectance(line, sample, band)`` and coordinate ``wavelength_nm(band)``
        (optionally ``fwhm_nm(band)``); Dask-backed data are computed chunk by chunk.
    path : str or Path
    inputs : iterable of path
        Files the command reads (never written over).
    progress : callable, optional
        Called with ``(lines_done, lines_total)`` after every chunk.

    Returns
    -------
    list of Path
        The files written (each replaced atomically).
    """
    import dask
    import dask.array as da

    path = Path(path)
    fmt = cube_format(path)
    refl = ds["reflectance"].transpose("line", "sample", "band")
    data = refl.data if isinstance(refl.data, da.Array) else da.from_array(refl.data)
    n_lines = data.shape[0]
    if fmt == "netcdf":
        out = ds.copy()
        # every other variable in memory before the write (they are small: lines × bands):
        # with more than one Dask-backed variable, the order in which the delayed store
        # computes them, and so where each lands in the file, varied from run to run (the
        # same content in different bytes in 1 of 6 runs)
        for name in list(out.data_vars) + list(out.coords):
            if name != "reflectance" and isinstance(out[name].data, da.Array):
                # synchronous: a thread pool would receive the SIGINT that atomic_path holds
                # back in the main thread while it makes its temporary file
                out[name] = out[name].compute(scheduler="synchronous")
        out["reflectance"] = refl.copy(data=data.astype(np.float32))
        enc = {
            "reflectance": {
                "chunksizes": (data.chunks[0][0], data.shape[1], data.shape[2]),
                "_FillValue": np.float32(np.nan),
            }
        }
        with atomic_path(path, inputs) as tmp, dask.config.set(scheduler="synchronous"):
            delayed = out.to_netcdf(tmp, engine="h5netcdf", encoding=enc, compute=False)
            _compute_with_progress(delayed, progress, n_lines)
        return [path]
    lam = ds["wavelength_nm"].values
    fwhm = ds["fwhm_nm"].values if "fwhm_nm" in ds else None
    data_path = _envi_paths(path, fmt)
    attrs = ", ".join(f"{k}={v}" for k, v in ds.attrs.items() if isinstance(v, (int, float, str)))
    with EnviWriter(
        data_path,
        (data.shape[2], data.shape[0], data.shape[1]),
        np.float32,
        interleave=fmt,
        wavelength_nm=lam,
        fwhm_nm=fwhm,
        data_ignore_value=ENVI_IGNORE_VALUE,
        default_bands=_default_bands(lam),
        description=f"hsgeo reflectance cube ({attrs})".replace("{", "(").replace("}", ")"),
        inputs=inputs,
    ) as w:
        done = 0
        for block_lines in data.chunks[0]:
            sl = slice(done, done + block_lines)
            with dask.config.set(scheduler="synchronous"):
                block = np.asarray(data[sl].compute(), dtype=np.float32)
            w[sl, :, :] = np.where(np.isfinite(block), block, np.float32(ENVI_IGNORE_VALUE))
            done += block_lines
            if progress is not None:
                progress(done, n_lines)
    return [data_path, w.header_path]


def _compute_with_progress(delayed, progress, n_lines):
    if progress is None:
        delayed.compute()
        return
    from dask.callbacks import Callback

    class _Cb(Callback):
        def _start_state(self, _dsk, state):  # dask's Callback protocol
            self._total = max(1, len(state["ready"]) + len(state["waiting"]))
            self._done = 0

        def _posttask(self, key, result, _dsk, state, _worker_id):
            self._done += 1
            progress(min(n_lines, int(n_lines * self._done / self._total)), n_lines)

    with _Cb():
        delayed.compute()
    progress(n_lines, n_lines)


def read_cube(path, *, chunks: int | None = 64):
    """Open a cube written by :func:`write_cube` (NetCDF: lazily, in chunks of lines).

    Returns
    -------
    xarray.Dataset
        ``reflectance(line, sample, band)`` with ``wavelength_nm`` (and ``fwhm_nm``).
    """
    import xarray as xr

    path = Path(path)
    fmt = cube_format(path)
    if fmt == "netcdf":
        if not path.is_file():
            raise InputError(f"cube file {str(path)!r} not found")
        return xr.open_dataset(path, engine="h5netcdf", chunks={"line": chunks} if chunks else None)
    from hsgeo.io.envi import read_envi

    data, hdr = read_envi(_envi_paths(path, fmt))
    refl = data.transpose(1, 2, 0).astype(np.float32)
    refl = np.where(refl == ENVI_IGNORE_VALUE, np.float32(np.nan), refl)
    coords = {"wavelength_nm": ("band", hdr["wavelength_nm"])}
    if "fwhm_nm" in hdr:
        coords["fwhm_nm"] = ("band", hdr["fwhm_nm"])
    return xr.Dataset({"reflectance": (("line", "sample", "band"), refl)}, coords=coords)
