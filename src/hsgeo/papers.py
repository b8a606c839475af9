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
