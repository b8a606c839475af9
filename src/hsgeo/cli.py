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
from hsgeo.errors import ConvergenceError, HsgeoError, InputError
from hsgeo.terminal import json_text

__all__ = ["main", "EXIT_INTERRUPTED", "EXIT_BROKEN_PIPE", "build_parser"]

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
    from hsgeo.workflows.line_calibration import calibrate_files

    cal = calibrate_files(
        args.observations,
        args.control,
        zeta0_px=args.zeta0_px,
        c_px=args.c_px,
        sigma_px=args.sigma_px,
        reject_k=args.reject_k,
    )
    if args.json:
        print(json_text(cal.to_dict()))
    else:
        stats = cal.residual_stats()
        print(cal.result.report())
        print(
            f"residuals: RMS {stats['rms_px']:.4f} px, max |v| {stats['max_abs_px']:.4f} px "
            f"over {stats['n_observations']} observations"
        )


def _cmd_calibrate_frame(args) -> int:
    from hsgeo.report import from_estimates
    from hsgeo.workflows.frame_calibration import calibrate_frame_files

    res = calibrate_frame_files(
        args.images,
        args.board,
        joint=args.joint,
        band_regex=args.band_regex,
        cube_regex=args.cube_regex,
        sigma_px=args.sigma_px,
    )
    out = from_estimates("calibrate-frame", res)
    print(
        out.to_json()
        if args.json
        else out.to_text() + "\n\n" + "\n".join(f"  {k}: {v}" for k, v in out.meta.items())
    )
    return 0


def _cmd_data(args) -> int:
    from hsgeo.reproduce.data import generate_all

    if args.what not in (None, "flight"):
        raise InputError(f"{args.what!r}: hsgeo data takes one subject, flight (or none)")
    if args.what == "flight" or args.site is not None:
        return _data_flight(args)

    return generate_all(
        verify=args.verify, update=args.update_manifest, out=args.out, overwrite=args.overwrite
    )


def _data_flight(args) -> int:
    """``hsgeo data flight --site LAT,LON --out DIR``: a flight in a real one's formats."""
    import shlex

    from hsgeo.io.flight_files import check_flight_outputs, orthorectify_command, write_flight
    from hsgeo.simulate.geo_flight import FlightConfig, simulate_flight

    if args.what != "flight":
        raise InputError("--site is for 'hsgeo data flight'; give: hsgeo data flight --site ...")
    if args.site is None or args.out is None:
        raise InputError(
            "hsgeo data flight needs --site LAT,LON (the flight's centre) and --out DIR "
            "(a folder for its files)"
        )
    if args.verify or args.update_manifest:
        raise InputError("--verify and --update-manifest are for the scenario data, not a flight")
    check_flight_outputs(args.out, overwrite=args.overwrite)
    cfg = FlightConfig(args.site[0], args.site[1], length_m=1000.0 * args.length_km)
    flight = simulate_flight(cfg, rng=args.seed)
    files = write_flight(args.out, flight, overwrite=args.overwrite)
    cmd = shlex.join(orthorectify_command(args.out, flight.output_epsg))
    print(
        f"a {args.length_km:g} km flight over {cfg.lat_deg:g}, {cfg.lon_deg:g}: "
        f"{flight.lines_lsb.shape[0]} lines of {flight.lines_lsb.shape[1]} pixels, ground "
        f"pixel {flight.gsd_m:.3g} m, output CRS EPSG:{flight.output_epsg}; {len(files)} files "
        f"in {args.out}\northorectify it with:\n  {cmd}"
    )
    return 0


def _cmd_adjust_pushbroom(args) -> int:
    from hsgeo.workflows.pushbroom_ba import adjust_files

    res = adjust_files(
        args.observations,
        args.trajectory,
        args.camera,
        args.gcp,
        node_interval_s=args.node_interval,
        progress=terminal.progress_printer(),
        y_as_time=not args.image_y,
        max_nav_gap_s=args.max_nav_gap_s,
        nav_crs=args.nav_crs,
        site=args.site,
    )
    out = res.to_dict()
    print(json_text(out) if args.json else res.result.report(max_block_size=20))
    fit = out["fit"]
    warnings = fit.get("warnings", [])
    if fit["verdict"] == "poor" and not args.accept_poor_fit:
        print(
            f"hsgeo {args.command}: error: implausible fit: {'; '.join(fit['reasons'])} "
            "(the result is printed above; --accept-poor-fit keeps it with exit status 0)"
            + "".join(f"; also: {w}" for w in warnings),
            file=sys.stderr,
        )
        return 2
    if warnings and args.strict:
        print(
            f"hsgeo {args.command}: error: --strict: {'; '.join(warnings)} (the result is "
            "printed above)",
            file=sys.stderr,
        )
        return 2
    for w in warnings:
        print(f"hsgeo {args.command}: warning: {w}", file=sys.stderr)
    return 0


