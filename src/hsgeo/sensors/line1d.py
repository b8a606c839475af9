"""The one-dimensional line scanner of 000 eq. (1)–(3): a 1D camera in the plane of its slit.

Geometry
--------
Everything happens in the *scanner plane*, the plane through the projection centre that contains
the slit's fan of rays. A point ``(x, y)`` [m] of that plane, seen from a station ``(x0, y0)`` [m]
whose optical axis makes the angle ``α`` [rad] with the reference ``y`` axis, has the camera
coordinates (000 eq. (2))::

    X = (x − x0) cos α + (y − y0) sin α      (across the optical axis)
    Y = (y − y0) cos α − (x − x0) sin α      (along the optical axis, the depth; Y > 0 in front)

and is imaged at the pixel coordinate ``ζ`` [px] along the spatial axis of the sensor with::

    ζ = ζ0 − c · X / Y + δ(ζ − ζ0),     δ(d) = K1 u³ + K2 u⁵ + K3 u⁷,  u = d / 100 px    (000 eq. 2)

The pixel coordinate has its origin at the centre of the first pixel (column 0); ``ζ0`` is the
principal point and ``c`` the principal distance, both in pixels.

Normalisation of the distortion polynomial
------------------------------------------
The published coefficients (000 Table 1: K1 = 1.459, K2 = −0.1636, K3 = 0.00526; 001 Table 2) give
distortions in **pixels** when the distance from the principal point is expressed in **units of
100 pixels**: ``u = (ζ − ζ0) / 100 px``. This is the only simple normalisation that reproduces the
papers' own statements (:func:`distortion_extremes`): a maximum of 4.0 px for the blue-indigo
line (001 §4: "ranges from 4 px for the blue-indigo"), at most 10.6 px in the visible (001 §3.1:
"0 to 11 for the visible part"), 28.4 px at 450 px from the centre for the near infrared (001 §3.1:
"above 25"), and 7 px at 200 px (000 §4.1: "significant values from the 200th pixel away"). With
``u`` in pixels the polynomial would reach 10¹⁷ px; in millimetres (6.7 µm pixels) 11 px in the
near infrared.

The measured coordinate inside δ
--------------------------------
The distortion term depends on the measured coordinate itself, so eq. (2) is *implicit* in ζ.
We solve it: :func:`project` finds ζ by Newton's method on
``F(ζ) = ζ − δ(ζ − ζ0) − ζ0 + c·X/Y = 0`` (``F' = 1 − δ'/100 px`` stays in [0.39, 1.05] inside
450 px for every published line) and the residual is ``ζ(θ) − ζ_observed``. Its Jacobian follows
from the implicit-function theorem, ``∂ζ/∂θ = −(∂F/∂θ) / F'``. This keeps the observation
equation in the space where the noise lives (the measured pixel), so the a-priori σ of a
measured minimum is the σ of the residual and σ0 keeps its meaning. Evaluating δ at the
observation instead (the explicit form) gives residuals ``F(ζ_obs)`` that are the implicit ones
multiplied by ``F'`` — down to 0.4 at the near-infrared edge — so with equal weights the edge
observations would be down-weighted by up to a factor 6 and σ0 would mix two scales; the two
forms agree only after reweighting by ``F'`` (a Gauss–Helmert model), which the implicit form
does exactly. (``tests/test_line1d.py`` checks this relation.)

Identifiability
---------------
A 1D camera that sees collinear object points cannot separate ``c`` (and, without distortion,
``ζ0``) from its exterior orientation: the map from the pattern line to the sensor line is a 1D
projective map with 3 degrees of freedom, which each view's ``x0, y0, α`` already have. See
:func:`identifiability_report` and the ``line-calibration`` chapter; the remedy used there is a
few control points standing off the pattern line (side signals on posts) or priors on the
station positions.

References
----------
Miljković, Gajski, Vela (2017), Geodetski list 2017/2, §4, eq. (1)–(3), Table 1 (paper 000).
Krtalić, Miljković, Gajski, Racetin (2019), Sensors 19(19) 4267, §2.3, §3.1, Table 2 (paper 001).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hsgeo.adjust import Indexed, Parameters, ResidualBlock
from hsgeo.distortion import _measured_from_ideal_1d, odd_radial_1d, odd_radial_1d_jacobian
from hsgeo.errors import ConvergenceError, InputError, ObservationError
from hsgeo.validate import finite_array

__all__ = [
    "DISTORTION_NORM_PX",
    "EOP_COLUMNS",
    "distortion_px",
    "distortion_derivative",
    "distortion_extremes",
    "tan_from_zeta",
    "zeta_from_tan",
    "camera_xy",
    "project",
    "LineObservations",
    "check_minimum_observations",
    "make_parameters",
    "resect",
    "Resection",
]

#: The unit of (ζ − ζ0) in the distortion polynomial: 100 px (see the module docstring).
DISTORTION_NORM_PX = 100.0
#: Columns of the per-image exterior orientation block.
EOP_COLUMNS = ("x0_m", "y0_m", "alpha_rad")


_finite = finite_array  # the boundary check shared by every module


def _K3(K: ArrayLike) -> NDArray[np.float64]:
    K = _finite(K, "K")
    if K.shape != (3,):
        raise InputError(f"K must be (K1, K2, K3), three numbers, got shape {K.shape}")
    return K


# ------------------------------------------------------------------------- distortion (000 eq. 2)
def distortion_px(
    zeta_px: ArrayLike, zeta0_px: float, K: ArrayLike, norm_px: float = DISTORTION_NORM_PX
) -> NDArray:
    """Radial distortion δ [px] at the pixel coordinate ζ (000 eq. (2)).

    ``δ = K1 u³ + K2 u⁵ + K3 u⁷`` with ``u = (ζ − ζ0) / norm_px``.

    Parameters
    ----------
    zeta_px : (...) array_like, px
    zeta0_px : float, px
        Principal point.
    K : (3,) array_like
        K1, K2, K3 in px per unit of ``u`` to the 3rd, 5th, 7th power.
    norm_px : float
        Unit of ``u`` (100 px reproduces the published statements, see the module docstring).

    References
    ----------
    .. [1] Miljković, V., Gajski, D. and Vela, E. (2017). Spatial calibration of the hyperspectral
           line scanner by the bundle block adjusting method. Geodetski list 2, 127–142 (paper 000).

    Examples
    --------
    >>> round(float(distortion_px(486.8 + 450, 486.8, [1.459, -0.164, 0.0053])), 2)
    28.37
    """
    d = _finite(zeta_px, "zeta_px") - float(zeta0_px)
    return odd_radial_1d(d, _K3(K), norm_px)  # 000 eq. (2)


def distortion_derivative(
    zeta_px: ArrayLike, zeta0_px: float, K: ArrayLike, norm_px: float = DISTORTION_NORM_PX
) -> NDArray:
    """dδ/dζ (dimensionless) of :func:`distortion_px`."""
    d = _finite(zeta_px, "zeta_px") - float(zeta0_px)
    return odd_radial_1d_jacobian(d, _K3(K), norm_px)[0]  # 000 eq. (2)


def distortion_extremes(
    K: ArrayLike, r_max_px: float = 450.0, n: int = 4501, norm_px: float = DISTORTION_NORM_PX
) -> tuple[float, float, float]:
    """Largest |δ| within ``|ζ − ζ0| ≤ r_max_px``, where it occurs, and δ at ``r_max_px``.

    Returns
    -------
    max_abs_px, at_px, at_rmax_px : float
    """
    d = np.linspace(0.0, float(r_max_px), int(n))
    delta = distortion_px(d, 0.0, K, norm_px)
    i = int(np.argmax(np.abs(delta)))
    return float(abs(delta[i])), float(d[i]), float(delta[-1])


# ------------------------------------------------------------------- ζ  ↔  tangent of view angle
def tan_from_zeta(
    zeta_px: ArrayLike,
    zeta0_px: float,
    c_px: float,
    K: ArrayLike,
    norm_px: float = DISTORTION_NORM_PX,
) -> NDArray:
    """Tangent of the view angle in the scanner plane of the pixel coordinate ζ (distortion
    included).

    ``tan θ = X / Y = −(ζ − δ(ζ − ζ0) − ζ0) / c`` (000 eq. (2) solved for the ray): θ is measured
    from the optical axis, positive towards the camera's +X axis (see the module docstring), so a
    ray with direction ``(X, Y) ∝ (tan θ, 1)`` in camera coordinates.

    Parameters
    ----------
    zeta_px : (...) array_like, px
    zeta0_px, c_px : float, px
    K : (3,) array_like

    Returns
    -------
    tan_theta : (...) ndarray

    References
    ----------
    .. [1] Miljković, V., Gajski, D. and Vela, E. (2017). Spatial calibration of the hyperspectral
           line scanner by the bundle block adjusting method. Geodetski list 2, 127–142 (paper 000).
    """
    if not (np.isfinite(c_px) and c_px > 0):
        raise InputError(f"c_px must be a positive number, got {c_px!r}")
    z = _finite(zeta_px, "zeta_px")
    return -(z - distortion_px(z, zeta0_px, K, norm_px) - zeta0_px) / c_px


def _solve_zeta(ideal_px, zeta0_px, K, norm_px):
    """Solve ζ − δ(ζ − ζ0) = ideal for ζ (000 eq. (2)); returns ζ and F' = 1 − δ'.

    :func:`hsgeo.distortion.measured_from_ideal_1d` without its checks (trial steps of an
    adjustment may leave the model's domain; the caller decides).
    """
    t = np.asarray(ideal_px, dtype=float) - zeta0_px  # target of d − δ(d)
    d, Fp = _measured_from_ideal_1d(
        t, np.asarray(K, dtype=float), float(norm_px), max_iter=50, tol=1e-10, max_step=200.0
    )
    return d + zeta0_px, Fp


def zeta_from_tan(
    tan_theta: ArrayLike,
    zeta0_px: float,
    c_px: float,
    K: ArrayLike,
    norm_px: float = DISTORTION_NORM_PX,
    max_abs_px: float = 450.0,
) -> NDArray:
    """Pixel coordinate ζ of a view direction: the inverse of :func:`tan_from_zeta`.

    Solves ``ζ − δ(ζ − ζ0) = ζ0 − c tan θ`` by Newton's method.

    Parameters
    ----------
    tan_theta : (...) array_like
    zeta0_px, c_px : float, px
    K : (3,) array_like
    max_abs_px : float
        The domain of the model, ``|ζ − ζ0| ≤ max_abs_px`` (the published curves end at 450 px;
        beyond it the 7th-order polynomial folds).

    Raises
    ------
    ConvergenceError
        If a direction maps outside the domain or onto the folded part of the polynomial.
    """
    if not (np.isfinite(c_px) and c_px > 0):
        raise InputError(f"c_px must be a positive number, got {c_px!r}")
    t = _finite(tan_theta, "tan_theta")
    K = _K3(K)
    z, Fp = _solve_zeta(zeta0_px - c_px * t, zeta0_px, K, norm_px)
    resid = z - distortion_px(z, zeta0_px, K, norm_px) - (zeta0_px - c_px * t)
    bad = (np.abs(resid) > 1e-6) | (Fp <= 0) | (np.abs(z - zeta0_px) > max_abs_px)
    if np.any(bad):
        raise ConvergenceError(
            f"zeta_from_tan: {int(np.sum(bad))} direction(s) fall outside |ζ − ζ0| ≤ "
            f"{max_abs_px:g} px or on the folded part of the distortion polynomial; restrict the "
            "directions to the calibrated field of view"
        )
    return z


# ------------------------------------------------------------------------------- projection
def camera_xy(xy_m: ArrayLike, eop: ArrayLike) -> tuple[NDArray, NDArray]:
    """Camera coordinates ``X`` (across) and ``Y`` (depth) of points (000 eq. (2)).

    Parameters
    ----------
    xy_m : (n, 2) array_like, m
    eop : (n, 3) or (3,) array_like
        ``x0_m, y0_m, alpha_rad`` for each point (or one station for all).

    References
    ----------
    .. [1] Miljković, V., Gajski, D. and Vela, E. (2017). Spatial calibration of the hyperspectral
           line scanner by the bundle block adjusting method. Geodetski list 2, 127–142 (paper 000).
    """
    xy = np.asarray(xy_m, dtype=float)
    e = np.asarray(eop, dtype=float)
    dx = xy[..., 0] - e[..., 0]
    dy = xy[..., 1] - e[..., 1]
    ca, sa = np.cos(e[..., 2]), np.sin(e[..., 2])
    return dx * ca + dy * sa, dy * ca - dx * sa


def project(
    xy_m: ArrayLike,
    eop: ArrayLike,
    zeta0_px: float,
    c_px: float,
    K: ArrayLike,
    norm_px: float = DISTORTION_NORM_PX,
) -> NDArray:
    """Pixel coordinates ζ of points seen from stations, eq. (2) solved implicitly.

    Parameters
    ----------
    xy_m : (n, 2) array_like, m
        Points in the scanner plane.
    eop : (n, 3) or (3,) array_like
        ``x0_m, y0_m, alpha_rad`` per point, or one station.
    zeta0_px, c_px : float, px
    K : (3,) array_like

    Returns
    -------
    zeta_px : (n,) ndarray

    Raises
    ------
    InputError
        On NaN, or a point behind the camera (depth Y ≤ 0).
    """
    xy = _finite(xy_m, "xy_m")
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise InputError(f"xy_m must have shape (n, 2), got {xy.shape}")
    X, Y = camera_xy(xy, _finite(eop, "eop"))
    if np.any(Y <= 0):
        raise InputError(f"{int(np.sum(Y <= 0))} point(s) lie behind the camera (depth ≤ 0)")
    return _solve_zeta(zeta0_px - c_px * X / Y, zeta0_px, _K3(K), norm_px)[0]


# ------------------------------------------------------------------------ observation equations
class LineObservations(ResidualBlock):
    """Observation equations of measured pixel coordinates ζ (000 eq. (2)–(3)).

    The residual is ``ζ(θ) − ζ_observed`` with ζ(θ) the implicit solution of eq. (2) (see the
    module docstring). Parameter blocks (names configurable):

    * ``eop`` (n_images, 3): ``x0_m, y0_m, alpha_rad`` per image;
    * ``zeta0_px`` (scalar), ``c_px`` (scalar), ``K`` (3,): the inner orientation of one spectral
      line, shared by all images;
    * ``xy_m`` (n_points, 2): object points (a ``points=True`` block: control points fixed or with
      a prior, tie points free).

    Parameters
    ----------
    image : (m,) int array_like
        Image index (row of ``eop``) of each observation.
    point : (m,) int array_like
        Point index (row of ``xy_m``) of each observation.
    zeta_px : (m,) array_like, px
        Measured coordinates.
    sigma_px : float or (m,) array_like, px
        A-priori σ of a measurement.
    blocks : mapping, optional
        Parameter-block names by role (``eop``, ``zeta0``, ``c``, ``K``, ``xy``; defaults
        ``eop``, ``zeta0_px``, ``c_px``, ``K``, ``xy_m``), see
        :class:`~hsgeo.adjust.ResidualBlock`.

    References
    ----------
    .. [1] Miljković, V., Gajski, D. and Vela, E. (2017). Spatial calibration of the hyperspectral
           line scanner by the bundle block adjusting method. Geodetski list 2, 127–142 (paper 000).
    """

    name = "zeta"
    BLOCKS = MappingProxyType(
        {"eop": "eop", "zeta0": "zeta0_px", "c": "c_px", "K": "K", "xy": "xy_m"}
    )

    def __init__(
        self,
        image,
        point,
        zeta_px,
        sigma_px,
        *,
        name: str | None = None,
        blocks: Mapping[str, str] | None = None,
        norm_px: float = DISTORTION_NORM_PX,
    ):
        z = _finite(zeta_px, "zeta_px").ravel()
        img = np.asarray(image)
        pt = np.asarray(point)
        if img.shape != z.shape or pt.shape != z.shape:
            raise InputError(
                f"image {img.shape}, point {pt.shape} and zeta_px {z.shape} must have one entry "
                "per observation"
            )
        if z.size == 0:
            raise ObservationError("no observations of ζ given")
        if not (np.issubdtype(img.dtype, np.integer) and np.issubdtype(pt.dtype, np.integer)):
            raise InputError("image and point must be integer indices")
        if img.min() < 0 or pt.min() < 0:
            raise InputError("image and point indices must be non-negative")
        super().__init__(
            np.broadcast_to(np.asarray(sigma_px, dtype=float), z.shape), name=name, blocks=blocks
        )
        self.image, self.point, self.zeta_px = img.astype(np.int64), pt.astype(np.int64), z
        self.norm_px = float(norm_px)

    def predict(self, values) -> tuple[NDArray, dict]:
        """Model ζ for every observation and the pieces of its Jacobian."""
        n = self.blocks
        eop = np.asarray(values[n["eop"]], dtype=float)
        xy = np.asarray(values[n["xy"]], dtype=float)
        z0 = float(values[n["zeta0"]])
        c = float(values[n["c"]])
        K = np.asarray(values[n["K"]], dtype=float)
        e = eop[self.image]
        p = xy[self.point]
        dx, dy = p[:, 0] - e[:, 0], p[:, 1] - e[:, 1]
        ca, sa = np.cos(e[:, 2]), np.sin(e[:, 2])
        X = dx * ca + dy * sa
        Y = dy * ca - dx * sa
        Y = np.where(np.abs(Y) < 1e-9, 1e-9, Y)  # keep trial steps finite
        q = X / Y
        zeta, Fp = _solve_zeta(z0 - c * q, z0, K, self.norm_px)
        return zeta, {
            "q": q,
            "X": X,
            "Y": Y,
            "ca": ca,
            "sa": sa,
            "Fp": Fp,
            "z0": z0,
            "c": c,
            "K": K,
        }

    def evaluate(self, values, jacobian):
        zeta, w = self.predict(values)
        r = zeta - self.zeta_px
        if not jacobian:
            return r, None
        n = self.blocks
        q, X, Y, ca, sa, Fp, c = w["q"], w["X"], w["Y"], w["ca"], w["sa"], w["Fp"], w["c"]
        dK = odd_radial_1d_jacobian(zeta - w["z0"], w["K"], self.norm_px)[1]  # ∂δ/∂K, 000 eq. (2)
        # ∂q/∂x, ∂q/∂y of the object point; ∂q/∂α = 1 + q²
        dq_dx = (Y * ca + X * sa) / Y**2
        dq_dy = (Y * sa - X * ca) / Y**2
        g = -c / Fp  # ∂ζ/∂q
        m = r.size
        J_eop = np.stack([-g * dq_dx, -g * dq_dy, g * (1.0 + q * q)], axis=1)
        J = {
            n["eop"]: Indexed(self.image, J_eop),
            n["zeta0"]: np.ones((m, 1)),  # ζ − ζ0 depends on c·q and K only
            n["c"]: (-q / Fp)[:, None],
            n["K"]: dK / Fp[:, None],
            n["xy"]: Indexed(self.point, np.stack([g * dq_dx, g * dq_dy], axis=1)),
        }
        return r, J


# ---------------------------------------------------------------------------- design checks
def check_minimum_observations(image, point, control, n_images: int | None = None) -> None:
    """The minimum-observation rule of 000 §4.1, raising :class:`~hsgeo.ObservationError`.

    * at least three control-point observations per image (for its ``x0, y0, α``);
    * at least five observations beyond those (for ``ζ0, c, K1, K2, K3``): in all,
      ``m ≥ 3·n_images + 5`` observations.

    Parameters
    ----------
    image, point : (m,) int array_like
        Image and point index of every observation.
    control : (n_points,) bool array_like
        Which points are control points (known coordinates).
    n_images : int, optional
        Number of images (default: ``max(image) + 1``).

    References
    ----------
    .. [1] Miljković, V., Gajski, D. and Vela, E. (2017). Spatial calibration of the hyperspectral
           line scanner by the bundle block adjusting method. Geodetski list 2, 127–142 (paper 000).
    """
    img = np.asarray(image, dtype=np.int64)
    pt = np.asarray(point, dtype=np.int64)
    ctrl = np.asarray(control, dtype=bool)
    if img.size != pt.size:
        raise InputError("image and point must have one entry per observation")
    n_img = int(img.max()) + 1 if n_images is None else int(n_images)
    for i in range(n_img):
        sel = img == i
        n_ctrl = int(np.unique(pt[sel][ctrl[pt[sel]]]).size)
        if n_ctrl < 3:
            raise ObservationError(
                f"image {i} observes {n_ctrl} control point(s); the line-scanner model needs at "
                "least 3 per image for its x0, y0, α (000 §4.1): measure more control points in "
                "that image or drop it"
            )
    need = 3 * n_img + 5
    if img.size < need:
        raise ObservationError(
            f"{img.size} observations for {n_img} image(s): the line-scanner model needs at least "
            f"3 per image plus 5 for ζ0, c, K1, K2, K3, i.e. {need} (000 §4.1); add observations "
            "or images"
        )


def make_parameters(
    eop,
    zeta0_px: float,
    c_px: float,
    K,
    xy_m,
    control,
    *,
    xy_sigma_m=None,
    eop_prior_sigma=None,
    eop_prior_mean=None,
    image_ids=None,
    point_ids=None,
) -> Parameters:
    """The parameter blocks of a 1D calibration (names as :class:`LineObservations` expects).

    Parameters
    ----------
    eop : (n_images, 3) array_like
        Initial ``x0_m, y0_m, alpha_rad``.
    zeta0_px, c_px : float
    K : (3,) array_like
    xy_m : (n_points, 2) array_like
        Object points (initial values for tie points).
    control : (n_points,) bool array_like
        Control points are fixed at ``xy_m`` unless ``xy_sigma_m`` gives them a prior.
    xy_sigma_m : (n_points,) or (n_points, 2) array_like, optional
        Prior σ of control points (``inf``: none); with it the control points are free with that
        prior instead of fixed.
    eop_prior_sigma, eop_prior_mean : (n_images, 3) array_like, optional
        Priors on the exterior orientation (e.g. measured bench positions); ``inf``: none.
    """
    eop = _finite(eop, "eop")
    if eop.ndim != 2 or eop.shape[1] != 3:
        raise InputError(f"eop must have shape (n_images, 3), got {eop.shape}")
    xy = _finite(xy_m, "xy_m")
    ctrl = np.asarray(control, dtype=bool)
    p = Parameters()
    p.add(
        "eop",
        eop,
        columns=EOP_COLUMNS,
        rows=image_ids,
        prior_sigma=eop_prior_sigma,
        prior_mean=eop_prior_mean,
    )
    p.add("zeta0_px", float(zeta0_px))
    p.add("c_px", float(c_px))
    p.add("K", _K3(K), columns=("K1", "K2", "K3"))
    if xy_sigma_m is None:
        free = np.repeat(~ctrl[:, None], 2, axis=1)
        p.add("xy_m", xy, points=True, free=free, columns=("x_m", "y_m"), rows=point_ids)
    else:
        s = np.broadcast_to(np.asarray(xy_sigma_m, dtype=float).reshape(len(xy), -1), xy.shape)
        s = np.where(ctrl[:, None], s, np.inf)
        p.add("xy_m", xy, points=True, columns=("x_m", "y_m"), rows=point_ids, prior_sigma=s)
    return p


@dataclass
class Resection:
    """Exterior orientation of one image from its control points (see :func:`resect`)."""

    eop: NDArray  # (3,)
    rms_px: float


def resect(
    xy_m: ArrayLike,
    zeta_px: ArrayLike,
    zeta0_px: float,
    c_px: float,
    K=(0.0, 0.0, 0.0),
    n_alpha: int = 720,
) -> Resection:
    """Initial ``x0, y0, α`` of one image from ≥ 3 control points, for given inner orientation.

    For a trial α, each measured ray ``tan θ_j`` gives a condition linear in the station:
    ``(x_j − x0)(cos α + t_j sin α) + (y_j − y0)(sin α − t_j cos α) = 0``; it is solved by least
    squares for α on a grid of ``n_alpha`` angles, keeping the best solution with every point in
    front. Works for collinear control points (the 1D camera's resection needs only the scale
    ``c``). Refine with the adjustment.
    """
    xy = _finite(xy_m, "xy_m")
    z = _finite(zeta_px, "zeta_px")
    if xy.shape[0] < 3 or xy.shape[0] != z.size:
        raise ObservationError(
            f"resection needs at least 3 control points with one ζ each, got {xy.shape[0]} points "
            f"and {z.size} coordinates"
        )
    t = tan_from_zeta(z, zeta0_px, c_px, K)
    best = None
    for a in np.linspace(-np.pi, np.pi, n_alpha, endpoint=False):
        ca, sa = np.cos(a), np.sin(a)
        A = np.column_stack([ca + t * sa, sa - t * ca])
        b = A[:, 0] * xy[:, 0] + A[:, 1] * xy[:, 1]
        sol, *_ = np.linalg.lstsq(A, b, rcond=None)
        e = np.array([sol[0], sol[1], a])
        X, Y = camera_xy(xy, e)
        if np.any(Y <= 0):
            continue
        zp = zeta0_px - c_px * X / Y
        zo = z - distortion_px(z, zeta0_px, K)
        rms = float(np.sqrt(np.mean((zp - zo) ** 2)))
        if best is None or rms < best.rms_px:
            best = Resection(e, rms)
    if best is None:
        raise ObservationError("resection failed: no station sees all control points in front")
    return best
