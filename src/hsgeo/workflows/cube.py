"""From raw ImSpector frames to a reflectance cube (001 §2.1, §2.4; ``hsgeo cube``).

The steps of 001 §2.4, in the order the physics needs them:

1. fit the dark signal h = a·T_exp + b of every pixel to dark frames at several exposure times
   (:func:`hsgeo.radiometry.fit_dark`), find the hot pixels, and subtract h from every frame;
2. average the diffuse collector's columns along each spectral line (hot pixels left out) and
   compute the reflection coefficient r = G_ref·E_ref·F(α) / (G_inc·E_inc·F(θ)) of every
   reflected pixel (001 §2.1), spectral rows averaged into bands;
3. stack the lines into an :class:`xarray.Dataset` (line, sample, band) backed by a Dask array
   computed in chunks of lines, so that a long run never sits in memory whole; writing it
   (:func:`hsgeo.io.cube.write_cube`) computes one chunk at a time.

The core (:func:`build_cube`) takes frozen :class:`CubeInputs` and :class:`CubeOptions` and
returns one :class:`CubeResult`; :func:`cube_files` is the file front end of ``hsgeo cube``.
Nothing here knows a simulation's truth.
"""

from __future__ import annotations

import sys
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.radiometry import (
    FULL_SCALE_DN,
    DarkModel,
    FrameLayout,
    band_fwhm_nm,
    bin_rows,
    find_hot_pixels,
    fit_dark,
    frame_layout,
    incident_mean,
    reflectance,
)

__all__ = [
    "CubeOptions",
    "CubeInputs",
    "CubeResult",
    "dark_model",
    "process_frames",
    "build_cube",
    "cube_files",
    "EXPOSURE_EXTRAPOLATION",
]


@dataclass(frozen=True)
class CubeOptions:
    """Settings of the cube pipeline.

    Attributes
    ----------
    binning : int
        The camera's binning factor, 1 or 2 (frame 1280 × 1024 or 640 × 512, 001 §2.1).
    rows_per_band : int
        Spectral rows averaged into one band (5 rows of 0.88 nm at binning 2 ≈ the 4.4 nm
        spectral resolution of 001 §2.1).
    lines_per_chunk : int
        Lines computed together (the memory of the pipeline is about one chunk).
    hot_k : float
        Threshold of :func:`hsgeo.radiometry.find_hot_pixels`.
    g_ref, g_inc : float
        Gains of the reflected and incident bands (001 §3.2: 1).
    f_alpha : float
        The diffuse collector's receiving pattern at the light's incidence, F(α).
    f_theta : tuple of float, optional
        The lens's receiving pattern F(θ) at every reflected sample (default: 1).

    References
    ----------
    .. [1] Krtalić, A., Miljković, V., Gajski, D. and Racetin, I. (2019). Spatial distortion
           assessments of a low-cost laboratory and field hyperspectral imaging system. Sensors
           19(19), 4267 (paper 001).
    """

    binning: int = 2
    rows_per_band: int = 5
    lines_per_chunk: int = 64
    hot_k: float = 8.0
    g_ref: float = 1.0
    g_inc: float = 1.0
    f_alpha: float = 1.0
    f_theta: tuple | None = None

    def __post_init__(self):
        frame_layout(self.binning)  # 1 or 2
        if int(self.rows_per_band) < 1 or int(self.lines_per_chunk) < 1:
            raise InputError("rows_per_band and lines_per_chunk must be positive integers")
        for name in ("g_ref", "g_inc", "f_alpha"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"{name} must be a positive number, got {v!r}")


@dataclass(frozen=True)
class CubeInputs:
    """What the pipeline reads.

    Attributes
    ----------
    frames, dark : frame sources
        Objects with ``n_frames``, ``frame_shape`` (rows, columns), ``exposure_s``
        ((n_frames,) s) and ``read(i0, i1)`` → (i1 − i0, rows, columns) uint16 raw DN, e.g.
        :class:`hsgeo.io.frames.FrameFolder`.
    wavelength_nm, fwhm_nm : (rows,) ndarray
        Spectral calibration of every frame row.
    """

    frames: object
    dark: object
    wavelength_nm: np.ndarray
    fwhm_nm: np.ndarray


