#!/usr/bin/env bash
# A team on separate "hosts" on this machine (docs/transport.md "Multi-host runs"): each UAV in
# its own Linux network namespace with its own replay and agent; the sensor streams stay on the
# namespace's loopback (the vehicle), the cooperation crosses a bridge as on a LAN (LCM ttl=1,
# its own multicast group), and each UAV's link is shaped on arrival: loss, delay and jitter by
# tc netem where the kernel has it, else by cvslam_link_shaper (netem in user space, on an
# iptables NFQUEUE). Replays start on one wall clock.
# Prints, per loss level, ATE per UAV (mean and range over --repeats loss patterns),
# cooperation bytes/s, request timeouts (retries) and what the links did.
#
#   sudo scripts/netns_team.sh --scenario config/scenarios/team3_aerial.yaml --out runs/net \
#        --loss-levels 0,5,20,40 --delay 50 --jitter 10 --repeats 3
#
# options:
#   --scenario FILE       scenario (features; the agents take calibration from it)     [required]
#   --out DIR             runs in DIR/loss_<L>[_r<k>]/, a table in DIR/loss_table.md      [required]
#   --agents LIST         UAV ids (default: the scenario's)
#   --loss-levels LIST    loss in % on each cooperation link, one run per level (default 0)
#   --delay MS, --jitter MS   delay and jitter per link (uniform in delay ± jitter; default 0)
#   --repeats K           runs per level, each with other loss/jitter draws (default 1)
#   --link-seed N         seed of the first repeat's draws (default 1)
#   --duration S, --seed N    passed to replays and agents
#   --mode dc             cooperation mode (dc)
#   --auth-key FILE       sign cooperation with this team key (docs/transport.md)
#   --build DIR           where the programs are (default build/)
# Needs root, iproute2 and, without netem, iptables and cvslam_link_shaper (built where
# libnetfilter-queue-dev is installed); with neither, loss only, by nftables.
set -uo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="$ROOT/build" SCENARIO="" OUT="" AGENTS="" LEVELS=0 DELAY=0 JITTER=0 DURATION="" SEED=""
MODE=dc AUTH="" REPEATS=1 LINK_SEED=1
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
    --repeats) REPEATS="${2:?}"; shift 2 ;;
    --link-seed) LINK_SEED="${2:?}"; shift 2 ;;
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
[[ "$REPEATS" =~ ^[1-9][0-9]*$ ]] || die "--repeats must be a whole number ≥ 1, not '$REPEATS'"
[[ "$LINK_SEED" =~ ^[0-9]+$ ]] || die "--link-seed must be a whole number, not '$LINK_SEED'"
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
  local loss="$1" shaped
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
    # The link: netem if the kernel has it; else cvslam_link_shaper on an NFQUEUE of what
    # arrives on eth0 (started by run_level); else loss by nftables, no delay.
    if ip netns exec "$ns" tc qdisc add dev eth0 root netem loss "${loss}%" \
         delay "${DELAY}ms" "${JITTER}ms" 2>/dev/null; then
      shaped=netem
    elif [ -x "$BUILD/tools/cvslam_link_shaper" ] && command -v iptables >/dev/null &&
         ip netns exec "$ns" iptables -A INPUT -i eth0 -j NFQUEUE --queue-num 0 2>/dev/null; then
      # On arrival, not on departure: a packet dropped on the way out fails the sender's
      # sendto() (EPERM), which a radio loss never does.
      shaped=shaper
    else
      shaped=nftables
      command -v nft >/dev/null || die "no netem, no link shaper and no nft to drop packets"
      ip netns exec "$ns" nft add table inet cvlink
      ip netns exec "$ns" nft "add chain inet cvlink in { type filter hook input priority 0; }"
      [ "$loss" != 0 ] && ip netns exec "$ns" nft add rule inet cvlink in iifname eth0 \
        numgen random mod 100 \< "$loss" drop
    fi
  done
  echo "$shaped"
}

