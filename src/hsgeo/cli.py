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


def _cmd_adjust_pushbroom(args) -> int:
    import json

    from hsgeo.pushbroom_ba import adjust_files

    out = adjust_files(args.observations, args.trajectory, args.camera, args.gcp,
                       node_interval_s=args.node_interval, progress=True,
                       y_as_time=not args.image_y)
    res = out.pop("_result")
    print(json.dumps(out, indent=1) if args.json else res.report(max_block_size=20))
    return 0


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

    p = sub.add_parser(
        "adjust-pushbroom",
        help="bundle-adjust LP lines with spline trajectory corrections (002 eq. 2-4)",
        description="Observation table: point_id, band, t_s, x_px, y_px; trajectory: t_s, E_m, "
        "N_m, H_m, roll_rad, pitch_rad, yaw_rad; GCPs: point_id, E_m, N_m, H_m (CSV or "
        "Parquet); camera TOML: see hsgeo.pushbroom_ba.adjust_files.")
    p.add_argument("observations", help="observation table (CSV or Parquet)")
    p.add_argument("--trajectory", required=True, help="GNSS/INS trajectory table")
    p.add_argument("--camera", required=True, help="camera and prior σ (TOML)")
    p.add_argument("--gcp", help="ground control points table (optional)")
    p.add_argument("--node-interval", type=float, default=10.0,
                   help="spline node interval in s (default 10, 002 §4)")
    p.add_argument("--image-y", action="store_true",
                   help="residual across the line as the image y of 002 eq. 2 (default: as a "
                   "time, which avoids a bias of the principal distance)")
    p.add_argument("--json", action="store_true", help="JSON instead of the text report")
    p.set_defaults(func=_cmd_adjust_pushbroom)

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
