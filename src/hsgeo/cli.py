"""The ``hsgeo`` command: ``hsgeo reproduce``, ``hsgeo data``, ``hsgeo versions``, ...

Every subcommand turns an :class:`hsgeo.HsgeoError`, an operating system's refusal and memory
exhausted into a one-line message and exit status 2, Ctrl-C (also inside a compiled kernel) into
one line and status 130, and a closed output pipe into a silent exit (status 141); its text
prints in any locale (:mod:`hsgeo.terminal`).
"""

from __future__ import annotations

import argparse
import io
import os
import sys

from hsgeo import terminal
from hsgeo.errors import ConvergenceError, HsgeoError
from hsgeo.terminal import json_text
from hsgeo.validate import option_number

__all__ = ["main", "EXIT_INTERRUPTED", "EXIT_BROKEN_PIPE"]

#: Exit status after Ctrl-C (128 + SIGINT, as a shell reports it).
EXIT_INTERRUPTED = 130
#: Exit status when the reader of the output closed the pipe (128 + SIGPIPE, as git and
#: coreutils end), silently.
EXIT_BROKEN_PIPE = 141


def _cmd_reproduce(args) -> int:
    from hsgeo.reproduce import run

    rep = run(args.chapter, seed=args.seed, scale=args.scale)
    print(rep.to_json() if args.json else rep.to_text())
    return 0


def _cmd_calibrate_line(args) -> int:

    import numpy as np

    from hsgeo.workflows.line_calibration import calibrate_files

    out = calibrate_files(
        args.observations,
        args.control,
        zeta0_px=args.zeta0_px,
        c_px=args.c_px,
        sigma_px=args.sigma_px,
        reject_k=args.reject_k,
    )
    res, v = out["result"], out["residuals_px"]
    names = [("zeta0_px", res.value("zeta0_px"), res.sigma("zeta0_px"))]
    names += [("c_px", res.value("c_px"), res.sigma("c_px"))]
    names += [
        (k, a, s)
        for k, a, s in zip(("K1", "K2", "K3"), res.value("K"), res.sigma("K"), strict=True)
    ]
    stats = {
        "sigma0": res.sigma0,
        "dof": res.dof,
        "rms_px": float(np.sqrt(np.mean(v**2))),
        "max_abs_px": float(np.max(np.abs(v))),
        "n_observations": int(v.size),
    }
    if args.json:
        print(
            json_text(
                {
                    "parameters": {k: {"value": float(a), "sigma": float(s)} for k, a, s in names},
                    "residuals": stats,
                }
            )
        )
    else:
        print(res.report())
        print(
            f"residuals: RMS {stats['rms_px']:.4f} px, max |v| {stats['max_abs_px']:.4f} px "
            f"over {stats['n_observations']} observations"
        )


def _cmd_calibrate_frame(args) -> int:
    from hsgeo.workflows.frame_calibration import calibrate_frame_files

    out = calibrate_frame_files(
        args.images,
        args.board,
        joint=args.joint,
        band_regex=args.band_regex,
        cube_regex=args.cube_regex,
        sigma_px=args.sigma_px,
    )
    print(
        out.to_json()
        if args.json
        else out.to_text() + "\n\n" + "\n".join(f"  {k}: {v}" for k, v in out.meta.items())
    )
    return 0


def _cmd_data(args) -> int:
    from hsgeo.reproduce.data import generate_all

    return generate_all(
        verify=args.verify, update=args.update_manifest, out=args.out, overwrite=args.overwrite
    )


def _cmd_adjust_pushbroom(args) -> int:

    from hsgeo.workflows.pushbroom_ba import adjust_files

    out = adjust_files(
        args.observations,
        args.trajectory,
        args.camera,
        args.gcp,
        node_interval_s=args.node_interval,
        progress=terminal.progress_printer(),
        y_as_time=not args.image_y,
        max_nav_gap_s=args.max_nav_gap_s,
    )
    res = out.pop("_result")
    print(json_text(out) if args.json else res.report(max_block_size=20))
    fit = out["fit"]
    if fit["verdict"] == "poor" and not args.accept_poor_fit:
        print(
            f"hsgeo {args.command}: error: implausible fit: {'; '.join(fit['reasons'])} "
            "(the result is printed above; --accept-poor-fit keeps it with exit status 0)",
            file=sys.stderr,
        )
        return 2
    return 0


