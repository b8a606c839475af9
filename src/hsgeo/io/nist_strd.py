"""NIST StRD nonlinear-regression files (``.dat``): certified values, starts and data.

The Statistical Reference Datasets of NIST's Information Technology Laboratory
(https://www.itl.nist.gov/div898/strd/nls/nls_main.shtml) give, for each of 27 problems, the
model, two starting vectors, certified parameter values and standard deviations, the residual
sum of squares, the residual standard deviation, the degrees of freedom and the data, in a
fixed ASCII layout: the header's ``File Format`` section names the lines of the starting
values, the certified values and the data (1-based, inclusive), and this reader uses them.

The 27 files ship with hsgeo (:func:`nist_strd_dir`, ``src/hsgeo/data/reference/nist-strd``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError

__all__ = ["NistProblem", "read_nist_strd", "nist_strd_dir", "NIST_STRD_NAMES"]

#: The 27 problems by NIST's level of difficulty (lower, average, higher), in NIST's order.
NIST_STRD_NAMES: dict[str, tuple[str, ...]] = {
    "lower": ("Misra1a", "Chwirut2", "Chwirut1", "Lanczos3", "Gauss1", "Gauss2", "DanWood",
              "Misra1b"),
    "average": ("Kirby2", "Hahn1", "Nelson", "MGH17", "Lanczos1", "Lanczos2", "Gauss3",
                "Misra1c", "Misra1d", "Roszman1", "ENSO"),
    "higher": ("MGH09", "Thurber", "BoxBOD", "Rat42", "MGH10", "Eckerle4", "Rat43", "Bennett5"),
}  # fmt: skip


@dataclass(frozen=True)
class NistProblem:
    """One NIST StRD nonlinear least-squares problem, as certified.

    Attributes
    ----------
    name : str
        Dataset name (``"Misra1a"``).
    difficulty : str
        ``"lower"``, ``"average"`` or ``"higher"`` (NIST's level of difficulty).
    model : str
        The model as the file writes it (``"y = b1*(1-exp[-b2*x])  +  e"``).
    starts : (2, p) ndarray
        Start 1 and Start 2.
    certified : (p,) ndarray
        Certified parameter values (11 significant digits).
    certified_sigma : (p,) ndarray
        Certified standard deviations of the parameters.
    rss : float
        Certified residual sum of squares (in the units of the response squared).
    residual_sd : float
        Certified residual standard deviation ``sqrt(rss / dof)``.
    dof : int
        Degrees of freedom ``n − p`` (checked against the certified residual σ; Rat43's file
        states 9, an erratum: its residual σ is ``sqrt(RSS / 11)``).
    x : (n, k) ndarray
        Predictor(s), one column per predictor.
    y : (n,) ndarray
        Response.
    """

    name: str
    difficulty: str
    model: str
    starts: np.ndarray
    certified: np.ndarray
    certified_sigma: np.ndarray
    rss: float
    residual_sd: float
    dof: int
    x: np.ndarray
    y: np.ndarray

    @property
    def n_params(self) -> int:
        return self.certified.size


def nist_strd_dir() -> Path:
    """Folder of the 27 shipped NIST StRD files (``hsgeo/data/reference/nist-strd``)."""
    return Path(str(resources.files("hsgeo") / "data" / "reference" / "nist-strd"))


_FLOAT = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_RANGE = re.compile(r"\(lines\s+(\d+)\s+to\s+(\d+)\)")


def read_nist_strd(source) -> NistProblem:
    """Read a NIST StRD nonlinear-regression file.

    Parameters
    ----------
    source : str or Path
        A ``.dat`` file, or the name of a shipped problem (``"Misra1a"``, case-insensitive).

    Returns
    -------
    NistProblem

    Raises
    ------
    InputError
        No such file or problem, or the file does not follow the StRD layout (the message
        names the file, the line and what was expected).
    """
    path = _resolve(source)
    lines = path.read_text(encoding="ascii", errors="replace").splitlines()
    ranges = {
        k: _section_range(path, lines, k) for k in ("Starting Values", "Certified Values", "Data")
    }
    name = _field(path, lines, r"Dataset Name:\s+(\S+)")
    difficulty = _field(path, lines, r"(Lower|Average|Higher) Level of Difficulty").lower()
    model = _model(path, lines)
    # -- parameters: "b1 =  start1  start2  certified  sigma" on the certified lines
    c0, c1 = ranges["Certified Values"]
    s0, s1 = ranges["Starting Values"]
    starts, cert, sd = [], [], []
    for i in range(s0, s1 + 1):
        ln = lines[i - 1]
        m = re.match(rf"\s*b(\d+)\s*=\s*({_FLOAT})\s+({_FLOAT})\s+({_FLOAT})\s+({_FLOAT})\s*$", ln)
        if not m or int(m.group(1)) != len(starts) + 1:
            raise InputError(
                f"{path}, line {i}: expected 'b{len(starts) + 1} = start1 start2 certified "
                f"sigma', got {ln.strip()!r}"
            )
        starts.append((float(m.group(2)), float(m.group(3))))
        cert.append(float(m.group(4)))
        sd.append(float(m.group(5)))
    summary = {}
    for i in range(s1 + 1, c1 + 1):
        m = re.match(rf"\s*([A-Za-z ]+):\s+({_FLOAT})\s*$", lines[i - 1])
        if m:
            summary[m.group(1).strip()] = float(m.group(2))
    for key in ("Residual Sum of Squares", "Residual Standard Deviation", "Degrees of Freedom"):
        if key not in summary:
            raise InputError(
                f"{path}: no '{key}:' line among the certified values (lines {c0} to {c1})"
            )
    # -- data: the header line just before the range names the columns ("y  x" or "y x1 x2")
    d0, d1 = ranges["Data"]
    head = lines[d0 - 2].split() if d0 >= 2 else []
    if not head or head[0] != "Data:" or head[1:2] != ["y"]:
        raise InputError(f"{path}, line {d0 - 1}: expected the data header 'Data:  y  x ...'")
    n_cols = len(head) - 1
    rows = []
    for i in range(d0, d1 + 1):
        parts = lines[i - 1].split() if i - 1 < len(lines) else []
        try:
            vals = [float(v) for v in parts]
        except ValueError:
            vals = []
        if len(vals) != n_cols:
            raise InputError(
                f"{path}, line {i}: expected {n_cols} numbers ({' '.join(head[1:])}), "
                f"got {lines[i - 1].strip() if i - 1 < len(lines) else 'end of file'!r}"
            )
        rows.append(vals)
    data = np.array(rows, dtype=np.float64)
    n_obs = summary.get("Number of Observations")
    if n_obs is not None and int(n_obs) != data.shape[0]:
        raise InputError(
            f"{path}: the header certifies {int(n_obs)} observations, the data lines hold "
            f"{data.shape[0]}"
        )
    p = len(cert)
    dof = data.shape[0] - p
    rss, sd_res = summary["Residual Sum of Squares"], summary["Residual Standard Deviation"]
    # the certified residual σ is sqrt(RSS / (n − p)); Rat43's 'Degrees of Freedom: 9' is an
    # erratum of the file (n − p = 11, and its residual σ is sqrt(RSS / 11)), so the degrees of
    # freedom are n − p, checked against the certified residual σ rather than the stated line
    if dof <= 0 or abs(rss / dof - sd_res**2) > 1e-8 * sd_res**2:
        raise InputError(
            f"{path}: the certified residual standard deviation {sd_res:.10g} is not "
            f"sqrt(RSS / (n − p)) with RSS {rss:.10g}, n {data.shape[0]}, p {p}: the data or "
            "the certified values are damaged"
        )
    return NistProblem(
        name=name,
        difficulty=difficulty,
        model=model,
        starts=np.array(starts, dtype=np.float64).T.copy(),
        certified=np.array(cert),
        certified_sigma=np.array(sd),
        rss=rss,
        residual_sd=sd_res,
        dof=dof,
        x=data[:, 1:].copy(),
        y=data[:, 0].copy(),
    )


def _resolve(source) -> Path:
    path = Path(source)
    if path.is_file():
        return path
    names = {n.lower(): n for group in NIST_STRD_NAMES.values() for n in group}
    key = str(source).lower().removesuffix(".dat")
    if key in names:
        return nist_strd_dir() / f"{names[key]}.dat"
    raise InputError(
        f"{source}: no such file, and not one of the 27 NIST StRD problems shipped with hsgeo "
        f"({', '.join(sorted(names.values()))})"
    )


def _section_range(path: Path, lines: list[str], key: str) -> tuple[int, int]:
    for i, ln in enumerate(lines[:20], start=1):
        if ln.strip().startswith(key):
            m = _RANGE.search(ln)
            if m:
                a, b = int(m.group(1)), int(m.group(2))
                if not (0 < a <= b <= len(lines)):
                    raise InputError(
                        f"{path}, line {i}: '{key}' lines {a} to {b} lie outside the file "
                        f"({len(lines)} lines)"
                    )
                return a, b
    raise InputError(
        f"{path}: no '{key}   (lines A to B)' entry in the File Format header: not a NIST StRD "
        "nonlinear-regression file"
    )


def _field(path: Path, lines: list[str], pattern: str) -> str:
    for ln in lines[:40]:
        m = re.search(pattern, ln)
        if m:
            return m.group(1)
    raise InputError(f"{path}: header has no line matching {pattern!r}")


def _model(path: Path, lines: list[str]) -> str:
    """The model expression: the header lines from the one with '=' to the one ending in 'e'."""
    out = []
    for ln in lines[:40]:
        s = ln.strip()
        if not out and re.match(r"(y|log\[y\])\s*=", s):
            out.append(s)
        elif out:
            if not s:
                break
            out.append(s)
    if not out:
        raise InputError(f"{path}: no model line ('y = ...') in the header")
    return " ".join(" ".join(out).split())
