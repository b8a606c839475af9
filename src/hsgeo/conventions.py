"""hsgeo's conventions in one place: frames, axis order, pixel origin, angles (the "gotchas").

Each convention is stated here once and implemented by exactly one function; the book page
*Conventions* shows them with small checks.

Pixels
    Pixel coordinates have their origin at the **centre** of the first pixel (OpenCV's
    convention): the first pixel covers −0.5 … 0.5. Image arrays are indexed ``[row, column]``
    = ``[v, u]``; points are ``(u, v)`` = ``(x, y)`` with y downwards. A line scanner's spatial
    coordinate is ``zeta_px`` along its line (000 eq. (2)).

Photogrammetric image frame
    Millimetres from the image centre (or the principal point), x right, **y up**, the camera
    looking along its −z axis (:func:`hsgeo.sensors.frame.pixel_to_mm`). OpenCV's camera frame
    has y down and looks along +z; the two differ by ``diag(1, −1, −1)``.

Rotations
    Named for what they do: ``R_world_from_cam`` maps camera-frame vectors to world-frame ones.
    ω-φ-κ: ``R_world_from_cam = Rx(ω) Ry(φ) Rz(κ)`` (:func:`hsgeo.rotations.R_from_opk`).
    Roll-pitch-yaw (aircraft, NED): ``R_ned_from_body = Rz(yaw) Ry(pitch) Rx(roll)``
    (:func:`hsgeo.rotations.R_from_rpy`). OpenCV's ``rvec`` is ``R_cam_from_world`` as a
    rotation vector (:func:`hsgeo.rotations.R_from_rotvec`).

Map frames
    A local east-north-up frame in metres (E, N, U). Paper 000 uses the Croatian y (east),
    x (north) convention: its Δy is our ΔE and its Δx our ΔN. The navigation's attitude refers to
    north-east-down; ``hsgeo.geocode.R_ENU_FROM_NED`` converts.

Units
    SI and radians inside; degrees only at the edges (files, tables, command line). Names carry
    units wherever a number could be misread: ``c_px``, ``f_mm``, ``t_s``, ``omega_rad``.

Distortion
    OpenCV's form distorts normalised ideal coordinates, ``(k1, k2, p1, p2, k3)``; the
    photogrammetric form corrects measured coordinates in mm, ``(K1, K2, K3, P1, P2)``; Brown's
    P1, P2 play the roles of OpenCV's p2, p1. The 1D line-scanner polynomial of 000 eq. (2) takes
    ``(ζ − ζ0)`` in units of 100 px and gives pixels (:mod:`hsgeo.sensors.line1d`).

Residuals and σ
    Residuals are model − observation. σ̂ is the a-posteriori standard deviation, scaled by σ0;
    standard deviations of samples use n − 1; NMAD = 1.4826·median|x − median(x)|.

Randomness
    Only ``numpy.random.Generator``; every simulator takes ``rng`` (a seed or a Generator).
    Sub-streams are derived with ``numpy.random.SeedSequence([seed, i])``.
"""

from hsgeo.geocode import R_ENU_FROM_NED

__all__ = ["R_ENU_FROM_NED", "PIXEL_ORIGIN"]

#: The coordinate of the centre of the first pixel (OpenCV convention).
PIXEL_ORIGIN = 0.0
