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
