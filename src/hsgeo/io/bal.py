"""Bundle-adjustment problems in the BAL format ("Bundle Adjustment in the Large").

Agarwal, Snavely, Seitz, Szeliski (2010), https://grail.cs.washington.edu/projects/bal/. A text
file (optionally ``.bz2`` compressed) of whitespace-separated numbers::

    n_cameras n_points n_observations
    camera_index point_index x y          (n_observations lines)
    rx ry rz tx ty tz f k1 k2            (9 values per camera, usually one per line)
    X Y Z                                 (3 values per point, usually one per line)

The camera model is Snavely's (:class:`hsgeo.sensors.bal.SnavelyReprojection`).
"""

from __future__ import annotations

import bz2
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError

__all__ = ["BALProblem", "read_bal", "ladybug_path", "CAMERA_COLUMNS", "MAX_XY_PX"]

#: The 9 parameters of a BAL camera, in file order.
CAMERA_COLUMNS = ("rx_rad", "ry_rad", "rz_rad", "tx", "ty", "tz", "f_px", "k1", "k2")


@dataclass
class BALProblem:
    """A BAL bundle-adjustment problem.

    Attributes
    ----------
    cameras : (n_cameras, 9) ndarray
        Rotation vector (rad, ``R_cam_from_world``), translation t (world units), focal length
        f (px), k1 (px⁻² in normalised units: dimensionless), k2 — see :data:`CAMERA_COLUMNS`.
    points : (n_points, 3) ndarray
        World coordinates.
    camera_index, point_index : (n_observations,) int64 ndarray
    xy_px : (n_observations, 2) ndarray
        Observed image coordinates, px from the image centre, y up.
    """

    cameras: np.ndarray
    points: np.ndarray
    camera_index: np.ndarray
    point_index: np.ndarray
    xy_px: np.ndarray

    @property
    def n_cameras(self) -> int:
        return int(self.cameras.shape[0])

    @property
    def n_points(self) -> int:
        return int(self.points.shape[0])

    @property
    def n_observations(self) -> int:
        return int(self.xy_px.shape[0])

    def subset(self, keep: np.ndarray) -> BALProblem:
        """The same problem with only the observations where ``keep`` (bool, n_obs) is True."""
        keep = np.asarray(keep, dtype=bool)
        return BALProblem(
            self.cameras.copy(),
            self.points.copy(),
            self.camera_index[keep],
            self.point_index[keep],
            self.xy_px[keep],
        )

    def select_cameras(self, cameras, min_views: int = 2) -> BALProblem:
        """A smaller problem: the given cameras, their observations of the points that at
        least ``min_views`` of them see, cameras and points renumbered from 0.

        Parameters
        ----------
        cameras : sequence of int
            Camera indices to keep (in the new order).
        min_views : int, default 2
            Points seen by fewer of the kept cameras are left out (one ray does not determine
            a point).
        """
        cams = np.asarray(cameras, dtype=np.int64)
        new_cam = np.full(self.n_cameras, -1, dtype=np.int64)
        new_cam[cams] = np.arange(cams.size)
        keep = new_cam[self.camera_index] >= 0
        views = np.bincount(self.point_index[keep], minlength=self.n_points)
        keep &= views[self.point_index] >= min_views
        pts = np.flatnonzero(np.bincount(self.point_index[keep], minlength=self.n_points))
        new_pt = np.full(self.n_points, -1, dtype=np.int64)
        new_pt[pts] = np.arange(pts.size)
        return BALProblem(
            self.cameras[cams].copy(),
            self.points[pts].copy(),
            new_cam[self.camera_index[keep]],
            new_pt[self.point_index[keep]],
            self.xy_px[keep].copy(),
        )


def ladybug_path() -> Path:
    """The shipped BAL Ladybug problem 49-7776 (``.bz2``; see its ``SOURCE.md``)."""
    from importlib import resources

    return Path(
        str(
            resources.files("hsgeo")
            / "data"
            / "reference"
            / "bal-ladybug"
            / "problem-49-7776-pre.txt.bz2"
        )
    )


def _read_text(path: Path) -> str:
    try:
        if path.suffix == ".bz2":
            with bz2.open(path, "rt", encoding="ascii") as fh:
                return fh.read()
        return path.read_text(encoding="ascii")
    except FileNotFoundError:
        raise InputError(f"{path}: no such file (give the path of a BAL problem file)") from None
    except (OSError, UnicodeDecodeError, EOFError) as exc:
        raise InputError(
            f"{path}: cannot read it as a BAL text file ({type(exc).__name__}: {exc})"
        ) from None


