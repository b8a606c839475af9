"""Chapter ``frame-reference``: self-calibration with hsgeo's engine, checked against OpenCV.

Three experiments:

1. OpenCV's calibration-tutorial chessboard (8 views × 54 real corners, in the OpenCV file): hsgeo
   under OpenCV's constraints (principal point fixed at the centre, square pixels, no decentering)
   against the published result; then the same data in the photogrammetric form of Brown's model.
2. Four real ChArUco photographs: corners detected with ``cv2.aruco``, all 9 intrinsics by hsgeo
   and by today's ``cv2.calibrateCamera`` on the same corners.
3. A simulated bench with the tutorial camera as truth (seeded): truth within 3σ̂.
"""

from __future__ import annotations

from dataclasses import replace
from importlib import resources

import numpy as np

from hsgeo.io import read_opencv_storage
from hsgeo.io.boards import OPENCV_TUTORIAL_CHARUCO, Board
from hsgeo.measure.charuco import detect_charuco
from hsgeo.report import Reproduction, Row
from hsgeo.workflows.frame_calibration import View, calibrate_opencv, calibrate_photogrammetric

__all__ = [
    "run",
    "chessboard_views",
    "charuco_views",
    "reference_dir",
    "opencv_sigmas",
    "largest_paper_deviation",
    "PIXEL_PITCH_MM",
    "opencv_calibrate",
    "SAME_REL",
    "INTRINSIC_ROWS",
]

#: nominal pixel pitch of the tutorial webcam (unknown; it only scales the mm units: f/pitch,
#: the residuals in px and the fit do not depend on it)
PIXEL_PITCH_MM = 0.006


def reference_dir():
    """Folder of the shipped reference data (``src/hsgeo/data/reference``)."""
    return resources.files("hsgeo") / "data" / "reference"


