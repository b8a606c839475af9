"""Names `vulture src/hsgeo --min-confidence 60` reports that are used, and by what.

Read by vulture, never imported: `vulture src/hsgeo vulture_whitelist.py --min-confidence 60`
must report nothing (tests/test_dead_code.py). Each line is a name (``_.name`` for an attribute
or method), then the file that uses it and why. A name is here only if it is used by reflection
(a protocol or a registry calls it by name) or only outside src/hsgeo (by a test, a benchmark
or a chapter of the book); tests/test_dead_code.py checks that the file named still uses it.
A name nothing uses is deleted instead.
"""

# ---- used by reflection: looked up or called by name ----------------------------------------
_cmd_reproduce  # src/hsgeo/cli_parsers.py: SUBCOMMANDS names each handler, cli.build_parser looks it up
_cmd_calibrate_line  # src/hsgeo/cli_parsers.py: a handler named in SUBCOMMANDS
_cmd_calibrate_frame  # src/hsgeo/cli_parsers.py: a handler named in SUBCOMMANDS
_cmd_data  # src/hsgeo/cli_parsers.py: a handler named in SUBCOMMANDS
_cmd_orthorectify  # src/hsgeo/cli_parsers.py: a handler named in SUBCOMMANDS
_cmd_adjust_pushbroom  # src/hsgeo/cli_parsers.py: a handler named in SUBCOMMANDS
_cmd_lp_observations  # src/hsgeo/cli_parsers.py: a handler named in SUBCOMMANDS
_cmd_adjust_bal  # src/hsgeo/cli_parsers.py: a handler named in SUBCOMMANDS
_cmd_mtf  # src/hsgeo/cli_parsers.py: a handler named in SUBCOMMANDS
_cmd_mtf_edge  # src/hsgeo/cli_parsers.py: a handler named in SUBCOMMANDS
_cmd_cube  # src/hsgeo/cli_parsers.py: a handler named in SUBCOMMANDS
_cmd_asf  # src/hsgeo/cli_parsers.py: a handler named in SUBCOMMANDS
_cmd_versions  # src/hsgeo/cli_parsers.py: a handler named in SUBCOMMANDS
__getattr__  # src/hsgeo/io/__init__.py: hsgeo.io.NAME loads NAME's module on first use (PEP 562, called by Python)
__dir__  # src/hsgeo/io/__init__.py: dir(hsgeo.io) and tab completion list the names not yet loaded (PEP 562)
_.sigma_att_deg  # src/hsgeo/workflows/pushbroom_ba.py: read by name from [gnss_ins] (io.sensor_file.present)
_.n_reflected_columns  # src/hsgeo/io/sensors.py: read_frame_layouts reads the fields of [frame] by name
_.n_incident_columns  # src/hsgeo/io/sensors.py: read_frame_layouts reads the fields of [frame] by name
_._start_state  # src/hsgeo/io/cube.py: a hook of dask.callbacks.Callback, called by dask's scheduler
_._posttask  # src/hsgeo/io/cube.py: a hook of dask.callbacks.Callback, called by dask's scheduler
_.cornerRefinementMethod  # src/hsgeo/measure/aruco.py: cv2.aruco.DetectorParameters, read by OpenCV
_.cornerRefinementWinSize  # src/hsgeo/measure/aruco.py: cv2.aruco.DetectorParameters, read by OpenCV
_.cornerRefinementMaxIterations  # src/hsgeo/measure/aruco.py: read by OpenCV's detector
_.cornerRefinementMinAccuracy  # src/hsgeo/measure/aruco.py: read by OpenCV's detector
_.__doc__  # src/hsgeo/nist/models.py: a generated model's docstring, read by help() and the reports
_._repr_markdown_  # src/hsgeo/report.py: Jupyter's display protocol (a label in a chapter's table)

