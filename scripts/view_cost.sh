#!/usr/bin/env bash
# What cvslam_view costs (docs/view.md): a 5-UAV team (config/scenarios/team5.yaml with the
# cameras at 20 Hz), DC, features, replayed in real time (--rate 1), watched by cvslam_view with
# viewers connected; prints the view's CPU time as a share of one core, and the load on the
# machine meanwhile.
#
#   scripts/view_cost.sh [--duration S] [--viewers N] [--sensing features|images] [--build DIR]
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="$ROOT/build" DURATION=30 VIEWERS=1 SENSING=features
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --duration) DURATION="$2"; shift 2 ;;
    --viewers) VIEWERS="$2"; shift 2 ;;
    --sensing) SENSING="$2"; shift 2 ;;
    --build) BUILD="$2"; shift 2 ;;
    *) echo "view_cost.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
done
VIEW="$BUILD/view/cvslam_view"
[ -x "$VIEW" ] || { echo "view_cost.sh: $VIEW not built" >&2; exit 2; }
TMP=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$TMP"' EXIT
sed 's/camera_rate_hz: *10.0/camera_rate_hz: 20.0/' "$ROOT/config/scenarios/team5.yaml" > "$TMP/team5_20hz.yaml"
URL='udpm://239.255.76.67:7695?ttl=0&recv_buf_size=16777216'
PORT=18095
"$VIEW" --lcm-url "$URL" --port "$PORT" --quiet > "$TMP/view.out" 2>&1 &
VIEW_PID=$!
sleep 0.5
for i in $(seq "$VIEWERS"); do curl -sN "http://127.0.0.1:$PORT/events" > "$TMP/events_$i" & done
ticks() { awk '{print $14 + $15}' "/proc/$VIEW_PID/stat"; }
hz=$(getconf CLK_TCK)
t0=$(date +%s.%N); c0=$(ticks)
"$ROOT/scripts/launch.sh" --scenario "$TMP/team5_20hz.yaml" --mode dc --sensing "$SENSING" \
  --rate 1 --duration "$DURATION" --lcm-url "$URL" --build "$BUILD" --out "$TMP/run" > "$TMP/launch.log" 2>&1 &
LAUNCH=$!
# Load on the machine while the team runs.
read -r _ u1 n1 s1 i1 _ < /proc/stat
sleep "$DURATION"
read -r _ u2 n2 s2 i2 _ < /proc/stat
wait "$LAUNCH" || echo "view_cost.sh: the team run failed (see below)" >&2
t1=$(date +%s.%N); c1=$(ticks)
busy=$(( (u2 + n2 + s2) - (u1 + n1 + s1) )); total=$(( busy + i2 - i1 ))
frames=$(grep -h "^cvslam_agent" "$TMP/run/logs/"agent_*.out | sed -E 's/.*: ([0-9]+) frames.*/\1/' | paste -sd+ - | bc)
events=$(cat "$TMP"/events_* | grep -c '^data: ' || true)
awk -v c0="$c0" -v c1="$c1" -v hz="$hz" -v t0="$t0" -v t1="$t1" -v busy="$busy" -v total="$total" \
    -v frames="$frames" -v events="$events" -v viewers="$VIEWERS" -v sensing="$SENSING" 'BEGIN {
  cpu = (c1 - c0) / hz; wall = t1 - t0;
  printf "cvslam_view, 5 UAVs at 20 Hz (%s, DC, --rate 1), %d viewer(s): %.2f s CPU in %.1f s wall = %.1f %% of one core\n", sensing, viewers, cpu, wall, 100 * cpu / wall;
  printf "  team frames estimated: %d; events pushed: %d; machine busy meanwhile: %.0f %% of 2 cores\n", frames, events, 100 * busy / total;
}'
grep -h "^launch.sh: .*failed" "$TMP/launch.log" || true
