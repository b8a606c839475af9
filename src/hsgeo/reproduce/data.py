"""``hsgeo data`` / ``make data``: generate ``data_synthetic/generated/`` from the scenario TOMLs.

Each scenario's ``[scenario] generator`` names a function ``generate(config: dict, outdir: Path)
-> list[Path]`` (:data:`GENERATORS`): the simulators write what a sensor records, and where the
files hold *measurements* (the line-scanner calibration's minima) the generator is the chapter's
experiment, which renders and then measures as a user would. Generated files are text (CSV with
``%.17g``).

The SHA-256 of every generated file is listed in ``data_synthetic/MANIFEST.sha256``. With
``--verify`` a file whose bytes differ fails unless every number in it agrees with the
committed file to :data:`VERIFY_RTOL` relative: on another CPU the same seed can give results
that differ in the last bit (a vectorised ``sin`` of another instruction set), which is the same
data, and is reported as such; anything more is a difference.
"""

from __future__ import annotations

import hashlib
import importlib
import sys
import tempfile
from pathlib import Path

import numpy as np

from hsgeo.errors import InputError
from hsgeo.io._files import copy_file, make_folder, write_text
from hsgeo.simulate.scenarios import data_dir, load_scenario

__all__ = ["GENERATORS", "VERIFY_RTOL", "generate_all", "default_out"]

#: scenario generator name -> module with its ``generate(config, outdir)`` function.
GENERATORS = {
    "frame_bench": "hsgeo.simulate.frame_bench",
    "line_lab": "hsgeo.reproduce.line_calibration",
    "mtf_bench": "hsgeo.reproduce.mtf",
    "pula_flight": "hsgeo.simulate.pula_flight",
    "rikola": "hsgeo.simulate.rikola",
}
#: relative agreement of every number for a file whose bytes differ from the manifest's.
VERIFY_RTOL = 1e-12


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _numbers(text: str) -> tuple[list[str], np.ndarray]:
    """The non-numeric tokens and the numbers of a CSV text, in order."""
    words, nums = [], []
    for tok in text.replace("\n", ",").split(","):
        try:
            nums.append(float(tok))
        except ValueError:
            words.append(tok)
    return words, np.asarray(nums)


def _same_numbers(a: str, b: str, rtol: float) -> bool:
    wa, na = _numbers(a)
    wb, nb = _numbers(b)
    if wa != wb or na.shape != nb.shape:
        return False
    return bool(np.all(np.abs(na - nb) <= rtol * np.maximum(np.abs(na), np.abs(nb))))


def default_out(ddir: Path) -> Path:
    """Where ``hsgeo data`` writes without ``--out``: the repository's
    ``data_synthetic/generated`` when the working directory is inside that repository, else
    ``./data_synthetic/generated`` under the working directory (never the installed package).
    """
    cwd = Path.cwd().resolve()
    if ddir.resolve().parent in (cwd, *cwd.parents):
        return ddir / "generated"
    return cwd / "data_synthetic" / "generated"


def _check_out(out: Path, *, repo: bool, overwrite: bool, default: bool) -> None:
    """The output folder, checked before any work (``--out``)."""
    import os

    # the folder as the user named it: --out DIR, or the default they never typed
    name = f"{out} (where hsgeo data writes without --out)" if default else f"--out {out}"
    if out.exists() and not out.is_dir():
        raise InputError(f"{name}: not a folder; give a folder")
    if not out.exists():
        if default:  # ./data_synthetic/generated is made with its parents
            return
        if not out.parent.is_dir():
            raise InputError(f"{name}: the folder {out.parent} does not exist; create it")
        if not os.access(out.parent, os.W_OK | os.X_OK):
            raise InputError(f"{name}: the folder {out.parent} is not writable")
        return
    if not os.access(out, os.W_OK | os.X_OK):
        raise InputError(f"{name}: the folder is not writable; choose another folder")
    if not repo and not overwrite and any(out.iterdir()):
        raise InputError(
            f"{name}: the folder is not empty; use --overwrite to replace the generated "
            "files in it, or choose an empty folder" + (" with --out" if default else "")
        )


def generate_all(
    verify: bool = False, update: bool = False, out=None, overwrite: bool = False
) -> int:
    """Generate every scenario; compare with (or rewrite) the manifest. Returns an exit status.

    Parameters
    ----------
    verify : bool
        Exit status 1 if a file differs from ``data_synthetic/MANIFEST.sha256``.
    update : bool
        Rewrite the manifest (next to the generated folder).
    out : path, optional
        The folder for the generated files (:func:`default_out` if not given). A folder other
        than the repository's own ``data_synthetic/generated`` must be empty, or ``overwrite``.
    overwrite : bool
        Replace files in a non-empty ``out``.
    """
    ddir = data_dir()
    repo_out = ddir / "generated"
    default = out is None
    out = Path(out) if out is not None else default_out(ddir)
    repo = out.resolve() == repo_out.resolve()
    _check_out(out, repo=repo, overwrite=overwrite, default=default)  # before the work
    make_folder(out, parents=default)
    sums: dict[str, str] = {}
    close: list[str] = []
    previous: dict[str, str] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for toml in sorted(ddir.glob("*.toml")):
            cfg = load_scenario(toml.stem)
            if cfg.scenario.generator not in GENERATORS:
                continue  # a chapter's in-memory scenario: it writes no files
            if cfg.scenario.seed is None:
                raise InputError(
                    f"scenario file {toml}: [scenario] seed: missing; add `seed = ...` (the seed "
                    "of the files it generates)"
                )
            mod = importlib.import_module(GENERATORS[cfg.scenario.generator])
            for path in mod.generate(cfg, Path(tmp)):
                dest = out / path.name
                if dest.is_file():
                    previous[path.name] = dest.read_text()
                copy_file(path, dest)
                sums[f"generated/{path.name}"] = _sha256(dest)
                print(f"  generated {dest}", file=sys.stderr)
    manifest = ddir / "MANIFEST.sha256"
    text = "".join(f"{h}  {p}\n" for p, h in sorted(sums.items()))
    if update or not manifest.exists():
        target = manifest if repo else out / "MANIFEST.sha256"
        write_text(target, text)
        print(f"wrote {target} ({len(sums)} files)", file=sys.stderr)
        return 0
    expected = {}
    for line in manifest.read_text().splitlines():
        h, p = line.split(maxsplit=1)
        expected[p] = h
    bad = []
    for p in sorted(set(expected) | set(sums)):
        if expected.get(p) == sums.get(p):
            continue
        name = Path(p).name
        old = previous.get(name)
        if old is None and (repo_out / name).is_file():
            # --out elsewhere: the repository's committed copy is the reference, with the same
            # tolerance and words as the check in the repository itself
            old = (repo_out / name).read_text()
        if (
            old is not None
            and p in sums
            and p in expected
            and hashlib.sha256(old.encode()).hexdigest() == expected[p]
            and _same_numbers(old, (out / name).read_text(), VERIFY_RTOL)
        ):
            close.append(p)
            write_text(out / name, old)  # keep the committed bytes
            continue
        bad.append(p)
    if bad:
        print(
            "data_synthetic: generated files differ from MANIFEST.sha256: "
            + ", ".join(bad)
            + " (if the change is deliberate: hsgeo data --update-manifest)",
            file=sys.stderr,
        )
        return 1 if verify else 0
    note = (
        f"; {len(close)} differ only in the last bits, every number within "
        f"{VERIFY_RTOL:g} relative ({', '.join(close)})"
        if close
        else ""
    )
    print(f"data_synthetic: {len(sums)} files match MANIFEST.sha256{note}", file=sys.stderr)
    return 0
