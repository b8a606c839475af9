"""002 Fig. 9: the orthomosaic of the rendered LP strips and the reference squares found in it.

002 Fig. 9 shows a true-colour mosaic of the orthoimages of the 1875 m AGL acquisition, 30 cm
cells, made on a 20 cm DSM with the adjusted trajectory, and the white reference squares
enlarged in it: "they can be accurately found in the orthomosaic". :func:`fig9` makes that
mosaic of a rendered campaign (:func:`hsgeo.simulate.lp_campaign.simulate`) twice, through the
user's path (``hsgeo orthorectify``: :mod:`hsgeo.workflows.orthorectify`, nearest
neighbour, nearest-to-nadir mosaic rule) in ETRS89 / UTM 32N (EPSG:25832, the
site :data:`hsgeo.crs.SITE_AAS`):

* **adjusted**: the navigation with the adjustment's node corrections (002 eq. 4) and the
  adjusted c, boresight, lever arm and distortion (the
  :class:`~hsgeo.workflows.pushbroom_ba.PushbroomResult` of the retrieved observations, the
  one ``hsgeo reproduce lp-observations`` computes);
* **raw**: the GNSS/INS navigation and the a-priori camera, for contrast.

The raw geometry puts a square ~20 m from its RTK position (the a-priori boresight is off by
a few tenths of a degree, ~10–15 m on the ground at 1875 m AGL, in opposite directions on
strips flown in opposite directions), farther than the squares' spacing allows a window
around the RTK position to search; there the window is centred on where the raw geometry
puts the square (:func:`where_squares_land`: the truth's line and pixel that saw it, sent down
the raw ray, per strip that saw it; the strip whose view is found there within
:data:`FOUND_WITHIN_M`; the truth only places the window, the position is measured in the
mosaic).

Both on a DSM with the error of 002's 20 cm photogrammetric DSM (:func:`photogrammetric_dsm`:
the simulation's true DSM plus a spatially correlated height error of
:data:`DSM_SIGMA_M`, ours), not on the true DSM the renderer used. Each of the 17 squares is
measured in each mosaic (:func:`hsgeo.measure.squares.square_centroids`, in the sum of the
bands) and
compared with its RTK position (``LpObservations.square_xyz_m``, mapped to EPSG:25832 by
:mod:`hsgeo.crs`): table ``"002 Fig. 9"``, each row's truth the error the measurement should
find (where the geometry puts the square, :func:`where_squares_land`, minus its RTK position:
the RTK noise and the geometry's error, none of the measurement's). The bar: the RMS of
the horizontal errors within 1 GSD (the mosaic's cell, 002's 0.30 m) with the adjusted
trajectory.
"""

from __future__ import annotations

import time

import numpy as np

from hsgeo.crs import SITE_AAS
from hsgeo.papers import P002
from hsgeo.report import Row
from hsgeo.sensors import adjusted as adjusted_geometry
from hsgeo.workflows.orthorectify import (
    OrthoInputs,
    OrthoOptions,
    adjustment_of,
    lp_strips,
    orthorectify,
)

#: The true-colour bands' wavelengths (R, G, B), nm.
TRUE_COLOUR_NM = (640.0, 550.0, 460.0)

__all__ = [
    "fig9",
    "mosaic_of",
    "square_errors",
    "where_squares_land",
    "photogrammetric_dsm",
    "TABLE",
    "SEARCH_M",
    "FOUND_WITHIN_M",
    "TRUE_COLOUR_NM",
    "DSM_SIGMA_M",
    "DSM_CORRELATION_M",
]

TABLE = "002 Fig. 9"
#: Height error (σ, m) and its correlation length (m) of the photogrammetric DSM the mosaic is
#: made on (ours: about 1.5 cells of 002's 20 cm DSM in σ, smooth over a metre — dense image
#: matching's typical error on open ground; 002 gives none).
DSM_SIGMA_M, DSM_CORRELATION_M = 0.3, 1.0
#: Half width of the window searched around each square's expected position, m: the adjusted
#: geometry is good to a few dm, the next square ≥ 30 m away.
SEARCH_M = 3.0
#: A square in the raw mosaic counts as found where a strip's view of it lands when its centroid
#: lies within this distance of that landing, m (which strip's view a cell shows depends on the
#: mosaic rule at that cell, among pixels that saw different ground).
FOUND_WITHIN_M = 1.0