@dataclass
class CubeResult:
    """The cube and what was learnt on the way.

    Attributes
    ----------
    cube : xarray.Dataset
        ``reflectance(line, sample, band)`` float32 (lazy, Dask), ``incident_dn(line, band)``,
        coordinates ``wavelength_nm``, ``fwhm_nm`` (band) and ``exposure_s`` (line); the
        settings as attributes.
    dark : DarkModel
    hot : (rows, columns) bool ndarray
    layout : FrameLayout
    options : CubeOptions
    files : list of Path
        Files written by the front end (empty for the in-memory core).
    """

    cube: object
    dark: DarkModel
    hot: np.ndarray
    layout: FrameLayout
    options: CubeOptions
    files: list = field(default_factory=list)

    def to_dict(self) -> dict:
        """A JSON-ready summary (no arrays)."""
        c = self.cube
        return {
            "lines": int(c.sizes["line"]),
            "samples": int(c.sizes["sample"]),
            "bands": int(c.sizes["band"]),
            "wavelength_nm": [float(c["wavelength_nm"][0]), float(c["wavelength_nm"][-1])],
            "binning": self.layout.binning,
            "n_hot_pixels": int(self.hot.sum()),
            "dark_exposures_s": sorted(set(self.dark.exposures_s)),
            "median_dark_current_dn_s": float(np.median(self.dark.a_dn_per_s)),
            "options": {k: v for k, v in asdict(self.options).items() if k != "f_theta"},
            "files": [str(p) for p in self.files],
        }


def _check(inputs: CubeInputs, layout: FrameLayout, options: CubeOptions) -> None:
    want = (layout.n_rows, layout.n_columns)
    for src, what in ((inputs.frames, "the frames"), (inputs.dark, "the dark frames")):
        if tuple(src.frame_shape) != want:
            r, c = src.frame_shape
            raise InputError(
                f"{what} are {r} × {c} px (rows × columns), binning {layout.binning} gives "
                f"{want[0]} × {want[1]}; use --binning {2 if layout.binning == 1 else 1} or "
                "other frames"
            )
    lam = np.asarray(inputs.wavelength_nm)
    if lam.shape != (layout.n_rows,) or np.asarray(inputs.fwhm_nm).shape != lam.shape:
        raise InputError(
            f"missing wavelengths: {lam.size} given for the frame's {layout.n_rows} spectral rows"
        )
    if options.f_theta is not None and len(options.f_theta) != layout.n_reflected:
        raise InputError(
            f"the lens pattern F(θ) has {len(options.f_theta)} values for "
            f"{layout.n_reflected} reflected samples"
        )


def dark_model(dark, options: CubeOptions = CubeOptions()) -> tuple[DarkModel, np.ndarray]:
    """Fit h = a·T_exp + b to a dark frame source (one frame in memory at a time) and find the
    hot pixels: ``(DarkModel, hot mask)``.
    """
    frames = (dark.read(i, i + 1)[0] for i in range(dark.n_frames))
    model = fit_dark(frames, dark.exposure_s)
    return model, find_hot_pixels(model, options.hot_k)