def _cmd_versions(args) -> int:
    from hsgeo import show_versions

    show_versions()
    return 0


def _cmd_geocode(args) -> int:
    from hsgeo.workflows.geocoding import geocode_files

    ortho, paths = geocode_files(
        args.lines,
        args.trajectory,
        args.sensor,
        output=args.output,
        dem=args.dem,
        height_m=args.height,
        resolution_m=args.resolution,
        envi=args.envi,
        progress=not args.quiet and sys.stderr.isatty(),  # progress on a terminal only
        overwrite=args.overwrite,
        max_grid_gib=args.max_grid_gib,
        max_nav_gap_s=args.max_nav_gap_s,
        band=args.band,
    )
    print(
        f"orthorectified {ortho.sizes['band']} band(s) onto {ortho.sizes['N']} x "
        f"{ortho.sizes['E']} cells of {args.resolution} m: " + ", ".join(map(str, paths))
    )
    return 0


def _cmd_adjust_bal(args) -> int:

    from hsgeo.workflows.bal import adjust_bal_file

    out = adjust_bal_file(args.file, progress=None if args.json else terminal.progress_printer())
    if args.json:
        print(json_text(out))
    else:
        print(
            f"{out['file']}: {out['n_cameras']} cameras, {out['n_points']} points, "
            f"{out['n_observations']} observations adjusted ({out['n_dropped']} behind their "
            f"camera left out)\n"
            f"cost ½Σr² {out['initial_cost']:.6f} → {out['final_cost']:.6f} px² in "
            f"{out['iterations']} iterations, {out['seconds']:.2f} s ({out['message']})\n"
            f"gauge {out['gauge']}"
        )
    return 0


def _cmd_mtf(args) -> int:
    import json

    from hsgeo.workflows.mtf import bars_files

    out = bars_files(args.profiles, args.bars)
    if args.json:
        d = {"profiles": [{"row": r, **res.to_dict()} for r, res in out.items()]}
        if len(out) == 1:
            d = next(iter(d["profiles"]))
        print(json.dumps(d, indent=1, allow_nan=False))
        return 0
    for r, res in out.items():
        head = "profile" if r is None else f"row {r}"
        if res.borderline_cy_px == res.borderline_cy_px:  # not NaN
            border = (
                f"borderline frequency (MTF 0.1) {res.borderline_cy_px:.3f} cy/px, determined "
                f"GSD {res.determined_gsd_mm:.3f} mm"
            )
        else:
            border = (
                f"MTF above 0.1 up to the finest bars ({res.ctf_frequency_cy_px.max():.3f} cy/px)"
            )
        print(f"{head}: {res.ctf.size} bar groups, GSD {res.gsd_mm:.4f} mm, {border}")
        print("  f_cy_px   MTF")
        for f, m in zip(res.frequency_cy_px, res.mtf, strict=True):
            print(f"  {f:7.3f}  {m:6.3f}")
    return 0


def _cmd_mtf_edge(args) -> int:
    import json

    import numpy as np

    from hsgeo.workflows.mtf import edge_file

    res = edge_file(args.image, args.roi)
    if args.json:
        print(json.dumps(res.to_dict(), indent=1, allow_nan=False))
        return 0
    print(
        f"edge at {res.edge_angle_deg:.2f} deg in ROI {res.roi}, LSF FWHM {res.lsf_fwhm_px:.2f} "
        f"px, borderline frequency (MTF 0.1) {res.borderline_cy_px:.3f} cy/px"
    )
    print("  f_cy_px   MTF")
    for f in np.arange(0.0, 1.0001, 0.05):
        print(f"  {f:7.3f}  {np.interp(f, res.frequency_cy_px, res.mtf):6.3f}")
    return 0


def _cmd_cube(args) -> int:

    from hsgeo.workflows.cube import CubeOptions, cube_files

    opts = CubeOptions(
        binning=args.binning,
        rows_per_band=args.rows_per_band,
        lines_per_chunk=args.lines_per_chunk,
        f_alpha=args.f_alpha,
    )
    res = cube_files(
        args.raw_dir,
        args.dark,
        args.output,
        options=opts,
        overwrite=args.overwrite,
        progress=not args.quiet and sys.stderr.isatty(),
    )
    d = res.to_dict()
    if args.json:
        print(json_text(d))
    else:
        print(
            f"reflectance cube of {d['lines']} lines x {d['samples']} samples x {d['bands']} "
            f"bands ({d['wavelength_nm'][0]:.1f}-{d['wavelength_nm'][1]:.1f} nm), "
            f"{d['n_hot_pixels']} hot pixels corrected: " + ", ".join(d["files"])
        )
    return 0


