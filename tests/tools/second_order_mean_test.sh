#!/usr/bin/env bash
# The second-order mean shortens the flown distance less (docs/filter.md "The
# second-order mean"). thesis_loop UAV2 flies ≈ 600 m away from its start, features, shipped
# configuration; without the mean term its estimate falls behind the truth along the track on
# every seed (−0.87 m on average at 209 s, seeds 201-220, where the run-to-run spread is
# 0.35 m): h(x̂) under-predicts the disparity of a landmark whose depth is uncertain. The same
# seeds with and without the term (paired: the same noise): with it, the along-track error
# from the start is less negative on every seed by at least 15 cm, and by 20 cm on average
# (32 cm on seeds 71-74). The term taken in additive coordinates instead of the filter's
# invariant chart gained 13-15 cm on these seeds and fails. Seeds 71-74 chose nothing.
#   tests/tools/second_order_mean_test.sh SOURCE_DIR BUILD_DIR OUT_DIR
set -uo pipefail
ROOT="$1" BUILD="$2" OUT="$3"
source "$(dirname "$0")/python_modules.sh" second_order_mean_test
rm -rf "$OUT" && mkdir -p "$OUT"
run() {  # seed, name, extra args
  "$BUILD/tools/cvslam_run" --scenario "$ROOT/config/scenarios/thesis_loop.yaml" --agents 2 \
    --seed "$1" --out "$OUT/$2_$1" "${@:3}" > "$OUT/$2_$1.log" 2>&1 ||
    { cat "$OUT/$2_$1.log"; echo "cvslam_run failed (seed $1, $2)"; return 1; }
}
status=0
for seed in 71 72 73 74; do
  run "$seed" with & a=$!
  run "$seed" without --set slam.second_order_mean=false & b=$!
  wait $a || status=1
  wait $b || status=1
done
[ $status -eq 0 ] || exit 1
"$PY" - "$OUT" <<'PYEOF'
import csv, math, sys
out = sys.argv[1]

def along_track_error(run):
    """Signed error of the end position along the line from the true start (m)."""
    states = list(csv.DictReader(open(run + '/agent_2/states.csv')))
    truth = {r['t']: r for r in csv.DictReader(open(run + '/agent_2/truth.csv'))}
    start = [float(truth[states[0]['t']][k]) for k in 'xyz']
    end, true_end = states[-1], truth[states[-1]['t']]
    p = [float(true_end[k]) for k in 'xyz']
    d = [a - b for a, b in zip(p, start)]
    n = math.sqrt(sum(c * c for c in d))
    return sum((float(end[k]) - float(true_end[k])) * c / n for k, c in zip('xyz', d))

ok, gains = True, []
for seed in (71, 72, 73, 74):
    w = along_track_error(f'{out}/with_{seed}')
    wo = along_track_error(f'{out}/without_{seed}')
    gains.append(w - wo)
    print(f'seed {seed}: along-track error {wo:+.3f} m without the mean term, {w:+.3f} m with it')
    ok = ok and w - wo >= 0.15
mean = sum(gains) / len(gains)
print(f'mean gain {mean:.3f} m (required: ≥ 0.15 m on every seed, ≥ 0.20 m on average)')
sys.exit(0 if ok and mean >= 0.20 else 1)
PYEOF