def _cmd_lp_observations(args) -> int:
    from hsgeo.workflows.lp_observations import LpOptions, lp_observation_files

    opts = LpOptions(
        n_lines_per_scene=args.scene_lines,
        ransac=args.ransac,
        threshold_px=args.threshold_px,
        bands=args.bands,
        x_at="subpixel" if args.subpixel_x else "pixel_centre",
        max_nav_gap_s=args.max_nav_gap_s,
        one_band_per_feature=not args.all_bands,
    )
    res = lp_observation_files(
        args.scenes,
        args.trajectory,
        args.camera,
        args.output,
        squares=args.squares,
        height_m=args.height,
        options=opts,
        overwrite=args.overwrite,
        progress=terminal.stage_printer(),
        n_px_full=args.line_pixels,
        nav_crs=args.nav_crs,
        site=args.site,
        line_times=args.line_times,
    )
    terminal.clear_progress()
    d = res.to_dict()
    if args.json:
        print(json_text(d))
        return 0
    c = d["counts"]["all"]
    print(
        f"{d['n_observations']} observations of {c['tie_points_adjusted']} tie points and "
        f"{d['n_squares']} squares ({c['observations']} tie-point observations in all bands, "
        f"{c['features']} features) from {c['scenes']} scenes in {len(args.scenes)} strips: "
        f"{c['keypoints']} key points, {c['matches']} matches, {c['inliers_lp']} LP-F and "
        f"{c['inliers_frame']} frame-F RANSAC inliers -> {args.output}"
    )
    return 0


def _cmd_versions(args) -> int:
    from hsgeo import show_versions

    show_versions()
    return 0


def _cmd_orthorectify(args) -> int:
    from hsgeo.workflows.orthorectify import orthorectify_files

    progress = None if args.quiet else terminal.progress_counter("raster tiles")
    try:
        res = orthorectify_files(
            args.lines,
            args.trajectory,
            args.sensor,
            output=args.output,
            dsm=args.dsm,
            height_m=args.height,
            adjustment=args.adjustment,
            resolution_m=args.resolution,
            bands=args.bands,
            band=args.band,
            mosaic=args.mosaic,
            crs=args.crs,
            site=args.site,
            scheduler=args.scheduler,
            overwrite=args.overwrite,
            progress=progress,
            max_nav_gap_s=args.max_nav_gap_s,
            line_pixels=args.line_pixels,
            max_gib=args.max_gib,
            nav_crs=args.nav_crs,
            gps_week=args.gps_week,
            vertical=args.vertical,
            line_times=args.line_times,
            frame_times=args.frame_times,
        )
    finally:
        terminal.clear_progress()
    out = res.to_dict()
    if args.json:
        print(json_text(out))
    else:
        print(
            f"orthorectified {len(out['strips'])} strip(s), {len(out['bands'])} band(s) onto "
            f"{out['height']} x {out['width']} cells of {out['resolution_m']:g} m "
            f"({out['crs']}, mosaic {out['mosaic']}) -> " + ", ".join(out["files"])
        )
    return 0


def _cmd_adjust_bal(args) -> int:
    from hsgeo.workflows.bal import adjust_bal_file

    fit = adjust_bal_file(args.file, progress=None if args.json else terminal.progress_printer())
    out = fit.to_dict()
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
    from hsgeo.workflows.mtf import bars_files

    out = bars_files(args.profiles, args.bars)
    if args.json:
        print(json_text(out.to_dict()))
        return 0
    for r, res in out.by_row.items():
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
    import numpy as np

    from hsgeo.workflows.mtf import edge_file

    res = edge_file(args.image, args.roi)
    if args.json:
        print(json_text(res.to_dict()))
        return 0
    print(
        f"edge at {res.edge_angle_deg:.2f} deg in ROI {res.roi}, LSF FWHM {res.lsf_fwhm_px:.2f} "
        f"px, borderline frequency (MTF 0.1) {res.borderline_cy_px:.3f} cy/px"
    )
    print("  f_cy_px   MTF")
    for f in np.arange(0.0, 1.0001, 0.05):
        print(f"  {f:7.3f}  {np.interp(f, res.frequency_cy_px, res.mtf):6.3f}")
    return 0


