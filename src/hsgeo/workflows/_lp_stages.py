"""The stages of :func:`hsgeo.workflows.lp_observations.retrieve`: scenes and key points per
strip (back to lines at once, so no scene image is kept), the squares measured, candidate pairs
matched and filtered by RANSAC.

Kept apart from :mod:`hsgeo.workflows.lp_observations` (the inputs, options, result and the file
front end) so each file holds one concern at a readable length.
"""

from __future__ import annotations

import time

import numpy as np

from hsgeo.measure.keypoints import detect_brisk, match_hamming
from hsgeo.workflows import _lp_geometry as geo
from hsgeo.workflows import _lp_squares as sq

__all__ = ["Keys", "strip_scenes", "match_all", "MIN_MATCHES"]

#: Correspondences the LP fundamental matrix needs (002 §3.1: "at least 11").
MIN_MATCHES = 11


class Keys:
    """The key points of every scene and band, in flat arrays (the match graph's nodes)."""

    def __init__(self):
        self.parts: dict[str, list] = {
            k: []
            for k in ("strip", "scene", "band", "uv", "line", "x", "t", "ground", "desc", "size")
        }
        self.slices: dict[tuple[int, int], slice] = {}
        self.n = 0

    def add(self, strip, scene, band, kp, line, x, t, ground):
        m = kp.n
        self.slices[(scene, band)] = slice(self.n, self.n + m)
        self.n += m
        for k, v in (
            ("strip", np.full(m, strip)),
            ("scene", np.full(m, scene)),
            ("band", np.full(m, band)),
            ("uv", kp.uv),
            ("line", line),
            ("x", x),
            ("t", t),
            ("ground", ground),
            ("desc", kp.descriptors),
            ("size", kp.size_px),
        ):
            self.parts[k].append(np.asarray(v))

    def freeze(self):
        for k, v in self.parts.items():
            shape = {"uv": (0, 2), "ground": (0, 2), "desc": (0, 64)}.get(k, (0,))
            setattr(self, k, np.concatenate(v) if v else np.zeros(shape))
        self.strip = self.strip.astype(np.int64)
        self.line = self.line.astype(np.int64)
        self.desc = self.desc.astype(np.uint8)
        return self


def strip_scenes(strip, si, inputs, options, bands, height, keys, rows, timings):
    """Scenes of one strip: key points back to lines, footprints, the squares measured.

    Returns the strip's ``(scene index, footprint)`` list; the scenes' images are not kept.
    """
    from hsgeo.measure.lp_scenes import make_scenes, scene_to_line

    nav, cam = inputs.navigation, inputs.camera
    h_px = (inputs.n_px_full - 1) / 2
    t0 = time.perf_counter()
    scenes = make_scenes(strip, nav, cam, options.n_lines_per_scene, inputs.n_px_full)
    timings["scenes"] += time.perf_counter() - t0
    t_s = np.asarray(strip.t_s, float)
    squares = sq.predict(strip, inputs, height) if len(inputs.square_ids) else None
    candidates = []
    out = []
    for sc in scenes:
        t0 = time.perf_counter()
        n, n_cols = sc.image.shape[:2]
        g = len(rows["scenes"])
        tr = t_s[sc.line0 + np.array([0, n - 1])]
        fp = geo.footprint(cam, (sc.col0 - h_px, sc.col0 + n_cols - 1 - h_px), tr, nav, height)
        dx = np.asarray(sc.dx_px, float)
        row = {
            "strip": str(strip.strip_id),
            "scene": g,
            "line0": int(sc.line0),
            "n_lines": int(n),
            "t_ref_s": float(sc.t_ref_s),
            "dx_rms_px": float(np.sqrt(np.nanmean(dx**2))),
            "dx_max_px": float(np.nanmax(np.abs(dx))),
        }
        for b in bands:
            kp = detect_brisk(
                sc.image[:, :, b], threshold=options.brisk_threshold, octaves=options.brisk_octaves
            )
            if kp.n:
                line, x = scene_to_line(sc, kp.uv)
                line = np.asarray(line, np.int64)
                t = t_s[line]
                ground = geo.ground_points(cam, x, t, nav, b, height)[:, :2]
            else:
                line, x, t, ground = (
                    np.zeros(0, np.int64),
                    np.zeros(0),
                    np.zeros(0),
                    np.zeros((0, 2)),
                )
            keys.add(si, g, b, kp, line, x, t, ground)
            row[f"keypoints_band{b}"] = kp.n
        rows["scenes"].append(row)
        out.append((g, fp))
        timings["detection"] += time.perf_counter() - t0
        if squares is not None:
            t0 = time.perf_counter()
            candidates += sq.candidates(sc, squares, inputs, options, bands)
            timings["squares"] += time.perf_counter() - t0
    if squares is not None:
        t0 = time.perf_counter()
        rows["squares"] += sq.choose(candidates, strip, squares, inputs, options)
        timings["squares"] += time.perf_counter() - t0
    return out


