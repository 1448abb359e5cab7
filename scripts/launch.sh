#!/usr/bin/env bash
# Starts a team on one host: cvslam_replay (a scenario or EuRoC folders, at a rate or in
# lockstep) + one cvslam_agent per UAV (+ cvslam_ground_station with --ground-station or
# --mode cc), each logging to OUT/logs/<process>.{out,err}. Ctrl-C stops them all. Exit status:
# 0 when every process succeeded, 1 otherwise (the failed ones are named).
#
#   scripts/launch.sh --scenario config/scenarios/team3_aerial.yaml --out runs/team3 --lockstep
#   scripts/launch.sh --dataset 1:data/uav1 --dataset 2:data/uav2 --mode dc --rate 1 --out runs/d
#   scripts/launch.sh --scenario config/scenarios/team3_aerial.yaml --mode cc --sensing features --out runs/cc
#
# options:
#   --out DIR              run folder (agents write DIR/agent_<id>/, logs in DIR/logs/) [required]
#   --scenario FILE        live simulation (agents take calibration and initial estimate from it)
#   --dataset ID:PATH      EuRoC folder of UAV ID (repeatable; agents read PATH's sensor.yaml)
#   --agents LIST          UAV ids to start (default: the scenario's or the datasets' ids)
#   --mode single|dc|cc    cooperation mode of the agents (default single); cc starts the
#                          ground station too
#   --ground-station       also start cvslam_ground_station (it writes OUT/ground_station/; in
#                          lockstep the replay waits for it as participant 0)
#   --sensing KIND         scenario: features | images (default: images)
#   --rate R | --lockstep  replay pacing (default --lockstep)
#   --lcm-url URL          LCM provider (default: port 7667, loopback, 16 MB receive buffer)
#   --build DIR            where the programs are (default: build/ of the repository)
#   --config FILE          agent configuration (default config/agent.yaml)
#   --duration S, --seed N passed to the replay (and, for scenarios, to the agents)
#   --agent-arg ARG        extra argument for every agent (repeatable), e.g. --detector orb
#   --gs-arg ARG           extra argument for the ground station (repeatable), e.g. --config F
#   --replay-arg ARG       extra argument for the replay (repeatable), e.g. --start 10
#   --view                 also start cvslam_view, the team in a browser page (its URL is
#                          printed); it stops with the run: `cvslam_view --run DIR` shows it again
#   --view-port P          cvslam_view's HTTP port (default 8088)
set -uo pipefail

ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="$ROOT/build"
OUT="" SCENARIO="" MODE=single SENSING=images PACING=(--lockstep) AGENTS=""
URL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216'
CONFIG="" DURATION="" SEED="" WITH_GS=false WITH_VIEW=false VIEW_PORT=8088
DATASETS=() AGENT_EXTRA=() GS_EXTRA=() REPLAY_EXTRA=()

die() { echo "launch.sh: $*" >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) sed -n '2,/^set -uo/p' "$0" | grep '^#' | sed 's/^# \{0,1\}//'; exit 0 ;;
    --out) OUT="${2:?--out needs a value}"; shift 2 ;;
    --scenario) SCENARIO="${2:?--scenario needs a value}"; shift 2 ;;
    --dataset) DATASETS+=("${2:?--dataset needs ID:PATH}"); shift 2 ;;
    --agents) AGENTS="${2:?--agents needs a list}"; shift 2 ;;
    --mode) MODE="${2:?--mode needs a value}"; shift 2 ;;
    --ground-station) WITH_GS=true; shift ;;
    --sensing) SENSING="${2:?--sensing needs a value}"; shift 2 ;;
    --rate) PACING=(--rate "${2:?--rate needs a value}"); shift 2 ;;
    --lockstep) PACING=(--lockstep); shift ;;
    --lcm-url) URL="${2:?--lcm-url needs a value}"; shift 2 ;;
    --build) BUILD="${2:?--build needs a value}"; shift 2 ;;
    --config) CONFIG="${2:?--config needs a value}"; shift 2 ;;
    --duration) DURATION="${2:?--duration needs a value}"; shift 2 ;;
    --seed) SEED="${2:?--seed needs a value}"; shift 2 ;;
    --agent-arg) AGENT_EXTRA+=("${2:?--agent-arg needs a value}"); shift 2 ;;
    --gs-arg) GS_EXTRA+=("${2:?--gs-arg needs a value}"); shift 2 ;;
    --replay-arg) REPLAY_EXTRA+=("${2:?--replay-arg needs a value}"); shift 2 ;;
    --view) WITH_VIEW=true; shift ;;
    --view-port) VIEW_PORT="${2:?--view-port needs a value}"; shift 2 ;;
    *) die "unknown option '$1' (try --help)" ;;
  esac