def mosaic_of(
    obs, truth, camera, trajectory, *, resolution_m: float, bands_nm=TRUE_COLOUR_NM, terrain=None
):
    """The mosaic (in memory) of the campaign's strips with this camera and trajectory.

    Returns
    -------
    xarray.DataArray
        ``(band, y, x)`` float32 in EPSG:25832, NaN outside every swath.
    """
    strips, wl, _ = lp_strips(obs.strips, camera, trajectory, bands_nm, obs.n_px_full)
    names = tuple(f"{w:g} nm" for w in wl)
    dsm = truth.terrain if terrain is None else terrain
    inputs = OrthoInputs(tuple(strips), dsm, names, tuple(float(w) for w in wl))
    return orthorectify(inputs, OrthoOptions(resolution_m=resolution_m, frame=SITE_AAS)).compute()


def where_squares_land(obs, truth, camera, trajectory, *, band: int = 3, terrain=None):
    """Where each square lands in a mosaic made with ``camera`` and ``trajectory``, once per
    strip that saw it: the line time and pixel that saw its centre (true camera and
    trajectory), sent down the given geometry's ray onto the DSM.

    Returns
    -------
    (k, n_strips, 2) ndarray
        Map x, y in EPSG:25832, m, per square the strips that saw it first, nearest to nadir
        first (NaN for the rest).
    """
    from hsgeo.ortho import Strip, geolocate_lines

    X = np.asarray(truth.square_xyz_m, float)
    out = np.full((X.shape[0], len(obs.strips), 2), np.nan)
    for k in range(X.shape[0]):
        seen = []
        for s in obs.strips:
            t = s.t_s
            y = truth.camera.project(
                np.repeat(X[k : k + 1], t.size, 0), t, truth.trajectory, band=band
            )[:, 1]
            i = np.flatnonzero(np.sign(y[:-1]) != np.sign(y[1:]))
            if i.size == 0:
                continue
            i = int(i[0])
            tt = t[i] + y[i] / (y[i] - y[i + 1]) * (t[i + 1] - t[i])
            x = truth.camera.project(X[k : k + 1], [tt], truth.trajectory, band=band)[0, 0]
            xs = s.x_px(obs.n_px_full)
            if not xs.min() <= x <= xs.max():
                continue
            st = Strip(camera, trajectory, [tt], np.array([[x, 0.0]]), None, {"band": band})
            dsm = truth.terrain if terrain is None else terrain
            enu, _, nadir = geolocate_lines(st, dsm, SITE_AAS)
            xm, ym, _ = SITE_AAS.enu_to_map(*enu.reshape(3))
            seen.append((float(nadir.ravel()[0]), float(xm), float(ym)))
        for j, (_, xm, ym) in enumerate(sorted(seen)):
            out[k, j] = xm, ym
    return out


def _found_where_landed(mosaic, square_xyz_m, landings, tol_m: float):
    """Per square, the landing (of :func:`where_squares_land`) where a square is found within
    ``tol_m`` of it, nearest to nadir first: the error found and the error expected, m.
    """
    none = np.full((landings.shape[0], 2), np.nan)
    rtk, err = square_errors(mosaic, square_xyz_m, search_m=SEARCH_M, search_xy_m=none)
    exp = landings[:, 0, :].copy()
    done = np.zeros(landings.shape[0], bool)
    for j in range(landings.shape[1]):
        at = np.where(done[:, None], np.nan, landings[:, j, :])
        if not np.isfinite(at).any():
            break
        rtk, e = square_errors(mosaic, square_xyz_m, search_m=SEARCH_M, search_xy_m=at)
        ok = np.all(np.isfinite(e), axis=1) & (np.hypot(*(rtk + e - at).T) <= tol_m)
        err[ok], exp[ok] = e[ok], at[ok]
        done |= ok
    return err, exp - rtk


