#!/usr/bin/env bash
# scripts/netns_team.sh end to end (docs/transport.md "Multi-host runs"): coop_pair, each UAV in
# its own network namespace, cooperation over the bridged LAN with 50 ± 10 ms of delay, without
# loss and with 20 % loss. Checks: both runs complete and evaluate with each UAV's ATE within
# ATE_MAX_M, each UAV heard the other across the namespaces, no agent error, the links'
# round trip (logs/link_rtt.json, whatever shaped them: netem or cvslam_link_shaper) is twice
# the asked delay, and where the link shaper shaped them, it saw the cooperation traffic,
# delayed it by the asked amount and dropped the asked share. Needs root and network
# namespaces, and netem or the link shaper to delay the links: without them skipped (77), or
# failed under CI=true (tests/tools/ci_facility.sh).
set -uo pipefail
ROOT="$1" BUILD="$2" OUT="$3"
source "$ROOT/tests/tools/ci_facility.sh"
ATE_MAX_M=(0 0.4 2.0)  # by UAV id [m]
[ "$(id -u)" -eq 0 ] || missing_facility netns_team_test "needs root (network namespaces)"
# A namespace left by a killed run is not a missing facility: remove it, then probe.
ip netns del cvslam_probe 2>/dev/null
err=$(ip netns add cvslam_probe 2>&1) ||
  missing_facility netns_team_test "cannot create a network namespace as root: $err"
ip netns del cvslam_probe
rm -rf "$OUT"
"$ROOT/scripts/netns_team.sh" --scenario "$ROOT/config/scenarios/coop_pair.yaml" --out "$OUT" \
  --loss-levels 0,20 --delay 50 --jitter 10 --build "$BUILD" || { echo "netns_team.sh failed"; exit 1; }
# Loss by nftables alone applies no delay: the checks below would not be about delay.
grep -qx nftables "$OUT"/loss_*/link.txt &&
  missing_facility netns_team_test "neither netem nor cvslam_link_shaper (iptables NFQUEUE) delays the links here"
fail=0
for loss in 0 20; do
  for id in 1 2; do
    other=$((3 - id))
    dir="$OUT/loss_$loss"
    grep -q ",peer_joined,$other," "$dir/agent_$id/coop.csv" ||
      { echo "loss $loss: UAV$id never heard UAV$other"; fail=1; }
    grep -q "errors 0$" "$dir/logs/agent_$id.out" ||
      { echo "loss $loss: UAV$id: $(head -1 "$dir/logs/agent_$id.out")"; fail=1; }
    if [ "$id" = 1 ]; then
      /usr/bin/python3 -c "import json,sys; s=json.load(open('$dir/logs/link_rtt.json')); print('loss $loss: round trip', s); sys.exit(0 if s['received'] >= 10 and abs(s['mean_rtt_ms'] / 2 - 50) < 5 else 1)" ||
        { echo "loss $loss: the links' round trip is not twice 50 ms: $(cat "$dir/logs/link_rtt.json")"; fail=1; }
    fi
    if [ "$(cat "$dir/link.txt")" = shaper ]; then
      /usr/bin/python3 -c "import json,sys; s=json.load(open('$dir/logs/link_$id.json')); sys.exit(0 if s['packets'] > 50 and abs(s['mean_delay_ms'] - 50) < 2 and abs(100.0 * s['dropped'] / s['packets'] - $loss) < 12 else 1)" ||
        { echo "loss $loss: UAV$id's link: $(cat "$dir/logs/link_$id.json")"; fail=1; }
    fi
  done
  /usr/bin/python3 -c "import json,sys; a=json.load(open('$dir/summary.json'))['agents']; print('loss $loss: ATE', {k: a[k]['ate_rmse_m'] for k in ('1','2')}); sys.exit(0 if all(a[k]['ate_rmse_m'] is not None and a[k]['ate_rmse_m'] < b for k, b in (('1', ${ATE_MAX_M[1]}), ('2', ${ATE_MAX_M[2]}))) else 1)" ||
    { echo "loss $loss: an ATE missing or above its bound (${ATE_MAX_M[1]} / ${ATE_MAX_M[2]} m)"; fail=1; }
done
cat "$OUT/loss_table.md"
exit $fail
