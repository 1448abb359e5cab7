#!/usr/bin/env bash
# The real-recordings benchmark (docs/results/euroc_recorded.md): EuRoC flights written as a
# real VI-sensor records them (cvslam_simulate --as-recorded: z-up world, IMU in the sensor's
# x-up axes, distorted unrectified images with the real calibration, turn-on biases, rotor
# vibration, a rest period at the start; MH_03 and V1_02 also with their real IMU recording),
# each run by scripts/run_dataset.sh with the default configuration — static initialisation,
# no ground truth given to the estimator — and evaluated against the folder's ground truth.
#
#   scripts/euroc_recorded.sh --calibration MAV0 [--out DIR] [--duration S] [--build DIR]
#                             [--only NAME ...] [--table FILE] [--lcm-url URL]
#                             [--map room|knearest] [--agent-arg ARG ...]
#
#   --calibration MAV0   a real EuRoC mav0/ folder whose cam0/cam1 sensor.yaml are the rig
#                        (e.g. the euroc_micro test data's mav0)                    [required]
#   --out DIR            work folder: datasets in DIR/data, runs in DIR/runs (default runs/euroc_recorded)
#   --duration S         simulate S seconds per flight (default: the scenarios' 83 s = 3 s rest,
#                        2 s take-off ramp, 80 s of flight)
#   --only NAME          run only this sequence (repeatable): MH_01 MH_02 MH_03 MH_03_real_imu
#                        V1_01 V1_02 V1_02_real_imu
#   --table FILE         write the Markdown table there (default DIR/euroc_recorded.md)
#   --lcm-url URL        LCM provider for the runs (default: run_dataset.sh's)
#   --map room|knearest  the agent's map (run_dataset.sh --map; default room: the full map
#                        bounded at 500 landmarks)
#   --agent-arg ARG      extra argument for every agent (repeatable)
# Datasets already in DIR/data are reused. Exit status: 0 when every run finished, 1 if one
# failed, 2 on bad usage.
set -uo pipefail

ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="$ROOT/build"
CAL="" OUT="runs/euroc_recorded" DURATION="" TABLE=""
ONLY=() EXTRA=()
die() { echo "euroc_recorded.sh: $*" >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) sed -n '2,/^set -uo/p' "$0" | grep '^#' | sed 's/^# \{0,1\}//'; exit 0 ;;
    --calibration) CAL="${2:?--calibration needs a value}"; shift 2 ;;
    --out) OUT="${2:?--out needs a value}"; shift 2 ;;
    --duration) DURATION="${2:?--duration needs a value}"; shift 2 ;;
    --build) BUILD="${2:?--build needs a value}"; shift 2 ;;
    --only) ONLY+=("${2:?--only needs a value}"); shift 2 ;;
    --table) TABLE="${2:?--table needs a value}"; shift 2 ;;
    --lcm-url) EXTRA+=(--lcm-url "${2:?--lcm-url needs a value}"); shift 2 ;;
    --map) EXTRA+=(--map "${2:?--map needs a value}"); shift 2 ;;
    --agent-arg) EXTRA+=(--agent-arg "${2:?--agent-arg needs a value}"); shift 2 ;;
    *) die "unknown argument '$1' (try --help)" ;;
  esac
done
[ -n "$CAL" ] || die "give --calibration MAV0 (a real EuRoC mav0/ folder)"
[ -f "$CAL/cam0/sensor.yaml" ] && [ -f "$CAL/cam1/sensor.yaml" ] ||
  die "$CAL: no cam0/sensor.yaml and cam1/sensor.yaml"
SIM="$BUILD/sensors_replay/cvslam_simulate"
EVAL="$BUILD/tools/cvslam_eval"
[ -x "$SIM" ] && [ -x "$EVAL" ] || die "$BUILD: cvslam_simulate / cvslam_eval not built"
[ -n "$TABLE" ] || TABLE="$OUT/euroc_recorded.md"

# name | scenario | uav | imu
SEQUENCES="MH_01 euroc_recorded_mh 1 synthetic
MH_02 euroc_recorded_mh 2 synthetic
MH_03 euroc_recorded_mh 3 synthetic
MH_03_real_imu euroc_recorded_mh 4 real
V1_01 euroc_recorded_v1 1 synthetic
V1_02 euroc_recorded_v1 2 synthetic
V1_02_real_imu euroc_recorded_v1 3 real"
wanted() {
  [ ${#ONLY[@]} -eq 0 ] && return 0
  local n; for n in "${ONLY[@]}"; do [ "$n" = "$1" ] && return 0; done; return 1
}
for n in "${ONLY[@]}"; do
  echo "$SEQUENCES" | awk '{print $1}' | grep -qx "$n" || die "--only: unknown sequence '$n'"
done

mkdir -p "$OUT/data" "$OUT/runs" || die "cannot create $OUT"
simulate() {  # scenario
  local dir="$OUT/data/$1"
  [ -d "$dir/uav1/mav0" ] && return 0
  echo "euroc_recorded.sh: writing $dir (as recorded)"
  local args=(--scenario "$ROOT/config/scenarios/$1.yaml" --out "$dir" --as-recorded "$CAL" --quiet)
  [ -n "$DURATION" ] && args+=(--duration "$DURATION")
  "$SIM" "${args[@]}" || { rm -rf "$dir"; echo "euroc_recorded.sh: cvslam_simulate failed" >&2; exit 1; }
}

status=0
rows=()
while read -r name scenario uav imu; do
  wanted "$name" || continue
  simulate "$scenario"
  run="$OUT/runs/$name"
  rm -rf "$run"
  echo "euroc_recorded.sh: $name ($imu IMU)"
  t0=$(date +%s.%N)
  if "$ROOT/scripts/run_dataset.sh" "$OUT/data/$scenario/uav$uav" --out "$run" --build "$BUILD" \
      "${EXTRA[@]}" > "$run.log" 2>&1; then
    wall=$(echo "$(date +%s.%N) - $t0" | bc)
    "$EVAL" --run "$run" --align se3 --quiet --summary-json "$run/summary_se3.json" ||
      { status=1; continue; }
    rows+=("$(python3 - "$name" "$imu" "$run" "$wall" <<'PY'
import json, sys
name, imu, run, wall = sys.argv[1:5]
se3 = next(iter(json.load(open(run + "/summary_se3.json"))["agents"].values()))
yaw = next(iter(json.load(open(run + "/summary.json"))["agents"].values()))
def cm(x): return "%.1f" % (100 * x) if x is not None else "—"
frame = se3.get('frame_time_ms_median')
print(f"| {name} | {imu} | {cm(se3.get('ate_rmse_m'))} | {cm(yaw.get('ate_rmse_m'))} | "
      f"{cm(se3.get('ate_max_m'))} | {'%.0f' % frame if frame is not None else '—'} | "
      f"{float(wall):.0f} |")
PY
)")
  else
    status=1
    rows+=("| $name | $imu | failed | failed | — | — | — |")
    echo "euroc_recorded.sh: $name failed (log: $run.log)" >&2
  fi
done <<< "$SEQUENCES"

{
  echo "| sequence | IMU | ATE SE(3) [cm] | ATE 4-DoF [cm] | max error SE(3) [cm] | frame [ms] | wall [s] |"
  echo "|---|---|---|---|---|---|---|"
  printf '%s\n' "${rows[@]}"
} > "$TABLE"
cat "$TABLE"
exit $status
