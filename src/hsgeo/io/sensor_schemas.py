"""The schemas of the sensor file: one frozen dataclass per model of the registry
(:data:`hsgeo.io.sensor_file.MODELS`), whose fields are the keys of ``[sensor]`` with their
units, limits and defaults, and the further tables a model's file may hold (the priors of
``hsgeo adjust-pushbroom``). :func:`hsgeo.io.sensor_file.read_sensor_file` loads a file into
them through the one loader (:func:`hsgeo.io.config.load_dataclass`); a new model adds its
dataclass here and its entry in :mod:`hsgeo.io.sensor_file`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, is_dataclass
from types import MappingProxyType

from hsgeo.io.config import Key
from hsgeo.sensors.panoramic import DAEDALUS_IFOV_DEG, DAEDALUS_N_PX
from hsgeo.sensors.rikola import RikolaCamera

__all__ = [
    "MAX_LEVER_ARM_M",
    "BODY",
    "present",
    "MountKeys",
    "LineScannerKeys",
    "LineScannerLinearKeys",
    "PushbroomKeys",
    "GnssInsPrior",
    "ObservationsPrior",
    "GcpPrior",
    "PUSHBROOM_PRIOR_TABLES",
    "PanoramicKeys",
    "FrameOpenCVKeys",
    "RikolaKeys",
    "ViewAngleKeys",
]

#: The largest lever arm taken as metres: no airborne or bench sensor sits 10 m from its
#: navigation reference point; beyond, the numbers are millimetres or centimetres.
MAX_LEVER_ARM_M = 10.0


def present(values) -> dict:
    """The keys a loaded table holds (fields that are not ``None``), as a dict; nested tables
    (dataclass fields) as dicts of theirs.
    """
    out = {}
    for f in fields(values):
        v = getattr(values, f.name)
        if is_dataclass(v):
            out[f.name] = present(v)
        elif v is not None:
            out[f.name] = v
    return out


def _key(kind: str, doc: str, default=None, **kw):
    """A field of a schema: its :class:`Key` (kind, unit, limits) and its default (``None``:
    an optional key absent from the file).
    """
    return field(default=default, metadata={"key": Key(kind, doc=doc, **kw)})


def _req(kind: str, doc: str, **kw):
    """A required field of a schema."""
    return field(metadata={"key": Key(kind, doc=doc, **kw)})


BODY = "body (x forward, y right, z down)"


@dataclass(frozen=True, kw_only=True)
class MountKeys:
    """The mount of a sensor in the body frame (x forward, y right, z down): the keys every
    model but ``pushbroom`` shares.
    """

    lever_arm_m: tuple[float, ...] = _key(
        "floats",
        f"lever arm, projection centre in the {BODY} frame, m (not mm)",
        (0.0, 0.0, 0.0),
        length=3,
        limit=MAX_LEVER_ARM_M,
    )
    boresight_deg: tuple[float, ...] = _key(
        "floats", "roll, pitch, heading of R_body_from_sensor, degrees", (0.0, 0.0, 0.0), length=3
    )


@dataclass(frozen=True, kw_only=True)
class LineScannerLinearKeys(MountKeys):
    """``line-scanner-linear-ifov``: the 000 line scanner without distortion."""

    zeta0_px: float = _req("float", "principal point ζ0 on the line, px", limit=1e5)
    c_px: float = _req("float", "principal distance, px", positive=True)


@dataclass(frozen=True, kw_only=True)
class LineScannerKeys(LineScannerLinearKeys):
    """``line-scanner``: the 000 line scanner, 000 eq. (2)."""

    K: tuple[float, ...] = _key(
        "floats", "K1..K3 of 000 eq. (2), px per (100 px)^(3, 5, 7)", (0.0, 0.0, 0.0), length=3
    )


@dataclass(frozen=True, kw_only=True)
class PushbroomKeys:
    """``pushbroom``: the 002 LP camera (and the former ``[camera]`` table); absent optional
    keys stay ``None`` (the workflow's defaults apply).
    """

    n_bands: int = _req("int", "number of bands", positive=True)
    pixel_mm: float = _req("float", "pixel pitch, mm (at most 1)", positive=True, limit=1.0)
    c_mm: float = _req("float", "principal distance, mm", positive=True, limit=2000.0)
    x0_mm: float | None = _key("float", "principal point x on the detector, mm", limit=100.0)
    y0_mm: float | None = _key("float", "principal point y on the detector, mm", limit=100.0)
    lever_arm_m: tuple[float, ...] | None = _key(
        "floats",
        "lever arm in the platform frame (x forward, y left, z up), m, not mm",
        length=3,
        limit=MAX_LEVER_ARM_M,
    )
    sigma_lever_m: float | None = _key(
        "float", "σ of the measured lever arm, m (adjust prior)", positive=True, limit=10.0
    )
    c_band_mm: tuple[float, ...] | None = _key(
        "floats", "principal distance of each band, mm", positive=True
    )
    distortion: tuple[float, ...] | None = _key(
        "floats", "K1 (mm^-2), K2 (mm^-4), P1, P2 (mm^-1) of 002 eq. (3)", length=4
    )
    boresight_deg: tuple[float, ...] | None = _key(
        "floats", "omega, phi, kappa of the boresight on the nominal mount, deg", length=3
    )


@dataclass(frozen=True, kw_only=True)
class GnssInsPrior:
    """``[gnss_ins]`` of a 002 camera file: the navigation's σ (``hsgeo adjust-pushbroom``)."""

    sigma_pos_m: tuple[float, ...] | None = _key(
        "floats", "σ of E, N, H, m", length=3, positive=True
    )
    sigma_att_deg: tuple[float, ...] | None = _key(
        "floats", "σ of roll, pitch, yaw, degrees", length=3, positive=True
    )


@dataclass(frozen=True, kw_only=True)
class ObservationsPrior:
    """``[observations]`` of a 002 camera file."""

    sigma_px: float | None = _key("float", "σ of an image coordinate, px", positive=True)


@dataclass(frozen=True, kw_only=True)
class GcpPrior:
    """``[gcp]`` of a 002 camera file."""

    sigma_m: float | None = _key("float", "σ of a GCP coordinate, m", positive=True)


#: The priors of ``hsgeo adjust-pushbroom`` a 002 camera file may carry (tables of the file).
PUSHBROOM_PRIOR_TABLES = MappingProxyType(
    {"gnss_ins": GnssInsPrior, "observations": ObservationsPrior, "gcp": GcpPrior}
)


@dataclass(frozen=True, kw_only=True)
class PanoramicKeys(MountKeys):
    """``panoramic``: the 004 whiskbroom scanner (defaults: the Daedalus of 004)."""

    n_px: int = _key("int", "pixels per scan", DAEDALUS_N_PX, positive=True)
    ifov_deg: float = _key("float", "angular pixel, deg", DAEDALUS_IFOV_DEG, positive=True)
    active_fraction: float = _key(
        "float",
        "share of the line period the mirror sweeps the pixels",
        2 * 43.0 / 360.0,
        positive=True,
        limit=1.0,
    )


@dataclass(frozen=True, kw_only=True)
class FrameOpenCVKeys(MountKeys):
    """``frame-opencv``: a frame camera in OpenCV's form."""

    fx_px: float = _req("float", "focal length x, px", positive=True)
    fy_px: float = _req("float", "focal length y, px", positive=True)
    cx_px: float = _req("float", "principal point x, px")
    cy_px: float = _req("float", "principal point y, px")
    distortion: tuple[float, ...] = _key(
        "floats", "k1, k2, p1, p2, k3 (OpenCV order)", (0.0,) * 5, length=5
    )
    image_size_px: tuple[float, ...] | None = _key(
        "floats", "w, h of the frames, px (optional)", length=2, positive=True
    )


@dataclass(frozen=True, kw_only=True)
class RikolaKeys(MountKeys):
    """``rikola``: the 003 Rikola two-sensor frame camera."""

    f_band_mm: tuple[float, ...] = _req("floats", "f of each band, mm", positive=True)
    band_sensor: tuple[float, ...] = _req("floats", "sensor of each band: 1 or 2", positive=True)
    bands: tuple[float, ...] | None = _key(
        "floats", "band numbers (default 1, 2, ...)", positive=True
    )
    pp_I_mm: tuple[float, ...] = _req("floats", "x0, y0 of sensor I, mm", length=2)
    pp_II_mm: tuple[float, ...] = _req("floats", "x0, y0 of sensor II, mm", length=2)
    distortion: tuple[float, ...] = _key(
        "floats", "K1 (mm^-2), K2 (mm^-4), K3 (mm^-6), P1, P2 (mm^-1)", (0.0,) * 5, length=5
    )
    rotation_deg: tuple[float, ...] = _key(
        "floats", "omega, phi, kappa of R_I_from_II, deg", (0.0,) * 3, length=3
    )
    offset_mm: tuple[float, ...] = _key(
        "floats", "sensor II's centre in sensor I's frame, mm", (0.0,) * 3, length=3
    )
    image_size_px: tuple[float, ...] = _key(
        "floats",
        "w, h, px",
        tuple(float(n) for n in RikolaCamera.image_size),
        length=2,
        positive=True,
    )
    pixel_mm: float = _key(
        "float", "pixel pitch, mm", RikolaCamera.pixel_mm, positive=True, limit=1.0
    )


@dataclass(frozen=True, kw_only=True)
class ViewAngleKeys(MountKeys):
    """``view-angle``: per-pixel view angles, from a CSV beside the file or as lists."""

    angles_csv: str | None = _key(
        "str", "CSV beside the sensor file: pixel, across_deg, along_deg[, band]"
    )
    across_deg: tuple[float, ...] | None = _key(
        "floats", "across-track angle per pixel, deg", limit=89.0
    )
    along_deg: tuple[float, ...] | None = _key(
        "floats", "along-track angle per pixel, deg", limit=89.0
    )
