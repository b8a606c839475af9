"""Geocoding of GCP observations of a flight line (000 Tables 2–3).

:func:`gcp_deviations` geocodes GCP observations after a GCP calibration of the boresight (as
PARGE does). The orthorectification of whole lines is :mod:`hsgeo.workflows.orthorectify`
(``hsgeo orthorectify``).
"""

from __future__ import annotations

import numpy as np

from hsgeo.geocode import PlaneTerrain, geocode_observations
from hsgeo.sensors.line import LineGeometry, calibrate_boresight

__all__ = ["gcp_deviations"]


def gcp_deviations(
    nav,
    sensor: LineGeometry,
    line,
    zeta_px,
    gcp_enu_m,
    *,
    height_m: float,
    t0_s: float,
    line_rate_hz: float,
    sigma_m: float = 0.3,
):
    """GCP deviations (geocoded − surveyed) after a GCP calibration of the boresight.

    The boresight is calibrated on the GCPs (:func:`hsgeo.geocode.calibrate_boresight`, the
    "GCP-calibrated auxiliary data" of PARGE), then every GCP observation is geocoded onto the
    plane ``height_m`` with it.

    Parameters
    ----------
    nav : Trajectory
        The recorded navigation.
    sensor : LineGeometry
        The assumed sensor model (nominal or calibrated).
    line : (n,) array_like
        Measured (fractional) line of each GCP.
    zeta_px : (n,) array_like
        Measured pixel of each GCP, px.
    gcp_enu_m : (n, 3) array_like
        Surveyed GCP coordinates, E, N, U in m.
    height_m : float
        Height of the flat terrain, m.
    t0_s, line_rate_hz : float
        Time of line 0 (s) and the line rate (Hz).
    sigma_m : float
        A-priori σ of a GCP's horizontal position in the boresight calibration, m.

    Returns
    -------
    dev_EN_m : (n, 2) ndarray
        Geocoded minus surveyed E, N, m (000 Tables 2–3: Δy, Δx).
    result : AdjustmentResult
        The boresight calibration.

    References
    ----------
    .. [1] Miljković, V., Gajski, D. and Vela, E. (2017). Spatial calibration of the hyperspectral
           line scanner by the bundle block adjusting method. Geodetski list 2, 127–142 (paper 000).
    """
    gcp_enu_m = np.asarray(gcp_enu_m, dtype=float)
    kw = {"t0_s": t0_s, "line_rate_hz": line_rate_hz}
    res = calibrate_boresight(
        nav, sensor, line, zeta_px, gcp_enu_m, height_m=height_m, sigma_m=sigma_m, **kw
    )
    X = geocode_observations(
        nav,
        sensor,
        line,
        zeta_px,
        terrain=PlaneTerrain(height_m),
        boresight_rad=res.value("boresight"),
        **kw,
    )
    return X[:, :2] - gcp_enu_m[:, :2], res
