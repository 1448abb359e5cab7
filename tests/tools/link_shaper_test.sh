#!/usr/bin/env bash
# cvslam_link_shaper on real packets (docs/transport.md "Multi-host runs"): two network
# namespaces joined by a veth pair; on the receiver, iptables queues what arrives to the
# shaper (loss 20 %, delay 50 ms ± 10 ms); 1000 UDP datagrams, each stamped with its send
# time, cross at 2 ms intervals. Checks no datagram leaves early (every delay ≥ 40 ms), 99 % of
# them within [40, 60] ms + 2 ms of scheduling (a single late wake-up on a loaded 2-core CI
# machine reached 67 ms; lateness of one packet is the host's, not the shaper's), their mean
# is 50 ± 3 ms, their spread is that of a uniform ±10 ms, the loss is 20 ± 4 % (3.2 σ of a
# binomial on 1000), jitter larger than the interval reorders, and the shaper's own counters
# agree with what the receiver saw.
# Needs root and network namespaces: without them skipped (77), or failed under CI=true
# (tests/tools/ci_facility.sh).
set -uo pipefail
BUILD="$1" OUT="$2"
SHAPER="$BUILD/tools/cvslam_link_shaper"
source "$(dirname "$0")/ci_facility.sh"
[ "$(id -u)" -eq 0 ] || missing_facility link_shaper_test "needs root (network namespaces)"
# Namespaces left by a killed run are not a missing facility: remove them first.
ip netns pids cvshape_b 2>/dev/null | xargs -r kill 2>/dev/null
ip netns del cvshape_a 2>/dev/null; ip netns del cvshape_b 2>/dev/null
err=$(ip netns add cvshape_a 2>&1) ||
  missing_facility link_shaper_test "cannot create a network namespace as root: $err"
[ -x "$SHAPER" ] || { echo "link_shaper_test: $SHAPER not built"; ip netns del cvshape_a; exit 1; }
command -v iptables >/dev/null || { echo "link_shaper_test: no iptables"; ip netns del cvshape_a; exit 1; }
cleanup() {
  ip netns pids cvshape_b 2>/dev/null | xargs -r kill 2>/dev/null
  ip netns del cvshape_a 2>/dev/null; ip netns del cvshape_b 2>/dev/null; true
}
trap cleanup EXIT
rm -rf "$OUT"; mkdir -p "$OUT"
ip netns add cvshape_b
ip link add veth_a netns cvshape_a type veth peer name veth_b netns cvshape_b
ip -n cvshape_a addr add 10.78.0.1/24 dev veth_a && ip -n cvshape_a link set veth_a up
ip -n cvshape_b addr add 10.78.0.2/24 dev veth_b && ip -n cvshape_b link set veth_b up
# iptables' NFQUEUE target (nft's own `queue` statement needs CONFIG_NFT_QUEUE, which some
# kernels lack; the xt target reaches the same queue through nft's compat layer).
ip netns exec cvshape_b iptables -A INPUT -i veth_b -p udp --dport 47000 -j NFQUEUE --queue-num 3
ip netns exec cvshape_b "$SHAPER" --queue 3 --loss 20 --delay 50 --jitter 10 --seed 5 \
  --ready-file "$OUT/ready" --stats-json "$OUT/shaper.json" > "$OUT/shaper.out" 2>&1 &
SHAPER_PID=$!
for _ in $(seq 50); do [ -e "$OUT/ready" ] && break; sleep 0.1; done
[ -e "$OUT/ready" ] || { echo "link_shaper_test: the shaper never bound its queue"; cat "$OUT/shaper.out"; exit 1; }

ip netns exec cvshape_b /usr/bin/python3 - "$OUT/received.txt" <<'PY' &
import socket, struct, sys, time
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.bind(("10.78.0.2", 47000)); s.settimeout(3.0)
out = open(sys.argv[1], "w")
try:
    while True:
        data = s.recv(64)
        seq, sent = struct.unpack("!Id", data[:12])
        out.write("%d %.6f\n" % (seq, time.time() - sent))
except socket.timeout:
    pass
PY
RECEIVER=$!
sleep 0.5
ip netns exec cvshape_a /usr/bin/python3 - <<'PY'
import socket, struct, time
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
for seq in range(1000):
    s.sendto(struct.pack("!Id", seq, time.time()) + b"x" * 100, ("10.78.0.2", 47000))
    time.sleep(0.002)
PY
wait $RECEIVER
kill -TERM $SHAPER_PID; wait $SHAPER_PID
/usr/bin/python3 - "$OUT/received.txt" "$OUT/shaper.json" <<'PY'
import json, statistics, sys
rows = [l.split() for l in open(sys.argv[1])]
seqs = [int(r[0]) for r in rows]; delays = [1000 * float(r[1]) for r in rows]
stats = json.load(open(sys.argv[2]))
loss = 100.0 * (1000 - len(set(seqs))) / 1000
reordered = sum(1 for a, b in zip(seqs, seqs[1:]) if b < a)
mean, sd = statistics.mean(delays), statistics.pstdev(delays)
print("received %d/1000 (loss %.1f %%), delay mean %.1f ms sd %.2f ms min %.1f max %.1f, "
      "%d arrivals out of order; shaper %s" % (len(seqs), loss, mean, sd, min(delays),
      max(delays), reordered, stats))
fail = []
if not 16 <= loss <= 24: fail.append("loss %.1f %% not 20 ± 4 %%" % loss)
if abs(mean - 50) > 3: fail.append("mean delay %.1f ms not 50 ± 3" % mean)
# Uniform ±10 ms: sd 10/√3 = 5.77 ms; scheduling adds a little.
if not 4.5 <= sd <= 7.5: fail.append("delay sd %.2f ms not that of ±10 ms" % sd)
q99 = sorted(delays)[int(0.99 * (len(delays) - 1))]
if min(delays) < 39.5: fail.append("a datagram left %.1f ms early" % (40 - min(delays)))
if q99 > 62: fail.append("99th percentile delay %.1f ms beyond 60 ms + slack" % q99)
if max(delays) > 150: fail.append("a datagram held %.1f ms (stuck queue)" % max(delays))
if reordered == 0: fail.append("jitter of ±10 ms at 2 ms spacing reordered nothing")
if stats["packets"] != 1000 or stats["dropped"] != 1000 - len(seqs):
    fail.append("shaper counters disagree with the receiver")
for f in fail: print("FAIL: " + f)
sys.exit(1 if fail else 0)
PY