def _ransac_pair(uv1, uv2, options, seed):
    """Both models' inliers on one pair's matches (fewer than 11: none)."""
    from hsgeo.measure.lp_ransac import ransac_frame_fundamental, ransac_lp_fundamental

    n = uv1.shape[0]
    if n < MIN_MATCHES:
        return np.zeros(n, bool), np.zeros(n, bool)
    lp = ransac_lp_fundamental(uv1, uv2, threshold_px=options.threshold_px, rng=seed).inliers
    fr = ransac_frame_fundamental(uv1, uv2, threshold_px=options.threshold_px)
    return np.asarray(lp, bool), np.asarray(fr, bool)


def _inside(keys, scene: int, band: int, edges, margin) -> np.ndarray:
    """Key points of a scene's band predicted inside a footprint (its
    :func:`~hsgeo.workflows._lp_geometry.convex_edges`, with a margin).
    """
    sl = keys.slices[(scene, band)]
    idx = np.arange(sl.start, sl.stop)
    return idx[geo.inside_convex(keys.ground[idx], None, margin, edges=edges)]


def _match_pair(keys, ga, ea, gb, eb, band, options, rows, m, seed, timings) -> None:
    """One scene pair in one band: matches inside the overlap, both RANSACs, appended
    (``ea``, ``eb``: the scenes' footprints as :func:`~hsgeo.workflows._lp_geometry.convex_edges`).
    """
    t0 = time.perf_counter()
    ia = _inside(keys, ga, band, eb, options.overlap_margin_m)
    ib = _inside(keys, gb, band, ea, options.overlap_margin_m)
    i1, i2, dist = match_hamming(keys.desc[ia], keys.desc[ib], ratio=options.ratio)
    a, b = ia[i1], ib[i2]
    t1 = time.perf_counter()
    lp, fr = _ransac_pair(keys.uv[a], keys.uv[b], options, seed)
    timings["matching"] += t1 - t0
    timings["_ransac_strip"] += time.perf_counter() - t1
    p = len(rows["pairs"])
    rows["pairs"].append(
        {
            "pair": p,
            "band": int(band),
            "scene_a": int(ga),
            "scene_b": int(gb),
            "n_matches": int(a.size),
            "n_inliers_lp": int(lp.sum()),
            "n_inliers_frame": int(fr.sum()),
        }
    )
    for k, v in (("pair", np.full(a.size, p)), ("a", a), ("b", b), ("hamming", dist)):
        m[k].append(v)
    m["lp"].append(lp)
    m["frame"].append(fr)


def match_all(per_strip, keys, options, bands, rows, timings, progress) -> dict:
    """Candidate pairs of scenes of different strips, matched per band, RANSAC: match arrays."""
    rng = np.random.default_rng(options.rng)
    m = {k: [] for k in ("pair", "a", "b", "hamming", "lp", "frame")}
    n = len(per_strip)
    # each footprint's edges once, not once per pair and band (issue 41)
    edges = [[geo.convex_edges(f) for _, f in s] for s in per_strip]
    for i in range(n):
        timings["_ransac_strip"] = 0.0
        for j in range(i + 1, n):
            for (ga, fa), ea in zip(per_strip[i], edges[i], strict=True):
                for (gb, fb), eb in zip(per_strip[j], edges[j], strict=True):
                    if not geo.convex_overlap(fa, fb, options.overlap_margin_m):
                        continue
                    for b in bands:
                        seed = int(rng.integers(2**31))
                        _match_pair(keys, ga, ea, gb, eb, b, options, rows, m, seed, timings)
        timings["ransac"] += timings["_ransac_strip"]
        timings["ransac_per_strip"].append(timings.pop("_ransac_strip"))
        if progress is not None:
            progress(i + 1, n, "matching strip by strip")
    out = {k: (np.concatenate(v) if v else np.zeros(0)) for k, v in m.items()}
    for k in ("pair", "a", "b"):
        out[k] = out[k].astype(np.int64)
    for k in ("lp", "frame"):
        out[k] = out[k].astype(bool)
    return out
