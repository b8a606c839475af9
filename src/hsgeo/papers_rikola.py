"""Paper 003 (Tommaselli et al., the Rikola FPI camera): its published tables as data.

Every value cites its table. The lead merges this module into :mod:`hsgeo.papers`.

References
----------
Tommaselli, A. M. G., Santos, L. D., Berveglieri, A., Oliveira, R. A., Honkavaara, E.: A study on
the variations of inner orientation parameters of a hyperspectral frame camera. ISPRS Archives
(paper 003 in ``/work/shared/papers``).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "RIKOLA_CAMERA",
    "RIKOLA_BANDS",
    "RIKOLA_TABLE3",
    "RIKOLA_TABLE3_SIGMA0_SQ",
    "RIKOLA_TABLE4_ROP_DEG",
    "RIKOLA_TABLE4_GAP_MODEL",
    "band_table",
]

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
    dtype=[("band", "i4"), ("sensor", "i4"), ("gap_nm", "f8"), ("wavelength_nm", "f8"),
           ("fwhm_nm", "f8")],
)

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