# ---- used only by the book's chapters ---------------------------------------------------------
RIKOLA_ROP_TEST_PX  # book/chapters/rikola.md: 003's numbers the chapter compares with
RIKOLA_FIG8_MAX_DIFF_PX  # book/chapters/rikola.md: 003 Fig. 8's largest difference
RIKOLA_FIG9_MAX_DECENTERING_PX  # book/chapters/rikola.md: 003 Fig. 9's largest decentering
VERDICT_MEANING  # book/scoreboard.md: the page explains each verdict with it
verdict_bars  # book/scoreboard.md: the scoreboard's figure
binned_residuals  # book/chapters/frame_reference.md: a figure of the chapter
z_errorbars  # book/chapters/frame_reference.md: a figure of the chapter
gcp_deviation_map  # book/chapters/geocoding.md: a figure of the chapter
iop_against_wavelength  # book/chapters/line_calibration.md: a figure of the chapter
residuals_by_band  # book/chapters/rikola.md: a figure of the chapter
rop_per_pair  # book/chapters/rikola.md: a figure of the chapter
against_interval  # book/chapters/pushbroom_ba.md: a figure of the chapter
checkpoint_heights  # book/chapters/pushbroom_ba.md: a figure of the chapter
per_band_values  # book/chapters/pushbroom_ba.md: a figure of the chapter
stats_vs_paper  # book/chapters/pushbroom_ba.md: a figure of the chapter
_.verdict_counts  # book/chapters/pushbroom_ba.md: the chapter's count of verdicts
_.n_groups  # book/chapters/mtf.md: the number of bar groups the chapter reports
_.n_incident  # book/chapters/cube.md: the survey's frames of the diffuse collector
_.shift_reverse_m  # book/chapters/asf.md: the opposite crossing's registration truth
_.window_centres_m  # book/chapters/asf.md: where the registration windows lie

# ---- public results and truths read only by the tests and benchmarks --------------------------
_.correlation  # tests/test_engine.py: Result.correlation(), against the inverse normal matrix
_.cov_ab  # tests/test_radiometry.py: the dark fit's covariance against numpy.polyfit
_.sigma0_dn  # tests/test_radiometry.py: the dark fit's residual σ against numpy.polyfit
_.formula  # tests/test_radiometry.py: each vegetation index's formula names its wavelengths
_.local_crs  # tests/test_crs.py: the local frame as a pyproj CRS
_.enu_to_crs  # tests/test_crs.py: the local frame to a map CRS, a round trip
_.crs_to_enu  # tests/test_crs.py: a map CRS to the local frame, a round trip
_.evaluate_numpy  # tests/test_pushbroom.py: the numpy reference of the compiled residual block
_.project_jacobian  # tests/test_panoramic.py: the analytic Jacobian against finite differences
_.example  # tests/test_sensor_file.py: each sensor model's example file
_.from_runs  # tests/test_report.py: a row from repeated runs
_.n_iterations  # tests/test_lp_ransac.py: RANSAC's iterations
_.nav_error  # tests/test_pushbroom_campaign.py: the campaign's true navigation error
_.residual_sd  # tests/test_nist_strd.py: NIST's certified residual standard deviation
_.sensor_nominal  # tests/test_geocode.py: the flight's uncalibrated sensor
_.strip_index  # tests/test_lp_campaign.py: the strip of each simulated observation
_.time_scale  # tests/test_io_navigation.py: the navigation file's time scale
_.true_start_px  # tests/test_measure_mtf.py: the simulated bar target's true position
_.uv_true_px  # tests/test_calibration.py: the bench's true image points
_.seconds_split  # bench/bench_pushbroom_ba.py: the solver's time by stage
_.select_cameras  # bench/bench_bal.py: a BAL problem cut to its first cameras
_.singular_values  # bench/bench_rikola_drift.py: the datum analysis's singular values
_._repr_png_  # src/hsgeo/report.py: IPython's display protocol calls _GluedFigure._repr_png_ (the glued PNG)
_.writeable  # src/hsgeo/sensors/pushbroom.py: numpy's flags.writeable = False (a read-only array for the kernel's one signature)
