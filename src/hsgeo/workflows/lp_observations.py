"""LP observations from pixels (002 §3.1, §4): scenes → BRISK → matches → RANSAC → tie points.

Kept as one file: one workflow in GUIDE §2's template — its inputs, options and result, the
in-memory core :func:`retrieve` and its file front end; the per-strip stages are in
:mod:`hsgeo.workflows._lp_stages`, the geometry in ``_lp_geometry``, the squares in ``_lp_squares``.

The user's pipeline, truth-free (002 §3.1 steps 2–3, and the reference squares of §4):

1. **Scenes**: each strip's lines, ``n_lines_per_scene`` at a time, rotation-compensated in x
   from the navigation and the a-priori camera (002 eq. 1; :func:`hsgeo.measure.lp_scenes.
   make_scenes`).
2. **Key points** per band of every scene (BRISK, :mod:`hsgeo.measure.keypoints`), each taken
   back at once to its original line and x (:func:`~hsgeo.measure.lp_scenes.scene_to_line`,
   undoing the compensation), and its ground point predicted from the navigation on a plane at
   the mean terrain height.
3. **Candidate pairs**: scenes of different strips whose footprints (the four corner rays on
   that plane) overlap; in each pair and band only the key points predicted inside the other
   scene's footprint (with ``overlap_margin_m``) are matched (Hamming, cross-check and ratio).
   This search region and the strict ratio leave few gross errors for RANSAC (on the rendered
   campaign 0.0–0.5 % of the matches were more than 1 m apart on the ground before RANSAC);
   ``overlap_margin_m=np.inf`` and ``ratio=0.8`` match as an unguided pipeline would, for a
   harder test of the two RANSAC models.
4. **RANSAC** on each pair's matches, with 002's LP fundamental matrix (Gupta & Hartley 1997,
   ≥ 11 correspondences; :mod:`hsgeo.measure.lp_ransac`) or, for comparison, the frame
   camera's (``cv2.findFundamentalMat``); both are run on the same matches and kept as
   diagnostics, ``options.ransac`` decides which survive.
5. **Tie points**: connected components of the surviving matches (union–find), one observation
   per strip, seen in ≥ 3 lines of ≥ 3 strips (002 §4; :mod:`hsgeo.measure.tie_points`).
   Each observation is registered at the centre of its original pixel (002 §3.1: "the
   observations are registered at the center of their respective pixel"; ``x_at``), in its
   line (``y_px = 0``, the line's ``t_s``). Matching is within a band, so a feature found in k
   bands is k tie points whose observations coincide (the same line and pixel): one
   measurement repeated, with one line rounding. The adjustment gets one of them
   (:func:`hsgeo.measure.tie_points.one_band_per_feature`: the one whose matches have the
   smallest mean Hamming distance, the band whose descriptors agree best between strips;
   ``one_band_per_feature``). Taken as k independent tie points they make σ̂ too small, and
   the chapter measures by how much, and how accurate the kept band is. Every band's
   observations stay in ``LpResult.all_bands``, and the counts (002's observations per band
   and scene length) are of those.
6. **Reference squares** (optional): each square's centre measured in every scene that should
   see it (:func:`hsgeo.measure.targets_lp.square_centroid`), back to line and x, with the
   square's id (``squares_as="centroid"``, the default). Sub-pixel: a centroid measures the
   centre, not a pixel, so x is its sub-pixel x in the nearest line and ``t_s`` the time of
   its sub-line row (between two lines' times; ``line`` names the nearest) — no line
   rounding, which the k bands that see a square in one line would share. Or as 002 measured
   them (§4, ``squares_as="tie_point"``, the LP chapter's check points): the tie points the
   matcher found on a square (step 5's, at the pixel centre of their line, in the strips and
   band where it found them; :func:`hsgeo.workflows._lp_squares.as_tie_points`), renamed to
   the square's id; the square's blob only locates it.

The in-memory core :func:`retrieve` (frozen :class:`LpInputs`, :class:`LpOptions` →
:class:`LpResult`) is what ``hsgeo reproduce lp-observations`` and ``hsgeo lp-observations``
(:func:`lp_observation_files`) both call; :func:`to_pushbroom_inputs` hands the table to the
bundle adjustment through the same table path as ``hsgeo adjust-pushbroom``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from hsgeo.errors import InputError, ObservationError
from hsgeo.measure.keypoints import BRISK_OCTAVES, BRISK_THRESHOLD, RATIO
from hsgeo.measure.targets_lp import SEARCH_PX
from hsgeo.measure.tie_points import link_tie_points, one_band_per_feature
from hsgeo.workflows import _lp_squares as sq
from hsgeo.workflows._lp_stages import MIN_MATCHES, Keys, match_all, strip_scenes

__all__ = [
    "LpInputs",
    "WIDE_FOV_DEG",
    "LpOptions",
    "LpResult",
    "retrieve",
    "to_pushbroom_inputs",
    "lp_observation_files",
    "MIN_MATCHES",
    "TABLE_COLUMNS",
]

#: Columns of the observation table (the first five are ``hsgeo adjust-pushbroom``'s).
TABLE_COLUMNS = ("point_id", "band", "t_s", "x_px", "y_px", "strip", "line")


@dataclass(frozen=True)
class LpInputs:
    """What one retrieval is given (nothing here is truth).

    Attributes
    ----------
    strips : sequence of hsgeo.io.lp_lines.LpStrip
        The LP strips (lines, ``t_s``, ``col0``, wavelengths, ``strip_id``).
    navigation : hsgeo.trajectory.Trajectory
        The GNSS/INS solution covering every line.
    camera : hsgeo.sensors.pushbroom.PushbroomCamera
        The a-priori camera (per-band ``c_mm``, boresight, lever arm).
    square_ids : sequence of str
        Ids of the reference squares (empty: none measured).
    square_xyz_m : (k, 3) ndarray, optional
        Their surveyed centres (E, N, U).
    terrain_height_m : float, optional
        Mean terrain height for the footprints and predictions (default: the mean of the
        squares' heights; one of the two is needed).
    n_px_full : int
        Pixels of a full line (002 §4: 1800); ``x_px = j − (n_px_full − 1)/2``.

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """

    strips: tuple
    navigation: object
    camera: object
    square_ids: tuple = ()
    square_xyz_m: np.ndarray | None = None
    terrain_height_m: float | None = None
    n_px_full: int = 1800


@dataclass(frozen=True)
class LpOptions:
    """How to retrieve (002's choices by default).

    Attributes
    ----------
    n_lines_per_scene : int
        Lines per scene (002 §4: 200).
    ransac : {"lp", "frame"}
        The model whose RANSAC inliers survive: 002's LP fundamental matrix, or the frame
        camera's (for comparison).
    threshold_px : float
        RANSAC's inlier threshold (first-order geometric distance, px).
    min_lines, min_strips : int
        A tie point is kept when seen in ≥ min_lines lines of ≥ min_strips strips (002 §4).
    bands : tuple of int, optional
        Bands used (0-based; default all).
    x_at : {"pixel_centre", "subpixel"}
        Observation x at the centre of the original pixel (002 §3.1) or at the key point's
        sub-pixel position.
    ratio : float
        Lowe's ratio of the matching.
    brisk_threshold, brisk_octaves : int
        BRISK's detection threshold and scale-space octaves.
    overlap_margin_m : float
        Key points predicted this far outside the other scene's footprint are still matched
        (the a-priori boresight's error on the ground).
    square_size_m : float
        Side of the reference squares (002 §4: 1.2 m).
    square_search_px : int
        Half-width of the square's search window around its predicted position.
    min_square_observations : int
        A square is kept when measured in at least this many lines.
    max_nav_gap_s : float
        The longest navigation gap interpolated across.
    rng : int
        Seed of RANSAC's sampling.
    one_band_per_feature : bool
        The adjustment's table keeps one tie point per ground feature, of the bands that found
        it in the same lines and pixels (module docstring, step 5); False: every band's.
    squares_as : {"centroid", "tie_point"}
        The squares in the table by their blobs' centroids in every strip and band that sees
        them (sub-pixel x and sub-line time; step 6; the default) or as 002 measured them (§4:
        tie points found by the matcher, at the pixel centre, in the strips and band where it
        found them; :func:`hsgeo.workflows._lp_squares.as_tie_points`; the LP chapter's
        check points). Both tables are in :attr:`LpResult.tables_by_squares`.

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """

    n_lines_per_scene: int = 200
    ransac: str = "lp"
    threshold_px: float = 1.0
    min_lines: int = 3
    min_strips: int = 3
    bands: tuple | None = None
    x_at: str = "pixel_centre"
    ratio: float = RATIO
    brisk_threshold: int = BRISK_THRESHOLD
    brisk_octaves: int = BRISK_OCTAVES
    overlap_margin_m: float = 30.0
    square_size_m: float = 1.2
    square_search_px: int = SEARCH_PX
    min_square_observations: int = 2
    max_nav_gap_s: float = 1.0
    rng: int = 0
    one_band_per_feature: bool = True
    squares_as: str = "centroid"

    def __post_init__(self):
        if self.squares_as not in sq.SQUARES_AS:
            raise InputError(
                f"squares_as must be 'tie_point' or 'centroid', got {self.squares_as!r}"
            )
        if self.ransac not in ("lp", "frame"):
            raise InputError(f"ransac must be 'lp' or 'frame', got {self.ransac!r}")
        if self.x_at not in ("pixel_centre", "subpixel"):
            raise InputError(f"x_at must be 'pixel_centre' or 'subpixel', got {self.x_at!r}")
        if not (
            isinstance(self.n_lines_per_scene, int | np.integer) and self.n_lines_per_scene >= 8
        ):
            raise InputError(
                f"--scene-lines must be an integer ≥ 8, got {self.n_lines_per_scene!r}"
            )
        if not self.threshold_px > 0:
            raise InputError(f"the RANSAC threshold must be positive, got {self.threshold_px!r}")


@dataclass(frozen=True)
class LpResult:
    """One retrieval: the observation table and its diagnostics.

    Attributes
    ----------
    table : pandas.DataFrame
        :data:`TABLE_COLUMNS`: ``point_id`` (``tp…`` for tie points, the square's id),
        ``band``, ``t_s``, ``x_px``, ``y_px`` (0), ``strip`` (its id), ``line`` (index in the
        strip) — the observation table of ``hsgeo adjust-pushbroom`` (one band per
        feature, :attr:`LpOptions.one_band_per_feature`).
    matches : pandas.DataFrame
        Every match before RANSAC: ``pair``, ``band``, ``strip_a``, ``strip_b``, ``scene_a``,
        ``scene_b``, scene coordinates ``u_a, v_a, u_b, v_b``, ``line_a, x_a_px, t_a_s,
        line_b, x_b_px, t_b_s`` (sub-pixel x), ``hamming``, ``inlier_lp``, ``inlier_frame``
        (False in pairs with fewer than 11 matches), ``kept`` (the chosen model's inliers),
        ``point`` (the tie point it ended in, −1 none).
    pairs : pandas.DataFrame
        Per scene pair and band: ``n_matches``, ``n_inliers_lp``, ``n_inliers_frame``.
    scenes : pandas.DataFrame
        Per scene: ``strip``, ``scene``, ``line0``, ``n_lines``, ``t_ref_s``, ``dx_rms_px``,
        ``dx_max_px`` and the key points per band.
    squares : pandas.DataFrame
        Per square measurement: ``point_id``, ``band``, ``strip``, ``line``, ``x_px``, ``u``,
        ``v``, ``snr``, ``ok``.
    counts : dict
        Per band and in all: key points, matches before and after RANSAC (both models),
        tie points and observations of every band (002's counts; ``tie_points``,
        ``observations``), and of the table (``tie_points_adjusted``,
        ``observations_adjusted``); in all also ``features``.
    timings_s : dict
        Seconds per stage: ``scenes``, ``detection``, ``matching``, ``ransac``, ``squares``,
        ``tie_points``; ``ransac_per_strip``.
    options : LpOptions
    all_bands : pandas.DataFrame
        Every band's tie-point observations (:data:`TABLE_COLUMNS`, then ``feature`` and
        ``adjusted``: in :attr:`table`) and the squares' (feature −1).
    tables_by_squares : dict
        ``{"tie_point": table, "centroid": table}``: the adjustment's table with the squares
        measured each way (:attr:`LpOptions.squares_as`); :attr:`table` is one of them.

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """

    table: object
    matches: object
    pairs: object
    scenes: object
    squares: object
    counts: dict
    timings_s: dict
    options: LpOptions = field(default_factory=LpOptions)
    all_bands: object = None
    tables_by_squares: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """Counts, timings and the options (JSON-ready); the tables stay in the attributes."""
        from dataclasses import asdict

        opts = asdict(self.options)
        return {
            "n_observations": int(len(self.table)),
            "n_observations_all_bands": int(len(self.all_bands)),
            "n_tie_points": int(self.counts["all"]["tie_points"]),
            "n_squares": int(self.counts["all"]["squares"]),
            "counts": self.counts,
            "timings_s": self.timings_s,
            "options": {k: list(v) if isinstance(v, tuple) else v for k, v in opts.items()},
        }


# ----------------------------------------------------------------------------------------------
# The in-memory core
# ----------------------------------------------------------------------------------------------
#: A line camera's field of view beyond which a unit of c_mm or pixel_mm is the likelier cause.
WIDE_FOV_DEG = 60.0


def _wide_camera(inputs: LpInputs) -> str:
    """The camera's full-line field of view, named when implausibly wide (c_mm or
    pixel_mm in another unit ended in 'too short, poor texture, or too far off').
    """
    c = float(np.atleast_1d(inputs.camera.c_mm)[0])
    half_mm = 0.5 * inputs.n_px_full * float(inputs.camera.pixel_mm)
    fov = float(np.degrees(2.0 * np.arctan2(half_mm, c)))
    if fov <= WIDE_FOV_DEG:
        return ""
    return (
        f"; the camera's field of view across the line is {fov:.0f}° ({inputs.n_px_full} px of "
        f"pixel_mm {float(inputs.camera.pixel_mm):g} at c_mm {c:g}): is c_mm or pixel_mm in "
        "another unit?"
    )


def _nm(wl) -> str:
    return "[" + ", ".join(f"{v:.6g}" for v in wl) + "] nm"


def _check(inputs: LpInputs, options: LpOptions) -> tuple[tuple, float]:
    """Bands and the terrain height; one clear error for what cannot work."""
    from hsgeo.validate import check_navigation_covers

    strips = list(inputs.strips)
    if len(strips) < max(2, options.min_strips):
        raise InputError(
            f"{len(strips)} strip(s) given; a tie point must be seen in ≥ {options.min_strips} "
            "strips (002 §4): give the LP line files of at least that many overlapping strips"
        )
    ids = [str(s.strip_id) for s in strips]
    if len(set(ids)) < len(ids):
        dup = sorted({i for i in ids if ids.count(i) > 1})
        raise InputError(f"strip id(s) {', '.join(dup)} given twice: give each strip once")
    n_cam = np.atleast_1d(inputs.camera.c_mm).size
    n_bands = {s.lines.shape[2] for s in strips}
    if len(n_bands) > 1:
        raise InputError(
            "the strips hold different numbers of bands "
            + ", ".join(f"{i}: {s.lines.shape[2]}" for i, s in zip(ids, strips, strict=True))
            + "; give strips of the same bands"
        )
    nb = n_bands.pop()
    wl0 = np.asarray(strips[0].wavelengths_nm, float)
    for i, s in zip(ids[1:], strips[1:], strict=True):
        wl = np.asarray(s.wavelengths_nm, float)
        if not np.allclose(wl, wl0, rtol=0.0, atol=0.5):  # matched band by band
            raise InputError(
                f"strip {i}'s bands differ from strip {ids[0]}'s (wavelength_nm "
                f"{_nm(wl)} against {_nm(wl0)}): a band is matched with the same band of the "
                "other strips; give strips of the same camera and bands"
            )
    if nb != n_cam:
        raise InputError(
            f"the strips hold {nb} bands but the camera has {n_cam} principal distances "
            "(n_bands, c_band_mm of the camera file): give the camera of these bands"
        )
    bands = tuple(range(nb)) if options.bands is None else tuple(int(b) for b in options.bands)
    missing = [b for b in bands if not 0 <= b < nb]
    if missing or not bands:
        raise InputError(
            f"band(s) {missing or '(none)'} not in the strips, which hold bands 0 to {nb - 1}; "
            "choose bands among those (--bands)"
        )
    t = np.concatenate([np.asarray(s.t_s, float) for s in strips])
    check_navigation_covers(
        inputs.navigation.t_s,
        t,
        nav="(the navigation)",
        used="the lines' t_s",
        max_gap_s=options.max_nav_gap_s,
    )
    h = inputs.terrain_height_m
    if h is None:
        if inputs.square_xyz_m is None or len(inputs.square_ids) == 0:
            raise InputError(
                "no terrain height: give the mean terrain height (--height) or the reference "
                "squares (--squares), whose mean height is taken"
            )
        h = float(np.mean(np.asarray(inputs.square_xyz_m, float)[:, 2]))
    return bands, float(h)


def _check_overlap(inputs: LpInputs, options: LpOptions, height: float) -> list:
    """Some two strips' footprints overlap (before any work; scenes are checked again)."""
    from hsgeo.workflows._lp_geometry import convex_overlap, footprint

    h_px = (inputs.n_px_full - 1) / 2
    fps = []
    for s in inputs.strips:
        x = (s.col0 - h_px, s.col0 + s.lines.shape[1] - 1 - h_px)
        t = (float(s.t_s[0]), float(s.t_s[-1]))
        fps.append(footprint(inputs.camera, x, t, inputs.navigation, height))
    m = options.overlap_margin_m
    if not any(
        convex_overlap(fps[i], fps[j], m) for i in range(len(fps)) for j in range(i + 1, len(fps))
    ):
        raise InputError(
            f"no two strips overlap on the ground (footprints from the navigation and the "
            f"camera on the plane at {height:.6g} m): give overlapping strips, the navigation "
            "of these lines (the same time scale), and the terrain height (--height) or the "
            "squares (--squares)"
        )
    return fps


def retrieve(inputs: LpInputs, options: LpOptions = LpOptions(), progress=None) -> LpResult:
    """Observations of tie points (and reference squares) from LP strips (module docstring).

    Parameters
    ----------
    inputs : LpInputs
    options : LpOptions
    progress : callable, optional
        Called ``progress(done, total, stage)`` after each strip's detection and matching.

    Returns
    -------
    LpResult

    Raises
    ------
    InputError
        Fewer strips than ``min_strips``, bands missing or unlike the camera's, a navigation
        that does not cover the lines, no terrain height, no two strips' scenes overlapping.
    ObservationError
        No scene pair with 11 matches (the LP fundamental matrix's minimum), or no tie point
        seen in enough lines and strips.
    """
    bands, height = _check(inputs, options)
    _check_overlap(inputs, options, height)
    timings = {k: 0.0 for k in ("scenes", "detection", "matching", "ransac", "squares")}
    timings["ransac_per_strip"] = []
    keys = Keys()
    rows = {"scenes": [], "squares": [], "pairs": []}
    per_strip = []
    n = len(inputs.strips)
    for si, strip in enumerate(inputs.strips):
        per_strip.append(
            strip_scenes(strip, si, inputs, options, bands, height, keys, rows, timings)
        )
        if progress is not None:
            progress(si + 1, n, "scenes and key points, strip by strip")
    keys.freeze()
    m = match_all(per_strip, keys, options, bands, rows, timings, progress)
    if not rows["pairs"]:
        raise InputError(
            f"no two scenes of different strips overlap on the ground (footprints from the "
            f"navigation and the camera on the plane at {height:.6g} m): give overlapping "
            "strips, the navigation of these lines (the same time scale), and the terrain "
            "height (--height) or the squares (--squares)"
        )
    if not np.any([r["n_matches"] >= MIN_MATCHES for r in rows["pairs"]]):
        most = max(r["n_matches"] for r in rows["pairs"])
        raise ObservationError(
            f"no pair of overlapping scenes has {MIN_MATCHES} matches (the LP fundamental "
            f"matrix's minimum, 002 §3.1; at most {most}): the scenes are too short "
            "(--scene-lines), the bands too poor in texture, or the navigation, the camera or "
            f"the terrain height ({height:.6g} m: --height, or the squares' H_m) too far off "
            "for the footprints" + _wide_camera(inputs)
        )
    kept = m["lp"] if options.ransac == "lp" else m["frame"]
    t0 = time.perf_counter()
    point, link = link_tie_points(
        keys.n,
        m["a"][kept],
        m["b"][kept],
        keys.strip,
        keys.line,
        keys.x,
        min_lines=options.min_lines,
        min_strips=options.min_strips,
    )
    timings["tie_points"] = time.perf_counter() - t0
    if link["n_points"] == 0:
        raise ObservationError(_no_tie_point_message(options, kept, rows["pairs"]))
    score = _mean_hamming(point, m, kept)
    by_way = _table(inputs, options, keys, point, rows["squares"], score)
    square_tables = {
        k: v.loc[v["adjusted"].to_numpy(), list(TABLE_COLUMNS)].reset_index(drop=True)
        for k, v in by_way.items()
    }
    all_bands = by_way[options.squares_as]
    table = square_tables[options.squares_as]
    matches = _matches_frame(inputs, keys, m, kept, point)
    out = _result(
        inputs, options, bands, keys, point, link, (table, all_bands), matches, rows, timings
    )
    return replace(out, tables_by_squares=square_tables)


def _no_tie_point_message(options, kept, pairs) -> str:
    """Why no tie point was linked: too few matches per scene pair for RANSAC to test, RANSAC
    rejecting most of those it tested, or kept matches that do not chain across the strips.
    """
    n = np.array([r["n_matches"] for r in pairs])
    testable = n >= MIN_MATCHES
    n_test = int(n[testable].sum())
    k = int(kept.sum())
    head = (
        f"no tie point is seen in ≥ {options.min_lines} lines of ≥ {options.min_strips} "
        "strips (002 §4): "
    )
    if n_test < 0.5 * kept.size:  # most matches lie in pairs RANSAC cannot test
        return head + (
            f"only {int(testable.sum())} of {n.size} scene pairs have the {MIN_MATCHES} matches "
            f"RANSAC needs (002 §3.1; they hold {n_test} of {kept.size} matches, RANSAC kept "
            f"{k}): the scenes have too little texture in these bands (--bands) or are too "
            "short (--scene-lines), or the strips overlap too little"
        )
    if k < 0.5 * n_test:  # RANSAC rejected most of what it tested
        return head + (
            f"RANSAC kept only {k} of the {n_test} matches in the {int(testable.sum())} scene "
            f"pairs it could test: they do not fit one LP epipolar geometry within "
            f"--threshold-px {options.threshold_px:g}; the navigation or the camera varies too "
            "much within a scene (check the navigation's time scale and the lines' times), or "
            "give a larger --threshold-px"
        )
    return head + (
        f"RANSAC kept {k} of {kept.size} matches in {n.size} scene pairs, but they do not "
        "chain through enough lines and strips: give more overlapping strips"
    )


def _observation_x(x, options, n_px_full):
    """X at the centre of the original pixel (002 §3.1) or as measured."""
    if options.x_at == "subpixel":
        return np.asarray(x, float)
    h = (n_px_full - 1) / 2
    return np.floor(np.asarray(x, float) + h + 0.5) - h


def _mean_hamming(point, m, kept) -> np.ndarray:
    """Per tie point, the mean Hamming distance of the surviving matches that made it (the
    feature's band whose descriptors agree best between strips scores lowest).
    """
    n = int(point.max()) + 1 if point.size else 0
    a, b, h = m["a"][kept], m["b"][kept], np.asarray(m["hamming"], float)[kept]
    same = (point[a] >= 0) & (point[a] == point[b])
    p = point[a][same]
    c = np.bincount(p, minlength=n)
    return np.where(c > 0, np.bincount(p, h[same], minlength=n) / np.maximum(c, 1), np.inf)


def _table(inputs, options, keys, point, square_rows, score):
    """Every band's observations, tie points then squares (:data:`TABLE_COLUMNS`, ``feature``,
    ``adjusted``: one band per feature, or all, :attr:`LpOptions.one_band_per_feature`), with
    the squares measured each way (:data:`~hsgeo.workflows._lp_squares.SQUARES_AS`):
    ``{way: table}``.
    """
    import pandas as pd

    ids = np.array([str(s.strip_id) for s in inputs.strips])
    obs = np.flatnonzero(point >= 0)
    obs = obs[np.lexsort((keys.strip[obs], point[obs]))]
    x = _observation_x(keys.x[obs], options, inputs.n_px_full)
    keep, feature = one_band_per_feature(
        point[obs], keys.strip[obs], keys.line[obs], x, score=score
    )
    if not options.one_band_per_feature:
        keep[:] = True
    ties = pd.DataFrame(
        {
            "point_id": [f"tp{p:07d}" for p in point[obs]],
            "band": keys.band[obs].astype(np.int64),
            "t_s": keys.t[obs],
            "x_px": x,
            "y_px": np.zeros(obs.size),
            "strip": ids[keys.strip[obs]],
            "line": keys.line[obs],
            "feature": feature[point[obs]],
            "adjusted": keep[point[obs]],
            "x_keypoint_px": keys.x[obs],
            "line_offset": keys.uv[obs, 0] - np.rint(keys.uv[obs, 0]),
        }
    )
    sq_rows = pd.DataFrame(square_rows, columns=sq.COLUMNS)
    sq_rows = sq_rows.loc[sq_rows["ok"].astype(bool)].drop_duplicates(["point_id", "band", "strip"])
    count = sq_rows.groupby("point_id")["point_id"].transform("size")
    cen = sq_rows[count >= options.min_square_observations].assign(
        y_px=0.0, feature=-1, adjusted=True
    )
    cols = [*TABLE_COLUMNS, "feature", "adjusted"]
    out = {"centroid": pd.concat([ties, cen[cols]], ignore_index=True)}
    # the squares as the matcher found them (002 §4): tie points on the squares' blobs
    blobs = sq_rows.assign(line_frac=sq_rows["line"] + (sq_rows["u"] - np.round(sq_rows["u"])))
    on, taken = sq.as_tie_points(ties.assign(point=point[obs]), blobs, score)
    t2 = ties.copy()
    t2.loc[np.isin(t2["feature"].to_numpy(), taken), "adjusted"] = False
    on = on.assign(feature=-1, adjusted=True)
    out["tie_point"] = pd.concat([t2, on[ties.columns]], ignore_index=True)
    for k, table in out.items():
        table["band"] = table["band"].astype(np.int64)
        table["line"] = table["line"].astype(np.int64)
        out[k] = table
    return out


def _matches_frame(inputs, keys, m, kept, point):
    """Every match before RANSAC with both models' verdicts (the chapter judges each)."""
    import pandas as pd

    ids = np.array([str(s.strip_id) for s in inputs.strips])
    a, b = m["a"], m["b"]
    same = (point[a] == point[b]) & (point[a] >= 0)
    return pd.DataFrame(
        {
            "pair": m["pair"],
            "band": keys.band[a].astype(np.int64),
            "strip_a": ids[keys.strip[a]],
            "strip_b": ids[keys.strip[b]],
            "scene_a": keys.scene[a].astype(np.int64),
            "scene_b": keys.scene[b].astype(np.int64),
            "u_a": keys.uv[a, 0],
            "v_a": keys.uv[a, 1],
            "u_b": keys.uv[b, 0],
            "v_b": keys.uv[b, 1],
            "line_a": keys.line[a],
            "x_a_px": keys.x[a],
            "t_a_s": keys.t[a],
            "line_b": keys.line[b],
            "x_b_px": keys.x[b],
            "t_b_s": keys.t[b],
            "hamming": m["hamming"],
            "inlier_lp": m["lp"],
            "inlier_frame": m["frame"],
            "kept": kept,
            "point": np.where(same, point[a], -1),
        }
    )


def _result(inputs, options, bands, keys, point, link, tables, matches, rows, timings):
    """Counts per band and in all, and the result."""
    import pandas as pd

    table, all_bands = tables
    pairs = pd.DataFrame(rows["pairs"])
    counts = {}
    for b in (*bands, "all"):
        sel = slice(None) if b == "all" else (keys.band == b)
        msel = slice(None) if b == "all" else (matches["band"].to_numpy() == b)
        tsel = slice(None) if b == "all" else (all_bands["band"].to_numpy() == b)
        tab = all_bands[tsel]
        tie = tab["feature"].to_numpy() >= 0
        adj = tie & tab["adjusted"].to_numpy(bool)
        counts["all" if b == "all" else f"band{b}"] = {
            "keypoints": int(np.sum(np.ones(keys.n, bool)[sel])),
            "matches": int(len(matches[msel])),
            "matches_in_pairs_of_11": int(
                np.sum(
                    pairs.set_index("pair").loc[matches["pair"][msel], "n_matches"].to_numpy()
                    >= MIN_MATCHES
                )
            )
            if len(matches)
            else 0,
            "inliers_lp": int(matches["inlier_lp"][msel].sum()),
            "inliers_frame": int(matches["inlier_frame"][msel].sum()),
            "tie_points": int(tab.loc[tie, "point_id"].nunique()),
            "observations": int(tie.sum()),
            "tie_points_adjusted": int(tab.loc[adj, "point_id"].nunique()),
            "observations_adjusted": int(adj.sum()),
            "squares": int(tab.loc[~tie, "point_id"].nunique()),
            "square_observations": int((~tie).sum()),
        }
    counts["all"].update(
        scenes=len(rows["scenes"]),
        pairs=int(pairs[["scene_a", "scene_b"]].drop_duplicates().shape[0]),
        pair_bands_with_11=int((pairs["n_matches"] >= MIN_MATCHES).sum()),
        features=int(all_bands.loc[all_bands["feature"] >= 0, "feature"].nunique()),
        **{f"link_{k}": v for k, v in link.items()},
    )
    return LpResult(
        table=table,
        matches=matches,
        pairs=pairs,
        scenes=pd.DataFrame(rows["scenes"]),
        squares=pd.DataFrame(
            rows["squares"],
            columns=sq.COLUMNS,
        ),
        counts=counts,
        timings_s=timings,
        options=options,
        all_bands=all_bands,
    )


def to_pushbroom_inputs(
    result: LpResult,
    navigation,
    camera_prior,
    gcp_ids=(),
    gcp_xyz_m=None,
    *,
    max_nav_gap_s: float = 1.0,
):
    """The retrieved table as the bundle adjustment's inputs, by ``hsgeo adjust-pushbroom``'s
    own table path (:func:`hsgeo.workflows.pushbroom_ba.observations_from_table`).

    Parameters
    ----------
    result : LpResult
    navigation : hsgeo.trajectory.Trajectory
    camera_prior : hsgeo.workflows.pushbroom_ba.CameraPrior
    gcp_ids : sequence of str
        Squares used as GCPs (the others are check points: tie points with known coordinates).
    gcp_xyz_m : (k, 3) array_like, optional
        Their surveyed centres.

    Returns
    -------
    hsgeo.workflows.pushbroom_ba.PushbroomInputs
    """
    from hsgeo.workflows.pushbroom_ba import PushbroomInputs, observations_from_table

    obs, ids = observations_from_table(
        result.table,
        navigation,
        camera_prior,
        source="the retrieved LP observations",
        nav="(the navigation)",
        max_nav_gap_s=max_nav_gap_s,
    )
    gi = gx = None
    gcp_ids = [str(g) for g in gcp_ids]
    if gcp_ids:
        pos = {v: i for i, v in enumerate(ids)}
        missing = [g for g in gcp_ids if g not in pos]
        if missing:
            raise ObservationError(
                f"GCP(s) {', '.join(missing)} were not measured in two or more lines, so they "
                "are not in the observation table: check their coordinates and the squares' "
                "visibility, or use the other GCPs"
            )
        gi = np.array([pos[g] for g in gcp_ids])
        gx = np.asarray(gcp_xyz_m, float).reshape(len(gcp_ids), 3)
    return PushbroomInputs(obs, ids.size, camera_prior, gcp_index=gi, gcp_xyz_m=gx, point_ids=ids)


# ----------------------------------------------------------------------------------------------
# Files: ``hsgeo lp-observations``
# ----------------------------------------------------------------------------------------------
def lp_observation_files(
    scenes,
    trajectory,
    camera,
    output,
    *,
    squares=None,
    height_m: float | None = None,
    options: LpOptions = LpOptions(),
    overwrite: bool = False,
    progress=None,
    n_px_full: int | None = None,
    nav_crs=None,
    site=None,
    line_times=None,
) -> LpResult:
    """``hsgeo lp-observations``: LP line files → the observation table of ``adjust-pushbroom``.

    Parameters
    ----------
    scenes : sequence of path
        The lines of one strip each: hsgeo's NetCDF LP line files (:mod:`hsgeo.io.lp_lines`)
        or ENVI cubes as line scanners write them (BIL/BIP/BSQ, ``name.hdr`` or
        ``name.ext.hdr``; :func:`hsgeo.io.read_line_strips`): sample s at x = s − (samples −
        1)/2 px unless ``n_px_full`` says the full line is wider, strip id the file's stem.
    trajectory : path
        The navigation file of every command (:mod:`hsgeo.io.navigation`), or one as delivered
        (geodetic CSV or Parquet, Applanix SBET: :func:`hsgeo.io.navigation.read_line_navigation`
        with ``nav_crs`` and ``site``, the origin of the squares' frame).
    camera : path
        The camera TOML of ``hsgeo adjust-pushbroom`` (:func:`hsgeo.io.read_pushbroom_camera`:
        ``c_band_mm`` or ``c_mm``, ``pixel_mm``, ``boresight_deg``, ``lever_arm_m`` …).
    output : path
        The observation table (``.parquet``, ``.pq`` or ``.csv``); checked before any work.
    squares : path, optional
        CSV or Parquet ``point_id, E_m, N_m, H_m``: the reference squares, measured in the
        images and written with their ids (give the GCPs among them to ``--gcp`` of
        ``adjust-pushbroom``).
    height_m : float, optional
        Mean terrain height (default: the squares' mean height).
    n_px_full : int, optional
        Pixels of a full line (``--line-pixels``); overrides the files' ``n_px_full``
        attribute (default: that attribute, else 1800 px, 002 §4:
        :func:`hsgeo.io.lp_lines.full_line_px`, the convention ``hsgeo orthorectify`` shares).
    line_times : sequence of path, optional
        ``--line-times``: one times file per ENVI cube of ``scenes`` (one time per line, the
        navigation's time scale); default each header's start time and line period.

    Returns
    -------
    LpResult

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """
    import pandas as pd

    from hsgeo.io import read_pushbroom_camera, read_table
    from hsgeo.io._files import check_outputs
    from hsgeo.io.line_cube import read_line_strips
    from hsgeo.io.lp_lines import full_line_px
    from hsgeo.io.navigation import read_line_navigation
    from hsgeo.io.tables import TABLE_FORMATS, write_table
    from hsgeo.validate import check_navigation_covers
    from hsgeo.workflows._lp_height import check_terrain_height
    from hsgeo.workflows.pushbroom_ba import GCP_COLUMNS

    files = [*scenes, *(line_times or ()), trajectory, camera, squares]
    check_outputs([(output, "-o/--output", TABLE_FORMATS)], files, overwrite=overwrite)
    strips = read_line_strips(scenes, line_times)
    traj, _ = read_line_navigation(
        trajectory,
        crs=nav_crs,
        site=site,
        frame_needed_by="--squares" if squares is not None else None,
    )
    cam = read_pushbroom_camera(camera)
    ids, xyz = (), None
    if squares is not None:
        table = read_table(
            squares, GCP_COLUMNS, "squares", text_columns=("point_id",), unique=("point_id",)
        )
        ids = tuple(table["point_id"].astype(str))
        xyz = table[["E_m", "N_m", "H_m"]].to_numpy(dtype=float)
    for p, s in zip(scenes, strips, strict=True):
        check_navigation_covers(
            traj.t_s,
            np.asarray(s.t_s, float),
            nav=repr(str(trajectory)),
            used=f"the lines of {str(p)!r} (t_s)",
            max_gap_s=options.max_nav_gap_s,
        )
    n_px = full_line_px(strips, n_px_full)
    inputs = LpInputs(tuple(strips), traj, cam, ids, xyz, height_m, n_px)
    if squares is not None:  # the squares where the strips see the ground
        _, height = _check(inputs, options)
        sq.check_placement(inputs, _check_overlap(inputs, options, height))
    res = retrieve(inputs, options, progress=progress)
    if squares is not None and res.counts["all"]["squares"] == 0:
        raise ObservationError(  # a navigation shifted in time gave 0 squares and exit 0
            f"none of the {len(ids)} squares of {str(squares)!r} was found where the navigation "
            "and the camera put it in the strips: is the navigation on the lines' time scale "
            "(not shifted), the camera's boresight and lever arm right (degrees, metres), the "
            "squares' E_m, N_m, H_m in the navigation's frame? (without --squares, give "
            "--height)"
        )
    _, height = _check(inputs, options)
    given = (
        (
            "--height",
            "give the mean terrain height in the navigation's frame (--height "
            "{h:.0f}) or the reference squares (--squares)",
        )
        if height_m is not None
        else (
            f"the mean H_m of the squares of {str(squares)!r}",
            "give the squares' heights in the "
            "navigation's frame and vertical datum, or the mean terrain height (--height {h:.0f})",
        )
    )
    check_terrain_height(res.table, cam, traj, height, *given)
    write_table(output, pd.DataFrame(res.table), inputs=[f for f in files if f is not None])
    return res
