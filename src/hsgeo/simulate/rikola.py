"""The Rikola FPI camera on a calibration bench (003 §3.1): an ArUco plate rendered per band.

Truth (:func:`make_truth`): per-band focal length from the gap model of 003 Table 4 (second) plus
scatter, a principal point per sensor (003 Table 3), one distortion set, sensor II rotated
relative to sensor I by the mean of 003 Table 4 (first), and ``n_cubes`` static camera poses.

Images (:func:`render_band`): for every pixel the *measured* image coordinate is turned into an
ideal ray by Brown's correction (the photogrammetric form evaluates the correction at the
measured coordinate, so no inversion is needed), the ray is intersected with the plate, and the
plate texture (ArUco markers from ``cv2.aruco.generateImageMarker``) is sampled on a
``supersample``² grid per pixel; a Gaussian PSF and pixel integration follow, then the band's
radiometry: the white level grows with the band's FWHM (fixed integration time, 003 §3.2), shot
and read noise, 12-bit quantisation and saturation.

Every image has its own random stream ``default_rng([seed, 1, cube, band])``, so a subset of
cubes and bands (the reduced size of the tests) renders the same pixels as the full set.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np

from hsgeo.distortion import brown_correction
from hsgeo.errors import InputError
from hsgeo.io.config import Key
from hsgeo.io.tables import write_csv_array
from hsgeo.papers import RIKOLA_BANDS, RIKOLA_CAMERA
from hsgeo.rotations import R_from_opk, opk_from_R
from hsgeo.sensors.frame import pixel_to_mm
from hsgeo.sensors.rikola import focal_from_gap_mm, project_measured_mm
from hsgeo.simulate._rikola_render import plate_texel_maps
from hsgeo.simulate.scenarios import ScenarioInfo

__all__ = [
    "RikolaBenchScenario",
    "BenchCameraRikola",
    "GapModel",
    "Misalignment",
    "BenchGeometryRikola",
    "BenchRadiometry",
    "BenchMeasure",
    "EopDrift",
    "Plate",
    "RikolaTruth",
    "make_truth",
    "eop_drift_rad",
    "band_radiometry",
    "render_band",
    "Renderer",
    "generate",
]


@dataclass(frozen=True)
class Plate:
    """A planar ArUco grid board (OpenCV ``GridBoard`` layout), world frame x right, y up, z
    toward the camera; ids ``0 … nx·ny−1`` row by row from the top left.

    Attributes
    ----------
    dictionary : str
        Name of an OpenCV predefined dictionary (``"DICT_4X4_100"``).
    nx, ny : int
    marker_mm, separation_mm, margin_mm : float
    texel_mm : float
        Texture resolution; the marker module (marker_mm / (bits + 2)) must be a whole number of
        texels so that edges fall on texel boundaries.
    white, black, background : float
        Reflectances.
    """

    dictionary: str = "DICT_4X4_100"
    nx: int = 9
    ny: int = 6
    marker_mm: float = 60.0
    separation_mm: float = 20.0
    margin_mm: float = 40.0
    texel_mm: float = 0.25
    white: float = 0.85
    black: float = 0.06
    background: float = 0.30

    def cv_dictionary(self):
        import cv2

        if not hasattr(cv2.aruco, self.dictionary):
            raise InputError(
                f"unknown ArUco dictionary {self.dictionary!r}; use an OpenCV name "
                "such as DICT_4X4_100"
            )
        return cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, self.dictionary))

    @property
    def ids(self) -> np.ndarray:
        return np.arange(self.nx * self.ny)

    @property
    def pitch_mm(self) -> float:
        return self.marker_mm + self.separation_mm

    def corners(self) -> np.ndarray:
        """(n_markers, 4, 3) world coordinates of the corners in ArUco order (top-left,
        top-right, bottom-right, bottom-left of the marker image).
        """
        k = self.ids
        x0 = (k % self.nx) * self.pitch_mm
        y0 = -(k // self.nx) * self.pitch_mm  # rows go down: world y up
        m = self.marker_mm
        dx = np.array([0.0, m, m, 0.0])
        dy = np.array([0.0, 0.0, -m, -m])
        return np.stack([x0[:, None] + dx, y0[:, None] + dy, np.zeros((k.size, 4))], axis=-1)

    def centres(self) -> np.ndarray:
        return self.corners().mean(axis=1)

    @property
    def extent_mm(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) of the plate including the margin."""
        w = self.nx * self.pitch_mm - self.separation_mm
        h = self.ny * self.pitch_mm - self.separation_mm
        return (-self.margin_mm, w + self.margin_mm, -h - self.margin_mm, self.margin_mm)

    @cached_property
    def texture(self) -> np.ndarray:
        """Reflectance texture (rows from the plate's top), float32."""
        import cv2

        d = self.cv_dictionary()
        nbits = d.markerSize + 2
        module = self.marker_mm / nbits / self.texel_mm
        if abs(module - round(module)) > 1e-9:
            raise InputError(
                f"marker module {self.marker_mm / nbits} mm is not a whole number "
                f"of texels of {self.texel_mm} mm"
            )
        side = int(round(self.marker_mm / self.texel_mm))
        x_min, x_max, y_min, y_max = self.extent_mm
        W = int(round((x_max - x_min) / self.texel_mm))
        H = int(round((y_max - y_min) / self.texel_mm))
        tex = np.full((H, W), self.white, dtype=np.float32)
        for k in self.ids:
            img = cv2.aruco.generateImageMarker(d, int(k), side, borderBits=1)
            c = int(round(((k % self.nx) * self.pitch_mm - x_min) / self.texel_mm))
            r = int(round((y_max + (k // self.nx) * self.pitch_mm) / self.texel_mm))
            tex[r : r + side, c : c + side] = np.where(img > 127, self.white, self.black)
        return tex


@dataclass
class RikolaTruth:
    """The simulated camera.

    Attributes
    ----------
    bands : structured ndarray
        003 Table 2 (band, sensor, gap_nm, wavelength_nm, fwhm_nm).
    f_mm : (25,) ndarray
        Focal length per band (gap model + scatter).
    pp_mm : (2, 2) ndarray
        Principal point per sensor (rows I, II).
    KP : (5,) ndarray
    rotation_rad : (3,) ndarray
        (dω, dφ, dκ) of ``R_I_from_II``.
    offset_mm : (3,) ndarray
    poses : (n_cubes, 6) ndarray
        Sensor I's exterior orientation per cube.
    gap_model : (2, 2) ndarray
        (a, b) per sensor (rows I, II) that generated ``f_mm``.
    scatter_mm : (2,) ndarray
    drift_rad : (25, 3) ndarray or None
        The drift of the exterior orientation across the bands of a cube (003 §3.4, Fig. 5):
        per band a rotation (dω, dφ, dκ) of the band's camera frame about its projection
        centre, ``R_world_from_band = R_rigid · R(dω, dφ, dκ)``, on top of the rigid model
        (sensor I's pose, sensor II rotated by ``rotation_rad``). None: no drift. No
        estimator of the chapter models it (:func:`eop_drift_rad`).
    """

    bands: np.ndarray
    f_mm: np.ndarray
    pp_mm: np.ndarray
    KP: np.ndarray
    rotation_rad: np.ndarray
    offset_mm: np.ndarray
    poses: np.ndarray
    gap_model: np.ndarray
    scatter_mm: np.ndarray
    drift_rad: np.ndarray | None = None

    def band_row(self, band: int) -> int:
        rows = np.flatnonzero(self.bands["band"] == band)
        if rows.size != 1:
            raise InputError(f"no band {band}; the Rikola bands are 1–25 (003 Table 2)")
        return int(rows[0])

    def sensor(self, band: int) -> int:
        return int(self.bands["sensor"][self.band_row(band)])

    def band_pose(self, cube: int, band: int) -> np.ndarray:
        """Exterior orientation (ω, φ, κ, X0, Y0, Z0) of the band's camera frame in a cube."""
        pose = self.poses[cube]
        if self.sensor(band) == 1:
            out = pose.copy()
        else:
            R_I = R_from_opk(*pose[:3])
            M = R_from_opk(*self.rotation_rad)  # R_I_from_II
            out = np.concatenate([opk_from_R(R_I @ M), pose[3:] + R_I @ self.offset_mm])
        if self.drift_rad is not None and np.any(self.drift_rad[self.band_row(band)]):
            D = R_from_opk(*self.drift_rad[self.band_row(band)])
            out[:3] = opk_from_R(R_from_opk(*out[:3]) @ D)  # about the projection centre
        return out

    def interior(self, band: int) -> np.ndarray:
        """(f, x0, y0) of a band in mm."""
        r = self.band_row(band)
        return np.concatenate([[self.f_mm[r]], self.pp_mm[self.sensor(band) - 1]])

    def project(self, cube: int, band: int, X: np.ndarray) -> np.ndarray:
        """Measured image coordinates (mm) of world points X (..., 3)."""
        pose = self.band_pose(cube, band)
        R = R_from_opk(*pose[:3])
        Xc = (np.asarray(X) - pose[3:]) @ R
        f, x0, y0 = self.interior(band)
        return project_measured_mm(Xc, f, np.array([x0, y0]), self.KP)


def _floats(n: int, doc: str = ""):
    return field(metadata={"key": Key("floats", length=n, doc=doc)})


@dataclass(frozen=True)
class BenchCameraRikola:
    """``[camera]`` of ``rikola_bench.toml``: 003 Tables 1 and 3 (one distortion set, §3.5).

    Image size and pixel pitch default to 003 Table 1 (:data:`hsgeo.papers.RIKOLA_CAMERA`).
    """

    pp_sensor1_mm: tuple[float, ...] = _floats(2, "x0, y0 of sensor I, mm")
    pp_sensor2_mm: tuple[float, ...] = _floats(2, "x0, y0 of sensor II, mm")
    K1_per_mm2: float
    K2_per_mm4: float
    K3_per_mm6: float
    P1_per_mm: float
    P2_per_mm: float
    width_px: int = RIKOLA_CAMERA["width_px"]
    height_px: int = RIKOLA_CAMERA["height_px"]
    pixel_mm: float = field(
        default=RIKOLA_CAMERA["pixel_mm"],
        metadata={"key": Key("float", positive=True, doc="pixel pitch, mm")},
    )


@dataclass(frozen=True)
class GapModel:
    """``[gap_model]``: f = a·gap + b per sensor (003 eq. (2), Table 4) and the scatter about it."""

    a_sensor1_mm_per_nm: float
    b_sensor1_mm: float
    a_sensor2_mm_per_nm: float
    b_sensor2_mm: float
    scatter_sensor1_mm: float
    scatter_sensor2_mm: float


@dataclass(frozen=True)
class Misalignment:
    """``[misalignment]``: ``R_I_from_II`` = R(dω, dφ, dκ) in degrees and the offset, mm."""

    domega_deg: float
    dphi_deg: float
    dkappa_deg: float
    offset_mm: tuple[float, ...] = _floats(3)


@dataclass(frozen=True)
class BenchGeometryRikola:
    """``[geometry]``: the cube poses (003 §3.1: twenty cubes)."""

    n_cubes: int = field(metadata={"key": Key("int", positive=True)})
    distance_mm: tuple[float, ...] = _floats(2, "min, max")
    tilt_deg: tuple[float, ...] = _floats(2, "min, max")
    aim_offset_mm: tuple[float, ...] = _floats(2)
    roll_jitter_deg: float
    min_targets: int


@dataclass(frozen=True)
class BenchRadiometry:
    """``[radiometry]``: the band's DN model and PSF (chosen; see the scenario file)."""

    full_dn: float
    response_peak_nm: float
    response_width_nm: float
    dark_dn: float
    electrons_per_dn: float
    read_noise_dn: float
    max_dn: int
    psf0_px: float
    psf1_px: float
    supersample: int = field(metadata={"key": Key("int", positive=True)})


@dataclass(frozen=True)
class BenchMeasure:
    """``[measure]``: a-priori σ of a centroid coordinate, px."""

    sigma_px: float


@dataclass(frozen=True)
class EopDrift:
    """``[eop_drift]``: φ of each band falls by ``dphi_deg_per_band``, zero at
    ``reference_band`` (003 §3.4, Fig. 5; :func:`eop_drift_rad`).
    """

    dphi_deg_per_band: float
    reference_band: int = 13


@dataclass(frozen=True)
class RikolaBenchScenario:
    """``data_synthetic/rikola_bench.toml`` (:func:`hsgeo.simulate.scenarios.load_scenario`);
    ``eop_drift`` None: no drift.
    """

    scenario: ScenarioInfo
    camera: BenchCameraRikola
    gap_model: GapModel
    misalignment: Misalignment
    plate: Plate
    geometry: BenchGeometryRikola
    radiometry: BenchRadiometry
    measure: BenchMeasure
    eop_drift: EopDrift | None = None


def _look_at(C, P, roll_rad):
    """R_world_from_cam for a camera at C looking at P (camera z backward), rolled about z."""
    z = (C - P) / np.linalg.norm(C - P)
    x = np.cross([0.0, 1.0, 0.0], z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.column_stack([x, y, z]) @ R_from_opk(0.0, 0.0, roll_rad)


def eop_drift_rad(cfg: RikolaBenchScenario, bands) -> np.ndarray:
    """The drift of the exterior orientation across the bands of a cube, ``(n_bands, 3)`` rad.

    003 §3.4 on its Fig. 5: the EOPs of the bands of one static cube vary, "estimated values of
    rotation φ and X0 coordinates decrease as a linear function" of the band. Here φ of each
    band's camera frame falls linearly with the band number, zero at ``reference_band``
    (``[eop_drift]`` of the scenario: ``dphi_deg_per_band``, ``reference_band``). The per-band
    calibration absorbs it in each band's EOPs; the relative orientation of 003 eq. (1) and the
    joint model, which assume one rigid rotation between the sensors and one pose per cube, do
    not model it.
    """
    d = cfg.eop_drift if cfg.eop_drift is not None else EopDrift(0.0)
    slope = np.deg2rad(float(d.dphi_deg_per_band))
    out = np.zeros((len(bands), 3))
    out[:, 1] = slope * (np.asarray(bands["band"], float) - float(d.reference_band))
    return out


def make_truth(
    cfg: RikolaBenchScenario, rng, n_cubes: int | None = None, *, eop_drift: bool = True
) -> RikolaTruth:
    """The camera and the cube poses of a scenario (``data_synthetic/rikola_bench.toml``).

    Parameters
    ----------
    cfg : RikolaBenchScenario
        The scenario configuration (``load_scenario("rikola_bench")``).
    rng : int or Generator
        Seed of the truth (band scatter, poses).
    n_cubes : int, optional
        Fewer cubes than the configuration (the first ones of the same sequence).
    eop_drift : bool
        Simulate the drift of the EOPs across the bands (:func:`eop_drift_rad`; the scenario's
        ``[eop_drift]``); it uses no random numbers, so the truth is otherwise the same.
    """
    from hsgeo.simulate import as_rng

    rng = as_rng(rng)
    cam, gm, mis, geo = cfg.camera, cfg.gap_model, cfg.misalignment, cfg.geometry
    bands = RIKOLA_BANDS.copy()
    ab = np.array(
        [
            [gm.a_sensor1_mm_per_nm, gm.b_sensor1_mm],
            [gm.a_sensor2_mm_per_nm, gm.b_sensor2_mm],
        ]
    )
    scatter = np.array([gm.scatter_sensor1_mm, gm.scatter_sensor2_mm])
    s = bands["sensor"] - 1
    # 003 eq. (2) plus a scatter about the line
    f = focal_from_gap_mm(bands["gap_nm"], ab[s, 0], ab[s, 1])
    f = f + scatter[s] * rng.standard_normal(len(bands))
    pp = np.array([cam.pp_sensor1_mm, cam.pp_sensor2_mm], dtype=float)
    KP = np.array([cam.K1_per_mm2, cam.K2_per_mm4, cam.K3_per_mm6, cam.P1_per_mm, cam.P2_per_mm])
    rot = np.deg2rad([mis.domega_deg, mis.dphi_deg, mis.dkappa_deg])
    plate = cfg.plate
    truth = RikolaTruth(
        bands, f, pp, KP, rot, np.asarray(mis.offset_mm, float), np.zeros((0, 6)), ab, scatter
    )
    n = geo.n_cubes if n_cubes is None else int(n_cubes)
    if n < 1:
        raise InputError(f"n_cubes must be at least 1, got {n}")
    centre = plate.centres().mean(axis=0)
    X = plate.corners().reshape(-1, 3)
    w, h, px = cam.width_px, cam.height_px, cam.pixel_mm
    half = np.array([(w - 1) / 2 - 8, (h - 1) / 2 - 8]) * px  # 8 px margin
    poses = []
    k = 0
    while len(poses) < n:
        k += 1
        if k > 1000 * n:
            raise InputError("could not place the cubes: widen geometry.distance_mm or tilt_deg")
        D = rng.uniform(*geo.distance_mm)
        tilt = np.deg2rad(rng.uniform(*geo.tilt_deg))
        azi = rng.uniform(0, 2 * np.pi)
        aim = centre + np.r_[rng.uniform(-1, 1, 2) * geo.aim_offset_mm, 0.0]
        C = aim + D * np.array(
            [np.sin(tilt) * np.cos(azi), np.sin(tilt) * np.sin(azi), np.cos(tilt)]
        )
        roll = np.deg2rad(90.0 * (len(poses) % 4) + rng.uniform(-1, 1) * geo.roll_jitter_deg)
        R = _look_at(C, aim, roll)
        Xc = (X - C) @ R
        xy = project_measured_mm(Xc, f.max(), pp[0], KP).reshape(-1, 4, 2)
        inside = np.all(np.abs(xy) < half, axis=(1, 2))
        if inside.sum() >= geo.min_targets:
            poses.append(np.concatenate([opk_from_R(R), C]))
    truth.poses = np.array(poses)
    if eop_drift and cfg.eop_drift is not None:
        truth.drift_rad = eop_drift_rad(cfg, bands)
    return truth


def band_radiometry(cfg: RikolaBenchScenario, band: int) -> dict:
    """White level, black level and PSF of a band (003 §3.2: FWHM sets the exposure)."""
    rad, plate = cfg.radiometry, cfg.plate
    r = np.flatnonzero(RIKOLA_BANDS["band"] == band)
    if r.size != 1:
        raise InputError(f"no band {band}; the Rikola bands are 1–25 (003 Table 2)")
    b = RIKOLA_BANDS[r[0]]
    resp = np.exp(-0.5 * ((b["wavelength_nm"] - rad.response_peak_nm) / rad.response_width_nm) ** 2)
    scale = rad.full_dn * b["fwhm_nm"] / RIKOLA_BANDS["fwhm_nm"].max() * resp
    psf = rad.psf0_px + rad.psf1_px * ((b["wavelength_nm"] - 680.0) / 160.0) ** 2
    return {
        "scale_dn": float(scale),
        "white_dn": float(scale * plate.white + rad.dark_dn),
        "black_dn": float(scale * plate.black + rad.dark_dn),
        "psf_px": float(psf),
    }


class Renderer:
    """Renders bands of the bench; caches the per-sensor ideal-coordinate grids.

    Parameters
    ----------
    cfg : RikolaBenchScenario
        Scenario configuration.
    truth : RikolaTruth
    grids : dict, optional
        A cache of the ideal-coordinate grids to share between the Renderers of one run (a
        campaign and its twin without the EOP drift): keyed by everything a grid depends on
        (image size, pixel pitch, supersampling, the sensor's principal point, the distortion),
        so Renderers of different cameras may share it safely. Default: a cache of its own.
    """

    def __init__(self, cfg: RikolaBenchScenario, truth: RikolaTruth, grids: dict | None = None):
        self.cfg, self.truth = cfg, truth
        self.plate = cfg.plate
        self._grids: dict = {} if grids is None else grids

    def _grid(self, sensor: int) -> np.ndarray:
        cam = self.cfg.camera
        s = int(self.cfg.radiometry.supersample)
        w, h = cam.width_px, cam.height_px
        key = (
            int(w),
            int(h),
            float(cam.pixel_mm),
            s,
            np.asarray(self.truth.pp_mm[sensor - 1], float).tobytes(),
            np.asarray(self.truth.KP, float).tobytes(),
        )
        if key not in self._grids:
            u = (np.arange(w * s) + 0.5) / s - 0.5
            v = (np.arange(h * s) + 0.5) / s - 0.5
            uu, vv = np.meshgrid(u, v)
            xy = pixel_to_mm(np.stack([uu, vv], axis=-1), (w, h), cam.pixel_mm)
            xbar = xy - self.truth.pp_mm[sensor - 1]
            ideal = xbar + brown_correction(xbar, self.truth.KP[:3], self.truth.KP[3:])
            self._grids[key] = ideal.astype(np.float32)
        return self._grids[key]

    def reflectance(self, cube: int, band: int) -> np.ndarray:
        """Noise-free reflectance image (height, width) after PSF and pixel integration."""
        import cv2

        t = self.truth
        sensor = t.sensor(band)
        ideal = self._grid(sensor)
        pose = t.band_pose(cube, band)
        R = R_from_opk(*pose[:3]).astype(np.float32)
        pl = self.plate
        x_min, _, _, y_max = pl.extent_mm
        # the ray of each pixel meets the plate Z = 0: texel coordinates, in float32 (compiled)
        col, row = plate_texel_maps(
            ideal, R, t.f_mm[t.band_row(band)], pose, x_min, y_max, pl.texel_mm
        )
        fine = cv2.remap(
            pl.texture,
            col,
            row,
            cv2.INTER_LINEAR,
            borderMode=cv2.BORDER_CONSTANT,
            borderValue=float(pl.background),
        )
        s = int(self.cfg.radiometry.supersample)
        psf = band_radiometry(self.cfg, band)["psf_px"]
        fine = cv2.GaussianBlur(fine, (0, 0), sigmaX=psf * s, sigmaY=psf * s)
        cam = self.cfg.camera
        return cv2.resize(fine, (cam.width_px, cam.height_px), interpolation=cv2.INTER_AREA)

    def render(self, cube: int, band: int, seed: int) -> np.ndarray:
        """The band's raw image in DN (uint16, 12 bit) with shot and read noise."""
        rng = np.random.default_rng([int(seed), 1, int(cube), int(band)])
        rad = self.cfg.radiometry
        br = band_radiometry(self.cfg, band)
        signal = self.reflectance(cube, band).astype(np.float64) * br["scale_dn"]
        sd = np.sqrt(signal / rad.electrons_per_dn + rad.read_noise_dn**2)
        dn = rad.dark_dn + signal + sd * rng.standard_normal(signal.shape)
        return np.clip(np.rint(dn), 0, rad.max_dn).astype(np.uint16)


def render_band(
    cfg: RikolaBenchScenario, truth: RikolaTruth, cube: int, band: int, seed: int
) -> np.ndarray:
    """One band of one cube (see :class:`Renderer`; use a Renderer for many images)."""
    return Renderer(cfg, truth).render(cube, band, seed)


def generate(cfg: RikolaBenchScenario, outdir: Path) -> list[Path]:
    """``make data``: the truth of the bench (bands and cube poses), as CSV.

    The images themselves are rendered by the ``rikola`` chapter (``hsgeo reproduce rikola``).
    """
    truth = make_truth(cfg, np.random.default_rng([cfg.scenario.seed, 0]))
    bands = outdir / "rikola_bench_truth_bands.csv"
    pp = truth.pp_mm[truth.bands["sensor"] - 1]
    table = np.column_stack(
        [truth.bands["band"], truth.bands["sensor"], truth.bands["gap_nm"], truth.f_mm, pp]
    )
    write_csv_array(
        bands,
        table,
        fmt=["%d", "%d", "%.17g", "%.17g", "%.17g", "%.17g"],
        header="band,sensor,gap_nm,f_mm,x0_mm,y0_mm",
    )
    cubes = outdir / "rikola_bench_truth_cubes.csv"
    write_csv_array(
        cubes,
        truth.poses,
        fmt="%.17g",
        header="omega_rad,phi_rad,kappa_rad,X0_mm,Y0_mm,Z0_mm",
    )
    return [bands, cubes]
