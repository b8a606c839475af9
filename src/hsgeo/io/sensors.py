"""The former per-command sensor files, the adjustment JSON and the instrument files.

A sensor file is read by :func:`hsgeo.io.read_sensor` (:mod:`hsgeo.io.sensor_file`, one
registry of models); :func:`read_pushbroom_camera` and :func:`read_scanning_sensor` are that
reader restricted to what a command can use. :func:`read_sensor_toml` and
:func:`read_camera_toml` are the low-level readers of the former ``hsgeo geocode --sensor``
(000) and ``hsgeo adjust-pushbroom --camera`` (002) files, which ``read_sensor`` reads too.
:func:`read_adjustment` reads the adjusted camera and node corrections that ``hsgeo
adjust-pushbroom --json`` prints (apply them with :func:`hsgeo.sensors.adjusted`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, fields

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import read_text
from hsgeo.io.config import Key, read_dataclass

__all__ = [
    "LineSensorTable",
    "LineSensorFile",
    "BandSplitInstrument",
    "FrameLayoutInstrument",
    "BandsTable",
    "FrameTable",
    "read_sensor_toml",
    "read_camera_toml",
    "read_pushbroom_camera",
    "read_adjustment",
    "read_scanning_sensor",
    "read_band_split",
    "read_frame_layouts",
    "BandSplitFile",
    "FrameLayoutFile",
    "MAX_NODE_CORRECTION",
]


def _key(kind: str, doc: str, **kw):
    return field(metadata={"key": Key(kind, doc=doc, **kw)})


@dataclass(frozen=True, kw_only=True)
class LineSensorTable:
    """``[sensor]`` of the former ``hsgeo geocode --sensor`` file: a line scanner (000 eq. (2))
    and its boresight.
    """

    model: str = field(
        default="calibrated",
        metadata={
            "key": Key(
                "str",
                choices=("calibrated", "linear-ifov"),
                doc="'calibrated' (000 eq. (2)) or 'linear-ifov' (no distortion)",
            )
        },
    )
    zeta0_px: float = _key("float", "principal point ζ0 on the line, px", limit=1e5)
    c_px: float = _key("float", "principal distance, px", positive=True)
    K: tuple[float, ...] = field(
        default=(0.0, 0.0, 0.0),
        metadata={
            "key": Key(
                "floats",
                length=3,
                doc="K1..K3 of 000 eq. (2), px per (100 px)^(3, 5, 7); calibrated only",
            )
        },
    )
    boresight_deg: tuple[float, ...] = field(
        default=(0.0, 0.0, 0.0),
        metadata={
            "key": Key("floats", length=3, doc="roll, pitch, heading of R_body_from_sensor, deg")
        },
    )


@dataclass(frozen=True, kw_only=True)
class LineSensorFile:
    """The former ``hsgeo geocode --sensor`` file (the schema of :func:`read_sensor_toml`)."""

    sensor: LineSensorTable


def read_sensor_toml(path):
    """A line-scanner description: ``(LineGeometry, boresight_rad)``.

    Format::

        [sensor]
        model = "calibrated"          # 000 eq. (2); or "linear-ifov" (no distortion)
        zeta0_px = 486.8
        c_px = 3539.0
        K = [1.459, -0.1636, 0.00526] # calibrated only; δ in px, (ζ − ζ0) in units of 100 px
        boresight_deg = [0.0, 0.0, 0.0]   # roll, pitch, heading of R_body_from_sensor

    Returns
    -------
    geometry : hsgeo.sensors.line.CalibratedLine or hsgeo.sensors.line.LinearIFOV
    boresight_rad : (3,) ndarray
        Roll, pitch, heading (rad).

    Raises
    ------
    InputError
        Missing file, malformed TOML, unknown or misspelled keys, missing ``zeta0_px`` /
        ``c_px``, values of the wrong type (:func:`~hsgeo.io.config.read_dataclass`).
    """
    from hsgeo.sensors.line import CalibratedLine, LinearIFOV

    s = read_dataclass(path, LineSensorFile, "sensor file").sensor
    if s.model == "linear-ifov" and any(s.K):
        raise InputError(
            f"sensor file {path}: [sensor] K is the distortion of model 'calibrated'; remove it "
            "or set model = 'calibrated' (model 'linear-ifov' has no distortion)"
        )
    if s.model == "calibrated":
        geom = CalibratedLine(s.zeta0_px, s.c_px, tuple(s.K))
    else:
        geom = LinearIFOV(s.zeta0_px, s.c_px)
    return geom, np.deg2rad(np.asarray(s.boresight_deg, dtype=float))


def read_camera_toml(path) -> dict:
    """The camera file of ``hsgeo adjust-pushbroom``, checked (the ``pushbroom`` model's
    schema, :class:`hsgeo.io.sensor_file.PushbroomKeys`, under ``[camera]``, and its priors).

    Format::

        [camera]
        n_bands = 4
        pixel_mm = 0.0065
        c_mm = 40.0
        x0_mm = 0.0                      # optional, as all below
        y0_mm = 0.0
        lever_arm_m = [0.1, 0.0, -0.2]
        sigma_lever_m = 0.02
        [gnss_ins]
        sigma_pos_m = [0.013, 0.013, 0.020]
        sigma_att_deg = [0.005, 0.005, 0.008]
        [observations]
        sigma_px = 0.5
        [gcp]
        sigma_m = 0.01

    Returns
    -------
    dict of dict
        The tables with the keys the file gives (angles still in degrees, as named).
    """
    from hsgeo.io.sensor_file import MODELS
    from hsgeo.io.sensor_schemas import present

    schema = MODELS["pushbroom"].file_schema("camera")
    return present(read_dataclass(path, schema, "camera file"))


def read_pushbroom_camera(path):
    """The 002 camera as a sensor: :func:`hsgeo.io.read_sensor` of a file whose model is
    ``pushbroom`` (or the former ``[camera]`` file, :func:`read_camera_toml`).

    Uses ``c_band_mm`` (one principal distance per band; default ``c_mm`` for all
    ``n_bands``), ``pixel_mm``, ``x0_mm``, ``y0_mm``, ``distortion``, ``boresight_deg`` and
    ``lever_arm_m``; the σ keys (for ``hsgeo adjust-pushbroom``) are read and not used.

    Returns
    -------
    hsgeo.sensors.pushbroom.PushbroomCamera
    """
    return _read_kind(path, ("pushbroom",), "the 002 pushbroom camera")


def read_scanning_sensor(path):
    """A scanning sensor for ``hsgeo geocode --sensor``: :func:`hsgeo.io.read_sensor` of a file
    whose model is a line scanner, the pushbroom camera or the panoramic scanner (the former
    000 ``[sensor]`` file and the 002 ``[camera]`` file included).

    Returns
    -------
    hsgeo.sensors.line.LineScanner, hsgeo.sensors.pushbroom.PushbroomCamera or
    hsgeo.sensors.panoramic.PanoramicScanner
    """
    from hsgeo.io.sensor_file import MODELS

    scanning = tuple(n for n, m in MODELS.items() if m.kind == "scanning")
    return _read_kind(path, scanning, "a scanning sensor")


def _read_kind(path, models: tuple, what: str):
    """:func:`hsgeo.io.read_sensor`, refusing a sensor of a model not in ``models``."""
    from hsgeo.io.sensor_file import model_of, read_sensor

    sensor = read_sensor(path)
    name = model_of(sensor)
    if name not in models:
        raise InputError(
            f"sensor file {path}: model {name!r} is not {what}; this command takes "
            f"model {' or '.join(repr(m) for m in models)}"
        )
    return sensor


@dataclass(frozen=True, kw_only=True)
class BandSplitInstrument:
    """``[instrument]`` of a band split."""

    name: str = _key("str", "instrument name")
    n_sensors: int = _key("int", "number of sensors", positive=True)


@dataclass(frozen=True, kw_only=True)
class FrameLayoutInstrument:
    """``[instrument]`` of a frame layout."""

    name: str = _key("str", "instrument name")
    bits: int = _key("int", "bit depth of a raw value", positive=True)


@dataclass(frozen=True, kw_only=True)
class BandsTable:
    """``[bands]`` of a band split: one entry per band."""

    band: tuple[float, ...] = _key("floats", "band numbers, 1-based")
    sensor: tuple[float, ...] = _key("floats", "sensor of each band, 1-based")
    gap_nm: tuple[float, ...] = _key("floats", "FPI air gap of each band, nm", positive=True)


@dataclass(frozen=True, kw_only=True)
class BandSplitFile:
    """An instrument's band split (``data/instruments/*.toml``): which sensor records each
    band (the schema of :func:`read_band_split`).
    """

    instrument: BandSplitInstrument
    bands: BandsTable


def read_band_split(path=None) -> np.ndarray:
    """An instrument's band split: band, sensor and FPI air gap (:class:`BandSplitFile`).

    Parameters
    ----------
    path : str or Path, optional
        Default: the Rikola FPI2015 of 003 (``hsgeo/data/instruments/rikola_fpi2015.toml``).

    Returns
    -------
    structured ndarray
        Fields ``band`` (i4), ``sensor`` (i4), ``gap_nm`` (f8), one row per band, in band order.
    """
    from pathlib import Path

    if path is None:
        path = Path(__file__).parent.parent / "data" / "instruments" / "rikola_fpi2015.toml"
    f = read_dataclass(path, BandSplitFile, "instrument file")
    b, n = f.bands, f.instrument.n_sensors
    lengths = {len(getattr(b, k)) for k in ("band", "sensor", "gap_nm")}
    band, sensor = np.asarray(b.band), np.asarray(b.sensor)
    problems = []
    if len(lengths) != 1:
        problems.append("[bands] band, sensor and gap_nm must have one entry per band")
    elif not (np.array_equal(band, np.arange(1, band.size + 1))):
        problems.append("[bands] band must be 1, 2, 3, … in order")
    elif not (np.all(sensor == np.round(sensor)) and np.all((sensor >= 1) & (sensor <= n))):
        problems.append(f"[bands] sensor must be integers 1…{n} (n_sensors)")
    if problems:
        raise InputError(f"instrument file {path}: " + "; ".join(problems))
    out = np.zeros(band.size, dtype=[("band", "i4"), ("sensor", "i4"), ("gap_nm", "f8")])
    out["band"], out["sensor"], out["gap_nm"] = band, sensor, b.gap_nm
    return out


@dataclass(frozen=True, kw_only=True)
class FrameTable:
    """``[frame]`` of a frame layout: one entry per binning factor."""

    binning: tuple[float, ...] = _key("floats", "binning factors", positive=True)
    n_rows: tuple[float, ...] = _key("floats", "spectral rows per frame", positive=True)
    n_columns: tuple[float, ...] = _key("floats", "columns per frame", positive=True)
    n_reflected_columns: tuple[float, ...] = _key(
        "floats", "columns that see the scene", positive=True
    )
    n_incident_columns: tuple[float, ...] = _key(
        "floats", "columns of the diffuse collector", positive=True
    )
    frame_rate_hz: tuple[float, ...] = _key("floats", "frame rate, Hz", positive=True)


@dataclass(frozen=True, kw_only=True)
class FrameLayoutFile:
    """A line scanner's raw-frame layout (``data/instruments/*.toml``): rows, columns, the
    scene's and the diffuse collector's columns and the frame rate, one entry per binning
    factor (the schema of :func:`read_frame_layouts`).
    """

    instrument: FrameLayoutInstrument
    frame: FrameTable


def read_frame_layouts(path=None) -> dict:
    """A line scanner's raw-frame layout per binning factor (:class:`FrameLayoutFile`).

    Parameters
    ----------
    path : str or Path, optional
        Default: the ImSpector V9 + PixelFly of 001
        (``hsgeo/data/instruments/imspector_v9_pixelfly.toml``).

    Returns
    -------
    dict
        ``name``, ``bits`` and ``layouts``: binning factor -> dict with ``n_rows``,
        ``n_columns``, ``n_reflected``, ``n_incident`` (int) and ``frame_rate_hz`` (float).
    """
    from pathlib import Path

    if path is None:
        path = Path(__file__).parent.parent / "data" / "instruments" / "imspector_v9_pixelfly.toml"
    file = read_dataclass(path, FrameLayoutFile, "instrument file")
    f = {k.name: getattr(file.frame, k.name) for k in fields(file.frame)}
    counts = ("binning", "n_rows", "n_columns", "n_reflected_columns", "n_incident_columns")
    problems = []
    if len({len(v) for v in f.values()}) != 1:
        problems.append("[frame] every key must have one entry per binning factor")
    elif not all(float(x).is_integer() for k in counts for x in f[k]):
        problems.append(f"[frame] {', '.join(counts)} must be whole numbers")
    elif any(
        r + i != c
        for r, i, c in zip(
            f["n_reflected_columns"], f["n_incident_columns"], f["n_columns"], strict=True
        )
    ):
        problems.append("[frame] n_reflected_columns + n_incident_columns must be n_columns")
    elif len(set(f["binning"])) != len(f["binning"]):
        problems.append("[frame] binning factors must differ")
    if problems:
        raise InputError(f"instrument file {path}: " + "; ".join(problems))
    layouts = {
        int(b): {
            "n_rows": int(f["n_rows"][i]),
            "n_columns": int(f["n_columns"][i]),
            "n_reflected": int(f["n_reflected_columns"][i]),
            "n_incident": int(f["n_incident_columns"][i]),
            "frame_rate_hz": float(f["frame_rate_hz"][i]),
        }
        for i, b in enumerate(f["binning"])
    }
    return {
        "name": file.instrument.name,
        "bits": file.instrument.bits,
        "layouts": layouts,
    }


def read_adjustment(path) -> dict:
    """Camera parameters and node corrections from ``hsgeo adjust-pushbroom --json``.

    Returns
    -------
    dict
        ``boresight_rad`` (3,), ``lever_arm_m`` (3,), ``distortion`` (4,), ``c_mm`` (n,),
        ``t_nodes_s`` (n_nodes,), ``nodes`` (n_nodes, 6) in m and rad, ``node_columns``, and
        ``sensor_model`` = ``"pushbroom"`` (the model of the camera parameters); apply it with
        :func:`hsgeo.sensors.adjusted`.

    Raises
    ------
    InputError
        Not that command's JSON, a key missing or not finite, values beyond a correction, or
        an adjustment that did not converge (``"converged": false``).
    """
    text = read_text(path, "--adjustment file", "JSON")
    where = f"--adjustment {str(path)!r}"
    try:
        d = json.loads(text)
        par, nodes = d["parameters"], d["nodes"]
        columns = tuple(nodes["columns"])
    except (ValueError, KeyError, TypeError) as exc:
        raise InputError(
            f"{where}: not the JSON of `hsgeo adjust-pushbroom --json` "
            f"({type(exc).__name__}: {exc}); give that command's output"
        ) from None
    if d.get("converged", True) is not True:
        raise InputError(
            f"{where}: the adjustment did not converge (converged: {d.get('converged')!r}), so "
            "its camera and node corrections are not a solution; rerun hsgeo adjust-pushbroom "
            "until it converges (its fit verdict names the likely causes) and give that output"
        )
    keys = {
        "boresight_rad": ("parameters.boresight_deg.value", lambda: par["boresight_deg"]["value"]),
        "lever_arm_m": ("parameters.lever_arm_m.value", lambda: par["lever_arm_m"]["value"]),
        "distortion": ("parameters.distortion.value", lambda: par["distortion"]["value"]),
        "c_mm": ("parameters.c_mm.value", lambda: par["c_mm"]["value"]),
        "t_nodes_s": ("nodes.t_s", lambda: nodes["t_s"]),
        "nodes": ("nodes.value", lambda: nodes["value"]),
    }
    out = {k: _adjustment_array(where, key, get) for k, (key, get) in keys.items()}
    out["boresight_rad"] = np.radians(out["boresight_rad"])
    out["c_mm"] = np.atleast_1d(out["c_mm"])
    out["node_columns"] = columns
    out["sensor_model"] = "pushbroom"  # whose parameters these are (hsgeo.sensors.adjusted)
    _check_adjustment(where, out)
    return out


def _adjustment_array(where: str, key: str, get) -> np.ndarray:
    """One array of the adjust-pushbroom result, finite, or an error naming its key."""
    try:
        a = np.asarray(get(), dtype=float)
    except (ValueError, KeyError, TypeError) as exc:
        raise InputError(
            f"{where}: {key} is missing or not numbers ({type(exc).__name__}: {exc}); give the "
            "output of `hsgeo adjust-pushbroom --json`"
        ) from None
    if not np.all(np.isfinite(a)):
        raise InputError(
            f"{where}: {key} holds NaN or inf; the adjustment did not give finite values, rerun "
            "hsgeo adjust-pushbroom"
        )
    return a


#: The largest node correction taken as one (m; rad): beyond, the file is not a correction of
#: a GNSS/INS solution (adjust-pushbroom's corrections are metres and hundredths of a degree).
MAX_NODE_CORRECTION = (1000.0, 1.0)


def _check_adjustment(where: str, out: dict) -> None:
    shapes = {"boresight_deg": (3,), "lever_arm_m": (3,), "distortion": (4,)}
    for k, shp in shapes.items():
        if out[k.replace("_deg", "_rad")].shape != shp:
            raise InputError(f"{where}: parameters.{k}.value must have {shp[0]} values")
    if np.any(np.abs(out["boresight_rad"]) > np.pi) or np.any(np.abs(out["lever_arm_m"]) > 100):
        raise InputError(
            f"{where}: boresight_deg beyond ±180° or lever_arm_m beyond ±100 m; give the output "
            "of `hsgeo adjust-pushbroom --json` (degrees, metres)"
        )
    if np.any(out["c_mm"] <= 0):
        raise InputError(f"{where}: c_mm must be positive (mm), got {out['c_mm'].tolist()}")
    n = out["t_nodes_s"].size
    if n < 4 or out["nodes"].shape != (n, len(out["node_columns"])):
        raise InputError(
            f"{where}: nodes.value must be ({n}, "
            f"{len(out['node_columns'])}) for {n} node times (at least 4)"
        )
    big = np.abs(out["nodes"][:, :3]).max() > MAX_NODE_CORRECTION[0]
    if big or np.abs(out["nodes"][:, 3:]).max() > MAX_NODE_CORRECTION[1]:
        raise InputError(
            f"{where}: nodes.value holds corrections beyond {MAX_NODE_CORRECTION[0]:g} m or "
            f"{MAX_NODE_CORRECTION[1]:g} rad, not those of a GNSS/INS solution; give the output "
            "of `hsgeo adjust-pushbroom --json` for this flight"
        )
