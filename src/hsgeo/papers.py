"""The source papers' published values as data, each row citing its table.

Numbers are copied from the papers' text files in ``/work/shared/papers/`` (see their README);
``source`` names the file, table and row. Nothing here is computed.

References
----------
000: Miljković, Gajski, Vela (2017). Spatial calibration of the hyperspectral line scanner by the
bundle block adjusting method. Geodetski list 2017/2.
001: Krtalić, Miljković, Gajski, Racetin (2019). Spatial distortion assessments of a low-cost
laboratory and field hyperspectral imaging system. Sensors 19(19), 4267.
"""

from __future__ import annotations

from dataclasses import dataclass

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
    None, 870.0, 486.8, 0.1, 3539.0, 14.0, 1.459, -0.1636, 0.00526,
    "000 Table 1, row 'calibrated'",
)
#: 000 Table 1, row "uncalibrated": the nominal values (x0 = 485 px, c = 3600 px).
P000_TABLE1_UNCALIBRATED = LineIOP(
    None, 870.0, 485.0, None, 3600.0, None, None, None, None,
    "000 Table 1, row 'uncalibrated'",
)

#: 001 Table 2: inner orientation per spectral line (rows 100, 300, 500, 1000 from the top).
P001_TABLE2 = (
    LineIOP(100, None, 499.9, 0.1, 3614.0, 14.0, 0.660, -0.080, 0.0024, "001 Table 2, line 100"),
    LineIOP(300, None, 497.5, 0.1, 3605.0, 14.0, 0.695, -0.085, 0.0027, "001 Table 2, line 300"),
    LineIOP(500, None, 494.7, 0.1, 3569.0, 14.0, 0.710, -0.084, 0.0027, "001 Table 2, line 500"),
    LineIOP(1000, None, 486.8, 0.1, 3539.0, 14.0, 1.459, -0.164, 0.0053,
            "001 Table 2, line 1000"),
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
    "distortion_450px_line1000_px": (25.0, "001 §3.1: 'rises drastically ... above 25' (NIR, at "
                                           "the line's edge, 450 px from the centre)"),
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
        "sum_dy_m": (-1.95, 2), "sum_dx_m": (0.25, 2), "sum_vyvy_m2": (6.98, 2),
        "sum_vxvx_m2": (3.84, 2), "bias_y_m": (-0.2, 1), "bias_x_m": (0.0, 1),
        "sigma_y_m": (0.88, 2), "sigma_x_m": (0.65, 2),
    },
    "000 Table 3": {
        "sum_dy_m": (-0.20, 2), "sum_dx_m": (0.34, 2), "sum_vyvy_m2": (1.49, 2),
        "sum_vxvx_m2": (0.75, 2), "bias_y_m": (-0.02, 2), "bias_x_m": (0.03, 2),
        "sigma_y_m": (0.40, 2), "sigma_x_m": (0.29, 2),
    },
}
