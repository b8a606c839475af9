"""The one sensor file: ``[sensor] model = "..."`` read through a registry of models.

The registry (each model's schema and builder) and its one reader are one concern: a new model
adds its entry here and its schema, a frozen dataclass of its keys, in
:mod:`hsgeo.io.sensor_schemas`.

:func:`read_sensor` is the one way a sensor file becomes a sensor of :mod:`hsgeo.sensors`
(the face of :mod:`hsgeo.sensors.mount`: ``rays`` / ``project``). The file names its model;
each model of :data:`MODELS` has its keys (with units in their names), and a key the model
cannot use is an error that names the key and the model (and, when the key belongs to another
model, that model). Example, the 002 LP camera::

    [sensor]
    model = "pushbroom"
    n_bands = 3
    pixel_mm = 0.0065
    c_mm = 40.0
    c_band_mm = [40.0, 40.1, 40.2]
    distortion = [1e-4, 0, 0, 0]
    boresight_deg = [0.3, -0.2, 0.1]
    lever_arm_m = [0.1, 0.0, -0.2]

The models (``hsgeo.io.sensor_file.MODELS``): ``line-scanner`` (000 eq. (2), calibrated),
``line-scanner-linear-ifov`` (000, the uncalibrated model), ``pushbroom`` (002 LP camera),
``panoramic`` (004 whiskbroom), ``frame-opencv`` (a frame camera in OpenCV's form), ``rikola``
(003 two-sensor frame camera), ``view-angle`` (per-pixel view angles, the form manufacturers
calibrate in: ``angles_csv = "name.csv"`` beside the file, :mod:`hsgeo.io.view_angles`).
The files each command read before are recognised:

* the 000 sensor file of ``hsgeo geocode`` (``[sensor] model = "calibrated"`` or
  ``"linear-ifov"``) is read (the names are aliases of ``line-scanner`` and
  ``line-scanner-linear-ifov``); without ``model`` it is refused with the line to add;
* the 002 camera file (``[camera]``, with ``[gnss_ins]``, ``[observations]``, ``[gcp]``) is
  read as the ``pushbroom`` model (the same keys);
* the instrument files of ``hsgeo/data/instruments`` (``[instrument]``: a band split or a
  frame layout) are refused: they say what an instrument records, not its geometry, and the
  message spells out the sensor file to write.

**A mount in the wrong units is refused.** A lever arm beyond
:data:`~hsgeo.io.sensor_schemas.MAX_LEVER_ARM_M` (10 m) is taken for millimetres or centimetres.
A boresight under ``boresight_deg`` whose every non-zero angle, read as radians, is a round
number of degrees (a multiple of 0.001° to 1e-9) while the value itself is not a round number
(not a multiple of 0.001) is taken for radians
pasted at full precision (``0.005235987755982988`` is 0.3° in radians); radians rounded by
hand are not detected (0.0052 "degrees" is a valid 19″ boresight).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields, make_dataclass, replace
from types import MappingProxyType

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io.config import did_you_mean, load_dataclass, read_toml
from hsgeo.io.sensor_schemas import (
    PUSHBROOM_PRIOR_TABLES,
    FrameOpenCVKeys,
    LineScannerKeys,
    LineScannerLinearKeys,
    PanoramicKeys,
    PushbroomKeys,
    RikolaKeys,
    ViewAngleKeys,
    present,
)
from hsgeo.sensors.panoramic import PanoramicScanner
from hsgeo.sensors.rikola import RikolaCamera

__all__ = [
    "SensorModel",
    "MODELS",
    "ALIASES",
    "read_sensor",
    "read_sensor_tables",
    "read_sensor_file",
    "model_of",
    "sensor_toml",
]


@dataclass(frozen=True)
class SensorModel:
    """One model of the registry: its keys, how a sensor is built from them, an example.

    Attributes
    ----------
    name : str
        The ``[sensor] model`` of the file.
    doc : str
        What the model is, with the paper and equation.
    schema : type
        The frozen dataclass whose fields are the keys of ``[sensor]`` (besides ``model``):
        the file's ``[sensor]`` table is loaded into it by the one loader
        (:func:`hsgeo.io.config.load_dataclass`).
    build : callable
        ``build(values, where: str) -> sensor``, ``values`` the loaded ``schema`` instance.
    cls : type
        The sensor class built.
    example : dict
        Values of a valid ``[sensor]`` table (the registry's test and the docs use it).
    kind : {"scanning", "frame"}
        How the sensor moves: ``rays(pixels, t_s, trajectory)`` or ``rays(pixels, poses,
        view)``.
    tables : mapping of str to type
        Further tables the file may hold (read by a command, not part of the sensor), each a
        frozen dataclass whose every key is optional.
    relative_files : tuple of str
        Keys holding a file name relative to the sensor file (resolved before ``build``).
    """

    name: str
    doc: str
    schema: type
    build: Callable
    cls: type
    example: dict
    kind: str = "scanning"
    tables: Mapping[str, type] = field(default_factory=dict)
    relative_files: tuple = ()

    @property
    def keys(self) -> tuple[str, ...]:
        """The key names of ``[sensor]`` (the fields of :attr:`schema`)."""
        return tuple(f.name for f in fields(self.schema))

    def file_schema(self, table: str = "sensor") -> type:
        """The frozen dataclass of the whole file: ``[table]`` (the schema) and the optional
        :attr:`tables`.
        """
        return _file_schema(self, table)


_FILE_SCHEMAS: dict = {}


def _file_schema(model: SensorModel, table: str) -> type:
    key = (model.name, table)
    if key not in _FILE_SCHEMAS:
        parts = [(table, model.schema)] + [
            (t, cls, field(default=cls())) for t, cls in model.tables.items()
        ]
        name = f"{model.schema.__name__.removesuffix('Keys')}File"
        _FILE_SCHEMAS[key] = make_dataclass(name, parts, frozen=True, kw_only=True)
    return _FILE_SCHEMAS[key]


def _mount(v):
    from hsgeo.sensors.mount import Mount

    return Mount.from_rpy(np.deg2rad(v.boresight_deg), v.lever_arm_m)


def _line(v, where):
    from hsgeo.sensors.line import CalibratedLine, LineScanner

    return LineScanner(CalibratedLine(v.zeta0_px, v.c_px, tuple(v.K)), _mount(v))


def _line_ifov(v, where):
    from hsgeo.sensors.line import LinearIFOV, LineScanner

    return LineScanner(LinearIFOV(v.zeta0_px, v.c_px), _mount(v))


def _or(value, default):
    return default if value is None else value


def _pushbroom(v, where):
    from hsgeo.sensors.pushbroom import PushbroomCamera

    c = _or(v.c_band_mm, (v.c_mm,) * v.n_bands)
    if len(c) != v.n_bands:
        raise InputError(
            f"{where}: c_band_mm has {len(c)} values for n_bands = {v.n_bands}; give one "
            "principal distance per band"
        )
    return PushbroomCamera(
        tuple(c),
        v.pixel_mm,
        tuple(_or(v.distortion, (0.0, 0.0, 0.0, 0.0))),
        _or(v.x0_mm, 0.0),
        _or(v.y0_mm, 0.0),
        tuple(float(x) for x in np.deg2rad(_or(v.boresight_deg, (0.0, 0.0, 0.0)))),
        tuple(_or(v.lever_arm_m, (0.0, 0.0, 0.0))),
    )


def _panoramic(v, where):
    from hsgeo.sensors.panoramic import PanoramicScanner

    return PanoramicScanner(v.n_px, v.ifov_deg, _mount(v), v.active_fraction)


def _frame(v, where):
    from hsgeo.sensors.frame import FrameCamera

    intr = (v.fx_px, v.fy_px, v.cx_px, v.cy_px)
    size = v.image_size_px
    if size is not None and not all(float(x).is_integer() for x in size):
        raise InputError(f"{where}: image_size_px = {list(size)} must be whole pixels (w, h)")
    size = None if size is None else tuple(int(x) for x in size)
    return FrameCamera(intr, tuple(v.distortion), _mount(v), size)


def _view_angle(v, where):
    from hsgeo.io.view_angles import read_view_angles
    from hsgeo.sensors.view_angle import ViewAngleScanner

    if (v.angles_csv is not None) == (v.across_deg is not None):
        raise InputError(
            f"{where}: give the view angles either as angles_csv (a CSV beside the sensor file, "
            "columns pixel, across_deg, along_deg[, band]) or as across_deg (and along_deg) "
            "lists, not both or neither"
        )
    if v.angles_csv is not None:
        across, along = read_view_angles(v.angles_csv)
    else:
        across = np.asarray(v.across_deg, float)
        along = np.asarray(_or(v.along_deg, np.zeros_like(across)), float)
        if along.shape != across.shape:
            raise InputError(
                f"{where}: along_deg has {along.size} values for {across.size} pixels "
                "(across_deg); give one per pixel"
            )
    try:
        return ViewAngleScanner(np.deg2rad(across), np.deg2rad(along), _mount(v))
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def _rikola(v, where):
    f, s = v.f_band_mm, v.band_sensor
    bands = v.bands
    problems = []
    if len(s) != len(f):
        problems.append(f"band_sensor has {len(s)} values for {len(f)} bands (f_band_mm)")
    if not all(x in (1.0, 2.0) for x in s):
        problems.append("band_sensor values must be 1 (sensor I) or 2 (sensor II)")
    if bands is not None and (
        len(bands) != len(f)
        or not all(float(b).is_integer() for b in bands)
        or list(bands) != sorted(set(bands))
    ):
        problems.append("bands must be one increasing whole band number per f_band_mm value")
    if problems:
        raise InputError(f"{where}: " + "; ".join(problems))
    return RikolaCamera(
        tuple(f),
        tuple(int(x) for x in s),
        (tuple(v.pp_I_mm), tuple(v.pp_II_mm)),
        tuple(v.distortion),
        tuple(float(x) for x in np.deg2rad(v.rotation_deg)),
        tuple(v.offset_mm),
        tuple(int(x) for x in v.image_size_px),
        v.pixel_mm,
        None if bands is None else tuple(int(b) for b in bands),
        _mount(v),
    )


MODELS: Mapping[str, SensorModel] = {}


def _register(m: SensorModel) -> None:
    MODELS[m.name] = m  # type: ignore[index]


def _models():
    from hsgeo.sensors.frame import FrameCamera
    from hsgeo.sensors.line import LineScanner
    from hsgeo.sensors.pushbroom import PushbroomCamera
    from hsgeo.sensors.view_angle import ViewAngleScanner

    _register(
        SensorModel(
            "line-scanner",
            "the 000 line scanner, calibrated: 000 eq. (2) (hsgeo.sensors.line.CalibratedLine)",
            LineScannerKeys,
            _line,
            LineScanner,
            {"zeta0_px": 486.8, "c_px": 3539.0, "K": [1.459, -0.1636, 0.00526]},  # 000 Table 1
        )
    )
    _register(
        SensorModel(
            "line-scanner-linear-ifov",
            "the 000 line scanner, uncalibrated: view angle linear in the pixel (LinearIFOV)",
            LineScannerLinearKeys,
            _line_ifov,
            LineScanner,
            {"zeta0_px": 485.0, "c_px": 3600.0},
        )
    )
    _register(
        SensorModel(
            "pushbroom",
            "the 002 LP camera: 002 eq. (2)-(4) (hsgeo.sensors.pushbroom.PushbroomCamera)",
            PushbroomKeys,
            _pushbroom,
            PushbroomCamera,
            {
                "n_bands": 3,
                "pixel_mm": 0.0065,
                "c_mm": 40.0,
                "c_band_mm": [40.0, 40.1, 40.2],
                "distortion": [1e-4, 0.0, 0.0, 0.0],
                "boresight_deg": [0.3, -0.2, 0.1],
                "lever_arm_m": [0.1, 0.0, -0.2],
            },
            tables=PUSHBROOM_PRIOR_TABLES,
        )
    )
    _register(
        SensorModel(
            "panoramic",
            "the 004 panoramic (whiskbroom) scanner (hsgeo.sensors.panoramic.PanoramicScanner)",
            PanoramicKeys,
            _panoramic,
            PanoramicScanner,
            {"n_px": 716, "ifov_deg": 0.12, "boresight_deg": [0.2, -0.1, 0.3]},
        )
    )
    _register(
        SensorModel(
            "frame-opencv",
            "a frame camera in OpenCV's form (hsgeo.sensors.frame.FrameCamera)",
            FrameOpenCVKeys,
            _frame,
            FrameCamera,
            {
                "fx_px": 1200.0,
                "fy_px": 1190.0,
                "cx_px": 640.0,
                "cy_px": 480.0,
                "distortion": [-0.2, 0.05, 1e-3, -5e-4, 0.0],
            },
            kind="frame",
        )
    )
    _register(
        SensorModel(
            "rikola",
            "the 003 Rikola two-sensor frame camera (hsgeo.sensors.rikola.RikolaCamera)",
            RikolaKeys,
            _rikola,
            RikolaCamera,
            {
                "f_band_mm": [8.7, 8.8, 8.75],
                "band_sensor": [2, 1, 1],
                "bands": [1, 2, 3],
                "pp_I_mm": [0.05, -0.03],
                "pp_II_mm": [-0.02, 0.04],
                "distortion": [-2e-3, 1e-5, 0.0, 1e-5, -2e-5],
                "rotation_deg": [0.1, -0.05, 0.2],
            },
            kind="frame",
        )
    )

    across = np.linspace(-17.0, 17.0, 971)  # a 34° line of 971 pixels with a slight smile
    _register(
        SensorModel(
            "view-angle",
            "a line scanner given by per-pixel view angles, one table or one per band "
            "(hsgeo.sensors.view_angle.ViewAngleScanner; table: hsgeo.io.view_angles)",
            ViewAngleKeys,
            _view_angle,
            ViewAngleScanner,
            {
                "across_deg": [round(float(x), 9) for x in across],
                "along_deg": [round(0.05 * (float(x) / 17.0) ** 2, 9) for x in across],
            },
            relative_files=("angles_csv",),
        )
    )


_models()
MODELS = MappingProxyType(dict(MODELS))

#: The model names of the former ``hsgeo geocode --sensor`` file, read as their models.
ALIASES = MappingProxyType(
    {"calibrated": "line-scanner", "linear-ifov": "line-scanner-linear-ifov"}
)


def _models_text() -> str:
    return ", ".join(repr(k) for k in MODELS)


def _owners(key: str) -> list[str]:
    return [n for n, m in MODELS.items() if key in m.keys]


def _instrument_refusal(path, cfg) -> InputError:
    kind = (
        "a band split (hsgeo.io.read_band_split)"
        if "bands" in cfg
        else "a frame layout (hsgeo.io.read_frame_layouts)"
        if "frame" in cfg
        else "an instrument description"
    )
    if "bands" in cfg:
        how = (
            'write [sensor] model = "rikola" with band_sensor = its [bands] sensor list, '
            "f_band_mm (one focal length per band, mm), pp_I_mm and pp_II_mm (from a "
            "calibration, e.g. hsgeo reproduce rikola)"
        )
    else:
        how = (
            'write [sensor] model = "line-scanner" with zeta0_px, c_px and K of a calibration '
            "(hsgeo calibrate-line)"
        )
    return InputError(
        f"sensor file {path}: this is an instrument file ([instrument]), {kind}: what the "
        f"instrument records, not its geometry; {how}"
    )


def read_sensor_file(path, what: str = "sensor file"):
    """A sensor file loaded into its model's schema: ``(model, file, table)``.

    ``file`` is an instance of ``MODELS[model].file_schema(table)``: ``getattr(file, table)``
    the sensor's keys (an instance of the model's :attr:`SensorModel.schema`), the further
    tables (the priors of ``hsgeo adjust-pushbroom`` for ``pushbroom``) beside it; ``table``
    is the name of the sensor's table in the file (``"sensor"``, or ``"camera"`` for the 002
    camera file, read as model ``pushbroom``). The file is read by :func:`read_toml` and
    loaded by :func:`~hsgeo.io.config.load_dataclass` once its model is known.
    """
    cfg = read_toml(path, what)
    if "camera" in cfg and "sensor" not in cfg:  # the 002 camera file of adjust-pushbroom
        out = load_dataclass(MODELS["pushbroom"].file_schema("camera"), cfg, f"{what} {path}")
        _check_mount(path, "camera", out.camera)
        return "pushbroom", out, "camera"
    if "instrument" in cfg and "sensor" not in cfg:
        raise _instrument_refusal(path, cfg)
    s = cfg.get("sensor")
    if not isinstance(s, dict):
        raise InputError(
            f"{what} {path}: [sensor]: missing table; a sensor file starts with [sensor] and "
            f'model = "..." (one of {_models_text()}), or is the former 002 camera file '
            "with a [camera] table"
        )
    if "model" not in s:
        raise InputError(
            f'{what} {path}: [sensor] model: missing; add model = "line-scanner" if this is the '
            "000 line-scanner file (the former default, model = 'calibrated'), or one of "
            f"{_models_text()}"
        )
    name = s["model"]
    name = ALIASES.get(name, name) if isinstance(name, str) else name
    if name not in MODELS:
        raise InputError(
            f"{what} {path}: [sensor] model: unknown model {s['model']!r}"
            f"{did_you_mean(str(s['model']), list(MODELS) + list(ALIASES))} "
            f"(known: {_models_text()})"
        )
    model = MODELS[name]
    problems = []
    for k in s:
        if k == "model" or k in model.keys:
            continue
        owners = _owners(k)
        if owners:
            problems.append(
                f"[sensor] {k}: model {name!r} cannot use this key (a key of model "
                f"{', '.join(repr(o) for o in owners)}){did_you_mean(k, model.keys)}; remove it "
                "or change the model"
            )
        else:
            problems.append(
                f"[sensor] {k}: unknown key for model {name!r}{did_you_mean(k, model.keys)} "
                f"(known: {', '.join(model.keys)})"
            )
    for t in cfg:
        if t != "sensor" and t not in model.tables:
            allowed = ", ".join(f"[{x}]" for x in ("sensor", *model.tables))
            problems.append(
                f"[{t}]: a table model {name!r} cannot use{did_you_mean(t, model.tables)} "
                f"(allowed: {allowed})"
            )
    if problems:
        raise InputError(f"{what} {path}: " + "; ".join(problems))
    table = {k: v for k, v in s.items() if k != "model"}
    out = load_dataclass(model.file_schema(), {**cfg, "sensor": table}, f"{what} {path}")
    _check_mount(path, "sensor", out.sensor)
    return name, out, "sensor"


def read_sensor_tables(path, what: str = "sensor file") -> tuple[str, dict, str]:
    """The model name and the checked tables of a sensor file as dicts of the keys the file
    gives (and the schema's defaults): ``(model, {"sensor": values, other tables ...},
    table)`` (:func:`read_sensor_file`; the sensor's table under ``"sensor"`` whatever its
    name in the file). Absent optional tables are empty dicts.
    """
    name, out, table = read_sensor_file(path, what)
    d = present(out)
    d["sensor"] = d.pop(table)
    return name, d, table


def _check_mount(path, table: str, v) -> None:
    """A boresight in radians under ``boresight_deg`` (see the module docstring)."""
    b = np.asarray(_or(v.boresight_deg, ()), dtype=float)
    nz = b[b != 0]
    if nz.size == 0:
        return
    deg = np.rad2deg(nz) * 1000.0
    round_deg = np.abs(deg - np.round(deg)) < 1e-6
    round_self = np.abs(nz * 1000.0 - np.round(nz * 1000.0)) < 1e-9
    if np.all(round_deg & ~round_self):
        shown = ", ".join(f"{x:.6g}" for x in np.rad2deg(b))
        given = ", ".join(f"{x:.17g}" for x in b)
        raise InputError(
            f"sensor file {path}: [{table}] boresight_deg = [{given}] are radians (each is a "
            f"round number of degrees in radians: [{shown}]°); give degrees: boresight_deg = "
            f"[{shown}]"
        )


def read_sensor(path):
    """The sensor a sensor file describes (see the module docstring for the format).

    Parameters
    ----------
    path : str or Path
        TOML with ``[sensor] model = "..."`` and the model's keys (:data:`MODELS`), or the
        002 camera file (``[camera]``).

    Returns
    -------
    sensor
        ``LineScanner``, ``PushbroomCamera``, ``PanoramicScanner``, ``FrameCamera`` or
        ``RikolaCamera`` (:mod:`hsgeo.sensors`).

    Raises
    ------
    InputError
        Missing or malformed file; no or an unknown model; a key the model cannot use (naming
        the key, the model and the models that use it); missing keys; values of the wrong type
        or beyond their unit's range; a mount in the wrong units; an instrument file.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "s.toml"
    >>> _ = p.write_text(sensor_toml("panoramic", {"n_px": 716}))
    >>> read_sensor(p).n_px
    716
    """
    from pathlib import Path

    name, out, table = read_sensor_file(path)
    values = getattr(out, table)
    for k in MODELS[name].relative_files:  # a file named in the sensor file: beside it
        if getattr(values, k) is not None:
            values = replace(values, **{k: str(Path(path).parent / getattr(values, k))})
    return MODELS[name].build(values, f"sensor file {path}: [{table}]")


def model_of(sensor) -> str:
    """The registry name of a sensor's model (:data:`MODELS`)."""
    from hsgeo.sensors.adjustment import sensor_model

    return sensor_model(sensor)


def sensor_toml(model: str, values: Mapping) -> str:
    """The text of a sensor file of ``model`` with ``values`` (e.g. a model's ``example``)."""

    def fmt(v):
        if isinstance(v, str):
            return f'"{v}"'
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(repr(float(x)) for x in v) + "]"
        return repr(v)

    lines = ["[sensor]", f'model = "{model}"'] + [f"{k} = {fmt(v)}" for k, v in values.items()]
    return "\n".join(lines) + "\n"