def _cmd_asf(args) -> int:
    import numpy as np

    from hsgeo.workflows.asf import AsfOptions
    from hsgeo.workflows.asf_flights import asf_files

    opts = AsfOptions(margin_m=args.margin, register=not args.no_register)
    out = asf_files(
        args.cross,
        args.along,
        args.runway,
        opts,
        sensor_path=args.sensor,
        trajectory_path=args.trajectory,
        reverse_path=args.reverse,
        terrain_height_m=args.runway_height,
    )
    if args.json:
        print(json_text(out.to_dict()))
        return 0
    res = out.cross
    for label, r in (("", res), ("reverse crossing: ", out.reverse)):
        reg = None if r is None else r.registration
        if reg is not None:
            print(
                f"{label}registration: along image shifted by ({reg.shift_m[0]:+.2f}, "
                f"{reg.shift_m[1]:+.2f}) m (E, N) from {reg.n_windows} windows; scatter between "
                f"windows {reg.scatter_px:.2f} px, σ̂ of the shift {reg.sigma_px:.3f} px"
            )
    usable, asf = out.usable, out.asf
    if out.reverse is not None:
        print("ASF of the two opposite crossings combined (sqrt of their product)")
    print(f"{int(usable.sum())} of {usable.size} columns usable")
    from hsgeo.workflows.asf import peak_to_peak_percent

    pp = ", ".join(f"{v:.1f}" for v in peak_to_peak_percent(asf, usable, res.smooth_px))
    print(f"peak-to-peak ASF variation per band, %: {pp}")
    print("scan_angle_deg " + " ".join(f"{'band ' + str(b + 1):>8}" for b in range(asf.shape[0])))
    for ang in (-40, -30, -20, -10, 0, 10, 20, 30, 40):
        j = int(np.argmin(np.abs(res.scan_angle_deg - ang)))
        if abs(res.scan_angle_deg[j] - ang) > 1 or not usable[j]:
            continue
        vals = " ".join(f"{v:8.4f}" for v in asf[:, j])
        print(f"{res.scan_angle_deg[j]:14.2f} {vals}")
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


def build_parser() -> argparse.ArgumentParser:
    """The ``hsgeo`` parser (:mod:`hsgeo.cli_parsers`), each subcommand with its handler."""
    from hsgeo.cli_parsers import SUBCOMMANDS, root_parser

    ap, sub = root_parser()
    handlers = globals()  # looked up now: a test may replace a handler
    for handler, add in SUBCOMMANDS:
        add(sub).set_defaults(func=handlers[handler])
    return ap


def _json_error(command: str | None, message: str, status: int) -> None:
    """With ``--json``, every exit path prints one JSON object on standard output (one shape):
    a failure is ``{"command", "ok": false, "exit_status", "error"}``, the same line as on
    standard error (which keeps it too).
    """
    try:
        print(json_text({"command": command, "ok": False, "exit_status": status, "error": message}))
        sys.stdout.flush()
    except (BrokenPipeError, OSError, ValueError):
        pass


def _json_usage_errors(ap: argparse.ArgumentParser, argv) -> None:
    """Make the parser's exits JSON too when ``--json`` is among the arguments: a usage error
    (``{"command", "ok": false, "exit_status": 2, "error"}``, the line standard error shows)
    and ``--help`` / ``--version`` (``{"command", "ok": true, "exit_status": 0, "text"}``).
    """
    if "--json" not in argv:
        return
    parsers = [ap]
    for action in ap._actions:  # the subcommands' parsers
        if isinstance(action, argparse._SubParsersAction):
            parsers += list(action.choices.values())
    names = {p.prog.split()[-1] for p in parsers[1:]}
    # the root parser refuses what the subcommand left over ("unrecognized arguments"): the
    # command is the first subcommand name on the line
    given = next((a for a in argv if a in names), None)
    for p in parsers:
        command = p.prog.split()[-1] if p is not ap else given

        def error(message, _p=p, _error=p.error, _command=command):
            line = " ".join(f"{_p.prog}: error: {message} (see {_p.prog} --help)".split())
            _json_error(_command, line, 2)
            _error(message)  # the parser's own one line on standard error, exit status 2

        def print_message(message, file=None, _print=p._print_message, _command=command):
            # --help and --version print on standard output through this, then exit 0
            if message and file is sys.stdout:
                doc = {"command": _command, "ok": True, "exit_status": 0, "text": message}
                _print(json_text(doc) + "\n", file)
            else:
                _print(message, file)

        p.error = error
        p._print_message = print_message


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``hsgeo`` console script."""
    terminal.setup_streams()  # any locale: Σ, σ, … in ASCII where the terminal cannot show them
    terminal.keep_freed_memory()  # freed arrays reused, not faulted in again (its docstring)
    args = None
    argv_list = list(sys.argv[1:] if argv is None else argv)

    def fail(msg: str, status: int = 2) -> int:
        terminal.clear_progress()
        msg = " ".join(msg.split())  # one line, whatever the message
        prog = "hsgeo" if args is None else f"hsgeo {args.command}"
        if (getattr(args, "json", False) if args is not None else "--json" in argv_list) and (
            status != EXIT_BROKEN_PIPE
        ):
            _json_error(None if args is None else args.command, f"{prog}: {msg}", status)
        print(f"{prog}: {msg}", file=sys.stderr)
        return status

    try:  # from the first import on: Ctrl-C while numpy, pandas, numba load is Ctrl-C too
        ap = build_parser()
        _json_usage_errors(ap, argv_list)
        args = ap.parse_args(argv_list)
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
            if getattr(args, "json", False):  # a bug: still JSON on stdout, then the traceback
                _json_error(args.command, f"internal error: {type(exc).__name__}: {exc}", 1)
            raise
        return fail(f"error: {line}")


if __name__ == "__main__":
    sys.exit(main())
