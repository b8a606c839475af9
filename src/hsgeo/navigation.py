"""Timed navigation records (GNSS/INS): position and attitude, interpolated to line times.

File format (CSV, one row per record, ascending time)::

    t_s,E_m,N_m,U_m,roll_deg,pitch_deg,heading_deg

Positions in a local east-north-up map frame (metres), attitude of the body (x forward, y right,
z down) in the north-east-down frame, degrees at the file boundary and radians inside.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError

__all__ = ["Navigation", "NAV_COLUMNS"]

NAV_COLUMNS = ("t_s", "E_m", "N_m", "U_m", "roll_deg", "pitch_deg", "heading_deg")


@dataclass(frozen=True)
class Navigation:
    """Navigation records.

    Attributes
    ----------
    t_s : (n,) ndarray
        Strictly increasing times.
    enu_m : (n, 3) ndarray
        Positions of the projection centre (E, N, U).
    rpy_rad : (n, 3) ndarray
        Roll, pitch, heading (NED).
    """

    t_s: np.ndarray
    enu_m: np.ndarray
    rpy_rad: np.ndarray

    def __post_init__(self):
        t = np.asarray(self.t_s, dtype=float)
        p = np.asarray(self.enu_m, dtype=float)
        a = np.asarray(self.rpy_rad, dtype=float)
        if t.ndim != 1 or p.shape != (t.size, 3) or a.shape != (t.size, 3):
            raise InputError(
                f"navigation: t (n,), positions (n, 3) and attitudes (n, 3) expected, got "
                f"{t.shape}, {p.shape}, {a.shape}"
            )
        if t.size < 2:
            raise InputError("navigation needs at least 2 records")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(p)) and np.all(np.isfinite(a))):
            raise InputError("navigation records contain NaN or inf")
        if np.any(np.diff(t) <= 0):
            i = int(np.flatnonzero(np.diff(t) <= 0)[0])
            raise InputError(f"navigation times must increase strictly (records {i}, {i + 1})")
        object.__setattr__(self, "t_s", t)
        object.__setattr__(self, "enu_m", p)
        object.__setattr__(self, "rpy_rad", np.unwrap(a, axis=0))

    def at(self, t_s) -> tuple[np.ndarray, np.ndarray]:
        """Position and attitude at the given times (linear interpolation).

        Returns
        -------
        enu_m : (m, 3) ndarray
        rpy_rad : (m, 3) ndarray
        """
        t = np.atleast_1d(np.asarray(t_s, dtype=float))
        if np.any(t < self.t_s[0]) or np.any(t > self.t_s[-1]):
            raise InputError(
                f"times {t.min():.3f}…{t.max():.3f} s fall outside the navigation record "
                f"{self.t_s[0]:.3f}…{self.t_s[-1]:.3f} s"
            )
        pos = np.stack([np.interp(t, self.t_s, self.enu_m[:, k]) for k in range(3)], axis=1)
        att = np.stack([np.interp(t, self.t_s, self.rpy_rad[:, k]) for k in range(3)], axis=1)
        return pos, att

    @classmethod
    def read_csv(cls, path) -> Navigation:
        """Read the CSV format of the module docstring."""
        from hsgeo.io import read_csv_table

        df = read_csv_table(path, NAV_COLUMNS)
        return cls(df["t_s"].to_numpy(), df[["E_m", "N_m", "U_m"]].to_numpy(),
                   np.deg2rad(df[["roll_deg", "pitch_deg", "heading_deg"]].to_numpy()))

    def write_csv(self, path) -> Path:
        """Write the CSV format of the module docstring (``%.17g``: a lossless round trip)."""
        path = Path(path)
        table = np.column_stack([self.t_s, self.enu_m, np.rad2deg(self.rpy_rad)])
        np.savetxt(path, table, delimiter=",", fmt="%.17g", header=",".join(NAV_COLUMNS),
                   comments="")
        return path
