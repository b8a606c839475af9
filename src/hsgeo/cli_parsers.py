"""The ``hsgeo`` command's argument parsers, one function per subcommand.

:func:`hsgeo.cli.build_parser` assembles them and attaches each subcommand's handler; what a
subcommand does lives in :mod:`hsgeo.cli` (and the workflows it calls), what it accepts here.
"""

from __future__ import annotations

import argparse

from hsgeo.validate import option_number

__all__ = [
    "HsgeoParser",
    "root_parser",
    "SUBCOMMANDS",
    "add_reproduce",
    "add_calibrate_line",
    "add_calibrate_frame",
    "add_data",
    "add_orthorectify",
    "add_adjust_pushbroom",
    "add_lp_observations",
    "add_adjust_bal",
    "add_mtf",
    "add_mtf_edge",
    "add_cube",
    "add_asf",
    "add_versions",
]

_POSITIVE = option_number(positive=True)


class HsgeoParser(argparse.ArgumentParser):
    """argparse with one-line errors: ``hsgeo mtf: error: ... (see hsgeo mtf --help)``
    and exit status 2 (the usage, which wraps over many lines, is left to ``--help``).
    """

    def error(self, message: str):
        msg = " ".join(message.split())
        self.exit(2, f"{self.prog}: error: {msg} (see {self.prog} --help)\n")


def _lp_line_options(p) -> None:
    """The options of every command that reads LP line files: the full line's width and the
    navigation gaps interpolated across (``lp-observations``, ``orthorectify``).
    """
    p.add_argument(
        "--line-pixels",
        type=option_number(integer=True, lo=1, hi=100000),
        default=None,
        help="pixels of a full line; overrides the files' n_px_full attribute (default: that "
        "attribute, else 1800, 002 §4)",
    )
    p.add_argument(
        "--max-nav-gap-s",
        type=_POSITIVE,
        default=1.0,
        help="longest gap between navigation records interpolated across, s (default 1)",
    )


def root_parser() -> tuple[argparse.ArgumentParser, argparse._SubParsersAction]:
    """The ``hsgeo`` parser and its subparsers action (no subcommand yet)."""
    from hsgeo import __version__

    ap = HsgeoParser(
        prog="hsgeo",
        description="Geometry of hyperspectral sensors: reproduce the book's tables, calibrate, "
        "orthorectify.",
    )
    ap.add_argument("--version", action="version", version=f"hsgeo {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)
    return ap, sub


def add_reproduce(sub) -> argparse.ArgumentParser:
    """``hsgeo reproduce``."""
    from hsgeo.reproduce import chapter_names

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
    return p


def add_calibrate_line(sub) -> argparse.ArgumentParser:
    """``hsgeo calibrate-line``."""
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
    return p


def add_calibrate_frame(sub) -> argparse.ArgumentParser:
    """``hsgeo calibrate-frame``."""
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
    p.set_defaults(joint=False)
    return p


def add_data(sub) -> argparse.ArgumentParser:
    """``hsgeo data``."""
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
    _data_flight_options(p)
    return p


def _data_flight_options(p) -> None:
    """``hsgeo data flight --site LAT,LON --out DIR``: a simulated flight."""
    p.add_argument(
        "what",
        nargs="?",
        metavar="flight",  # checked by the command, so that an unknown option is named first
        help="flight: write a simulated flight about --site into --out DIR in the formats a "
        "real one is delivered in (ENVI lines + times file, geodetic navigation CSV, a "
        "view-angle sensor file, a DSM GeoTIFF, the targets' true positions; command.txt: "
        "the hsgeo orthorectify command that maps it)",
    )
    p.add_argument("--site", type=_site, metavar="LAT,LON", help="the flight's centre (WGS 84)")
    p.add_argument(
        "--length-km",
        type=option_number(lo=0.1, hi=200.0),
        default=30.0,
        help="length of the flight line, km (default 30)",
    )
    p.add_argument(
        "--seed", type=option_number(integer=True, lo=0, hi=2**31), default=0, help="rng seed"
    )


def _site(text: str) -> tuple:
    """``--site LAT,LON[,H]``."""
    try:
        v = tuple(float(x) for x in text.split(","))
    except ValueError:
        v = ()
    if len(v) not in (2, 3) or not (-90 < v[0] < 90 and -180 <= v[1] <= 180):
        raise argparse.ArgumentTypeError(
            f"{text!r}: give LAT,LON or LAT,LON,H (degrees north and east, metres), e.g. "
            "-33.9,151.2,40"
        )
    return v


def _wavelengths(text: str) -> tuple:
    """``--bands 640,550,460``: wavelengths in nm."""
    try:
        out = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: give band wavelengths in nm separated by commas, e.g. 640,550,460"
        ) from None
    if not out or not all(0 < v < 1e5 for v in out):
        raise argparse.ArgumentTypeError(f"{text!r}: wavelengths must be positive numbers of nm")
    return out