def square_errors(mosaic, square_xyz_m, *, search_m: float, search_xy_m=None):
    """Each square's position in the mosaic minus its RTK position.

    Parameters
    ----------
    mosaic : xarray.DataArray
    square_xyz_m : (k, 3) ndarray
        RTK positions in the site's local frame (E, N, U), m.
    search_m : float
    search_xy_m : (k, 2) ndarray, optional
        Where to centre each square's window (default its RTK position), EPSG:25832, m.

    Returns
    -------
    rtk_xy_m : (k, 2) ndarray
        The RTK positions in EPSG:25832, m.
    error_xy_m : (k, 2) ndarray
        Found minus RTK, m (NaN where the square is not in the mosaic or not found).
    """
    from hsgeo.measure.squares import square_centroids

    P = np.asarray(square_xyz_m, float)
    x, y, _ = SITE_AAS.enu_to_map(P[:, 0], P[:, 1], P[:, 2])
    rtk = np.column_stack([x, y])
    at = rtk if search_xy_m is None else np.asarray(search_xy_m, float)
    inside = (
        np.all(np.isfinite(at), axis=1)
        & (at[:, 0] >= float(mosaic["x"].min()))
        & (at[:, 0] <= float(mosaic["x"].max()))
        & (at[:, 1] >= float(mosaic["y"].min()))
        & (at[:, 1] <= float(mosaic["y"].max()))
    )
    err = np.full(rtk.shape, np.nan)
    if inside.any():
        found, _ = square_centroids(mosaic, at[inside], search_m=search_m)
        err[inside] = found - rtk[inside]
    return rtk, err


def photogrammetric_dsm(truth, rng=0, *, sigma_m=DSM_SIGMA_M, correlation_m=DSM_CORRELATION_M):
    """The simulation's true DSM plus the error of a photogrammetric DSM: Gaussian noise
    smoothed over ``correlation_m`` and scaled to σ ``sigma_m`` (on the true DSM's grid).

    Returns
    -------
    hsgeo.geocode.DemTerrain
    """
    from scipy.ndimage import gaussian_filter

    from hsgeo.geocode import DemTerrain

    dem = truth.ground.dsm_dataarray()
    cell = float(abs(dem["E"].values[1] - dem["E"].values[0]))
    g = np.random.default_rng(rng)
    e = gaussian_filter(g.standard_normal(dem.shape), correlation_m / cell, mode="wrap")
    e *= sigma_m / max(float(e.std()), 1e-12)
    return DemTerrain(dem + e)


def _rms(err) -> float:
    ok = np.all(np.isfinite(err), axis=1)
    return float(np.sqrt(np.mean(np.sum(err[ok] ** 2, axis=1)))) if ok.any() else float("nan")


