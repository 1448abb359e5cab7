#!/usr/bin/env bash
# The main job in one command: on a fresh machine, set up (scripts/setup.sh), build if
# needed, then fly the default 3-UAV rendered scenario (config/scenarios/team3_aerial.yaml)
# through real processes — cvslam_replay in lockstep + one cvslam_agent per UAV over LCM —
# once with decentralised cooperation (dc) and once alone (single); print a per-UAV table
# (ATE single vs DC, cooperation bytes sent per second) and write plots.
#
#   scripts/demo.sh [--out DIR] [--detector fast_sift|adaptive_sift|orb|sift]
#                   [--sensing images|features] [--duration S] [--rate R] [--build DIR]
#                   [--no-build] [--view [--view-port P]]
#
# --view: watch each run in a browser (cvslam_view; the URL is printed, default port 8088).
# --rate R: the replay paces the sensors at R × real time instead of lockstep (R = 1: the team
#   as it would fly). Each agent's closing line (printed in either pacing) gives the frames it
#   processed, the messages and frames it dropped, the latency from a frame's arrival to its
#   pose (median, p95) and the median time of each stage.
#
# Detector: the configuration's (config/agent.yaml: fast_sift, our adaptive SIFT of thesis
# §4.2.5, ≈ 10 ms per 320×240 pair). --detector adaptive_sift is the OpenCV-based reference
# (≈ 3.5× slower: lockstep only on 2 cores); ORB has its own feature-index vocabulary
# (config/vocabulary_orb.cvoc), but its map association is less precise (docs/front_end.md).
set -euo pipefail

ROOT="$(cd "$(dirname "$0")/.." && pwd)"
OUT="$ROOT/runs/demo" DETECTOR="" SENSING=images RATE="" DURATION="" BUILD="$ROOT/build" DO_BUILD=true
SCENARIO="$ROOT/config/scenarios/team3_aerial.yaml"
VIEW_ARGS=()
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --out) OUT="$2"; shift 2 ;;
    --detector) DETECTOR="$2"; shift 2 ;;
    --sensing) SENSING="$2"; shift 2 ;;
    --duration) DURATION="$2"; shift 2 ;;
    --rate) RATE="${2:?--rate needs a value}"; shift 2 ;;
    --build) BUILD="$2"; shift 2 ;;
    --no-build) DO_BUILD=false; shift ;;
    --view) VIEW_ARGS+=(--view); shift ;;
    --view-port) VIEW_ARGS+=(--view-port "$2"); shift 2 ;;
    *) echo "demo.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
done

echo "== setup"
"$ROOT/scripts/setup.sh" || { echo "demo.sh: setup incomplete (see above)" >&2; exit 1; }

echo "== build"
if $DO_BUILD && [ ! -f "$BUILD/CMakeCache.txt" ]; then
  launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" >/dev/null
fi
$DO_BUILD && cmake --build "$BUILD" -j2 --target cvslam_agent cvslam_replay cvslam_eval cvslam_view >/dev/null

extra=()
[ -n "$DURATION" ] && extra+=(--duration "$DURATION")
agent_args=()
[ "$SENSING" = images ] && [ -n "$DETECTOR" ] && agent_args+=(--agent-arg --detector --agent-arg "$DETECTOR")
pacing=(--lockstep) pacing_name=lockstep
[ -n "$RATE" ] && pacing=(--rate "$RATE") pacing_name="rate $RATE"
# A port of its own, so the demo does not mix with other LCM traffic on the default one.
URL='udpm://239.255.76.67:7690?ttl=0&recv_buf_size=16777216'
for mode in dc single; do
  echo "== $mode: replay ($pacing_name) + 3 agents, $SENSING${DETECTOR:+, $DETECTOR}"
  rm -rf "$OUT/$mode"
  start=$(date +%s)
  "$ROOT/scripts/launch.sh" --scenario "$SCENARIO" --mode "$mode" --sensing "$SENSING" \
    "${pacing[@]}" --lcm-url "$URL" --build "$BUILD" --out "$OUT/$mode" "${extra[@]}" "${agent_args[@]}" "${VIEW_ARGS[@]}"
  echo "   $(( $(date +%s) - start )) s; load average after the run: $(cut -d' ' -f1-3 /proc/loadavg)"
  "$BUILD/tools/cvslam_eval" --run "$OUT/$mode" --summary-json "$OUT/$mode/summary.json" >/dev/null
done

echo "== results ($OUT)"
/usr/bin/python3 - "$OUT" <<'PY'
import json, os, sys
out = sys.argv[1]
s = json.load(open(os.path.join(out, "single", "summary.json")))["agents"]
d = json.load(open(os.path.join(out, "dc", "summary.json")))["agents"]
def coop_rate(mode, uav):
    try:
        st = json.load(open(os.path.join(out, mode, "agent_" + uav, "stats.json")))
        return st["bytes_sent_per_s"]["cooperation"]
    except (OSError, KeyError, ValueError):
        return float("nan")
print("%-5s %14s %14s %9s %18s %12s" % ("UAV", "ATE single [m]", "ATE DC [m]", "change",
                                         "DC coop [B/s]", "INS ATE [m]"))
for uav in sorted(set(s) | set(d), key=int):
    a, b = s.get(uav, {}).get("ate_rmse_m"), d.get(uav, {}).get("ate_rmse_m")
    ins = s.get(uav, {}).get("ins_ate_rmse_m")
    change = "%+.0f %%" % (100.0 * (b - a) / a) if a and b is not None else "-"
    fmt = lambda x: "%.3f" % x if x is not None else "-"
    print("%-5s %14s %14s %9s %18.0f %12s" % (uav, fmt(a), fmt(b), change, coop_rate("dc", uav),
                                             fmt(ins)))
PY
for mode in dc single; do
  /usr/bin/python3 "$ROOT/scripts/plot_run.py" "$OUT/$mode" >/dev/null && echo "plots: $OUT/$mode/plots/"
done