_POSITIVE = option_number(positive=True)


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``hsgeo geocode: error: ... (see hsgeo geocode --help)``
    and exit status 2 (the usage, which wraps over many lines, is left to ``--help``).
    """

    def error(self, message: str):
        msg = " ".join(message.split())
        self.exit(2, f"{self.prog}: error: {msg} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    from hsgeo import __version__
    from hsgeo.reproduce import chapter_names

    ap = _Parser(
        prog="hsgeo",
        description="Geometry of hyperspectral sensors: reproduce the book's tables, calibrate, "
        "geocode.",
    )
    ap.add_argument("--version", action="version", version=f"hsgeo {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)

    p = sub.add_parser("reproduce", help="print a chapter's tables (paper | reproduced | truth)")
    p.add_argument(
        "chapter",
        choices=chapter_names(),
        metavar="CHAPTER",
        help="one of: " + ", ".join(chapter_names()),
    )
    p.add_argument(
        "--seed",
        type=option_number(integer=True, lo=0),
        default=0,
        help="random seed (default 0); any works",
    )
    p.add_argument(
        "--scale",
        type=option_number(positive=True, hi=1.0),
        default=1.0,
        help="problem size in (0, 1] for chapters that have a size knob (default 1)",
    )
    p.add_argument("--json", action="store_true", help="one JSON object instead of text tables")
    p.set_defaults(func=_cmd_reproduce)

    p = sub.add_parser(
        "calibrate-line",
        help="calibrate one spectral line of a 1D line scanner (000 eq. 2) from measured minima",
        description="OBSERVATIONS: CSV 'image,point,zeta_px' (ids, ζ in px, pixel-centre "
        "origin); CONTROL: CSV 'point,x_m,y_m' (coordinates in the scanner plane, m). Some "
        "control points must lie off the pattern line, or the scale c is undetermined.",
    )
    p.add_argument("observations", metavar="OBSERVATIONS")
    p.add_argument("--control", required=True, metavar="CONTROL")
    p.add_argument(
        "--zeta0-px",
        type=option_number(lo=-1e6, hi=1e6),
        default=485.0,
        help="initial ζ0 (000 Table 1: 485)",
    )
    p.add_argument(
        "--c-px",
        type=option_number(positive=True, hi=1e6),
        default=3600.0,
        help="initial c (000 Table 1: 3600)",
    )
    p.add_argument("--sigma-px", type=_POSITIVE, default=0.1, help="a-priori σ of ζ (px, positive)")
    p.add_argument(
        "--reject-k",
        type=_POSITIVE,
        default=None,
        help="reject observations whose standardised residual exceeds k robust σ (default: none)",
    )
    p.add_argument("--json", action="store_true", help="estimates and residual statistics as JSON")
    p.set_defaults(func=_cmd_calibrate_line)
    p = sub.add_parser(
        "calibrate-frame",
        help="self-calibrate a frame camera (per band or "
        "jointly, 003) from images of an ArUco / ChArUco board",
    )
    p.add_argument("images", nargs="+", metavar="IMAGES", help="image files")
    p.add_argument("--board", required=True, help="board description (TOML, see hsgeo.io.boards)")
    g = p.add_mutually_exclusive_group()
    g.add_argument(
        "--per-band", action="store_false", dest="joint", help="one calibration per band (default)"
    )
    g.add_argument(
        "--joint",
        action="store_true",
        help="one joint adjustment of all bands "
        "(Rikola band numbering of 003 Table 2; needs --band-regex and --cube-regex)",
    )
    p.add_argument("--band-regex", help="regex with one group: band number from the file name")
    p.add_argument("--cube-regex", help="regex with one group: cube (view) from the file name")
    p.add_argument(
        "--sigma-px",
        type=_POSITIVE,
        default=0.1,
        help="a-priori σ of an image point in px (default 0.1)",
    )
    p.add_argument("--json", action="store_true", help="one JSON object instead of text")
    p.set_defaults(func=_cmd_calibrate_frame, joint=False)

    p = sub.add_parser("data", help="generate data_synthetic/generated from the scenario TOMLs")
    mode = p.add_mutually_exclusive_group()  # verifying and rewriting the manifest exclude
    mode.add_argument(
        "--verify",
        action="store_true",
        help="fail if a generated file differs from data_synthetic/MANIFEST.sha256",
    )
    mode.add_argument(
        "--update-manifest",
        action="store_true",
        help="rewrite the manifest from what was generated (after a deliberate change)",
    )
    p.add_argument(
        "--out",
        metavar="DIR",
        help="folder for the generated files (default: data_synthetic/generated of the "
        "repository the working directory is in, else ./data_synthetic/generated); never the "
        "installed package",
    )
    p.add_argument("--overwrite", action="store_true", help="replace existing files in --out DIR")
    p.set_defaults(func=_cmd_data)

    p = sub.add_parser(
        "geocode",
        help="orthorectify a line-scanner flight line onto a map grid",
        description="Geocode every pixel of a flight line (ray from the recorded navigation and "
        "the sensor model, intersected with a DEM or a plane) and resample it onto a north-up "
        "grid by nearest neighbour. LINES: NetCDF with radiance(line, pixel) or (band, line, "
        "pixel), coordinate pixel (ζ, px), attributes t0_s and line_rate_hz. "
        "NAV: the navigation file of every command, CSV or Parquet with t_s, E_m, N_m, U_m, "
        "roll_deg, pitch_deg, heading_deg (positions east-north-up in m; attitude of the body, "
        "x forward, y right, z down, in north-east-down, in degrees; see hsgeo.io.navigation). "
        "SENSOR: TOML, the 000 line-scanner file ([sensor], see hsgeo.io.read_sensor_toml) or "
        "the 002 pushbroom camera file ([camera], see hsgeo.io.read_pushbroom_camera; then the "
        "LINES pixel coordinate is x in px from the line centre). DEM: NetCDF with "
        "height(N, E) in metres.",
    )
    p.add_argument("lines", metavar="LINES")
    p.add_argument(
        "--trajectory",
        required=True,
        metavar="NAV",
        help="navigation file (GNSS/INS solution, CSV or Parquet; see above)",
    )
    p.add_argument("--sensor", required=True, metavar="SENSOR.toml")
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--dem", metavar="DEM.nc")
    g.add_argument(
        "--height",
        type=option_number(lo=-1e5, hi=1e5),
        metavar="H",
        help="terrain height of a plane (m)",
    )
    p.add_argument("-o", "--output", required=True, metavar="ORTHO.nc")
    p.add_argument("--envi", metavar="PATH", help="also write ENVI BSQ + .hdr with map info")
    p.add_argument(
        "--overwrite", action="store_true", help="replace existing output files (default: refuse)"
    )
    p.add_argument("--resolution", type=_POSITIVE, default=0.5, help="cell size in m (default 0.5)")
    p.add_argument(
        "--max-grid-gib",
        type=_POSITIVE,
        default=2.0,
        help="largest memory of the map grid, GiB (default 2); checked before the work",
    )
    p.add_argument(
        "--max-nav-gap-s",
        type=_POSITIVE,
        default=1.0,
        help="longest gap between navigation records interpolated across, s (default 1)",
    )
    p.add_argument(
        "--band",
        type=int,
        default=0,
        help="band of a pushbroom camera file whose geometry is used (default 0)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress display")
    p.set_defaults(func=_cmd_geocode)

    p = sub.add_parser(
        "adjust-pushbroom",
        help="bundle-adjust LP lines with spline trajectory corrections (002 eq. 2-4)",
        description="Observation table: point_id, band, t_s, x_px, y_px; GCPs: point_id, E_m, "
        "N_m, H_m (CSV or Parquet); camera TOML: see hsgeo.io.read_camera_toml. "
        "NAV: the navigation file of every command, CSV or Parquet with t_s, E_m, N_m, U_m, "
        "roll_deg, pitch_deg, heading_deg (positions east-north-up in m; attitude of the body, "
        "x forward, y right, z down, in north-east-down, in degrees; see hsgeo.io.navigation). "
        "The former format (H_m, roll_rad, pitch_rad, yaw_rad in ENU platform angles) converts "
        "as U_m = H_m, roll_deg = deg(roll_rad), pitch_deg = -deg(pitch_rad), heading_deg = "
        "90 - deg(yaw_rad).",
    )
    p.add_argument("observations", help="observation table (CSV or Parquet)")
    p.add_argument(
        "--trajectory",
        required=True,
        metavar="NAV",
        help="navigation file (GNSS/INS solution, CSV or Parquet; see above)",
    )
    p.add_argument("--camera", required=True, help="camera and prior σ (TOML)")
    p.add_argument("--gcp", help="ground control points table (optional)")
    p.add_argument(
        "--max-nav-gap-s",
        type=_POSITIVE,
        default=1.0,
        help="longest gap between navigation records interpolated across, s (default 1)",
    )
    p.add_argument(
        "--node-interval",
        type=_POSITIVE,
        default=10.0,
        help="spline node interval in s (default 10, 002 §4)",
    )
    p.add_argument(
        "--image-y",
        action="store_true",
        help="residual across the line as the image y of 002 eq. 2 (default: as a "
        "time, the image y over its rate from the trajectory's velocity and angular "
        "rate, which avoids a bias of the principal distance and the pitch "
        "corrections)",
    )
    p.add_argument(
        "--accept-poor-fit",
        action="store_true",
        help="exit 0 even when the fit is implausible (σ0 off by more than a factor of 3, more "
        "than 5 %% of the observations rejected, or no convergence; the JSON's 'fit' says why)",
    )
    p.add_argument("--json", action="store_true", help="JSON instead of the text report")
    p.set_defaults(func=_cmd_adjust_pushbroom)

    p = sub.add_parser(
        "adjust-bal",
        help="bundle-adjust a 'Bundle Adjustment in the Large' problem file (Snavely cameras)",
    )
    p.add_argument("file", help="BAL problem file (.txt, or .txt.bz2)")
    p.add_argument("--json", action="store_true", help="one JSON object instead of text")
    p.set_defaults(func=_cmd_adjust_bal)

    p = sub.add_parser(
        "mtf",
        help="MTF from bar-target profiles: CTF per bar group, then the Coltman series",
        description="MTF from bar-target profiles (001 eq. 5-7, Coltman 1954). PROFILES: CSV "
        "or Parquet with columns x_px (position along the line, px) and intensity_dn (raw "
        "intensity), optionally row (spectral line; one MTF per row). BARS: TOML with [target] "
        "pair_mm (pair width per group, mm), n_pairs, white_reflectance, black_reflectance and "
        "[profile] gsd_mm, start_px (target start on the profile, to a few px), dark_dn, "
        "saturation_dn. Groups follow each other, each starting with a white bar.",
    )
    p.add_argument("profiles", help="profile table (x_px, intensity_dn[, row])")
    p.add_argument("--bars", required=True, help="bar-target TOML ([target], [profile])")
    p.add_argument("--json", action="store_true", help="one JSON object instead of text")
    p.set_defaults(func=_cmd_mtf)

    p = sub.add_parser(
        "mtf-edge",
        help="slanted-edge MTF (ISO 12233) of an image",
        description="The ISO 12233 slanted-edge MTF of an 8- or 16-bit PNG or TIFF: edge angle, "
        "4x oversampled edge spread, derivative, Hamming window, FFT. Without --roi the region "
        "around the strongest edge is used.",
    )
    p.add_argument("image", help="8- or 16-bit PNG or TIFF holding one slanted edge")
    p.add_argument("--roi", help="region x0,y0,x1,y1 in pixels around the edge")
    p.add_argument("--json", action="store_true", help="one JSON object instead of text")
    p.set_defaults(func=_cmd_mtf_edge)

    p = sub.add_parser(
        "cube",
        help="raw ImSpector frames -> reflectance cube (dark current, hot pixels, 001 §2.1/§2.4)",
        description="Build a reflectance cube from raw frames of the ImSpector V9 + PixelFly "
        "(001 §2.1, §2.4): fit h = a*T_exp + b to every pixel of the dark frames, find the hot "
        "pixels, subtract h from every frame, average the diffuse collector's columns along "
        "each spectral line and compute r = G_ref*E_ref*F(alpha) / (G_inc*E_inc*F(theta)); "
        "stack the lines, in chunks, into a cube (line, sample, band). "
        "RAW_DIR and DARK_DIR: frames in file-name order, 16-bit grayscale TIFF (.tif/.tiff, "
        "one frame per file) or NumPy (.npy, one frame (rows, columns) or a stack (n, rows, "
        "columns)), raw 12-bit DN, spectral rows down, spatial columns across (binning 1: "
        "1024 x 1280 with the scene in columns 0-1169 and the diffuse collector in 1170-1279; "
        "binning 2: 512 x 640, 585 + 55 columns); each folder has exposures.csv with columns "
        "file, exposure_s (one row per frame file; a .npy stack shares its value). The dark "
        "frames (aperture closed) need two or more exposure times. RAW_DIR also has "
        "wavelengths.csv with columns row, wavelength_nm, fwhm_nm for every spectral row. "
        "Output: .nc (NetCDF-4) or .hdr / .bsq / .bil / .bip (ENVI with wavelength, fwhm, data "
        "ignore value -9999 and default bands 850/650/550 nm).",
    )
    p.add_argument("raw_dir", metavar="RAW_DIR", help="folder of raw frames (see above)")
    p.add_argument("--dark", required=True, metavar="DARK_DIR", help="folder of dark frames")
    p.add_argument(
        "--binning",
        type=option_number(integer=True, lo=1, hi=2),
        default=2,
        help="the camera's binning factor, 1 or 2 (default 2, 001 §3.2)",
    )
    p.add_argument(
        "--rows-per-band",
        type=option_number(integer=True, lo=1, hi=64),
        default=5,
        help="spectral rows averaged into one band (default 5: 4.4 nm at binning 2)",
    )
    p.add_argument(
        "--f-alpha",
        type=option_number(positive=True, hi=10.0),
        default=1.0,
        help="the diffuse collector's receiving pattern F(alpha) at the light's incidence "
        "(default 1)",
    )
    p.add_argument(
        "--lines-per-chunk",
        type=option_number(integer=True, lo=1, hi=4096),
        default=64,
        help="lines processed together (memory is about one chunk; default 64)",
    )
    p.add_argument("-o", "--output", required=True, metavar="CUBE.nc|CUBE.hdr")
    p.add_argument(
        "--overwrite", action="store_true", help="replace an existing output (default: refuse)"
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar (shown on a terminal)")
    p.add_argument("--json", action="store_true", help="a JSON summary instead of one line")
    p.set_defaults(func=_cmd_cube)

    p = sub.add_parser("versions", help="versions of hsgeo, Python and the dependencies")
    p.set_defaults(func=_cmd_versions)
    return ap


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``hsgeo`` console script."""
    terminal.setup_streams()  # any locale: Σ, σ, … in ASCII where the terminal cannot show them
    args = None

    def fail(msg: str, status: int = 2) -> int:
        terminal.clear_progress()
        msg = " ".join(msg.split())  # one line, whatever the message
        prog = "hsgeo" if args is None else f"hsgeo {args.command}"
        print(f"{prog}: {msg}", file=sys.stderr)
        return status

    try:  # from the first import on: Ctrl-C while numpy, pandas, numba load is Ctrl-C too
        args = build_parser().parse_args(argv)
        from hsgeo.adjust.threads import blas_threads

        # BLAS on one thread, whatever the shell says: on small dense solves a second OpenBLAS
        # thread was slower, and on a busy machine many times slower (README, "Threads");
        # the engine chooses its own kernels' threads by the size of each problem
        with blas_threads(1):
            status = int(args.func(args) or 0)
        terminal.clear_progress()
        return status
    except ConvergenceError:
        return fail(
            "error: the adjustment did not converge; look for gross errors in the input files "
            "(a wrong unit, id or coordinate) and check the initial values given as options"
        )
    except HsgeoError as exc:
        return fail(f"error: {exc}")
    except KeyboardInterrupt:
        return fail("interrupted", EXIT_INTERRUPTED)
    except BrokenPipeError:
        # the reader of our output went away (`hsgeo reproduce ... --json | head -1`): stop
        # without a word; stdout goes to /dev/null so that flushing it at exit cannot fail again
        # (the recipe of the Python docs, "Note on SIGPIPE")
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        except (OSError, ValueError, io.UnsupportedOperation):
            pass
        return EXIT_BROKEN_PIPE
    except Exception as exc:
        # Ctrl-C inside a numba kernel arrives as SystemError caused by KeyboardInterrupt
        if terminal.interrupted(exc):
            return fail("interrupted", EXIT_INTERRUPTED)
        line = terminal.error_line(exc)  # the OS refused, or memory ran out
        if line is None:
            raise
        return fail(f"error: {line}")


if __name__ == "__main__":
    sys.exit(main())