def chessboard_views():
    """The tutorial's 8 views of the 9×6 chessboard (50 mm squares) and OpenCV's result.

    Returns
    -------
    views : list of View
    image_size : (640, 480)
    ref : dict
        ``fx_px``, ``k1``, ``k2``, ``k3``, ``rms_px`` of OpenCV's file, and the raw file entries.
    """
    d = read_opencv_storage(
        reference_dir() / "opencv-chessboard" / "out_camera_data.yml",
        required=(
            "Image_points",
            "Camera_Matrix",
            "Distortion_Coefficients",
            "board_Width",
            "board_Height",
            "square_Size",
            "image_Width",
            "image_Height",
        ),
    )
    nx, ny, sq = int(d["board_Width"]), int(d["board_Height"]), d["square_Size"]
    uv = d["Image_points"].reshape(-1, nx * ny, 2)
    k = np.arange(nx * ny)  # row-major board order: object point k = (sq (k % nx), sq (k // nx), 0)
    X = np.column_stack([sq * (k % nx), sq * (k // nx), np.zeros(k.size)])
    views = [View(X, uv[i], k) for i in range(uv.shape[0])]
    dist = d["Distortion_Coefficients"].ravel()
    ref = {
        "fx_px": d["Camera_Matrix"][0, 0],
        "k1": dist[0],
        "k2": dist[1],
        "k3": dist[4],
        "rms_px": d["Avg_Reprojection_Error"],
        "file": d,
    }
    return views, (int(d["image_Width"]), int(d["image_Height"])), ref


def charuco_views(board: Board | None = None):
    """ChArUco corners detected in the four tutorial photographs, and the 2021 reference file.

    The board (default: :data:`~hsgeo.io.boards.OPENCV_TUTORIAL_CHARUCO`, lengths in mm) is
    given to OpenCV in metres, as in OpenCV's tutorial: OpenCV interpolates the corners in
    float32, and the unit moves them by ~3e-5 px, which moves the four-image calibration by
    ~1e-4 relative. The views' object coordinates are therefore in metres (the tutorial's
    extrinsic translations too); the intrinsics do not depend on the unit.
    """
    board = board or OPENCV_TUTORIAL_CHARUCO
    folder = reference_dir() / "opencv-charuco"
    views = []
    for i in range(4):
        ids, uv_px, X_m = detect_charuco(
            folder / "images" / f"img_{i:02d}.jpg", board, length_unit="m"
        )
        views.append(View(X_m, uv_px, ids))
    ref = read_opencv_storage(
        folder / "tutorial_camera_charuco.yml",
        required=("camera_matrix", "distortion_coefficients"),
    )
    return views, (int(ref["image_width"]), int(ref["image_height"])), ref


def opencv_calibrate(views, image_size, flags=0):
    """``cv2.calibrateCamera`` on the same views: (K, dist (k1, k2, p1, p2, k3), rms_px).

    OpenCV runs single-threaded here: with its thread pool the result varies in the 7th digit from
    call to call, and the book's numbers must be the same bits for the same input.
    """
    import cv2

    cv2.setNumThreads(1)

    obj = [v.X.astype(np.float32) for v in views]
    img = [v.uv_px.astype(np.float32).reshape(-1, 1, 2) for v in views]
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-15)
    rms, K, dist, _, _ = cv2.calibrateCamera(
        obj, img, image_size, None, None, flags=flags, criteria=crit
    )
    return K, dist.ravel()[:5], float(rms)


def opencv_sigmas(views, image_size) -> np.ndarray:
    """``cv2.calibrateCameraExtended``'s standard deviations of the 9 intrinsics
    (fx, fy, cx, cy, k1, k2, p1, p2, k3), all free, on the same views (single-threaded).
    """
    import cv2

    cv2.setNumThreads(1)
    obj = [v.X.astype(np.float32) for v in views]
    img = [v.uv_px.astype(np.float32) for v in views]
    crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-15)
    out = cv2.calibrateCameraExtended(obj, img, image_size, None, None, criteria=crit)
    return out[5].ravel()[:9].astype(float)


#: relative difference up to which two numbers without a σ (an RMS, a σ̂) count as the same
#: result of two implementations (the tolerance of tests/test_calibration.py)
SAME_REL = 1e-3


def _same(ours: float, theirs: float, what: str) -> tuple[str, str]:
    """Verdict for a number without a σ: reproduced when within :data:`SAME_REL` relative."""
    rel = abs(ours - theirs) / abs(theirs)
    words = f"{what} differ by {rel:.1e} relative (no σ; tolerance {SAME_REL:g})"
    return ("reproduced" if rel <= SAME_REL else "differs"), words


INTRINSIC_ROWS = (
    ("fx_px", "px"),
    ("fy_px", "px"),
    ("cx_px", "px"),
    ("cy_px", "px"),
    ("k1", "1"),
    ("k2", "1"),
    ("p1", "1"),
    ("p2", "1"),
    ("k3", "1"),
)


def _chessboard_rows(extras: dict) -> list[Row]:
    """1. The chessboard under OpenCV's constraints (flags 14), the σ̂ of all nine intrinsics
    against OpenCV's, and the two forms of Brown's model.
    """
    rows: list[Row] = []
    views, size, ref = chessboard_views()
    cal = calibrate_opencv(
        views, size, fix_principal_point=True, square_pixels=True, zero_tangent=True
    )
    v, s = cal.values(), cal.sigmas()
    t = "OpenCV chessboard"
    for q in ("fx_px", "k1", "k2", "k3"):
        rows.append(
            Row(
                table=t,
                quantity=q,
                unit="px" if q.endswith("px") else "1",
                paper=ref[q],
                reproduced=v[q],
                sigma=s[q],
            )
        )
    verdict, why = _same(cal.rms_px, ref["rms_px"], "the RMS residuals")
    rows.append(
        Row(
            table=t,
            quantity="rms_px",
            unit="px",
            paper=ref["rms_px"],
            reproduced=cal.rms_px,
            verdict=verdict,
            reason=why,
        )
    )
    # σ̂ of all nine intrinsics (free) against OpenCV's stdDeviationsIntrinsics, same corners
    full = calibrate_opencv(views, size)
    sd_cv, sd_hs = opencv_sigmas(views, size), full.sigmas()
    t = "σ̂ against OpenCV (chessboard, 9 intrinsics free)"
    for (q, unit), s_cv in zip(INTRINSIC_ROWS, sd_cv, strict=True):
        verdict, why = _same(sd_hs[q], s_cv, "the σ̂")
        rows.append(
            Row(
                table=t,
                quantity=f"σ({q})",
                unit=unit,
                paper=s_cv,
                reproduced=sd_hs[q],
                verdict=verdict,
                reason=why,
            )
        )
    pg = calibrate_photogrammetric(
        views, size, PIXEL_PITCH_MM, fix_principal_point=True, zero_decentering=True
    )
    t = "two forms of Brown's model (chessboard)"
    f_pg, sf_pg = pg.values()["f_mm"] / PIXEL_PITCH_MM, pg.sigmas()["f_mm"] / PIXEL_PITCH_MM
    rows += [
        Row(
            table=t, quantity="f_px_opencv_form", unit="px", reproduced=v["fx_px"], sigma=s["fx_px"]
        ),
        Row(table=t, quantity="f_px_photogrammetric_form", unit="px", reproduced=f_pg, sigma=sf_pg),
        Row(table=t, quantity="rms_px_opencv_form", unit="px", reproduced=cal.rms_px),
        Row(table=t, quantity="rms_px_photogrammetric_form", unit="px", reproduced=pg.rms_px),
    ]
    extras["chessboard"] = {
        "views": views,
        "opencv_form": cal,
        "all_free": full,
        "photogrammetric_form": pg,
        "reference": ref,
    }
    return rows


def _charuco_rows(extras: dict) -> list[Row]:
    """2. ChArUco: hsgeo against today's ``cv2.calibrateCamera`` on the same detected corners,
    and against OpenCV's reference file of 2021.
    """
    rows: list[Row] = []
    cviews, csize, cref = charuco_views()
    ccal = calibrate_opencv(cviews, csize)
    K, dist, rms_cv = opencv_calibrate(cviews, csize)
    cv_vals = {
        "fx_px": K[0, 0],
        "fy_px": K[1, 1],
        "cx_px": K[0, 2],
        "cy_px": K[1, 2],
        "k1": dist[0],
        "k2": dist[1],
        "p1": dist[2],
        "p2": dist[3],
        "k3": dist[4],
    }
    hv, hs = ccal.values(), ccal.sigmas()
    t = "OpenCV ChArUco"
    for q, unit in INTRINSIC_ROWS:
        rows.append(
            Row(table=t, quantity=q, unit=unit, paper=cv_vals[q], reproduced=hv[q], sigma=hs[q])
        )
    verdict, why = _same(ccal.rms_px, rms_cv, "the RMS residuals")
    rows.append(
        Row(
            table=t,
            quantity="rms_px",
            unit="px",
            paper=rms_cv,
            reproduced=ccal.rms_px,
            verdict=verdict,
            reason=why,
        )
    )
    cm, cd = cref["camera_matrix"], cref["distortion_coefficients"].ravel()
    extras["charuco"] = {
        "views": cviews,
        "hsgeo": ccal,
        "opencv": cv_vals,
        "opencv_rms": rms_cv,
        "reference_2021": {
            "fx_px": cm[0, 0],
            "fy_px": cm[1, 1],
            "cx_px": cm[0, 2],
            "cy_px": cm[1, 2],
            "k1": cd[0],
            "k2": cd[1],
            "p1": cd[2],
            "p2": cd[3],
            "k3": cd[4],
            "rms_px": cref["avg_reprojection_error"],
        },
    }

    # OpenCV's reference file of 2021 (an older corner detector) against hsgeo today
    t = "OpenCV ChArUco 2021 file"
    r21 = extras["charuco"]["reference_2021"]
    for q, unit in INTRINSIC_ROWS:
        rows.append(
            Row(table=t, quantity=q, unit=unit, paper=r21[q], reproduced=hv[q], sigma=hs[q])
        )
    rows.append(
        Row(
            table=t,
            quantity="rms_px",
            unit="px",
            paper=r21["rms_px"],
            reproduced=ccal.rms_px,
            verdict="differs" if abs(ccal.rms_px / r21["rms_px"] - 1) > SAME_REL else "reproduced",
            reason="other corners (the 2021 file used an older detector); no σ for an RMS",
        )
    )
    return rows


def _bench_rows(seed: int, extras: dict) -> list[Row]:
    """3. The simulated bench, truth known."""
    from hsgeo.simulate.frame_bench import simulate
    from hsgeo.simulate.scenarios import load_scenario

    rows: list[Row] = []
    cfg = load_scenario("frame_bench")
    sim, sim_truth = simulate(cfg, seed)
    sviews = [
        View(sim.X_mm[sim.point[sim.view == i]], sim.uv_px[sim.view == i])
        for i in range(sim.n_views)
    ]
    scal = calibrate_opencv(sviews, sim.image_size_px, sigma_px=sim.sigma_px)
    truth = dict(zip(("fx_px", "fy_px", "cx_px", "cy_px"), sim_truth.intrinsics, strict=True))
    truth.update(zip(("k1", "k2", "p1", "p2", "k3"), sim_truth.distortion, strict=True))
    sv, ss = scal.values(), scal.sigmas()
    t = "simulated bench"
    for q, unit in INTRINSIC_ROWS:
        rows.append(
            Row(table=t, quantity=q, unit=unit, reproduced=sv[q], sigma=ss[q], truth=truth[q])
        )
    rows.append(Row(table=t, quantity="sigma0", unit="1", reproduced=scal.result.sigma0, truth=1.0))
    extras["bench"] = {
        "calibration": scal,
        "truth": truth,
        "observations": sim,
        "simulation_truth": sim_truth,
    }
    return rows


def run(seed: int = 0, scale: float = 1.0) -> Reproduction:
    """Compute every table of the chapter (``scale`` is unused: the data are small)."""
    extras: dict = {}
    rows = _chessboard_rows(extras) + _charuco_rows(extras) + _bench_rows(seed, extras)
    meta = {
        "chessboard_source": "opencv/opencv samples/cpp/tutorial_code/calib3d/camera_calibration/"
        "out_camera_data.yml (flags 14)",
        "charuco_source": "opencv_contrib aruco tutorial images img_00..03.jpg; board 5x7, "
        "0.04 m squares, 0.02 m markers, DICT_6X6_250",
        "charuco_corners_per_image": [int(v.X.shape[0]) for v in extras["charuco"]["views"]],
        "charuco_reference_2021": extras["charuco"]["reference_2021"],
        "pixel_pitch_mm_nominal": PIXEL_PITCH_MM,
        "bench_seed": seed,
        "iterations": {
            "chessboard": extras["chessboard"]["opencv_form"].result.iterations,
            "charuco": extras["charuco"]["hsgeo"].result.iterations,
        },
    }
    # the "paper" column is OpenCV's result on its own sample images (or its reference
    # file): an independent implementation, nothing of it built into our estimate; the
    # reference data are our chosen yardstick (every verdict row says whence)
    rows = [replace(r, provenance="chosen") if r.paper is not None else r for r in rows]
    return Reproduction("frame-reference", seed, rows, meta, extras)


def largest_paper_deviation(rep, table: str) -> str:
    """The largest ``|reproduced − paper| / σ̂`` over the rows of ``table`` with a σ̂ and a
    paper value (here: OpenCV's), in words: ``"0.3σ̂ (largest: k1)"``.
    """
    zs = [
        (r.quantity, (r.reproduced - r.paper) / r.sigma)
        for r in rep.rows_of(table)
        if r.sigma and r.paper is not None
    ]
    q, z = max(zs, key=lambda t: abs(t[1]))
    return f"{abs(z):.1g}σ̂ (largest: {q})"
