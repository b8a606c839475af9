"""One way to apply an adjustment to any sensor: :func:`adjusted` (after the Ames Stereo
Pipeline's adjusted camera models, which wrap any camera with the corrections a bundle
adjustment estimated).

An adjustment is the dict of :func:`hsgeo.io.read_adjustment` (``hsgeo adjust-pushbroom
--json``) or one built in memory with the same keys. Two kinds of entries:

* the **trajectory corrections**: ``t_nodes_s`` (n_nodes,) and ``nodes`` (n_nodes, 6) in the
  order of :data:`hsgeo.trajectory.CORRECTION_COLUMNS` (``node_columns``): cubic B-spline
  corrections of the platform's position and angles (002 eq. (4),
  :func:`hsgeo.trajectory.corrected_trajectory`). They move the body, so they apply to any
  sensor carried by the trajectory;
* the **sensor's parameters**, absolute values in the sensor's own parametrisation (what the
  adjustment estimated, starting from the sensor file): for the 002 LP camera ``c_mm`` (one per
  band, or one for all), ``boresight_rad`` (ω, φ, κ on the nominal mount), ``lever_arm_m``
  (platform frame) and ``distortion`` (K1, K2, P1, P2); for a sensor on a
  :class:`~hsgeo.sensors.mount.Mount` (line scanner, panoramic scanner, frame cameras)
  ``boresight_rad`` (roll, pitch, heading of ``R_body_from_sensor``, as
  :func:`hsgeo.sensors.line.calibrate_boresight` estimates it) and ``lever_arm_m`` (body
  frame). ``sensor_model`` (optional) names the model the parameters belong to
  (:data:`hsgeo.io.sensor_file.MODELS`); given, it must be the sensor's, so that the 002
  camera's ω, φ, κ are never read as a line scanner's roll, pitch, heading.

A key the sensor cannot take is an error naming it; nothing is dropped silently.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from hsgeo.errors import InputError

__all__ = ["adjusted", "adjusted_trajectory", "sensor_model", "CAMERA_KEYS"]

#: The sensor-parameter keys of an adjustment (the rest are the trajectory's).
CAMERA_KEYS = ("c_mm", "boresight_rad", "lever_arm_m", "distortion")
_TRAJECTORY_KEYS = ("t_nodes_s", "nodes", "node_columns")


def sensor_model(sensor) -> str:
    """The registry name of a sensor's model (``[sensor] model`` of its file,
    :data:`hsgeo.io.sensor_file.MODELS`).
    """
    from hsgeo.sensors.frame import FrameCamera
    from hsgeo.sensors.line import LinearIFOV, LineScanner
    from hsgeo.sensors.panoramic import PanoramicScanner
    from hsgeo.sensors.pushbroom import PushbroomCamera
    from hsgeo.sensors.rikola import RikolaCamera
    from hsgeo.sensors.view_angle import ViewAngleScanner

    if isinstance(sensor, LineScanner):
        return (
            "line-scanner-linear-ifov"
            if isinstance(sensor.geometry, LinearIFOV)
            else "line-scanner"
        )
    for cls, name in (
        (PushbroomCamera, "pushbroom"),
        (PanoramicScanner, "panoramic"),
        (FrameCamera, "frame-opencv"),
        (RikolaCamera, "rikola"),
        (ViewAngleScanner, "view-angle"),
    ):
        if isinstance(sensor, cls):
            return name
    raise InputError(
        f"{type(sensor).__name__} is not a sensor of hsgeo.sensors (line scanner, "
        "pushbroom camera, panoramic scanner, frame or Rikola camera)"
    )


def _pushbroom(sensor, adj: dict):
    kw = {}
    if "c_mm" in adj:
        n = len(sensor.c_mm)
        c = np.atleast_1d(np.asarray(adj["c_mm"], dtype=float))
        if c.size not in (1, n):
            raise InputError(
                f"adjustment: {c.size} values of c_mm for a camera of {n} bands; give the "
                "adjustment of this camera (its n_bands)"
            )
        kw["c_mm"] = tuple(float(v) for v in np.broadcast_to(c, (n,)))
    for k in ("boresight_rad", "lever_arm_m", "distortion"):
        if k in adj:
            kw[k] = tuple(float(v) for v in np.asarray(adj[k], dtype=float))
    return replace(sensor, **kw) if kw else sensor


def _mounted(sensor, adj: dict, model: str):
    from hsgeo.sensors.mount import Mount

    bad = [k for k in ("c_mm", "distortion") if k in adj]
    if bad:
        raise InputError(
            f"adjustment: {', '.join(bad)} are parameters of the 002 pushbroom camera; a "
            f"{model!r} sensor cannot take them (give an adjustment of this sensor)"
        )
    if not ("boresight_rad" in adj or "lever_arm_m" in adj):
        return sensor
    from hsgeo.rotations import R_from_rpy

    m = sensor.mount
    R = m.R_body_from_sensor
    if "boresight_rad" in adj:
        R = R_from_rpy(*np.asarray(adj["boresight_rad"], dtype=float))
    lever = np.asarray(adj.get("lever_arm_m", m.lever_arm_m), dtype=float)
    return replace(sensor, mount=Mount(lever, R))


def adjusted_trajectory(trajectory, adjustment: dict):
    """``trajectory`` with the node corrections of ``adjustment`` (002 eq. (4),
    :func:`hsgeo.trajectory.corrected_trajectory`); unchanged when it has none.

    References
    ----------
    .. [1] Jonassen, V. O., Ressl, C., Pfeifer, N., Kjørsvik, N. S. and Gjevestad, J. G. O. (2024).
           Bundle adjustment of aerial linear pushbroom hyperspectral images with sub-pixel
           accuracy. PFG – Journal of Photogrammetry, Remote Sensing and Geoinformation Science
           (paper 002).
    """
    from hsgeo.trajectory import CORRECTION_COLUMNS, SplineNodes, corrected_trajectory

    if "nodes" not in adjustment:
        return trajectory
    if trajectory is None or not hasattr(trajectory, "t_s"):
        raise InputError(
            "adjustment: it holds trajectory corrections (nodes); give the trajectory "
            "(hsgeo.trajectory.Trajectory) they correct"
        )
    t = np.asarray(adjustment["t_nodes_s"], dtype=float)
    cols = tuple(adjustment.get("node_columns", CORRECTION_COLUMNS))
    if cols != CORRECTION_COLUMNS:
        raise InputError(f"adjustment: node columns {cols} are not {CORRECTION_COLUMNS}")
    if t.size < 4:
        raise InputError(f"adjustment: {t.size} node times; a cubic spline needs at least 4")
    dt = float(t[2] - t[1])
    nodes = SplineNodes(float(t[1]), float(t[1] + (t.size - 3) * dt), dt)
    if not np.allclose(nodes.t_nodes_s, t, atol=1e-6 * dt):
        raise InputError("adjustment: the node times are not evenly spaced")
    return corrected_trajectory(trajectory, nodes, adjustment["nodes"])


def adjusted(sensor, trajectory, adjustment: dict | None):
    """The sensor and trajectory an adjustment describes: ``(sensor, trajectory)``.

    Parameters
    ----------
    sensor : a sensor of :mod:`hsgeo.sensors`
        As the sensor file describes it (:func:`hsgeo.io.read_sensor`).
    trajectory : hsgeo.trajectory.Trajectory or None
        The GNSS/INS trajectory the adjustment started from (None for a frame camera's
        poses, which an adjustment with trajectory corrections cannot correct).
    adjustment : dict or None
        See the module docstring; None: both unchanged.

    Returns
    -------
    sensor, trajectory
        New objects (the inputs are frozen and unchanged).

    Raises
    ------
    InputError
        A sensor parameter the sensor's model cannot take, an adjustment of another model
        (``sensor_model``), a key that is no adjustment's, node corrections without a trajectory.
    """
    if adjustment is None:
        return sensor, trajectory
    model = sensor_model(sensor)
    known = set(CAMERA_KEYS) | set(_TRAJECTORY_KEYS) | {"sensor_model"}
    unknown = sorted(set(adjustment) - known)
    if unknown:
        import difflib

        close = difflib.get_close_matches(unknown[0], sorted(known), n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise InputError(
            f"adjustment: unknown key {unknown[0]!r}{hint} (known: {', '.join(sorted(known))})"
        )
    given = adjustment.get("sensor_model")
    if given is not None and given != model:
        raise InputError(
            f"adjustment: it adjusts a {given!r} sensor, the sensor is {model!r}; give the "
            "adjustment of this sensor"
        )
    if model == "pushbroom":
        new = _pushbroom(sensor, adjustment)
    else:
        new = _mounted(sensor, adjustment, model)
    return new, adjusted_trajectory(trajectory, adjustment)
