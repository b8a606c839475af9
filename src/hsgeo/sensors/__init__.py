"""Sensor geometries, one file each, all with the interface of :mod:`hsgeo.sensors.mount`.

* :mod:`~hsgeo.sensors.mount`: :class:`~hsgeo.sensors.mount.Mount` (lever arm + boresight),
  the ``Sensor`` protocol (``rays`` / ``project``) and ``line_time`` for scanning sensors;
* :mod:`~hsgeo.sensors.line`: the 000 line scanner in flight (``LineScanner``; the laboratory
  model of 000 eq. (2) is :mod:`~hsgeo.sensors.line1d`);
* :mod:`~hsgeo.sensors.pushbroom`: the 002 LP camera (``PushbroomCamera``, ``PushbroomLines``);
* :mod:`~hsgeo.sensors.frame`, :mod:`~hsgeo.sensors.bal`, :mod:`~hsgeo.sensors.rikola`: frame
  cameras (``FrameCamera`` offers ``rays`` / ``project`` at given exposure poses, and
  ``rays_along`` a trajectory: :class:`~hsgeo.sensors.mount.OnTrajectory` gives a frame
  camera the scanning sensors' face for ``hsgeo orthorectify``);
* :mod:`~hsgeo.sensors.panoramic`: the 004 panoramic (whiskbroom) scanner
  (``PanoramicScanner``): a scanning sensor like ``LineScanner`` whose samples along one scan
  have their own times;
* :mod:`~hsgeo.sensors.adjustment`: :func:`adjusted`, the one way to apply an adjustment
  (trajectory corrections and the sensor's parameters) to any of them.

A sensor file (``[sensor] model = ...``) becomes one of these through
:func:`hsgeo.io.read_sensor` (the registry :data:`hsgeo.io.sensor_file.MODELS`).
"""

from __future__ import annotations

from hsgeo.sensors.adjustment import adjusted, sensor_model

__all__ = ["as_sensor", "adjusted", "sensor_model"]


def as_sensor(sensor, boresight_rad=None):
    """A sensor with ``rays``: the sensor itself, or a bare 000 LineGeometry on a mount.

    Parameters
    ----------
    sensor : a sensor with ``rays``, or hsgeo.sensors.line.LineGeometry
    boresight_rad : (3,) sequence, optional
        Roll, pitch, heading of ``R_body_from_sensor`` for a bare LineGeometry (a sensor with
        ``rays`` carries its own mount).
    """
    from hsgeo.errors import InputError
    from hsgeo.sensors.line import LineGeometry, LineScanner
    from hsgeo.sensors.mount import Mount

    if hasattr(sensor, "rays"):
        if boresight_rad is not None and any(boresight_rad):
            raise InputError(
                "boresight_rad is for a bare LineGeometry; a sensor with rays() carries its "
                "boresight in its mount"
            )
        return sensor
    if isinstance(sensor, LineGeometry):
        b = (0.0, 0.0, 0.0) if boresight_rad is None else boresight_rad
        return LineScanner(sensor, Mount.from_rpy(b))
    raise InputError(
        f"{type(sensor).__name__} is not a sensor: give one of hsgeo.sensors (with rays()) or a "
        "hsgeo.sensors.line.LineGeometry"
    )