def process_frames(
    raw_dn,
    exposure_s,
    dark: DarkModel,
    hot,
    layout: FrameLayout,
    options,
    *,
    first_index: int = 0,
    where=None,
):
    """Dark correction and reflectance of a block of frames (001 §2.1, §2.4).

    Parameters
    ----------
    raw_dn : (n, rows, columns) ndarray
    exposure_s : (n,) ndarray
    dark, hot, layout, options
        From :func:`dark_model`, :func:`hsgeo.radiometry.frame_layout`, :class:`CubeOptions`.
    first_index : int
        Index of the first frame in the run (for messages).
    where : callable, optional
        ``where(i)`` → a text naming frame ``i`` (its file) in messages.

    Returns
    -------
    reflectance : (n, samples, bands) float32 ndarray
        NaN where a reflected pixel was saturated.
    incident_dn : (n, bands) float32 ndarray
        Dark-corrected incident signal averaged along each line, per band.

    Raises
    ------
    InputError
        The diffuse collector's signal is saturated in a frame, or holds no light.

    References
    ----------
    .. [1] Krtalić, A., Miljković, V., Gajski, D. and Racetin, I. (2019). Spatial distortion
           assessments of a low-cost laboratory and field hyperspectral imaging system. Sensors
           19(19), 4267 (paper 001).
    """
    raw = np.asarray(raw_dn)
    t = np.asarray(exposure_s, dtype=float)
    nr = layout.n_reflected
    a32 = dark.a_dn_per_s.astype(np.float32)
    b32 = dark.b_dn.astype(np.float32)
    corr = raw.astype(np.float32)
    for k in range(corr.shape[0]):  # in place, frame by frame: a chunk's memory stays small
        corr[k] -= a32 * np.float32(t[k]) + b32  # 001 §2.4, h = a·T_exp + b
    sat = raw >= FULL_SCALE_DN
    bad = sat[:, :, nr:].any(axis=2)
    if bad.any():
        k, _ = np.argwhere(bad)[0]
        i = first_index + int(k)
        name = where(i) if where else f"frame {i}"
        raise InputError(
            f"{name}: the diffuse collector's incident signal is saturated ({FULL_SCALE_DN} DN) "
            f"in {int(bad[k].sum())} spectral rows, so the reflectance cannot be computed; "
            "record with a shorter exposure time"
        )
    e_inc = incident_mean(corr[:, :, nr:], hot[:, nr:])  # (n, rows), 001 §2.4
    dim = e_inc <= 0
    if dim.all(axis=1).any():
        i = first_index + int(np.flatnonzero(dim.all(axis=1))[0])
        name = where(i) if where else f"frame {i}"
        raise InputError(f"{name}: no light on the diffuse collector (incident signal ≤ dark)")
    f_theta = 1.0 if options.f_theta is None else np.asarray(options.f_theta, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = reflectance(
            corr[:, :, :nr],
            np.where(dim, np.nan, e_inc).astype(np.float32),
            g_ref=options.g_ref,
            g_inc=options.g_inc,
            f_alpha=options.f_alpha,
            f_theta=f_theta,
        )  # (n, rows, samples), 001 §2.1
    r[sat[:, :, :nr]] = np.nan
    del corr
    k = options.rows_per_band
    cube = bin_rows(r, k, axis=1).transpose(0, 2, 1).astype(np.float32)
    inc = bin_rows(e_inc, k, axis=1).astype(np.float32)
    return cube, inc


def build_cube(inputs: CubeInputs, options: CubeOptions = CubeOptions(), *, dark=None):
    """The reflectance cube of a run of frames, lazily (Dask, chunks of lines).

    Parameters
    ----------
    inputs : CubeInputs
    options : CubeOptions
    dark : (DarkModel, hot) tuple, optional
        A dark model fitted before (default: :func:`dark_model` of ``inputs.dark``).

    Returns
    -------
    CubeResult
    """
    import dask
    import dask.array as da
    import xarray as xr

    layout = frame_layout(options.binning)
    _check(inputs, layout, options)
    model, hot = dark_model(inputs.dark, options) if dark is None else dark
    src = inputs.frames
    n = int(src.n_frames)
    lam, fwhm = band_fwhm_nm(inputs.wavelength_nm, inputs.fwhm_nm, options.rows_per_band)
    nb, ns = lam.size, layout.n_reflected
    where = None
    if hasattr(src, "locate"):

        def where(i):
            p, j = src.locate(i)
            return f"frame {i} ({p.name}" + (f", frame {j} of the stack)" if j else ")")

    def block(i0, i1):
        return process_frames(
            src.read(i0, i1),
            src.exposure_s[i0:i1],
            model,
            hot,
            layout,
            options,
            first_index=i0,
            where=where,
        )

    refl, inc = [], []
    c = int(options.lines_per_chunk)
    for i0 in range(0, n, c):
        i1 = min(n, i0 + c)
        d = dask.delayed(block, pure=True)(i0, i1)
        refl.append(da.from_delayed(d[0], shape=(i1 - i0, ns, nb), dtype=np.float32))
        inc.append(da.from_delayed(d[1], shape=(i1 - i0, nb), dtype=np.float32))
    ds = xr.Dataset(
        {
            "reflectance": (("line", "sample", "band"), da.concatenate(refl, axis=0)),
            "incident_dn": (("line", "band"), da.concatenate(inc, axis=0)),
        },
        coords={
            "wavelength_nm": ("band", lam),
            "fwhm_nm": ("band", fwhm),
            "exposure_s": ("line", np.asarray(src.exposure_s, dtype=float)),
        },
        attrs={
            "title": "reflectance cube, r = G_ref E_ref F(α) / (G_inc E_inc F(θ)) (001 §2.1)",
            "binning": layout.binning,
            "frame_rate_hz": layout.frame_rate_hz,
            "rows_per_band": options.rows_per_band,
            "g_ref": options.g_ref,
            "g_inc": options.g_inc,
            "f_alpha": options.f_alpha,
            "n_hot_pixels": int(hot.sum()),
            "dark_exposures_s": ", ".join(f"{t:g}" for t in sorted(set(model.exposures_s))),
        },
    )
    ds["wavelength_nm"].attrs["units"] = "nm"
    ds["fwhm_nm"].attrs["units"] = "nm"
    ds["reflectance"].attrs["units"] = "1"
    return CubeResult(ds, model, hot, layout, options)


def _stderr_progress(done: int, total: int) -> None:
    width = 30
    k = int(width * done / max(total, 1))
    sys.stderr.write(f"\r  stacking lines [{'#' * k}{'.' * (width - k)}] {done}/{total}")
    if done >= total:
        sys.stderr.write("\n")
    sys.stderr.flush()


#: The survey's exposure times may lie this factor outside the dark frames' (the dark current
#: h = a·T + b is extrapolated that far); beyond, a unit is wrong (ms for s) or the dark frames
#: are another camera's setting
EXPOSURE_EXTRAPOLATION = 10.0


def _check_exposures(frames, dark) -> None:
    """The survey's exposure times near the dark frames' (exposures in ms where s are
    expected would otherwise give a wrong cube with exit 0).
    """
    t, td = np.asarray(frames.exposure_s), np.asarray(dark.exposure_s)
    lo, hi = td.min() / EXPOSURE_EXTRAPOLATION, td.max() * EXPOSURE_EXTRAPOLATION
    out = (t < lo) | (t > hi)
    if out.any():
        f, _ = frames.locate(int(np.flatnonzero(out)[0]))
        raise InputError(
            f"{frames.what} {str(frames.folder / 'exposures.csv')!r}: exposure_s of {f.name} is "
            f"{t[out][0]:g} s, but the dark frames (--dark) span {td.min():g}–{td.max():g} s "
            f"(the dark current is extrapolated at most {EXPOSURE_EXTRAPOLATION:g}× beyond "
            "them); give both exposure files in seconds (not ms), or dark frames of the "
            "survey's exposure times"
        )


def cube_files(
    raw_dir,
    dark_dir,
    output,
    *,
    options: CubeOptions = CubeOptions(),
    overwrite: bool = False,
    progress=False,
) -> CubeResult:
    """``hsgeo cube``: read the frame folders, build the cube, write it (see ``--help``).

    Every check comes before the work: the output (folder exists, not an input, an existing
    file only with ``overwrite``), the folders, the frame sizes, the exposure times and the
    wavelengths (:mod:`hsgeo.io.frames`).

    Parameters
    ----------
    raw_dir, dark_dir : str or Path
        Frame folders (:class:`hsgeo.io.frames.FrameFolder`); ``raw_dir`` holds
        ``wavelengths.csv``.
    output : str or Path
        ``.nc`` (NetCDF) or ``.hdr`` / ``.bsq`` / ``.bil`` / ``.bip`` (ENVI).
    options : CubeOptions
    overwrite : bool
    progress : bool or callable
        True draws a bar on stderr while stacking; a callable gets ``(done, total)``.
    """
    from hsgeo.io._files import check_outputs
    from hsgeo.io.cube import cube_outputs, write_cube
    from hsgeo.io.frames import FrameFolder, read_wavelengths

    outputs = cube_outputs(output)  # checks the format
    frames = FrameFolder(raw_dir, "RAW_DIR")
    dark = FrameFolder(dark_dir, "--dark")
    inputs_files = [*frames.files, *dark.files, Path(raw_dir) / "wavelengths.csv"]
    check_outputs([(p, "-o") for p in outputs], inputs_files, overwrite=overwrite)
    layout = frame_layout(options.binning)
    for src, what in ((frames, "RAW_DIR"), (dark, "--dark")):
        if tuple(src.frame_shape) != (layout.n_rows, layout.n_columns):
            r, c = src.frame_shape
            raise InputError(
                f"{what}: frames of {r} × {c} px (rows × columns), but --binning "
                f"{layout.binning} gives {layout.n_rows} × {layout.n_columns}; check --binning"
            )
    _check_exposures(frames, dark)
    lam, fwhm = read_wavelengths(Path(raw_dir) / "wavelengths.csv", layout.n_rows)
    res = build_cube(CubeInputs(frames, dark, lam, fwhm), options)
    bar = _stderr_progress if progress is True else (progress or None)
    res.files = write_cube(res.cube, output, inputs=inputs_files, progress=bar)
    return res
