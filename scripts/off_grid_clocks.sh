#!/usr/bin/env bash
# Camera and IMU off one grid (docs/agent.md): the MH_03 flight as a real VI-sensor records it,
# with its real IMU recording (config/scenarios/euroc_recorded_mh03_real_imu.yaml), written
# with its frames taken 0, 0.1, 2.5 and 4.9 ms after the IMU ticks (cvslam_simulate
# --camera-delay), each run by scripts/run_dataset.sh from rest (the folder's start) and in
# flight (--from S), without ground truth; prints the Markdown table of ATE (4-DoF alignment)
# and of how long each start took.
#
#   scripts/off_grid_clocks.sh --calibration MAV0 [--out DIR] [--duration S] [--from S]
#                              [--delays LIST] [--build DIR] [--lcm-url URL]
#
#   --calibration MAV0   a real EuRoC mav0/ folder whose cam0/cam1 sensor.yaml are the rig
#                        (e.g. the euroc_micro test data's mav0)                    [required]
#   --out DIR            work folder: datasets in DIR/data, runs in DIR/runs (default runs/off_grid)
#   --duration S         seconds of the flight to write (default 25: 2 s at rest, 23 s of flight)
#   --from S             the in-flight start begins S seconds into the folder (default 8)
#   --delays LIST        camera delays after the IMU ticks [s] (default 0,0.0001,0.0025,0.0049)
# Datasets already in DIR/data are reused. Exit status: 0 when every run finished, 1 if one
# failed, 2 on bad usage.
set -uo pipefail

ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="$ROOT/build"
CAL="" OUT="runs/off_grid" DURATION=25 FROM=8 DELAYS="0,0.0001,0.0025,0.0049" URL=()
die() { echo "off_grid_clocks.sh: $*" >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) sed -n '2,/^set -uo/p' "$0" | grep '^#' | sed 's/^# \{0,1\}//'; exit 0 ;;
    --calibration) CAL="${2:?--calibration needs a value}"; shift 2 ;;
    --out) OUT="${2:?--out needs a value}"; shift 2 ;;
    --duration) DURATION="${2:?--duration needs a value}"; shift 2 ;;
    --from) FROM="${2:?--from needs a value}"; shift 2 ;;
    --delays) DELAYS="${2:?--delays needs a value}"; shift 2 ;;
    --build) BUILD="${2:?--build needs a value}"; shift 2 ;;
    --lcm-url) URL=(--lcm-url "${2:?--lcm-url needs a value}"); shift 2 ;;
    *) die "unknown argument '$1' (try --help)" ;;
  esac
done
[ -n "$CAL" ] || die "give --calibration MAV0 (a real EuRoC mav0/ folder)"
[ -f "$CAL/cam0/sensor.yaml" ] && [ -f "$CAL/cam1/sensor.yaml" ] ||
  die "$CAL: no cam0/sensor.yaml and cam1/sensor.yaml"
SIM="$BUILD/sensors_replay/cvslam_simulate"
[ -x "$SIM" ] || die "$SIM not built (cmake --build build)"
mkdir -p "$OUT/data" "$OUT/runs" || die "cannot create $OUT"

status=0
rows=()
for delay in ${DELAYS//,/ }; do
  data="$OUT/data/delay_$delay"
  if [ ! -d "$data/uav1/mav0" ]; then
    echo "off_grid_clocks.sh: writing $data (frames $delay s after the IMU ticks)" >&2
    "$SIM" --scenario "$ROOT/config/scenarios/euroc_recorded_mh03_real_imu.yaml" --out "$data" \
      --as-recorded "$CAL" --duration "$DURATION" --camera-delay "$delay" --quiet ||
      { rm -rf "$data"; echo "off_grid_clocks.sh: cvslam_simulate failed" >&2; exit 1; }
  fi
  for start in rest flight; do
    run="$OUT/runs/${start}_$delay"
    args=("$data/uav1" --out "$run" --build "$BUILD" "${URL[@]}")
    [ "$start" = flight ] && args+=(--from "$FROM")
    echo "off_grid_clocks.sh: delay $delay s, start $start" >&2
    if ! "$ROOT/scripts/run_dataset.sh" "${args[@]}" > "$run.log" 2>&1; then
      status=1
      rows+=("| $delay | $start | failed | — | — |")
      continue
    fi
    rows+=("$(/usr/bin/python3 - "$delay" "$start" "$run" <<'PY'
import json, re, sys
delay, start, run = sys.argv[1:4]
a = next(iter(json.load(open(run + "/summary.json"))["agents"].values()))
out = open(run + "/logs/agent_1.out").read()
m = re.search(r"before start (\d+)", out)
waited = f"{int(m.group(1)) / 20.0:.2f}" if m else "—"   # 20 Hz frames before the start
ate = a.get("ate_rmse_m")
print(f"| {float(delay) * 1e3:.1f} | {start} | {100 * ate:.2f} | {waited} | {a.get('steps')} |"
      if ate is not None else f"| {delay} | {start} | — | {waited} | {a.get('steps')} |")
PY
)")
  done
done
echo "| frames after the IMU ticks [ms] | start | ATE 4-DoF [cm] | start after [s] | frames estimated |"
echo "|---:|---|---:|---:|---:|"
printf '%s\n' "${rows[@]}"
exit $status
