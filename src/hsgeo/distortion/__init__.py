"""Lens-distortion models, each with matching forward, inverse and Jacobian.

One implementation per equation; the sensor models call these (or, in compiled kernels, the
same scalar core in :mod:`hsgeo._kernels`). Four forms are provided; all take arbitrary leading
batch dimensions ``...``.

1. **Odd radial series in one dimension** for line scanners (000 eq. (2)):
   ``δ(d) = K1 u³ + K2 u⁵ + K3 u⁷ + …``, ``u = d / norm`` — :func:`odd_radial_1d`,
   :func:`odd_radial_1d_jacobian`, :func:`ideal_from_measured_1d` (undistort, ``d − δ(d)``),
   :func:`measured_from_ideal_1d` (distort: 000 eq. (2) is implicit in the measured ``d``).
2. **OpenCV form**: distortion *applied* to normalised ideal coordinates
   (``x = X/Z``, ``y = Y/Z``), coefficients ``(k1, k2, p1, p2, k3)`` in OpenCV order —
   :func:`distort_opencv`, :func:`undistort_opencv`, :func:`distort_opencv_jacobian`.
3. **Photogrammetric form** (Brown 1971, Fraser 1997; 003 Table 3): a *correction* computed
   from measured, principal-point-reduced image coordinates in mm, added to obtain the ideal
   coordinates — :func:`brown_correction`, :func:`brown_correction_jacobian`,
   :func:`ideal_from_measured_mm`, :func:`measured_from_ideal_mm`.
4. **Pushbroom line form** (002 eq. (3)): ``x = x̄ + K1 x̄³ + K2 x̄⁵ + 3 P1 x̄²``,
   ``y = ȳ + P2 x̄²`` at the ideal coordinates in mm — :func:`distort_pushbroom_line`,
   :func:`distort_pushbroom_line_jacobian`, :func:`undistort_pushbroom_line`.

The two 2D forms are not the same parameterisation:

* direction: OpenCV maps ideal → distorted, the photogrammetric form maps measured
  (distorted) → ideal, so the coefficients have opposite signs to first order;
* units: OpenCV coefficients are dimensionless (normalised coordinates), Brown's K_i are in
  mm^(−2i) and P_i in mm⁻¹ (to first order ``K1 ≈ −k1 / c_mm²``, ``P1 ≈ −p2 / c_mm``);
* roles: Brown's ``P1`` multiplies ``(r² + 2x̄²)`` in δx, which is OpenCV's ``p2`` term;
  Brown's ``P2`` is OpenCV's ``p1``.

References
----------
.. [1] Brown, D. C. (1971). Close-range camera calibration. Photogrammetric Engineering 37(8).
.. [2] Fraser, C. S. (1997). Digital camera self-calibration. ISPRS J. Photogramm. Remote
   Sens. 52(4), 149-159.
.. [3] Miljković, Gajski, Vela (2017). Spatial calibration of the hyperspectral line scanner
   by the bundle block adjusting method. Geodetski list 2017/2, eq. (2) (paper 000).
.. [4] Tommaselli et al. A study on the variations of inner orientation parameters of a
   hyperspectral frame camera. ISPRS Archives, Table 3 (paper 003).
.. [5] Jonassen et al. (2024), eq. (3) (paper 002).

The models live one per module (GUIDE §2: ``distortion/`` with one file per model):
:mod:`~hsgeo.distortion.odd_radial`, :mod:`~hsgeo.distortion.opencv`,
:mod:`~hsgeo.distortion.photogrammetric`, :mod:`~hsgeo.distortion.pushbroom_line`; every name
is importable from ``hsgeo.distortion`` as before.
"""

from hsgeo.distortion.odd_radial import (
    _measured_from_ideal_1d as _measured_from_ideal_1d,  # for hsgeo.sensors.line1d
)
from hsgeo.distortion.odd_radial import (
    ideal_from_measured_1d,
    measured_from_ideal_1d,
    odd_radial_1d,
    odd_radial_1d_jacobian,
)
from hsgeo.distortion.opencv import distort_opencv, distort_opencv_jacobian, undistort_opencv
from hsgeo.distortion.photogrammetric import (
    brown_correction,
    brown_correction_jacobian,
    ideal_from_measured_mm,
    measured_from_ideal_mm,
)
from hsgeo.distortion.pushbroom_line import (
    distort_pushbroom_line,
    distort_pushbroom_line_jacobian,
    undistort_pushbroom_line,
)

__all__ = [
    "odd_radial_1d",
    "odd_radial_1d_jacobian",
    "ideal_from_measured_1d",
    "measured_from_ideal_1d",
    "distort_opencv",
    "undistort_opencv",
    "distort_opencv_jacobian",
    "brown_correction",
    "brown_correction_jacobian",
    "ideal_from_measured_mm",
    "measured_from_ideal_mm",
    "distort_pushbroom_line",
    "distort_pushbroom_line_jacobian",
    "undistort_pushbroom_line",
]
