"""The source papers' published values as data, each row citing its table.

Numbers are copied from the papers' text files in ``/work/shared/papers/`` (see their README);
``source`` names the file, table and row. Nothing here is computed.

References
----------
000: Miljković, Gajski, Vela (2017). Spatial calibration of the hyperspectral line scanner by the
bundle block adjusting method. Geodetski list 2017/2.
001: Krtalić, Miljković, Gajski, Racetin (2019). Spatial distortion assessments of a low-cost
laboratory and field hyperspectral imaging system. Sensors 19(19), 4267.
002: the LP (line-pair) bundle adjustment of a HySpex VNIR-1800 pushbroom camera with spline
trajectory corrections (see ``/work/shared/papers/002_*.txt``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "LineIOP",
    "P000_TABLE1_CALIBRATED",
    "P000_TABLE1_UNCALIBRATED",
    "P001_TABLE2",
    "P001_SENSOR",
    "P001_DISTORTION_STATEMENTS",
    "P000_GCP_COLUMNS",
    "P000_TABLE2_ROWS",
    "P000_TABLE3_ROWS",
    "P000_GCP_FOOTERS",
    "RIKOLA_CAMERA",
    "RIKOLA_BANDS",
    "RIKOLA_TABLE3",
    "RIKOLA_TABLE3_SIGMA0_SQ",
    "RIKOLA_TABLE4_ROP_DEG",
    "RIKOLA_TABLE4_GAP_MODEL",
    "band_table",
    "ASF_004",
]


@dataclass(frozen=True)
class LineIOP:
    """Inner orientation of one spectral line of the ImSpector V9 + PixelFly (000 eq. (2)).

    ``K1..K3`` in px per (100 px)^(3, 5, 7): see :mod:`hsgeo.sensors.line1d` for the
    normalisation. ``None`` where the paper gives no value.
    """

    row_px: int | None  # spectral line: sensor row counted from the top of the image
    wavelength_nm: float | None
    zeta0_px: float
    zeta0_sigma_px: float | None
    c_px: float
    c_sigma_px: float | None
    K1: float | None
    K2: float | None
    K3: float | None
    source: str


#: 000 Table 1, row "calibrated": λ = 870 nm (000 §4.1, "calibration was performed for 870 nm").
P000_TABLE1_CALIBRATED = LineIOP(
    None,
    870.0,
    486.8,
    0.1,
    3539.0,
    14.0,
    1.459,
    -0.1636,
    0.00526,
    "000 Table 1, row 'calibrated'",
)
#: 000 Table 1, row "uncalibrated": the nominal values (x0 = 485 px, c = 3600 px).
P000_TABLE1_UNCALIBRATED = LineIOP(
    None,
    870.0,
    485.0,
    None,
    3600.0,
    None,
    None,
    None,
    None,
    "000 Table 1, row 'uncalibrated'",
)

#: 001 Table 2: inner orientation per spectral line (rows 100, 300, 500, 1000 from the top).
P001_TABLE2 = (
    LineIOP(100, None, 499.9, 0.1, 3614.0, 14.0, 0.660, -0.080, 0.0024, "001 Table 2, line 100"),
    LineIOP(300, None, 497.5, 0.1, 3605.0, 14.0, 0.695, -0.085, 0.0027, "001 Table 2, line 300"),
    LineIOP(500, None, 494.7, 0.1, 3569.0, 14.0, 0.710, -0.084, 0.0027, "001 Table 2, line 500"),
    LineIOP(1000, None, 486.8, 0.1, 3539.0, 14.0, 1.459, -0.164, 0.0053, "001 Table 2, line 1000"),
)

#: ImSpector V9 + PixelFly (001 Table 1 and §2.1).
P001_SENSOR = {
    "n_columns": 1280,  # 001 Table 1 "Image resolution 1280 × 1024"
    "n_rows": 1024,  # 001 Table 1
    "n_reflected_columns": 1170,  # 001 §2.1 "1170 × 1024 ... reflected waves"
    "n_incident_columns": 110,  # 001 §2.1 "110 × 512 ... incident waves"
    "pixel_um": 6.7,  # 001 Table 1 "Pixel size 6.7 µm × 6.7 µm"
    "focal_mm": 23.0,  # 001 §2.1 "Schneider Kreuznach Xenoplan 1.4/23"
    "lambda_min_nm": 430.0,  # 001 Table 1 "Spectral range 430–900 nm"
    "lambda_max_nm": 900.0,  # 001 Table 1
    "bits": 12,  # 001 §2.1 "12-bit CCD"
    "distance_m": 3.0,  # 001 §3.1 "Imaging was performed at a distance of 3 m"
    "source": "001 Table 1, §2.1, §3.1",
}

#: The papers' statements about the size of the distortion (what the normalisation must give).
P001_DISTORTION_STATEMENTS = {
    "max_distortion_line100_px": (4.0, "001 §4: 'ranges from 4 px for the blue-indigo'"),
    "max_distortion_visible_px": (11.0, "001 §3.1: 'within a range of 0 to 11 for the visible'"),
    "distortion_450px_line1000_px": (
        25.0,
        "001 §3.1: 'rises drastically ... above 25' (NIR, at "
        "the line's edge, 450 px from the centre)",
    ),
}


#: 000 Tables 2 and 3: deviations at the control points (geocoded − reference, m) without
#: (Table 2, Jakšić 2009) and with (Table 3, Miljković 2017) the spatial calibration, as printed.
#: Columns: GCP, Δy, Δx, Δy − n_y, v_y·v_y, Δx − n_x, v_x·v_x (y is east, x north).
P000_GCP_COLUMNS = ("gcp", "dy_m", "dx_m", "dy_minus_n_m", "vyvy_m2", "dx_minus_n_m", "vxvx_m2")
P000_TABLE2_ROWS = (
    (2, -1.1, -1.1, -0.91, 0.82, -1.13, 1.27),
    (3, -1.27, 0.96, -1.08, 1.16, 0.94, 0.87),
    (7, -0.3, 0.49, -0.11, 0.01, 0.47, 0.22),
    (8, -0.44, 0.01, -0.25, 0.06, -0.02, 0.00),
    (11, -0.61, -0.25, -0.42, 0.17, -0.28, 0.08),
    (12, -1.13, 0.93, -0.94, 0.87, 0.91, 0.82),
    (16, 0.34, 0.32, 0.54, 0.29, 0.30, 0.09),
    (17, 0.61, -0.27, 0.81, 0.65, -0.30, 0.09),
    (20, 1.3, -0.32, 1.50, 2.24, -0.35, 0.12),
    (22, 0.65, -0.52, 0.85, 0.71, -0.55, 0.30),
)
P000_TABLE3_ROWS = (
    (2, -0.31, 0.21, -0.29, 0.08, 0.18, 0.03),
    (3, -0.58, 0.33, -0.56, 0.31, 0.30, 0.09),
    (7, -0.36, 0.45, -0.34, 0.12, 0.42, 0.17),
    (8, -0.44, 0.15, -0.42, 0.18, 0.12, 0.01),
    (11, -0.26, -0.35, -0.24, 0.06, -0.38, 0.15),
    (12, 0.31, 0.11, 0.33, 0.11, 0.08, 0.01),
    (16, 0.22, 0.21, 0.24, 0.06, 0.18, 0.03),
    (17, 0.28, -0.17, 0.30, 0.09, -0.20, 0.04),
    (20, 0.53, -0.28, 0.55, 0.30, -0.31, 0.10),
    (22, 0.41, -0.32, 0.43, 0.18, -0.35, 0.13),
)
#: The footers as printed: value and printed decimals. Table 2 prints the y bias as "n_x".
P000_GCP_FOOTERS = {
    "000 Table 2": {
        "sum_dy_m": (-1.95, 2),
        "sum_dx_m": (0.25, 2),
        "sum_vyvy_m2": (6.98, 2),
        "sum_vxvx_m2": (3.84, 2),
        "bias_y_m": (-0.2, 1),
        "bias_x_m": (0.0, 1),
        "sigma_y_m": (0.88, 2),
        "sigma_x_m": (0.65, 2),
    },
    "000 Table 3": {
        "sum_dy_m": (-0.20, 2),
        "sum_dx_m": (0.34, 2),
        "sum_vyvy_m2": (1.49, 2),
        "sum_vxvx_m2": (0.75, 2),
        "bias_y_m": (-0.02, 2),
        "bias_x_m": (0.03, 2),
        "sigma_y_m": (0.40, 2),
        "sigma_x_m": (0.29, 2),
    },
}


# ---- 003 (Rikola)
#: 003 Table 1: technical data of the Rikola camera (FPI2015).
RIKOLA_CAMERA = {
    "width_px": 1017,  # 003 Table 1
    "height_px": 648,  # 003 Table 1
    "pixel_mm": 0.0055,  # 003 Table 1: 5.5 x 5.5 µm
    "f_nominal_mm": 9.0,  # 003 Table 1
    "range_nm": (500.0, 900.0),  # 003 Table 1
}

#: 003 Table 2: band, sensor, FPI air gap (nm), wavelength (nm), FWHM (nm).
#: Bands 1-10 are on sensor II, 11-25 on sensor I (003 §3.1).
RIKOLA_BANDS = np.array(
    [
        # band, sensor, gap_nm, wavelength_nm, fwhm_nm
        (1, 2, 337, 506.217, 12.43),
        (2, 2, 603, 519.940, 17.38),
        (3, 2, 628, 535.085, 16.84),
        (4, 2, 653, 550.385, 16.53),
        (5, 2, 678, 565.104, 17.25),
        (6, 2, 703, 580.156, 15.95),
        (7, 2, 722, 591.896, 16.61),
        (8, 2, 750, 608.995, 15.07),
        (9, 2, 768, 620.221, 16.26),
        (10, 2, 782, 628.734, 15.29),
        (11, 1, 814, 650.963, 14.44),
        (12, 1, 498, 659.719, 16.83),
        (13, 1, 509, 669.747, 19.80),
        (14, 1, 519, 679.840, 20.44),
        (15, 1, 530, 690.280, 18.86),
        (16, 1, 541, 700.284, 18.94),
        (17, 1, 551, 710.059, 19.70),
        (18, 1, 561, 720.168, 19.31),
        (19, 1, 571, 729.567, 19.00),
        (20, 1, 583, 740.422, 17.97),
        (21, 1, 593, 750.159, 17.96),
        (22, 1, 613, 769.890, 18.72),
        (23, 1, 625, 780.489, 17.35),
        (24, 1, 635, 790.302, 17.38),
        (25, 1, 666, 819.655, 17.84),
    ],
    dtype=[
        ("band", "i4"),
        ("sensor", "i4"),
        ("gap_nm", "f8"),
        ("wavelength_nm", "f8"),
        ("fwhm_nm", "f8"),
    ],
)
RIKOLA_BANDS.setflags(write=False)

#: 003 Table 3: IOP of band 5 (sensor II) and band 20 (sensor I), value and σ, with the
#: photogrammetric parameterisation (f, x0, y0 in mm; k1-k3 in mm^-2, mm^-4, mm^-6; p1, p2 in
#: mm^-1), which is hsgeo's ``FramePhotogrammetric`` (K1, K2, K3, P1, P2).
RIKOLA_TABLE3 = {
    5: {
        "f_mm": (8.661, 0.003),
        "x0_mm": (0.003, 0.004),
        "y0_mm": (-0.279, 0.003),
        "K1_per_mm2": (-4.14e-3, 9.09e-5),
        "K2_per_mm4": (-2.05e-6, 2.06e-5),
        "K3_per_mm6": (-6.35e-7, 1.45e-6),
        "P1_per_mm": (2.32e-5, 7.98e-6),
        "P2_per_mm": (3.09e-5, 1.02e-5),
    },
    20: {
        "f_mm": (8.707, 0.003),
        "x0_mm": (-0.044, 0.004),
        "y0_mm": (-0.305, 0.002),
        "K1_per_mm2": (-4.61e-3, 8.36e-5),
        "K2_per_mm4": (3.29e-6, 1.88e-5),
        "K3_per_mm6": (-1.95e-7, 1.31e-6),
        "P1_per_mm": (3.66e-5, 7.22e-6),
        "P2_per_mm": (1.10e-5, 9.99e-5),
    },
}

#: 003 Table 3: a-posteriori variance of unit weight (a-priori 1).
RIKOLA_TABLE3_SIGMA0_SQ = {5: 0.035, 20: 0.030}

#: 003 Table 4 (first): relative orientation between the sensors for ten pairs of bands
#: (dω, dφ, dκ in degrees); the paper's "Min"/"Max" rows are the smallest and largest |value|.
RIKOLA_TABLE4_ROP_DEG = np.array(
    [
        (-0.16552, 0.152352, 0.014667),
        (-0.08118, 0.187758, -0.00698),
        (-0.06986, 0.158446, -0.00671),
        (-0.06754, 0.194756, -0.01079),
        (-0.03576, 0.088987, -0.01057),
        (-0.06284, 0.144537, -0.01336),
        (-0.08299, 0.211213, -0.01205),
        (-0.10068, 0.178419, -0.01015),
        (-0.09576, 0.219952, -0.01203),
        (-0.08946, 0.201233, -0.00671),
    ]
)
RIKOLA_TABLE4_ROP_DEG.setflags(write=False)
#: 003 Table 4 (first), "Average" row: (dω, dφ, dκ) in degrees.
RIKOLA_TABLE4_ROP_MEAN_DEG = (-0.08516, 0.173765, -0.00747)

#: 003 Table 4 (second): f = a·gap + b per sensor (003 eq. (2)), value and σ, and R² in %.
RIKOLA_TABLE4_GAP_MODEL = {
    1: {"a_mm_per_nm": (8.4e-5, 2e-5), "b_mm": (8.6633, 1e-2), "r2_percent": 54.4},
    2: {"a_mm_per_nm": (2.9e-5, 2e-5), "b_mm": (8.6460, 1e-2), "r2_percent": 23.3},
}

__all__ += ["RIKOLA_TABLE4_ROP_MEAN_DEG"]


def band_table():
    """003 Table 2 as a pandas DataFrame indexed by band."""
    import pandas as pd

    return pd.DataFrame(RIKOLA_BANDS).set_index("band")


#: 003 §3.4, transformation test: mean discrepancy (columns, rows) in px between the sensor-II
#: and sensor-I coordinates before the transformation, and after it with the best ROP set.
RIKOLA_ROP_TEST_PX = {"before": (-6.8, 5.4), "after_best": (0.99, 0.91)}

#: 003 §3.5 (Fig. 8-9): differences of the radial effect at the image corner below 1 px; largest
#: decentering effect 1/5 px, 1/3 px at the sensor transition (bands 10-11).
RIKOLA_FIG8_MAX_DIFF_PX = 1.0
RIKOLA_FIG9_MAX_DECENTERING_PX = (1 / 5, 1 / 3)

__all__ += ["RIKOLA_ROP_TEST_PX", "RIKOLA_FIG8_MAX_DIFF_PX", "RIKOLA_FIG9_MAX_DECENTERING_PX"]


# ---- 002 (pushbroom bundle adjustment of LP image lines)
#: Column order of 002 Tables 1-3: Min, Max, Median, Mean, STD, NMAD.
P002_STATS = ("min", "max", "median", "mean", "std", "nmad")

#: 002 Tables 1-3 (Table 1 in px, Tables 2-3 in m, columns :data:`P002_STATS`), the Fig. 8
#: caption, §4 and §5, as printed.
P002 = {
    # 002 Table 1: reprojection errors of the 113758 tie points, with the four GCPs (px)
    "002 Table 1": {
        "x": (-1.87, 1.82, 0.00, 0.00, 0.37, 0.32),  # 002 Table 1, row x
        "y": (-2.64, 2.62, 0.02, 0.00, 0.48, 0.42),
    },  # 002 Table 1, row y
    # 002 Table 2: errors of the 13 check points, with the four GCPs (m)
    "002 Table 2": {
        "e": (-0.13, 0.14, 0.04, 0.03, 0.07, 0.08),  # 002 Table 2, row E
        "n": (-0.05, 0.12, 0.03, 0.03, 0.04, 0.03),  # 002 Table 2, row N
        "h": (-1.61, 0.41, -0.78, -0.78, 0.66, 0.99),
    },  # 002 Table 2, row H
    # 002 Table 3: errors of the 13 check points, without GCPs (m)
    "002 Table 3": {
        "e": (-0.13, 0.14, 0.05, 0.04, 0.07, 0.08),  # 002 Table 3, row E
        "n": (-0.04, 0.13, 0.04, 0.04, 0.04, 0.03),  # 002 Table 3, row N
        "h": (-1.93, 0.04, -1.18, -1.13, 0.66, 0.95),
    },  # 002 Table 3, row H
    "fig8_max_abs_diff_um": 11.8,  # 002 Fig. 8 caption: "differences are ≤ 11.8 µm"
    "fig8_sigma_um": (1.2, 2.4),  # 002 Fig. 8 caption: "precision estimates of 1.2–2.4 µm"
    "fig9_pixel_m": 0.30,  # 002 Fig. 9 caption: orthoimages "with a pixel size of 30 cm"
    "fig9_dsm_m": 0.20,  # 002 §5.1: orthoimages "created using a 20 cm digital surface model"
    "fig9_agl_m": 1875.0,  # 002 Fig. 9 caption: "the acquisition at 1875 m AGL"
    "chromatic_shift_px": 0.27,  # 002 §5: "maximum absolute shift ≤ 0.27 pixels"
    "n_unknowns": 342407,  # 002 §4: "A total of 342407 unknowns"
    "n_observations_2d": 441587,  # 002 §4: "441 587 2D observations"
    # 002 §4: observation retrieval from LP image scenes (§3.1)
    "scene_lines": 200,  # 002 §4: "created from sequences of 200 LP image lines"
    "dx_rms_px": 0.91,  # 002 §4: "|δx| with root mean square (RMS) of 0.91 pixels"
    "dx_max_px": 4.43,  # 002 §4: "and a maximum of 4.43 pixels"
    "observations_by_scene_lines": {  # 002 §4: 2D observations from scenes of 100/200/300 lines
        100: 352431,  # 002 §4: "100 and 300 LP image lines ... 352 431 and 385 166"
        200: 441587,  # 002 §4: "441 587 2D observations"
        300: 385166,
    },
    "min_ransac_correspondences": 11,  # 002 §3.1: "at least 11 key-point correspondences"
    "n_tie_points": 113758,  # 002 §4: "113758 used tie points"
    "gsd_m": (0.3, 0.4),  # 002 §4: "ground sampling distances of 0.3 and 0.4 m"
}

__all__ += ["P002_STATS", "P002"]

#: 002 §4 and Fig. 8: the aerial campaign's flight, camera and a-priori σ, as printed; the
#: simulated campaign's defaults (:class:`hsgeo.simulate.pushbroom_campaign_types.CampaignConfig`).
P002_CAMPAIGN = {
    "pixels_per_line": 1800,  # 002 §4: HySpex VNIR-1800, 1800 px
    "pixel_mm": 0.0065,  # 002 §4: 6.5 µm
    "c_nominal_mm": 40.0,  # 002 §4: initial principal distance 4 cm
    "c_mean_mm": 40.3,  # 002 Fig. 8: mean of the estimated principal distances
    "speed_m_s": 67.0,  # 002 §4
    "line_rate_hz": 200.0,  # 002 §4: 200 lines ≈ 1 s
    "area_m": 600.0,  # 002 §4: 600 m × 600 m
    "agl_low_m": 1875.0,  # 002 §4: 8 flight lines at 1875 m AGL
    "agl_high_m": 2500.0,  # 002 §4: 4 flight lines at 2500 m AGL
    "node_interval_s": 10.0,  # 002 §4: trajectory correction nodes every 10 s
    # 002 §4: "a positional STD of < 1.3 cm in each of east and north, and < 2.0 cm in height"
    "sigma_pos_m": (0.013, 0.013, 0.020),
    "sigma_obs_px": 0.5,  # 002 §4: observation precision 1/2 px
    "sigma_gcp_m": 0.01,  # 002 §4: RTK ≈ 1 cm
}

__all__ += ["P002_CAMPAIGN"]


# ---- claims of the chapters still to be written (the scoreboard lists them as planned) ----

#: 001 Table 3: GSD along the line sensor (GSDv), mm: the theoretical value for binning factor 1
#: ((1.7 m × 0.333)/1170, 001 §3) and the values determined from the bar-target profiles at the
#: spectral lines 100, 500, 700 and 1000 px.
GSD_001_TABLE3_MM = {"theoretical": 0.48, "actual": {100: 0.58, 500: 0.58, 700: 0.51, 1000: 0.51}}

#: 001 §2.3, §3.1, §4: the sharpness (MTF) experiment: the bar target (pair widths from the
#: widest to the narrowest, shrinking by 2^(1/6), §2.3), the distance and the field ratio of the
#: theoretical GSD ((1.7 m × 0.333)/1170, §3.1), and the statements of §3.1 and §4 on the MTF
#: curves (Fig. 9): "falls almost linearly from an initial value of 0.7 to 0.1, with a
#: borderline frequency of around 0.3 cy/px for blue, and to 0.6 cy/px for near infrared".
P001_MTF = {
    "widest_pair_mm": 20.88,  # 001 §2.3
    "narrowest_pair_mm": 0.92,  # 001 §2.3
    "pair_ratio": 2 ** (1 / 6),  # 001 §2.3 "increase factor ... 2^(1/6)"
    "distance_m": 1.7,  # 001 §3.1
    "fov_ratio": 0.333,  # 001 §3.1 "(1.7 m × 0.333)/1170"
    "mtf_initial": 0.7,  # 001 §3.1, §4 (Fig. 9)
    "mtf_final": 0.1,  # 001 §3.1, §4 (Fig. 9): the "borderline" level
    "borderline_blue_cy_px": 0.3,  # 001 §4 (Fig. 9, line 100)
    "borderline_nir_cy_px": 0.6,  # 001 §4 (Fig. 9, line 1000)
    "source": "001 §2.3, §3.1, §4, Table 3, Fig. 9",
}
__all__ += ["P001_MTF", "GSD_001_TABLE3_MM"]

#: 004: the flights over the runway, as printed; the simulated scene's defaults
#: (:class:`hsgeo.simulate.asf_runway.RunwayScene`).
ASF_004_FLIGHT = {
    "height_m": 300.0,  # 004: "ground resolution at a flight height of 300 m"
    "sun_zenith_deg": 40.0,  # 004: "The sun angle of i = 40°"
    "reflectance_variation": 0.10,  # 004: "deviations of up to 20 %" (±10 %)
}
__all__ += ["ASF_004_FLIGHT"]

#: 004 (abstract and text): the DAEDALUS AADS 1268's numbers: (value, unit).
ASF_004 = {
    "ASF variation, largest channel": (15.0, "%"),  # abstract: "variations up to 15 %"
    "lab ASF max-min, channels 2-9": (5.0, "%"),  # 1994 integrating sphere, "about 5 %"
    "lab ASF max-min, channel 1": (20.0, "%"),  # "almost 20 % for channel 1"
    "angular pixel size": (0.12, "deg"),  # 2 · 43° / 716
    "nadir GSD at 300 m": (0.7, "m"),  # "about 0.7 m for nadir"
    "runway width": (50.0, "px"),  # "about 50 pixels"
    "registration accuracy": (1.0, "px"),  # "estimated to be about one pixel"
}


# ---- 001 §2.1, §2.4, §3.2: building the hyperspectral cube (the `cube` chapter) ----

#: The acquisition of the vineyard survey and the frame layout per binning factor, as printed.
P001_CUBE = {
    "n_reflected_columns": {1: 1170, 2: 585},  # 001 §2.1 "1170 × 1024 or 585 × 512 pixels"
    "n_incident_columns": {1: 110, 2: 55},  # 001 §2.1 "110 × 512 or 55 × 512 pixels"
    "frame_rate_hz": {1: 12.5, 2: 24.0},  # 001 §2.1 / Table 1 "12.5 fps ... 24 fps"
    "swath_per_height": 0.333,  # 001 §2.1 "a narrow strip measuring (0.333 × h) × (0.00208 × h)"
    "slit_per_height": 0.00208,  # 001 §2.1
    "spectral_resolution_nm": 4.4,  # 001 §2.1 "a spectral resolution of 4.4 nm for 95 channels"
    "n_channels": 95,  # 001 §2.1
    "binning": 2,  # 001 §3.2 "The HSLS V9 was used with binning factor 2"
    "gain": 1.0,  # 001 §3.2 "a default gain value of 1"
    "height_m": 2.5,  # 001 §3.2 "the tops of the vines (top leaves) were about 2.5 m from the lens"
    "gsd_v_mm": 1.4,  # 001 §3.2 "GSDv ≈ 1.4 mm" (binning 2, along the line sensor)
    "gsd_h_mm": 5.2,  # 001 §3.2 "GSDh across the line sensor was 5.2 mm"
    "exposure_s": 0.042,  # 001 §3.2 "the exposition time was 0.042 s"
    "speed_mm_s": 33.0,  # 001 §3.2 "calculated according to (8) at 33 mm/s"
    "section_length_m": 2.4,  # 001 §3.2 "in two sections, each 2.4 m long"
    "n_vegetation_indices": 16,  # 001 §3.2 "16 selected vegetation indices"
    "source": "001 §2.1, Table 1, §3.2",
}

__all__ += ["P001_CUBE"]
