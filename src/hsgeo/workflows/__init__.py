"""Truth-free pipelines a user runs on their own files (GUIDE §1–§2).

Each workflow goes measure → model → adjust → products with the same code whether the input
comes from a user's files or from :mod:`hsgeo.simulate`; none of them ever sees a simulation's
truth (only :mod:`hsgeo.reproduce` compares results with the truth and the papers).

=========================  =====================================================================
module                     what it does
=========================  =====================================================================
``line_calibration``       1D spatial calibration of a line scanner (000 §4,
                           ``hsgeo calibrate-line``)
``frame_calibration``      frame-camera self-calibration, OpenCV and photogrammetric forms
``rikola``                 per-band and joint calibration of the Rikola FPI camera (003,
                           ``hsgeo calibrate-frame``)
``pushbroom_ba``           bundle adjustment of pushbroom lines (002, ``hsgeo adjust-pushbroom``)
``geocoding``              GCP deviations after a GCP boresight calibration (000 Tables 2–3)
``orthorectify``           one line or many strips of any scanning sensor onto a map grid, COG,
                           NetCDF or ENVI (``hsgeo orthorectify``)
``cube``                   raw ImSpector frames → reflectance cube: dark current and hot pixels,
                           reflectance from the diffuse collector, chunked (001 §2.1, §2.4,
                           ``hsgeo cube``)
``bal``                    a "Bundle Adjustment in the Large" problem, Snavely cameras
                           (``hsgeo adjust-bal``)
``lp_observations``       LP lines → tie-point observations: BRISK, RANSAC on the LP
                           fundamental matrix (002 §3.1, §4, ``hsgeo lp-observations``)
``mtf``                    MTF from bar-target profiles (CTF → MTF) and from slanted edges
                           (001 eq. 4–7, ``hsgeo mtf``, ``hsgeo mtf-edge``)
``rikola_bands``           the Rikola band by band: targets from pixels, one camera per band (003)
``rikola_joint``           the Rikola's joint model: all bands in one adjustment (003 §3.5)
``asf``                    a whiskbroom scanner's angular sensitivity from crossing flight lines
                           (004, ``hsgeo asf``)
``asf_checks``             what must hold of the two scans of ``hsgeo asf``
``asf_flights``            ``hsgeo asf`` from raw scans: georegistration, one ASF per crossing
=========================  =====================================================================
"""

__all__: list[str] = []
