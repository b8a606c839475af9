"""The ``hsgeo`` command: ``hsgeo reproduce``, ``hsgeo data``, ``hsgeo versions``, ...

Every subcommand turns an :class:`hsgeo.HsgeoError` into a one-line message and exit status 2.
"""

from __future__ import annotations

import argparse
import sys

from hsgeo.errors import HsgeoError

__all__ = ["main"]


def _cmd_reproduce(args) -> int:
    from hsgeo.reproduce import run

    rep = run(args.chapter, seed=args.seed, scale=args.scale)
    print(rep.to_json() if args.json else rep.to_text())
    return 0


def _cmd_calibrate_frame(args) -> int:
    from hsgeo.rikola import calibrate_frame_files

    out = calibrate_frame_files(args.images, args.board, joint=args.joint,
                                band_regex=args.band_regex, cube_regex=args.cube_regex,
                                sigma_px=args.sigma_px)
    print(out.to_json() if args.json else out.to_text() + "\n\n" + "\n".join(
        f"  {k}: {v}" for k, v in out.meta.items()))
    return 0


def _cmd_data(args) -> int:
    from hsgeo.simulate.scenarios import generate_all

    return generate_all(verify=args.verify, update=args.update_manifest)


def _cmd_versions(args) -> int:
    from hsgeo import show_versions

    show_versions()
    return 0


def build_parser() -> argparse.ArgumentParser:
    from hsgeo import __version__
    from hsgeo.reproduce import chapter_names

    ap = argparse.ArgumentParser(
        prog="hsgeo",
        description="Geometry of hyperspectral sensors: reproduce the book's tables, calibrate, "
        "geocode.",
    )
    ap.add_argument("--version", action="version", version=f"hsgeo {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)

    p = sub.add_parser("reproduce", help="print a chapter's tables (paper | reproduced | truth)")
    p.add_argument("chapter", choices=chapter_names(), metavar="CHAPTER",
                   help="one of: " + ", ".join(chapter_names()))
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0); any works")
    p.add_argument("--scale", type=float, default=1.0,
                   help="problem size in (0, 1] for chapters that have a size knob (default 1)")
    p.add_argument("--json", action="store_true", help="one JSON object instead of text tables")
    p.set_defaults(func=_cmd_reproduce)

    p = sub.add_parser("calibrate-frame", help="self-calibrate a frame camera (per band or "
                       "jointly, 003) from images of an ArUco / ChArUco board")
    p.add_argument("images", nargs="+", metavar="IMAGES", help="image files")
    p.add_argument("--board", required=True, help="board description (TOML, see "
                   "hsgeo.measure.boards)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--per-band", action="store_false", dest="joint",
                   help="one calibration per band (default)")
    g.add_argument("--joint", action="store_true", help="one joint adjustment of all bands "
                   "(Rikola band numbering of 003 Table 2; needs --band-regex and --cube-regex)")
    p.add_argument("--band-regex", help="regex with one group: band number from the file name")
    p.add_argument("--cube-regex", help="regex with one group: cube (view) from the file name")
    p.add_argument("--sigma-px", type=float, default=0.1,
                   help="a-priori σ of an image point in px (default 0.1)")
    p.add_argument("--json", action="store_true", help="one JSON object instead of text")
    p.set_defaults(func=_cmd_calibrate_frame, joint=False)

    p = sub.add_parser("data", help="generate data_synthetic/generated from the scenario TOMLs")
    p.add_argument("--verify", action="store_true",
                   help="fail if a generated file differs from data_synthetic/MANIFEST.sha256")
    p.add_argument("--update-manifest", action="store_true",
                   help="rewrite the manifest from what was generated (after a deliberate change)")
    p.set_defaults(func=_cmd_data)

    p = sub.add_parser("versions", help="versions of hsgeo, Python and the dependencies")
    p.set_defaults(func=_cmd_versions)
    return ap


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``hsgeo`` console script."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except HsgeoError as exc:
        print(f"hsgeo {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