#: The largest image coordinate a BAL observation can plausibly have (px from the image centre):
#: no camera has a million pixels across (:data:`hsgeo.validate.UNIT_LIMITS`).
MAX_XY_PX = 1e6


def _read_observations(lines, n_obs: int, n_cam: int, n_pts: int, fail):
    """The observation lines 2 … n_obs + 1 as (camera index, point index, xy px)."""
    cam = np.empty(n_obs, np.int64)
    pt = np.empty(n_obs, np.int64)
    xy = np.empty((n_obs, 2))
    for i in range(n_obs):
        tok = lines[1 + i].split()
        if len(tok) != 4:
            raise fail(2 + i, f"expected 'camera_index point_index x y', got {lines[1 + i]!r}")
        try:
            cam[i], pt[i] = int(tok[0]), int(tok[1])
            xy[i] = float(tok[2]), float(tok[3])
        except ValueError:
            raise fail(
                2 + i, f"expected 'camera_index point_index x y', got {lines[1 + i]!r}"
            ) from None
        if not (0 <= cam[i] < n_cam and 0 <= pt[i] < n_pts):
            raise fail(
                2 + i,
                f"camera index {cam[i]} or point index {pt[i]} out of range (the header "
                f"declares {n_cam} cameras and {n_pts} points)",
            )
        if not np.isfinite(xy[i]).all():
            raise fail(2 + i, "the image coordinates are NaN or inf")
        if np.abs(xy[i]).max() > MAX_XY_PX:
            raise fail(
                2 + i,
                f"the image coordinates {xy[i, 0]:.6g} {xy[i, 1]:.6g} px are beyond "
                f"{MAX_XY_PX:.0e} px from the image centre; correct the value or delete the "
                "observation (and lower the header's count)",
            )
    return cam, pt, xy


def read_bal(path) -> BALProblem:
    """Read a BAL problem file (plain text or ``.bz2``).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    BALProblem

    Raises
    ------
    InputError
        Unreadable file, or malformed content: the message names the file and the line
        (a wrong count, a non-numeric value, an index out of range, NaN/inf, missing or extra
        values).
    """
    path = Path(path)
    # whitespace-separated: blank lines carry nothing (kept out, with the file's line numbers)
    numbered = [(i, ln) for i, ln in enumerate(_read_text(path).splitlines(), 1) if ln.strip()]
    lines = [ln for _, ln in numbered]

    def fail(k: int, what: str) -> InputError:
        lineno = numbered[min(k, len(numbered)) - 1][0] if numbered else 1
        return InputError(f"{path}, line {lineno}: {what}")

    if not lines:
        raise InputError(f"{path}: empty file (expected a BAL header 'n_cameras n_points n_obs')")
    head = lines[0].split()
    try:
        n_cam, n_pts, n_obs = (int(v) for v in head)
    except ValueError:
        raise fail(
            1, f"expected the header 'n_cameras n_points n_observations', got {lines[0]!r}"
        ) from None
    if min(n_cam, n_pts, n_obs) <= 0:
        raise fail(1, f"the counts must be positive, got {n_cam} {n_pts} {n_obs}")
    if len(lines) < 1 + n_obs:
        raise fail(len(lines), f"the file ends after {len(lines) - 1} of {n_obs} observation lines")
    n_val = 9 * n_cam + 3 * n_pts
    # the sizes the header declares, against the file, before allocating anything
    n_tok = sum(len(ln.split()) for ln in lines[1 + n_obs :])
    if n_tok < n_val:
        raise fail(
            len(lines),
            f"the file ends after {n_tok} of {n_val} camera and point values ({n_cam} cameras × "
            f"9 + {n_pts} points × 3 that the header on line 1 declares); check the header's "
            "counts, or whether the file was cut short",
        )
    cam, pt, xy = _read_observations(lines, n_obs, n_cam, n_pts, fail)
    values = np.empty(n_val)
    k = 0
    for j in range(1 + n_obs, len(lines)):
        tok = lines[j].split()
        if k + len(tok) > n_val:
            raise fail(
                j + 1,
                f"more values than the header's {n_cam} cameras × 9 + {n_pts} points × 3 = {n_val}",
            )
        try:
            vals = [float(t) for t in tok]
        except ValueError:
            raise fail(j + 1, f"expected numbers, got {lines[j]!r}") from None
        if not np.isfinite(vals).all():
            raise fail(j + 1, "a camera or point value is NaN or inf")
        values[k : k + len(vals)] = vals
        k += len(vals)
    return BALProblem(
        values[: 9 * n_cam].reshape(n_cam, 9),
        values[9 * n_cam :].reshape(n_pts, 3),
        cam,
        pt,
        xy,
    )