def fig9(obs, truth, adjusted, *, resolution_m: float = P002["fig9_pixel_m"], rng=0):
    """002 Fig. 9 (module docstring): both mosaics, the squares' errors, table ``"002 Fig. 9"``.

    Parameters
    ----------
    obs : hsgeo.simulate.lp_campaign.LpObservations
        The rendered strips, the GNSS/INS navigation, the a-priori camera, the RTK squares.
    truth : hsgeo.simulate.lp_campaign.LpTruth
        Its ``terrain`` is the DSM.
    adjusted : hsgeo.workflows.pushbroom_ba.PushbroomResult
        The adjustment of the observations retrieved from these strips.
    resolution_m : float
        Cell size, m (002: 0.30).
    rng : int or numpy.random.Generator
        Seed of the photogrammetric DSM's error (:func:`photogrammetric_dsm`).

    Returns
    -------
    rows : list of Row
    mosaic_adjusted, mosaic_raw : xarray.DataArray
        ``(band, y, x)`` true colour (R, G, B), EPSG:25832.
    per_square : dict
        ``square_ids``, ``rtk_xy_m`` (k, 2), ``error_adjusted_m`` / ``error_raw_m`` (k, 2),
        ``expected_adjusted_m`` / ``expected_raw_m`` (k, 2): where that geometry puts each
        square minus its RTK position (:func:`where_squares_land`: the error the measurement
        should find, the rows' truth), ``seconds`` (each mosaic's wall time).
    """
    adj = adjustment_of(adjusted)
    runs = {
        "adjusted": adjusted_geometry(obs.camera, obs.navigation, adj),
        "raw": (obs.camera, obs.navigation),
    }
    mosaics, errors, seconds, expected = {}, {}, {}, {}
    dsm = photogrammetric_dsm(truth, rng)
    for key, (cam, traj) in runs.items():
        t0 = time.perf_counter()
        mosaics[key] = mosaic_of(obs, truth, cam, traj, resolution_m=resolution_m, terrain=dsm)
        seconds[key] = time.perf_counter() - t0
        land = where_squares_land(obs, truth, cam, traj, terrain=dsm)
        if key == "adjusted":  # the window around the RTK position (not steered by the truth)
            rtk, errors[key] = square_errors(mosaics[key], obs.square_xyz_m, search_m=SEARCH_M)
            expected[key] = land[:, 0, :] - rtk
        else:  # around where each strip's view of the square lands: the one found there
            errors[key], expected[key] = _found_where_landed(
                mosaics[key], obs.square_xyz_m, land, FOUND_WITHIN_M
            )
    per_square = {
        "square_ids": tuple(obs.square_ids),
        "rtk_xy_m": rtk,
        "error_adjusted_m": errors["adjusted"],
        "error_raw_m": errors["raw"],
        "expected_adjusted_m": expected["adjusted"],
        "expected_raw_m": expected["raw"],
        "seconds": seconds,
    }
    rows = _rows(per_square, resolution_m)
    return rows, mosaics["adjusted"], mosaics["raw"], per_square


def _rows(per_square, gsd_m: float) -> list[Row]:
    ea, er = per_square["error_adjusted_m"], per_square["error_raw_m"]
    xa, xr = per_square["expected_adjusted_m"], per_square["expected_raw_m"]
    n_a = int(np.all(np.isfinite(ea), axis=1).sum())
    rms_a, rms_r = _rms(ea), _rms(er)
    ok = bool(rms_a <= gsd_m)
    rows = [
        Row(
            table=TABLE,
            quantity="square_position_error_rms_m",
            unit="m",
            reproduced=rms_a,
            truth=_rms(np.where(np.isfinite(ea), xa, np.nan)),
            provenance="chosen",
            verdict="not testable",
            reason=f"{'meets' if ok else 'misses'} our bar (no paper value, so not a "
            f"reproduction): horizontal RMS over the {n_a} squares found in the mosaic with the "
            f"adjusted trajectory and camera on a DSM with a photogrammetric DSM's error, "
            f"{'within' if ok else 'beyond'} 1 GSD ({gsd_m:g} m); 002 shows the squares "
            "'accurately found in the orthomosaic' (Fig. 9) without a number",
        ),
        Row(
            table=TABLE,
            quantity="square_position_error_rms_raw_m",
            unit="m",
            reproduced=rms_r,
            truth=_rms(np.where(np.isfinite(er), xr, np.nan)),
            provenance="chosen",
            verdict="not testable",
            reason="the contrast: the GNSS/INS navigation and the a-priori camera (002 gives no "
            f"such mosaic); {int(np.all(np.isfinite(er), axis=1).sum())} squares found",
        ),
        Row(
            table=TABLE,
            quantity="squares_found",
            unit="1",
            reproduced=float(n_a),
            provenance="chosen",
        ),
    ]
    for k, sid in enumerate(per_square["square_ids"]):
        for key, e, x in (("", ea[k], xa[k]), ("_raw", er[k], xr[k])):
            if np.all(np.isfinite(e)):
                rows.append(
                    Row(
                        table=TABLE,
                        quantity=f"square_error{key}_m.{sid}",
                        unit="m",
                        reproduced=float(np.hypot(*e)),
                        truth=float(np.hypot(*x)) if np.all(np.isfinite(x)) else None,
                        provenance="chosen",
                    )
                )
    return rows
