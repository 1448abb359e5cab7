#!/usr/bin/env bash
# A team on separate "hosts" on this machine (docs/transport.md "Multi-host runs"): each UAV in
# its own Linux network namespace with its own replay and agent; the sensor streams stay on the
# namespace's loopback (the vehicle), the cooperation crosses a bridge as on a LAN (LCM ttl=1,
# its own multicast group), and each UAV's link is shaped: loss always (tc netem on departure,
# or nftables on arrival where the kernel has no netem), delay and jitter with netem. Replays start on one wall clock.
# Prints, per loss level, ATE per UAV, cooperation bytes/s and request timeouts (retries).
#
#   sudo scripts/netns_team.sh --scenario config/scenarios/team3_aerial.yaml --out runs/net \
#        --loss-levels 0,5,20,40 --delay 50 --jitter 10
#
# options:
#   --scenario FILE       scenario (features; the agents take calibration from it)     [required]
#   --out DIR             runs in DIR/loss_<L>/, a table in DIR/loss_table.md             [required]
#   --agents LIST         UAV ids (default: the scenario's)
#   --loss-levels LIST    loss in % on each cooperation link, one run per level (default 0)
#   --delay MS, --jitter MS   netem delay and jitter per link (default 0)
#   --duration S, --seed N    passed to replays and agents
#   --mode dc             cooperation mode (dc)
#   --auth-key FILE       sign cooperation with this team key (docs/transport.md)
#   --build DIR           where the programs are (default build/)
# Needs root, iproute2 and, without netem, nftables (apt-get install nftables).
set -uo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="$ROOT/build" SCENARIO="" OUT="" AGENTS="" LEVELS=0 DELAY=0 JITTER=0 DURATION="" SEED=""
MODE=dc AUTH=""
die() { echo "netns_team.sh: $*" >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) sed -n '2,/^set -uo/p' "$0" | grep '^#' | sed 's/^# \{0,1\}//'; exit 0 ;;
    --scenario) SCENARIO="${2:?}"; shift 2 ;;
    --out) OUT="${2:?}"; shift 2 ;;
    --agents) AGENTS="${2:?}"; shift 2 ;;
    --loss-levels) LEVELS="${2:?}"; shift 2 ;;
    --delay) DELAY="${2:?}"; shift 2 ;;
    --jitter) JITTER="${2:?}"; shift 2 ;;
    --duration) DURATION="${2:?}"; shift 2 ;;
    --seed) SEED="${2:?}"; shift 2 ;;
    --mode) MODE="${2:?}"; shift 2 ;;
    --auth-key) AUTH="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift 2 ;;
    --build) BUILD="${2:?}"; shift 2 ;;
    *) die "unknown option '$1' (try --help)" ;;
  esac
done
[ -n "$SCENARIO" ] && [ -n "$OUT" ] || die "--scenario and --out are required (try --help)"
[ "$(id -u)" -eq 0 ] || die "needs root (network namespaces)"
[ "$MODE" = dc ] || die "--mode: only dc crosses the namespaces (cc needs the agents' POSE at the ground station)"
[ -z "$AGENTS" ] && AGENTS=$(grep -E '^\s*-\s*id:\s*[0-9]+' "$SCENARIO" | grep -oE '[0-9]+' | paste -sd, -)
for exe in sensors_replay/cvslam_replay agent/cvslam_agent tools/cvslam_eval; do
  [ -x "$BUILD/$exe" ] || die "$BUILD/$exe not built"
done
mkdir -p "$OUT" || die "cannot create $OUT"
OUT="$(cd "$OUT" && pwd)"; SCENARIO="$(cd "$(dirname "$SCENARIO")" && pwd)/$(basename "$SCENARIO")"
SENSORS='udpm://239.255.76.67:7667?ttl=0'   # the vehicle's own loopback
COOP='udpm://239.255.77.67:7667?ttl=1'      # the team's LAN
LAN=cvlan

