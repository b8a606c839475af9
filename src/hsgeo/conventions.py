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
    Roll-pitch-yaw: ``R = Rz(yaw) Ry(pitch) Rx(roll)`` (:func:`hsgeo.rotations.R_from_rpy`),
    ``R_nav_from_body``; the angles mean different things in NED and ENU (below). OpenCV's
    ``rvec`` is ``R_cam_from_world`` as a rotation vector (:func:`hsgeo.rotations.R_from_rotvec`).

Map frames
    A local east-north-up frame in metres (E, N, U). Paper 000 uses the Croatian y (east),
    x (north) convention: its Δy is our ΔE and its Δx our ΔN. ``R_ENU_FROM_NED``
    (:data:`hsgeo.rotations.R_ENU_FROM_NED`) takes north-east-down vectors to east-north-up.

Trajectories and navigation files
    One class for every timed pose, :class:`hsgeo.trajectory.Trajectory`: positions ``xyz_m``
    (E, N, U) and ``roll_pitch_heading_rad``, the attitude as a GNSS/INS gives it, of the body
    (x forward, y right, z down) relative to north-east-down:
    ``R_map_from_body = R_ENU_FROM_NED @ R_from_rpy(roll, pitch, heading)``. One file format for
    every command (:mod:`hsgeo.io.navigation`):
    ``t_s, E_m, N_m, U_m, roll_deg, pitch_deg, heading_deg``. The pushbroom model of 002 keeps its
    own angles, roll, pitch, yaw of the platform (x forward, y left, z up) relative to
    east-north-up, ``R_map_from_platform = R_from_rpy(roll, pitch, yaw)``; exactly
    ``(roll, pitch, yaw) = (roll, −pitch, π/2 − heading)``
    (:func:`hsgeo.trajectory.platform_rpy_from_rph`), because
    ``R_ENU_FROM_NED R_from_rpy(r, p, h) diag(1, −1, −1) = R_from_rpy(r, −p, π/2 − h)``.

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

__all__ = ["PIXEL_ORIGIN"]

#: The coordinate of the centre of the first pixel (OpenCV convention).
PIXEL_ORIGIN = 0.0
