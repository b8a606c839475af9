#!/usr/bin/env bash
# `make check-wheel`: the wheel is the product too (issue 42). Install dist/hsgeo-*.whl alone into
# a fresh venv (its dependencies from the package index, held to requirements.lock's versions by
# `-c`), then, from an empty folder, run the README's commands on files written there: the data,
# the chapters that read the scenarios, and every command on inputs the installed hsgeo writes
# (.ci/wheel_inputs.py). Any failure stops the check with the command that failed.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
PYTHON="${PYTHON:-python3.11}"
WHEEL="$(ls "$ROOT"/dist/hsgeo-*.whl | head -n 1)"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
"$PYTHON" -m venv "$WORK/venv"
"$WORK/venv/bin/python" -m pip install --quiet --disable-pip-version-check \
  -c "$ROOT/requirements.lock" "$WHEEL"
echo "check-wheel: $(basename "$WHEEL"), .ci/check_wheel.sh sha256 $(sha256sum "$ROOT/.ci/check_wheel.sh" | cut -c1-16)"
HS="$WORK/venv/bin/hsgeo"
PY="$WORK/venv/bin/python"
mkdir "$WORK/empty" && cd "$WORK/empty"
export OPENBLAS_NUM_THREADS=1 PYTHONDONTWRITEBYTECODE=1

step() { echo "+ hsgeo $*"; "$HS" "$@" > "$WORK/out.txt"; }
json() { echo "+ hsgeo $* (JSON)"; "$HS" "$@" | "$PY" -c "import json, sys; json.load(sys.stdin)"; }

step --help
step versions
step data --verify                    # ./data_synthetic/generated from the wheel's scenarios
step reproduce frame-reference
json reproduce geocoding --seed 3 --scale 0.1 --json   # the README's command, smaller
json reproduce rikola --scale 0.1 --json
G=data_synthetic/generated
step calibrate-line $G/line_lab_observations.csv --control $G/line_lab_control.csv
step mtf $G/mtf_bench_profiles.csv --bars $G/mtf_bench_bars.toml
# the installed package's own data (not the repository's): the BAL problem, ChArUco photographs
PKG="$("$PY" -c 'import hsgeo, pathlib; print(pathlib.Path(hsgeo.__file__).parent)')"
step adjust-bal "$PKG/data/reference/bal-ladybug/problem-49-7776-pre.txt.bz2"
step calibrate-frame "$PKG"/data/reference/opencv-charuco/images/*.jpg \
  --board "$PKG/data/reference/opencv-charuco/board.toml" --per-band
# a usage error says what the option takes (was "a positive number in [-inf, 1]")
if "$HS" reproduce mtf --scale small 2> "$WORK/err.txt"; then echo "--scale small accepted"; exit 1; fi
grep -q "(0, 1\]" "$WORK/err.txt" || { cat "$WORK/err.txt"; exit 1; }

"$PY" "$ROOT/.ci/wheel_inputs.py" in > /dev/null
step mtf-edge in/EDGE.png --roi 8,8,88,88
step mtf-edge in/EDGE.png
step cube in/raw --dark in/dark --binning 2 -o cube.nc
step cube in/raw --dark in/dark --binning 2 -o cube.hdr
step asf in/CROSS.nc in/ALONG.nc --runway in/RUNWAY.csv
step lp-observations in/STRIP_*.nc --trajectory in/NAV.csv --camera in/CAM.toml \
  --squares in/SQUARES.csv -o OBS.parquet
# the GCPs that the matcher found among the squares (a GCP without observations is refused)
"$PY" -c "import pandas as pd; o = set(pd.read_parquet('OBS.parquet')['point_id'].astype(str)); \
g = pd.read_csv('in/GCP.csv', dtype={'point_id': str}); g[g['point_id'].isin(o)].to_csv('GCP.csv', index=False)"
echo "+ hsgeo adjust-pushbroom … --json > ADJ.json"
"$HS" adjust-pushbroom OBS.parquet --trajectory in/NAV.csv --camera in/CAM.toml \
  --gcp GCP.csv --node-interval 10 --json > ADJ.json
"$PY" -c "import json; json.load(open('ADJ.json'))"
step orthorectify in/STRIP_*.nc --trajectory in/NAV.csv --site 59.665,10.775,0 \
  --nav-crs EPSG:4937 --sensor in/CAM.toml --dsm in/DSM.tif --resolution 2 -o mosaic.tif
# the README's strips line: the adjustment's file, chosen bands, the mosaic rule
step orthorectify in/STRIP_*.nc --trajectory in/NAV.csv --site 59.665,10.775,0 \
  --nav-crs EPSG:4937 --sensor in/CAM.toml --adjustment ADJ.json --dsm in/DSM.tif \
  --resolution 2 --bands 681,604,450 --mosaic nearest-nadir -o mosaic_adj.tif
# the README's single line over flat terrain (--height), to CF NetCDF
step orthorectify "$(ls in/STRIP_*.nc | head -n 1)" --trajectory in/NAV.csv \
  --site 59.665,10.775,0 --nav-crs EPSG:4937 --sensor in/CAM.toml --height 100 -o ortho.nc
# the README's simulated flight anywhere (shorter line) and the command it prints
step data flight --site=-33.9,151.2 --length-km 2 --out flight
step orthorectify flight/lines.raw --line-times flight/line_times.csv \
  --trajectory flight/nav.csv --sensor flight/sensor.toml --dsm flight/dsm.tif \
  --vertical ellipsoidal -o flight/ortho.tif
# the README's real-flight line: the same flight as an Applanix SBET, one NetCDF line file and a
# DSM of EGM96 heights (the geoid from Debian's proj-data, as the README says)
"$PY" "$ROOT/.ci/wheel_inputs.py" --sbet flight
step orthorectify flight/LINE.nc --trajectory flight/FLIGHT.sbet --nav-crs EPSG:4979 \
  --sensor flight/sensor.toml --dsm flight/DSM_egm96.tif --vertical EPSG:5773 -o ortho_sbet.tif
"$PY" -c "import numpy as np, rasterio; a, b = (rasterio.open(p).read() for p in ('ortho_sbet.tif', \
'flight/ortho.tif')); assert np.array_equal(np.isnan(a), np.isnan(b)), 'cells differ'; \
d = np.nanmax(np.abs(a - b)); assert d <= 1e-4 * np.nanmax(np.abs(b)), d"  # the same flight
# the README's frame-camera line: three frames of the Rikola's two sensors
step orthorectify in/FRAMES/*.raw --frame-times in/TIMES.csv --trajectory in/FRAMES_NAV.csv \
  --site 59.665,10.775 --sensor in/RIKOLA.toml --dsm in/FRAMES_DSM.tif -o frames.tif
echo "check-wheel: the installed wheel ran every command above from an empty folder (${SECONDS} s)"
