#!/usr/bin/env bash
# One command for a recorded EuRoC-format folder: replay it in lockstep into one cvslam_agent
# (scripts/launch.sh), evaluate the result against the folder's ground truth when it has one
# (cvslam_eval), and draw the plots (scripts/plot_run.py).
#
#   scripts/run_dataset.sh PATH [--out DIR] [--start auto|rest|dynamic|known] [--map room|knearest]
#                          [--duration S] [--from S] [--camera-time-offset S] [--build DIR]
#                          [--lcm-url URL] [--agent-arg ARG ...]
#
#   PATH                 EuRoC ASL folder (PATH/mav0/...) with cam0, cam1, imu0 and their sensor.yaml
#   --out DIR            run folder (default runs/<folder name>)
#   --start auto         (default) the agent starts without ground truth in its own
#                        gravity-aligned frame: from the IMU's first rest period, or in motion
#                        from the first frames and the IMU (rest | dynamic force one); the
#                        evaluation aligns the estimate to the ground truth by yaw +
#                        translation (4-DoF)
#   --start known        the agent starts at the folder's first ground-truth pose (a NED folder,
#                        e.g. written by cvslam_simulate); no alignment
#   --map room           (default) one vehicle's recording keeps its map whole: the full
#                        stochastic map, bounded at 500 landmarks (the least recently observed
#                        leave first); 30-90 ms per frame on a 2-core machine, which the lockstep
#                        replay waits for (docs/results/euroc_recorded.md)
#   --map knearest       the thesis's k-nearest map of config/agent.yaml (what the team
#                        scenarios run; up to 2.4x less accurate inside one room)
#   --duration S         replay only S seconds of the folder (default: all of it)
#   --from S             begin S seconds into the folder (a vehicle that joins in flight: the
#                        dynamic start, or auto's, takes it from its first frames in motion)
#   --camera-time-offset S  a frame stamped t was taken at IMU time t + S (a constant
#                        camera-IMU clock offset, as Kalibr's timeshift_cam_imu; default 0)
#   --build DIR          where the programs are (default build/)
#   --lcm-url URL        LCM provider (default: launch.sh's)
#   --agent-arg ARG      extra argument for the agent (repeatable), e.g. --detector fast_sift
# Exit status: 0 on success, 1 when a process failed, 2 on bad usage.
set -uo pipefail

ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="$ROOT/build"
DATA="" OUT="" START=auto MAP=room URL="" DURATION="" FROM="" CAM_OFFSET=""
EXTRA=()
die() { echo "run_dataset.sh: $*" >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) sed -n '2,/^set -uo/p' "$0" | grep '^#' | sed 's/^# \{0,1\}//'; exit 0 ;;
    --out) OUT="${2:?--out needs a value}"; shift 2 ;;
    --start) START="${2:?--start needs a value}"; shift 2 ;;
    --map) MAP="${2:?--map needs a value}"; shift 2 ;;
    --duration) DURATION="${2:?--duration needs a value}"; shift 2 ;;
    --from) FROM="${2:?--from needs a value}"; shift 2 ;;
    --camera-time-offset) CAM_OFFSET="${2:?--camera-time-offset needs a value}"; shift 2 ;;
    --build) BUILD="${2:?--build needs a value}"; shift 2 ;;
    --lcm-url) URL="${2:?--lcm-url needs a value}"; shift 2 ;;
    --agent-arg) EXTRA+=(--agent-arg "${2:?--agent-arg needs a value}"); shift 2 ;;
    -*) die "unknown option '$1' (try --help)" ;;
    *) [ -z "$DATA" ] || die "one folder only (got '$DATA' and '$1')"; DATA="$1"; shift ;;
  esac
done
[ -n "$DATA" ] || die "give the EuRoC folder (try --help)"
[ -d "$DATA/mav0" ] || [ "$(basename "$DATA")" = mav0 ] || die "$DATA: no mav0/ folder (not a EuRoC ASL dataset)"
case "$START" in auto|rest|dynamic) ALIGN=yaw ;; known) ALIGN=none ;; *) die "--start must be auto, rest, dynamic or known" ;; esac
case "$MAP" in
  room) MAP_ARGS=(--agent-arg --map --agent-arg full --agent-arg --set --agent-arg map.max_landmarks=500) ;;
  knearest) MAP_ARGS=() ;;
  *) die "--map must be room or knearest" ;;
esac
[ -n "$OUT" ] || OUT="runs/$(basename "$(cd "$DATA" && pwd)")"
[ -x "$BUILD/tools/cvslam_eval" ] || die "$BUILD/tools/cvslam_eval not built (cmake --build build)"

launch=("$ROOT/scripts/launch.sh" --dataset "1:$DATA" --lockstep --out "$OUT" --build "$BUILD"
        --agent-arg --start --agent-arg "$START" "${MAP_ARGS[@]}" "${EXTRA[@]}")
[ -n "$URL" ] && launch+=(--lcm-url "$URL")
[ -n "$DURATION" ] && launch+=(--duration "$DURATION")
[ -n "$FROM" ] && launch+=(--replay-arg --start --replay-arg "$FROM")
[ -n "$CAM_OFFSET" ] && launch+=(--replay-arg --camera-time-offset --replay-arg "$CAM_OFFSET")
"${launch[@]}" || { echo "run_dataset.sh: the run failed (logs in $OUT/logs/)" >&2; exit 1; }

"$BUILD/tools/cvslam_eval" --run "$OUT" --align "$ALIGN" --summary-json "$OUT/summary.json" ||
  { echo "run_dataset.sh: evaluation failed" >&2; exit 1; }
if /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then
  /usr/bin/python3 "$ROOT/scripts/plot_run.py" "$OUT" > /dev/null &&
    echo "run_dataset.sh: plots in $OUT/plots/"
else
  echo "run_dataset.sh: no plots (python3-matplotlib missing: scripts/setup.sh installs it)"
fi
echo "run_dataset.sh: run in $OUT (summary: $OUT/summary.json)"