teardown() {
  for id in ${AGENTS//,/ }; do ip netns pids "cvuav$id" 2>/dev/null | xargs -r kill 2>/dev/null; done
  for id in ${AGENTS//,/ }; do ip netns del "cvuav$id" 2>/dev/null; done
  ip netns del "$LAN" 2>/dev/null
  true
}
trap 'teardown' EXIT INT TERM

# The LAN: a bridge in its own namespace, one veth per UAV.
setup() {  # loss%
  local loss="$1" shaped=netem
  teardown
  ip netns add "$LAN" && ip -n "$LAN" link add br0 type bridge mcast_snooping 0 &&
    ip -n "$LAN" link set br0 up || die "cannot create the LAN namespace"
  for id in ${AGENTS//,/ }; do
    local ns="cvuav$id"
    ip netns add "$ns"
    ip link add "v$id" netns "$LAN" type veth peer name eth0 netns "$ns"
    ip -n "$LAN" link set "v$id" master br0 up
    ip -n "$ns" addr add "10.77.0.$id/24" dev eth0
    ip -n "$ns" link set eth0 up multicast on
    ip -n "$ns" link set lo up multicast on
    ip -n "$ns" route add 239.255.76.0/24 dev lo
    ip -n "$ns" route add 239.255.77.0/24 dev eth0
    # The link: netem if the kernel has it, else loss by nftables (no delay then).
    if ! ip netns exec "$ns" tc qdisc add dev eth0 root netem loss "${loss}%" \
         delay "${DELAY}ms" "${JITTER}ms" 2>/dev/null; then
      shaped=nftables
      command -v nft >/dev/null || die "no netem in this kernel and no nft (apt-get install nftables)"
      # On arrival, not on departure: a packet dropped in the output hook fails the sender's
      # sendto() (EPERM), which a radio loss never does.
      ip netns exec "$ns" nft add table inet cvlink
      ip netns exec "$ns" nft "add chain inet cvlink in { type filter hook input priority 0; }"
      [ "$loss" != 0 ] && ip netns exec "$ns" nft add rule inet cvlink in iifname eth0 \
        numgen random mod 100 \< "$loss" drop
    fi
  done
  echo "$shaped"
}

run_level() {  # loss% → DIR/loss_<L>
  local loss="$1" dir="$OUT/loss_$1" shaped
  rm -rf "$dir"; mkdir -p "$dir/logs"
  shaped=$(setup "$loss") || exit 2
  if [ "$shaped" = nftables ] && { [ "$DELAY" != 0 ] || [ "$JITTER" != 0 ]; }; then
    echo "netns_team.sh: this kernel has no netem: ${loss} % loss by nftables, delay/jitter not applied" >&2
  fi
  local start_at=$(( $(date +%s) + 3 )) pids=()
  for id in ${AGENTS//,/ }; do
    local ns="cvuav$id" extra=()
    [ -n "$DURATION" ] && extra+=(--duration "$DURATION")
    [ -n "$SEED" ] && extra+=(--seed "$SEED")
    local agent=("$BUILD/agent/cvslam_agent" --id "$id" --mode "$MODE" --scenario "$SCENARIO"
                 --lcm-url "$SENSORS" --coop-lcm-url "$COOP" --out "$dir" --idle-exit 3 "${extra[@]}")
    [ -n "$AUTH" ] && agent+=(--auth-key "$AUTH")
    ip netns exec "$ns" "${agent[@]}" > "$dir/logs/agent_$id.out" 2> "$dir/logs/agent_$id.err" &
    pids+=($!)
    ip netns exec "$ns" "$BUILD/sensors_replay/cvslam_replay" --scenario "$SCENARIO" --sensing features \
      --agents "$id" --rate 1 --start-at "$start_at" --lcm-url "$SENSORS" --quiet "${extra[@]}" \
      > "$dir/logs/replay_$id.out" 2> "$dir/logs/replay_$id.err" &
    pids+=($!)
  done
  local failed=0
  for p in "${pids[@]}"; do wait "$p" || failed=1; done
  [ $failed -eq 0 ] || echo "netns_team.sh: a process failed at ${loss} % (logs in $dir/logs)" >&2
  "$BUILD/tools/cvslam_eval" --run "$dir" --summary-json "$dir/summary.json" > /dev/null ||
    echo "netns_team.sh: evaluation failed at ${loss} %" >&2
  echo "$shaped" > "$dir/link.txt"
}

for loss in ${LEVELS//,/ }; do
  echo "netns_team.sh: ${loss} % loss, delay ${DELAY} ms ± ${JITTER} ms, UAVs $AGENTS"
  run_level "$loss"
done
teardown

/usr/bin/python3 - "$OUT" "$LEVELS" "$AGENTS" "$DELAY" "$JITTER" <<'PY'
import json, os, re, sys
out, levels, agents, delay, jitter = sys.argv[1], sys.argv[2].split(","), sys.argv[3].split(","), sys.argv[4], sys.argv[5]
rows, base = [], {}
for loss in levels:
    d = os.path.join(out, "loss_" + loss)
    try:
        s = json.load(open(os.path.join(d, "summary.json")))["agents"]
    except (OSError, ValueError, KeyError):
        s = {}
    link = open(os.path.join(d, "link.txt")).read().strip() if os.path.exists(os.path.join(d, "link.txt")) else "?"
    for a in agents:
        ate = s.get(a, {}).get("ate_rmse_m")
        log = open(os.path.join(d, "logs", "agent_%s.out" % a)).read() if os.path.exists(os.path.join(d, "logs", "agent_%s.out" % a)) else ""
        def num(label):
            m = re.search(label + r" (\d+)", log)
            return int(m.group(1)) if m else None
        m = re.search(r"; (\d+) B/s", log)
        bps = int(m.group(1)) if m else None
        if loss == levels[0] and ate is not None: base[a] = ate
        change = "" if ate is None or a not in base else "%+.1f %%" % (100 * (ate / base[a] - 1))
        m = re.search(r"links \(received/expected\) (.*)", log)
        heard = m.group(1).replace(", ", "; ") if m else "?"
        rows.append("| %s | %s | UAV%s | %s | %s | %s | %s | %s | %s | %s |" % (
            loss, link, a, "%.3f" % ate if ate is not None else "failed", change,
            bps if bps is not None else "?", num("exchanges"), num("request timeouts"),
            num("landmarks fused"), heard))
table = ["| loss %% | link | UAV | ATE [m] | vs %s %% | coop B/s | exchanges | request timeouts | fused | heard from peers (received/expected) |" % levels[0],
         "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"] + rows
text = "\n".join(table)
open(os.path.join(out, "loss_table.md"), "w").write(
    "Delay %s ms, jitter %s ms (netem only).\n\n" % (delay, jitter) + text + "\n")
print(text)
PY
