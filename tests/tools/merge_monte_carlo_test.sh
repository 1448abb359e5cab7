#!/usr/bin/env bash
# scripts/merge_monte_carlo.py on coop_pair, seeds 1-3 (12 s each, both ways): every UAV of
# every seed merges, none wrongly, the relation candidates' NEES stays within 3× its χ²₄ mean,
# a second call resumes without running again, and bad seeds are refused. Needs only the
# standard library.
set -uo pipefail
SRC="$1" BUILD="$2" OUT="$3"
rm -rf "$OUT" && mkdir -p "$OUT" || exit 1
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
MC=("$PY" "$SRC/scripts/merge_monte_carlo.py" --scenario "$SRC/config/scenarios/coop_pair.yaml"
    --build-dir "$BUILD" --out "$OUT/mc")
"${MC[@]}" --seeds 1-3 > "$OUT/table.md" || { echo "merge_monte_carlo.py failed"; exit 1; }
grep -q "team-frame ATE, apart" "$OUT/table.md" || { echo "no table"; cat "$OUT/table.md"; exit 1; }
"$PY" - "$OUT/mc/summary.json" <<'PYEOF' || exit 1
import json, sys
s = json.load(open(sys.argv[1]))
assert s['seeds'] == [1, 2, 3], s['seeds']
assert s['adoptions'] == 6, s['adoptions']  # both UAVs of every seed
assert s['wrong_adoptions'] == 0, s['wrong_adoptions']
n = s['relation_nees']
assert n['count'] > 0 and n['mean'] < 12.0, n
for uav, u in s['per_uav'].items():
    assert all(t is not None for t in u['merged']), (uav, u['merged'])
    assert all(k is not None and k > 0 for k in u['known']), (uav, u['known'])
PYEOF
before=$(stat -c %Y "$OUT/mc/apart/seed_2/run.json")
sleep 1
"${MC[@]}" --seeds 1-3 > /dev/null || { echo "resume failed"; exit 1; }
[ "$(stat -c %Y "$OUT/mc/apart/seed_2/run.json")" = "$before" ] || { echo "ran seed 2 again"; exit 1; }
if "${MC[@]}" --seeds 3-1 2> "$OUT/err.txt"; then echo "--seeds 3-1 accepted"; exit 1; fi
grep -q "LAST must not be below FIRST" "$OUT/err.txt" || { cat "$OUT/err.txt"; exit 1; }
echo "merge_monte_carlo_test: ok"