def _line_times_option(p, lines: str = "LINES", pixels: str | None = None) -> None:
    """``--line-times``: the times files of ENVI cubes among the command's ``lines``."""
    if pixels is None:
        pixels = (
            "zeta = s of a line scanner or view-angle sensor, x = s - (samples - 1)/2 px of the "
            "002 camera"
        )
    p.add_argument(
        "--line-times",
        action="append",
        metavar="TIMES",
        default=None,
        help=f"line times of an ENVI {lines} cube: a file of one time (s, the navigation's time "
        f"scale) per line, or a CSV with a t_s column; once per cube, in the order of {lines} "
        f"(default: the header's start time and line period). {lines} may be ENVI cubes (BIL/"
        "BIP/BSQ, name.hdr or name.ext.hdr beside name.raw/.dat/.bil …): sample s is " + pixels,
    )


def add_orthorectify(sub) -> argparse.ArgumentParser:
    """``hsgeo orthorectify``."""
    from hsgeo.io.raster import RASTER_FORMATS, raster_formats_text

    p = sub.add_parser(
        "orthorectify",
        help="orthorectify one line or mosaic many strips of any scanning sensor, or the "
        "frames of a frame camera, onto a map grid (COG, NetCDF or ENVI by the output's suffix)",
        description="Orthorectify every pixel of every line (the sensor's ray at the line's "
        "time on the trajectory, met with the terrain at its first crossing) and resample it "
        "onto a north-up grid by nearest neighbour in the grid's metres: every spectrum stays as "
        "measured. Where strips overlap, --mosaic decides: nearest-nadir (default: the pixel "
        "whose ray is nearest to the nadir), first (the first LINES file that covers the "
        "cell), mean (band by band, of the strips' nearest pixels). LINES: hsgeo's recorded "
        "flight line (NetCDF radiance(band, line, pixel), coordinate pixel: zeta px of the "
        "000 line scanner or x px from the line centre of the 002 camera, attributes t0_s and "
        "line_rate_hz; see hsgeo.io.lines) or LP line files (NetCDF lines(line, column, "
        "band), t_s(line), wavelength_nm(band), attributes col0, strip_id, n_px_full; see "
        "hsgeo.io.lp_lines); an optional fwhm_nm(band) is carried into the output; or, with a "
        "frame camera's sensor file (frame-opencv, rikola), its frames: one ENVI or TIFF file "
        "per frame, pixel (u, v) = (column, row) from the centre of the top-left pixel, "
        "placed by the navigation at the exposure time of --frame-times composed with the "
        "sensor file's mount, each frame a strip of the mosaic (nearest-nadir: the frame that "
        "sees the cell most nearly from above). NAV: the "
        "navigation file of every command (t_s, E_m, N_m, U_m, roll_deg, pitch_deg, "
        "heading_deg in the local east-north-up frame about --site, required), or a geodetic "
        "one: a CSV or Parquet (gps_sow_s or sod_s, lat_deg, lon_deg, h_m, roll_deg, pitch_deg, "
        "heading_deg; CRS by '# crs: EPSG:n' or --nav-crs) or an Applanix SBET (.out, "
        "--nav-crs required), whose local frame comes from the data and whose output CRS "
        "defaults to the UTM zone of its centre on its datum (see hsgeo.io.read_navigation); "
        "its DSM GeoTIFF may be in any CRS (--vertical for a 2D one) and is read under the "
        "lines' edge rays followed down to U = -500 m, plus 100 m. SENSOR: a sensor file "
        "([sensor] model = ...: line-scanner, pushbroom, panoramic, view-angle, frame-opencv, "
        "rikola; see hsgeo.io.read_sensor) or the 002 camera file ([camera], read in full: c "
        "per band, distortion, boresight, lever arm). RESULT: hsgeo adjust-pushbroom --json "
        "(camera parameters and node corrections). DSM: a GeoTIFF of ellipsoidal heights with "
        "an EPSG CRS, or a NetCDF height(N, E) in the local frame's metres; or --height, a "
        f"plane. OUT ({raster_formats_text()}) with the bands' wavelengths and FWHM; "
        "tiles computed with Dask (--scheduler: on a dask.distributed cluster).",
    )
    p.add_argument("lines", nargs="+", metavar="LINES")
    p.add_argument("--sensor", required=True, metavar="SENSOR.toml", help="sensor file (TOML)")
    p.add_argument("--trajectory", required=True, metavar="NAV", help="navigation file")
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--dsm", metavar="DSM", help="terrain: GeoTIFF (EPSG CRS) or NetCDF DEM")
    g.add_argument(
        "--height",
        type=option_number(lo=-1e5, hi=1e5),
        metavar="H_M",
        help="terrain: a plane at this height, m (the navigation's height system)",
    )
    p.add_argument("--adjustment", metavar="RESULT.json", help="hsgeo adjust-pushbroom --json")
    p.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="OUT",
        help="OUT" + ", OUT".join(RASTER_FORMATS) + " (the format by the suffix)",
    )
    p.add_argument(
        "--resolution",
        type=_POSITIVE,
        default=None,
        help="cell size in m (default: the lines' largest ground pixel spacing, 2 digits)",
    )
    p.add_argument(
        "--mosaic",
        choices=("nearest-nadir", "first", "mean"),
        default="nearest-nadir",
        help="where strips overlap (default nearest-nadir)",
    )
    p.add_argument(
        "--bands",
        type=_wavelengths,
        default=None,
        metavar="NM,NM,...",
        help="wavelengths (nm) of the bands to keep, nearest band each (default: all bands)",
    )
    p.add_argument(
        "--band",
        type=option_number(integer=True, lo=0, hi=100000),
        default=None,
        help="band of a pushbroom camera whose geometry every band uses (default: the middle "
        "kept band's when the camera has the lines' bands, else band 0)",
    )
    p.add_argument(
        "--crs",
        metavar="CRS",
        default=None,
        help="output CRS, e.g. EPSG:32756 (default: the UTM zone of --site on its datum, or of a "
        "geodetic navigation's centre on its datum)",
    )
    p.add_argument(
        "--site",
        type=_site,
        metavar="LAT,LON[,H]",
        help="latitude, longitude (degrees) and ellipsoidal height (m, default 0) of the origin "
        "of a local-ENU navigation's east-north-up frame, on the datum --nav-crs (default "
        "EPSG:4979, WGS 84); required for a local-ENU navigation (e.g. --site=-33.9,151.2,40), "
        "refused for a geodetic one",
    )
    p.add_argument(
        "--nav-crs",
        metavar="CRS",
        default=None,
        help="the datum of a geodetic navigation (an SBET names none), e.g. EPSG:4979 (WGS 84) "
        "or EPSG:4937 (ETRS89), overriding a CSV's '# crs:' line; for a local-ENU navigation "
        "the datum of --site (default EPSG:4979)",
    )
    p.add_argument(
        "--gps-week",
        type=option_number(integer=True, lo=0, hi=100000),
        default=None,
        help="GPS week of an SBET's or a gps_sow_s navigation's times (recorded, not applied)",
    )
    p.add_argument(
        "--vertical",
        metavar="ellipsoidal|EPSG:n",
        default=None,
        help="heights of a --dsm whose CRS is 2D (with a geodetic navigation): ellipsoidal, or "
        "a vertical CRS such as EPSG:5711 (AHD) or EPSG:5773 (EGM96)",
    )
    _line_times_option(p)
    p.add_argument(
        "--frame-times",
        metavar="TIMES.csv",
        default=None,
        help="exposure times of a frame camera's frames (sensor models frame-opencv, rikola; "
        "LINES are then the frames, one ENVI or TIFF file each): CSV or Parquet with columns "
        "file (the frame's file name, with or without folder and extension) and time_s (s, "
        "the navigation's time scale); for the Rikola optionally band (a band number of the "
        "sensor file: one row per frame and band)",
    )
    p.add_argument("--scheduler", metavar="ADDRESS", help="dask.distributed scheduler address")
    p.add_argument(
        "--max-gib",
        type=_POSITIVE,
        default=64.0,
        help="largest raster, GiB of float32 (default 64); checked before the work",
    )
    _lp_line_options(p)
    p.add_argument("--overwrite", action="store_true", help="replace an existing output")
    p.add_argument("--json", action="store_true", help="the summary as JSON")
    p.add_argument("--quiet", action="store_true", help="no progress display")
    return p