# The links' delay as packets see it, whatever shapes them: 40 UDP datagrams, one every 20 ms,
# from the first UAV to the second, which echoes them (each way shaped on arrival, or by netem
# on departure: the round trip is twice a link's delay) → DIR/logs/link_rtt.json.
probe_link() {  # DIR
  local ids=(${AGENTS//,/ }) echo_pid
  [ ${#ids[@]} -ge 2 ] || return 0
  ip netns exec "cvuav${ids[1]}" /usr/bin/python3 -c '
import socket, sys
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM); s.bind((sys.argv[1], 47100)); s.settimeout(2.0)
try:
    while True:
        data, peer = s.recvfrom(64); s.sendto(data, peer)
except socket.timeout:
    pass' "10.77.0.${ids[1]}" &
  echo_pid=$!
  sleep 0.3
  ip netns exec "cvuav${ids[0]}" /usr/bin/python3 - "10.77.0.${ids[1]}" "$1/logs/link_rtt.json" <<'PY'
import json, select, socket, struct, sys, time
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
sent, rtts, next_send, end = 0, [], time.time(), None
while end is None or time.time() < end:
    now = time.time()
    if sent < 40 and now >= next_send:
        s.sendto(struct.pack("!d", now), (sys.argv[1], 47100)); sent += 1; next_send += 0.02
        if sent == 40: end = now + 1.0
    if select.select([s], [], [], 0.002)[0]:
        rtts.append(1000.0 * (time.time() - struct.unpack("!d", s.recv(64)[:8])[0]))
json.dump({"sent": sent, "received": len(rtts),
           "mean_rtt_ms": sum(rtts) / len(rtts) if rtts else None,
           "min_rtt_ms": min(rtts) if rtts else None}, open(sys.argv[2], "w"))
PY
  wait "$echo_pid"
}

run_level() {  # loss% repeat → DIR/loss_<L>[_r<k>]
  local loss="$1" repeat="$2" dir="$OUT/loss_$1" shaped link_seed=$((LINK_SEED + $2))
  [ "$REPEATS" -gt 1 ] && dir="$OUT/loss_${loss}_r$repeat"
  rm -rf "$dir"; mkdir -p "$dir/logs"
  shaped=$(setup "$loss") || exit 2
  if [ "$shaped" = nftables ] && { [ "$DELAY" != 0 ] || [ "$JITTER" != 0 ]; }; then
    echo "netns_team.sh: no netem and no link shaper: ${loss} % loss by nftables, delay/jitter not applied" >&2
  fi
  local shapers=()
  if [ "$shaped" = shaper ]; then
    for id in ${AGENTS//,/ }; do
      ip netns exec "cvuav$id" "$BUILD/tools/cvslam_link_shaper" --queue 0 --loss "$loss" \
        --delay "$DELAY" --jitter "$JITTER" --seed $((link_seed * 100 + id)) \
        --ready-file "$dir/logs/link_$id.ready" --stats-json "$dir/logs/link_$id.json" \
        > "$dir/logs/link_$id.out" 2>&1 &
      shapers+=($!)
    done
    for id in ${AGENTS//,/ }; do
      for _ in $(seq 50); do [ -e "$dir/logs/link_$id.ready" ] && break; sleep 0.1; done
      [ -e "$dir/logs/link_$id.ready" ] || die "UAV$id's link shaper did not start: $(cat "$dir/logs/link_$id.out")"
    done
  fi
  probe_link "$dir"
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
  for p in "${shapers[@]}"; do kill -TERM "$p" 2>/dev/null; wait "$p"; done
  [ $failed -eq 0 ] || echo "netns_team.sh: a process failed at ${loss} % (logs in $dir/logs)" >&2
  "$BUILD/tools/cvslam_eval" --run "$dir" --summary-json "$dir/summary.json" > /dev/null ||
    echo "netns_team.sh: evaluation failed at ${loss} %" >&2
  echo "$shaped" > "$dir/link.txt"
}

for loss in ${LEVELS//,/ }; do
  for repeat in $(seq 0 $((REPEATS - 1))); do
    echo "netns_team.sh: ${loss} % loss, delay ${DELAY} ms ± ${JITTER} ms, UAVs $AGENTS, repeat $((repeat + 1))/$REPEATS"
    run_level "$loss" "$repeat"
  done
done
teardown

/usr/bin/python3 - "$OUT" "$LEVELS" "$AGENTS" "$DELAY" "$JITTER" "$REPEATS" <<'PY'
import json, math, os, re, statistics, sys
out, levels, agents = sys.argv[1], sys.argv[2].split(","), sys.argv[3].split(",")
delay, jitter, repeats = sys.argv[4], sys.argv[5], int(sys.argv[6])

def read(path):
    return open(path).read() if os.path.exists(path) else ""

def run_dirs(loss):
    if repeats == 1:
        return [os.path.join(out, "loss_" + loss)]
    return [os.path.join(out, "loss_%s_r%d" % (loss, k)) for k in range(repeats)]

def number(text, label):
    m = re.search(label + r" (\d+)", text)
    return int(m.group(1)) if m else None

def mean(xs):
    xs = [x for x in xs if x is not None]
    return statistics.mean(xs) if xs else None

rows, base, links = [], {}, []
for loss in levels:
    per = {a: {"ate": [], "bps": [], "exchanges": [], "timeouts": [], "fused": [], "errors": []}
           for a in agents}
    kinds, packets, dropped, delays, reordered = set(), 0, 0, [], 0
    for d in run_dirs(loss):
        try:
            s = json.load(open(os.path.join(d, "summary.json")))["agents"]
        except (OSError, ValueError, KeyError):
            s = {}
        kinds.add(read(os.path.join(d, "link.txt")).strip() or "?")
        for a in agents:
            log = read(os.path.join(d, "logs", "agent_%s.out" % a))
            ate = s.get(a, {}).get("ate_rmse_m")
            per[a]["ate"].append(ate if ate is not None and math.isfinite(ate) else None)
            m = re.search(r"; (\d+) B/s", log)
            per[a]["bps"].append(int(m.group(1)) if m else None)
            per[a]["exchanges"].append(number(log, "exchanges"))
            per[a]["timeouts"].append(number(log, "request timeouts"))
            per[a]["fused"].append(number(log, "landmarks fused"))
            per[a]["errors"].append(number(log, "errors"))
            try:
                link = json.loads(read(os.path.join(d, "logs", "link_%s.json" % a)))
                packets += link["packets"]; dropped += link["dropped"]; reordered += link["reordered"]
                delays.append(link["mean_delay_ms"])
            except ValueError:
                pass
    if packets:
        links.append("| %s | %d | %.1f %% | %.1f ms | %d |" % (
            loss, packets, 100.0 * dropped / packets, mean(delays), reordered))
    for a in agents:
        v = per[a]
        ates = [x for x in v["ate"] if x is not None]
        ate = mean(ates)
        if loss == levels[0] and ate is not None:
            base[a] = ate
        change = "" if ate is None or a not in base else "%+.1f %%" % (100 * (ate / base[a] - 1))
        spread = "%.3f–%.3f" % (min(ates), max(ates)) if len(ates) > 1 else ""
        failed = len(v["ate"]) - len(ates)
        fmt = lambda key: "%.1f" % mean(v[key]) if mean(v[key]) is not None else "?"
        rows.append("| %s | %s | UAV%s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            loss, "/".join(sorted(kinds)), a, "%.3f" % ate if ate is not None else "failed",
            spread, change, fmt("bps"), fmt("exchanges"), fmt("timeouts"), fmt("fused"),
            "%d" % (sum(e or 0 for e in v["errors"]) + failed)))
head = ["| loss %% | link | UAV | ATE [m] (mean of %d) | range | vs %s %% | coop B/s | exchanges | "
        "request timeouts | fused | errors + invalid |" % (repeats, levels[0]),
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
text = "\n".join(head + rows)
if links:
    text += ("\n\nWhat the links did (cvslam_link_shaper, all UAVs and repeats):\n\n"
             "| loss % | packets | dropped | mean delay | overtaken |\n| --- | --- | --- | --- | --- |\n"
             + "\n".join(links))
open(os.path.join(out, "loss_table.md"), "w").write(
    "Delay %s ms, jitter ±%s ms, %d run(s) per level.\n\n" % (delay, jitter, repeats) + text + "\n")
print(text)
PY