done
[ -n "$OUT" ] || die "--out is required (try --help)"
if [ -n "$SCENARIO" ] && [ ${#DATASETS[@]} -gt 0 ]; then die "give --scenario or --dataset, not both"; fi
if [ -z "$SCENARIO" ] && [ ${#DATASETS[@]} -eq 0 ]; then die "give --scenario FILE or --dataset ID:PATH"; fi
case "$MODE" in single|dc) ;; cc) WITH_GS=true ;; *) die "--mode must be single, dc or cc" ;; esac
REPLAY="$BUILD/sensors_replay/cvslam_replay"
AGENT="$BUILD/agent/cvslam_agent"
GS="$BUILD/ground_station/cvslam_ground_station"
VIEW="$BUILD/view/cvslam_view"
for exe in "$REPLAY" "$AGENT"; do [ -x "$exe" ] || die "$exe not built (cmake --build build)"; done
if $WITH_GS && [ ! -x "$GS" ]; then die "$GS not built (cmake --build build)"; fi
if $WITH_VIEW && [ ! -x "$VIEW" ]; then die "$VIEW not built (cmake --build build)"; fi

# Which UAVs: given, or the scenario's agent ids, or the datasets' ids.
if [ -z "$AGENTS" ]; then
  if [ -n "$SCENARIO" ]; then
    AGENTS=$(grep -E '^\s*-\s*id:\s*[0-9]+' "$SCENARIO" | grep -oE '[0-9]+' | paste -sd, -)
  else
    AGENTS=$(for d in "${DATASETS[@]}"; do echo "${d%%:*}"; done | paste -sd, -)
  fi
fi
[ -n "$AGENTS" ] || die "no agent ids (use --agents)"

mkdir -p "$OUT/logs" || die "cannot create $OUT"
PIDS=() NAMES=()
start() {  # name, command...
  local name="$1"; shift
  "$@" >"$OUT/logs/$name.out" 2>"$OUT/logs/$name.err" &
  PIDS+=($!); NAMES+=("$name")
}
stop_all() {
  for pid in "${PIDS[@]}"; do kill -TERM "$pid" 2>/dev/null; done
}
trap 'echo "launch.sh: stopping"; stop_all' INT TERM

# The viewer before anyone publishes, so the page shows the whole run.
if $WITH_VIEW; then
  start view "$VIEW" --lcm-url "$URL" --port "$VIEW_PORT" --quiet
  sleep 0.3
  kill -0 "${PIDS[-1]}" 2>/dev/null || die "cvslam_view did not start: $(tail -n 1 "$OUT/logs/view.err")"
  echo "launch.sh: the team in a browser: http://127.0.0.1:$VIEW_PORT/ (after the run: $VIEW --run $OUT)"
fi

# The ground station first: in --rate runs it must be listening when the agents start and
# publish their initial estimates (it would start them from a later POSE otherwise).
participants="$AGENTS"
if $WITH_GS; then
  gs=("$GS" --agents "$AGENTS" --lcm-url "$URL" --out "$OUT")
  # Feature-level simulation names landmarks by true id; images by each agent's own ids.
  if [ -n "$SCENARIO" ] && [ "$SENSING" = features ]; then
    gs+=(--association true_ids)
  else
    gs+=(--association local_ids)
  fi
  if [ -n "$SCENARIO" ]; then
    gs+=(--scenario "$SCENARIO")
    [ -n "$DURATION" ] && gs+=(--duration "$DURATION")
    [ -n "$SEED" ] && gs+=(--seed "$SEED")
  else
    for d in "${DATASETS[@]}"; do gs+=(--calibration "$d"); done
  fi
  start ground_station "${gs[@]}" "${GS_EXTRA[@]}"
  participants="$AGENTS,0"
fi

common=(--lcm-url "$URL")
[ -n "$CONFIG" ] && common+=(--config "$CONFIG")
for id in ${AGENTS//,/ }; do
  args=(--id "$id" --mode "$MODE" --out "$OUT" "${common[@]}" "${AGENT_EXTRA[@]}")
  if [ -n "$SCENARIO" ]; then
    args+=(--scenario "$SCENARIO")
    [ -n "$DURATION" ] && args+=(--duration "$DURATION")
    [ -n "$SEED" ] && args+=(--seed "$SEED")
  else
    path=""
    for d in "${DATASETS[@]}"; do [ "${d%%:*}" = "$id" ] && path="${d#*:}"; done
    [ -n "$path" ] || die "no --dataset for UAV $id"
    args+=(--calibration "$path")
  fi
  start "agent_$id" "$AGENT" "${args[@]}"
done
replay=("$REPLAY" "${PACING[@]}" --lcm-url "$URL" --quiet)
[ "${PACING[0]}" = --lockstep ] && replay+=(--participants "$participants")
if [ -n "$SCENARIO" ]; then
  replay+=(--scenario "$SCENARIO" --sensing "$SENSING")
  [ -n "$SEED" ] && replay+=(--seed "$SEED")
else
  for d in "${DATASETS[@]}"; do replay+=(--dataset "$d"); done
fi
[ -n "$DURATION" ] && replay+=(--duration "$DURATION")
replay+=("${REPLAY_EXTRA[@]}")
echo "launch.sh: UAVs $AGENTS, mode $MODE, ${PACING[*]}, logs in $OUT/logs/"
start replay "${replay[@]}"

# The replay ends the run; then the agents process what they hold and write their records.
# A process that fails early (bad option, no LCM) stops the whole run at once.
replay_pid="${PIDS[-1]}"
declare -A STATUS
early_failure=false
while kill -0 "$replay_pid" 2>/dev/null; do
  for i in "${!PIDS[@]}"; do
    pid="${PIDS[$i]}"
    [ "$pid" = "$replay_pid" ] && continue
    [ -n "${STATUS[$pid]:-}" ] && continue
    if ! kill -0 "$pid" 2>/dev/null; then
      wait "$pid"; STATUS[$pid]=$?
      if [ "${STATUS[$pid]}" -ne 0 ]; then early_failure=true; fi
    fi
  done
  if $early_failure; then stop_all; break; fi
  sleep 0.2
done
wait "$replay_pid"; replay_status=$?
# A trapped Ctrl-C interrupts `wait` (status > 128): wait again for the replay's own status.
if [ "$replay_status" -gt 128 ]; then wait "$replay_pid"; replay_status=$?; fi
[ "$replay_status" -ne 0 ] && ! $early_failure && echo "launch.sh: replay failed ($replay_status): $(tail -n 1 "$OUT/logs/replay.err")" >&2
$early_failure || sleep 0.5
stop_all
failed=0
[ "$replay_status" -ne 0 ] && ! $early_failure && failed=1
for i in "${!PIDS[@]}"; do
  pid="${PIDS[$i]}"
  [ "$pid" = "$replay_pid" ] && continue
  if [ -z "${STATUS[$pid]:-}" ]; then
    wait "$pid"; s=$?
    if [ "$s" -gt 128 ]; then wait "$pid"; s=$?; fi
    STATUS[$pid]=$s
  fi
  if [ "${STATUS[$pid]}" -ne 0 ]; then
    echo "launch.sh: ${NAMES[$i]} failed (${STATUS[$pid]}): $(tail -n 1 "$OUT/logs/${NAMES[$i]}.err")" >&2
    failed=1
  fi
done
for id in ${AGENTS//,/ }; do grep -h -A1 "^cvslam_agent" "$OUT/logs/agent_$id.out" 2>/dev/null; done
$WITH_GS && grep -h "^cvslam_ground_station" "$OUT/logs/ground_station.out" 2>/dev/null
exit $failed