def add_adjust_pushbroom(sub) -> argparse.ArgumentParser:
    """``hsgeo adjust-pushbroom``."""
    p = sub.add_parser(
        "adjust-pushbroom",
        help="bundle-adjust LP lines with spline trajectory corrections (002 eq. 2-4)",
        description="Observation table: point_id, band, t_s, x_px, y_px; GCPs: point_id, E_m, "
        'N_m, H_m (CSV or Parquet); camera: the sensor file ([sensor] model = "pushbroom", '
        "or the former [camera] table; see hsgeo.io.read_sensor), whose c_band_mm, distortion "
        "and boresight_deg the adjustment starts from, and whose a-priori σ weight it (your "
        "instruments', required: sigma_lever_m in that table; [gnss_ins] sigma_pos_m = [E, N, "
        "H] m and sigma_att_deg = [roll, pitch, yaw]; [observations] sigma_px; [gcp] sigma_m "
        "with --gcp). "
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
    _geodetic_navigation_options(p, "--gcp")
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
    p.add_argument(
        "--strict",
        action="store_true",
        help="exit 2 when the data do not determine some parameters at the solution (default: "
        "a warning; the rest is estimated, those are named with no σ)",
    )
    p.add_argument("--json", action="store_true", help="JSON instead of the text report")
    return p


def add_lp_observations(sub) -> argparse.ArgumentParser:
    """``hsgeo lp-observations``."""
    p = sub.add_parser(
        "lp-observations",
        help="tie-point observations from LP image lines: rotation-compensated scenes, BRISK, "
        "RANSAC on the LP fundamental matrix (002 §3.1)",
        description="Retrieve the observations of hsgeo adjust-pushbroom from the pixels of "
        "LP strips (002 §3.1, §4): scenes of N lines rotation-compensated in x (002 eq. 1), "
        "BRISK key points matched within each band between scenes of different strips whose "
        "footprints overlap, RANSAC on the Gupta-Hartley LP fundamental matrix (or the frame "
        "camera's), tie points seen in >= 3 lines of >= 3 strips, each observation at the "
        "centre of its original pixel; of the bands that found one feature in the same "
        "lines and pixels, one tie point is written (--all-bands: every band's). SCENES: LP "
        "line files, one strip each (NetCDF, see "
        "hsgeo.io.lp_lines: lines(line, column, band) DN, t_s(line), wavelength_nm(band), "
        "attributes col0, strip_id and optionally n_px_full; or ENVI cubes with wavelengths "
        "in the header and their line times, see --line-times). NAV: the navigation file of "
        "every command, CSV or "
        "Parquet with t_s, E_m, N_m, U_m, roll_deg, pitch_deg, heading_deg (see "
        "hsgeo.io.navigation). CAMERA: the camera TOML of hsgeo adjust-pushbroom (one band "
        "per band of the line files; c_band_mm, boresight_deg as known a priori). SQUARES: "
        "CSV or Parquet point_id, E_m, N_m, H_m of the reference squares: their centres are "
        "measured in the images and written with their ids (give the GCPs among them to "
        "adjust-pushbroom --gcp). OUT: the observation table point_id, band, t_s, x_px, y_px "
        "(+ strip, line), .parquet or .csv: it feeds hsgeo adjust-pushbroom unchanged.",
    )
    p.add_argument(
        "scenes",
        nargs="+",
        metavar="SCENES",
        help="LP line files (NetCDF) or ENVI cubes, one strip each",
    )
    p.add_argument("--trajectory", required=True, metavar="NAV", help="navigation file (see above)")
    p.add_argument("--camera", required=True, metavar="CAMERA.toml", help="camera (TOML)")
    p.add_argument("-o", "--output", required=True, metavar="OUT.parquet")
    p.add_argument(
        "--scene-lines",
        type=option_number(integer=True, lo=8, hi=100000),
        default=200,
        help="lines per scene (default 200, 002 §4)",
    )
    p.add_argument(
        "--ransac",
        choices=("lp", "frame"),
        default="lp",
        help="RANSAC model: the LP fundamental matrix (default, 002) or the frame camera's",
    )
    p.add_argument(
        "--threshold-px",
        type=_POSITIVE,
        default=1.0,
        help="RANSAC inlier threshold, px (default 1)",
    )
    p.add_argument("--squares", metavar="SQUARES.csv", help="reference squares (see above)")
    _geodetic_navigation_options(p, "--squares")
    p.add_argument(
        "--height",
        type=option_number(lo=-1e4, hi=1e4),
        metavar="H",
        help="mean terrain height, m (default: the squares' mean height)",
    )
    p.add_argument(
        "--bands",
        type=_band_list,
        help="bands to use, 0-based, comma-separated (default all)",
    )
    p.add_argument(
        "--subpixel-x",
        action="store_true",
        help="x at the key point's sub-pixel position (default: the pixel centre, 002 §3.1)",
    )
    p.add_argument(
        "--all-bands",
        action="store_true",
        help="write every band's tie points, also where several bands found one feature in "
        "the same lines and pixels (default: one per feature; those coincide and share their "
        "rounding, so adjusted as independent they make σ̂ too small)",
    )
    _lp_line_options(p)
    _line_times_option(
        p,
        "SCENES",
        "x = x0 + s - (n - 1)/2 px, x0 the header's 'x start' - 1 (0 without it) and n the "
        "full line's pixels (--line-pixels; else the samples without 'x start', 1800 with "
        "it); the strip's id is the file's name without extension",
    )
    p.add_argument(
        "--overwrite", action="store_true", help="replace an existing output (default: refuse)"
    )
    p.add_argument("--json", action="store_true", help="a JSON summary instead of text")
    return p


def _geodetic_navigation_options(p, table: str) -> None:
    """``--nav-crs`` and ``--site`` of the line scanners' commands."""
    p.add_argument(
        "--nav-crs",
        metavar="EPSG:n",
        help="the CRS of a navigation as delivered instead of the local-ENU file: a geodetic "
        "CSV or Parquet (gps_sow_s [gps_week] or sod_s, lat_deg, lon_deg, h_m ellipsoidal, "
        "roll_deg, pitch_deg, heading_deg against the NED at each record; or X_m, Y_m, Z_m "
        "geocentric) or an Applanix SBET (.out); e.g. EPSG:4979 (WGS 84), EPSG:4937 (ETRS89). "
        "A CSV may name it in a first line '# crs: EPSG:4979'. Its times are the lines' and the "
        "observations' time scale",
    )
    p.add_argument(
        "--site",
        type=_site,
        metavar="LAT,LON[,H]",
        help="with a geodetic navigation: the origin of the local east-north-up frame "
        f"(degrees, ellipsoidal m, on the navigation's datum) in which {table}'s E_m, N_m, H_m "
        "are given (required with " + table + "; default the navigation's centre)",
    )


def _band_list(text: str) -> tuple:
    """``--bands 0,2,5`` → (0, 2, 5)."""
    try:
        out = tuple(int(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a comma-separated list of band numbers (e.g. 0,2,5)"
        ) from None
    if not out or min(out) < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: bands are numbered from 0")
    return out


def add_adjust_bal(sub) -> argparse.ArgumentParser:
    """``hsgeo adjust-bal``."""
    p = sub.add_parser(
        "adjust-bal",
        help="bundle-adjust a 'Bundle Adjustment in the Large' problem file (Snavely cameras)",
    )
    p.add_argument("file", help="BAL problem file (.txt, or .txt.bz2)")
    p.add_argument("--json", action="store_true", help="one JSON object instead of text")
    return p


def add_mtf(sub) -> argparse.ArgumentParser:
    """``hsgeo mtf``."""
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
    return p


def add_mtf_edge(sub) -> argparse.ArgumentParser:
    """``hsgeo mtf-edge``."""
    p = sub.add_parser(
        "mtf-edge",
        help="slanted-edge MTF (ISO 12233) of an image",
        description="The ISO 12233 slanted-edge MTF of an 8- or 16-bit PNG or TIFF: edge angle, "
        "4x oversampled edge spread, derivative, Hamming window, FFT. A region is measured only "
        "if it holds one straight edge between two plateaus, no fill, nodata or clipped level, "
        "at least 4 px of each plateau, and a line spread function at least 1 px wide; "
        "otherwise the reason is given. Without --roi the region around the strongest edge is "
        "used if it qualifies, else a region that does is searched for (e.g. inside a target "
        "whose surroundings are set to 0).",
    )
    p.add_argument("image", help="8- or 16-bit PNG or TIFF holding one slanted edge")
    p.add_argument("--roi", help="region x0,y0,x1,y1 in pixels around the edge")
    p.add_argument("--json", action="store_true", help="one JSON object instead of text")
    return p


def add_cube(sub) -> argparse.ArgumentParser:
    """``hsgeo cube``."""
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
    return p


def add_asf(sub) -> argparse.ArgumentParser:
    """``hsgeo asf``."""
    p = sub.add_parser(
        "asf",
        help="angular sensitivity of a whiskbroom scanner: cross-runway / along-runway (004)",
        description="The angular sensitivity function (ASF) of a whiskbroom scanner from a scan "
        "crossing a runway divided by an overflight along it (004 steps 1-3): the scans are "
        "georegistered with the sensor and the navigation (the panoramic model), the along "
        "image is registered onto the cross scan by the landmarks at the runway's sides (a "
        "shift per window along both long edges, their median), both are averaged over the "
        "runway's width, divided, and normalised to nadir; with --reverse, a second crossing "
        "flown the opposite way is combined with the first (sqrt of the product: the odd part "
        "of a BRDF cancels). RAW SCANS (with --sensor and --trajectory): NetCDF flight lines "
        "with radiance(band, line, pixel), the coordinate pixel (the detector pixel of each "
        "column) and the attributes t0_s (time of line 0 on the navigation's time scale) and "
        'line_rate_hz. SENSOR: TOML, [sensor] model = "panoramic", n_px, ifov_deg (degrees), '
        "active_fraction, boresight_deg, lever_arm_m. NAV: t_s, E_m, N_m, U_m, roll_deg, "
        "pitch_deg, heading_deg (hsgeo.io.navigation). SCANS GEOREGISTERED ELSEWHERE (without "
        "--sensor/--trajectory): NetCDF with reflectance(band, line, pixel), E_m(line, pixel) "
        "and N_m(line, pixel) (the ground point of every sample, m, in one map frame) and "
        "scan_angle_deg(pixel) (degrees, positive to the right of the heading). RUNWAY: CSV or "
        "Parquet with columns E_m, N_m, the runway's corners in order around it, in the "
        "navigation's map frame.",
    )
    p.add_argument("cross", metavar="CROSS.nc", help="the scan crossing the runway")
    p.add_argument("along", metavar="ALONG.nc", help="the scan flown along the runway")
    p.add_argument(
        "--runway", required=True, metavar="RUNWAY.csv", help="runway corners (E_m, N_m)"
    )
    p.add_argument("--sensor", metavar="SENSOR.toml", help="the scanner's sensor file (raw scans)")
    p.add_argument(
        "--trajectory", metavar="NAV.csv", help="the navigation of the flights (raw scans)"
    )
    p.add_argument(
        "--reverse",
        metavar="REVERSE.nc",
        help="a second crossing flown with the opposite heading (raw scans)",
    )
    p.add_argument(
        "--runway-height",
        type=option_number(lo=-1000.0, hi=10000.0),
        default=0.0,
        help="the runway's height U in the navigation's frame, m (default 0)",
    )
    p.add_argument(
        "--margin",
        type=option_number(lo=0.0, hi=100.0),
        default=2.0,
        help="samples closer than this to the runway's edge are left out, m (default 2)",
    )
    p.add_argument(
        "--no-register",
        action="store_true",
        help="take the georegistration as it is (no shift by the landmarks)",
    )
    p.add_argument("--json", action="store_true", help="one JSON object instead of text")
    return p


def add_versions(sub) -> argparse.ArgumentParser:
    """``hsgeo versions``."""
    p = sub.add_parser("versions", help="versions of hsgeo, Python and the dependencies")
    return p


#: Subcommands in the order of ``hsgeo --help``: (name of the handler in hsgeo.cli, adder).
SUBCOMMANDS = (
    ("_cmd_reproduce", add_reproduce),
    ("_cmd_calibrate_line", add_calibrate_line),
    ("_cmd_calibrate_frame", add_calibrate_frame),
    ("_cmd_data", add_data),
    ("_cmd_orthorectify", add_orthorectify),
    ("_cmd_adjust_pushbroom", add_adjust_pushbroom),
    ("_cmd_lp_observations", add_lp_observations),
    ("_cmd_adjust_bal", add_adjust_bal),
    ("_cmd_mtf", add_mtf),
    ("_cmd_mtf_edge", add_mtf_edge),
    ("_cmd_cube", add_cube),
    ("_cmd_asf", add_asf),
    ("_cmd_versions", add_versions),
)
