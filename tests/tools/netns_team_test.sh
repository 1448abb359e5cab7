#!/usr/bin/env bash
# scripts/netns_team.sh end to end (docs/transport.md "Multi-host runs"): coop_pair, each UAV in
# its own network namespace, cooperation over the bridged LAN with 50 ± 10 ms of delay, without
# loss and with 20 % loss. Checks: both runs complete and evaluate, each UAV heard the other
# across the namespaces, no agent error, and where the link shaper shaped the links, it saw
# the cooperation traffic and delayed it by the asked amount. Skipped (77) where network namespaces cannot be made (not root, no netns).
set -uo pipefail
ROOT="$1" BUILD="$2" OUT="$3"
if [ "$(id -u)" -ne 0 ] || ! ip netns add cvslam_probe 2>/dev/null; then
  echo "netns_team_test: no network namespaces here (needs root): skipped"; exit 77
fi
ip netns del cvslam_probe
rm -rf "$OUT"
"$ROOT/scripts/netns_team.sh" --scenario "$ROOT/config/scenarios/coop_pair.yaml" --out "$OUT" \
  --loss-levels 0,20 --delay 50 --jitter 10 --build "$BUILD" || { echo "netns_team.sh failed"; exit 1; }
fail=0
for loss in 0 20; do
  for id in 1 2; do
    other=$((3 - id))
    dir="$OUT/loss_$loss"
    grep -q ",peer_joined,$other," "$dir/agent_$id/coop.csv" ||
      { echo "loss $loss: UAV$id never heard UAV$other"; fail=1; }
    grep -q "errors 0$" "$dir/logs/agent_$id.out" ||
      { echo "loss $loss: UAV$id: $(head -1 "$dir/logs/agent_$id.out")"; fail=1; }
    if [ "$(cat "$dir/link.txt")" = shaper ]; then
      /usr/bin/python3 -c "import json,sys; s=json.load(open('$dir/logs/link_$id.json')); sys.exit(0 if s['packets'] > 50 and abs(s['mean_delay_ms'] - 50) < 2 and abs(100.0 * s['dropped'] / s['packets'] - $loss) < 12 else 1)" ||
        { echo "loss $loss: UAV$id's link: $(cat "$dir/logs/link_$id.json")"; fail=1; }
    fi
  done
  /usr/bin/python3 -c "import json,sys; a=json.load(open('$dir/summary.json'))['agents']; sys.exit(0 if all(a[k]['ate_rmse_m'] is not None and a[k]['ate_rmse_m'] < 5 for k in ('1','2')) else 1)" ||
    { echo "loss $loss: no valid ATE"; fail=1; }
done
cat "$OUT/loss_table.md"
exit $fail
