#!/usr/bin/env bash
# scripts/mc_consistency.py end to end: team3_aerial, seeds 1-3, 8 s, two at a time. Checks:
# consistency.md, consistency.csv and a NEES plot per UAV exist, the table has a finite mean
# NEES per group (the bias groups too: the shipped filter has bias states), a share of time in
# the one-run band no smaller than in the band of the 3 runs, and a final-map
# landmark NEES for each of the 3 UAVs, a second call resumes (runs nothing), and a bad seed
# range or a missing binary exits non-zero with a one-line error.
#   tests/tools/mc_consistency_test.sh SOURCE_DIR BUILD_DIR OUT_DIR
set -uo pipefail
ROOT="$1" BUILD="$2" OUT="$3"
source "$(dirname "$0")/python_modules.sh" mc_consistency_test numpy matplotlib
SCRIPT="$ROOT/scripts/mc_consistency.py"
SCENARIO="$ROOT/config/scenarios/team3_aerial.yaml"
rm -rf "$OUT"
fail=0
"$PY" "$SCRIPT" --scenario "$SCENARIO" --seeds 1-3 --duration 8 --jobs 2 --build-dir "$BUILD" \
  --out "$OUT" > "$OUT.log" 2>&1 || { cat "$OUT.log"; echo "mc_consistency.py failed"; exit 1; }
for f in consistency.md consistency.csv nees_agent1.png nees_agent2.png nees_agent3.png; do
  [ -s "$OUT/$f" ] || { echo "missing $OUT/$f"; fail=1; }
done
"$PY" - "$OUT/consistency.md" <<'PYEOF' || fail=1
import math, re, sys
text = open(sys.argv[1]).read()
sections = re.split(r'^## UAV(\d+)$', text, flags=re.M)[1:]
agents = dict(zip(sections[0::2], sections[1::2]))
ok = sorted(agents) == ['1', '2', '3']
for a, body in sorted(agents.items()):
    means = {m.group(1): float(m.group(2)) for m in
             re.finditer(r'^\| (position|velocity|tilt|yaw|vehicle|accel bias|gyro bias) \| \d \| '
                         r'([^ |]+) \|', body, re.M)}
    if len(means) != 7 or not all(math.isfinite(v) for v in means.values()):
        print(f'UAV{a}: no finite mean NEES per group: {means}'); ok = False
    # The band of one run contains the band of N: never less of the time inside it.
    shares = [(float(m.group(1)), float(m.group(2))) for m in
              re.finditer(r'^\| [a-z ]+ \| \d \| [^|]+ \| \[[^]]+\] \| ([0-9.]+) \| [0-9.]+ \| '
                          r'([0-9.]+) \|$', body, re.M)]
    if len(shares) != 7 or any(one < n for n, one in shares):
        print(f'UAV{a}: % in the one-run band missing or below the N-run one: {shares}'); ok = False
    if not re.search(r'^\| Rco \| [0-9.]', body, re.M):
        print(f'UAV{a}: no Rco row'); ok = False
    m = re.search(r'^Final map, landmark NEES .*: mean ([0-9.]+) over 3 runs', body, re.M)
    if not m or not float(m.group(1)) > 0:
        print(f'UAV{a}: no final-map landmark NEES'); ok = False
if not ok:
    print(text)
sys.exit(0 if ok else 1)
PYEOF
# A second call resumes: every seed is already run.
again=$("$PY" "$SCRIPT" --scenario "$SCENARIO" --seeds 1-3 --duration 8 --build-dir "$BUILD" \
  --out "$OUT" 2>&1)
grep -q "3 of 3 seeds already run, running 0" <<< "$again" ||
  { echo "second call did not resume: $(head -1 <<< "$again")"; fail=1; }
# Bad input: non-zero exit, one line on stderr.
check_error() {  # description, then the arguments
  local what="$1"; shift
  local err
  err=$("$PY" "$SCRIPT" "$@" 2>&1 >/dev/null) && { echo "$what: exit status 0"; fail=1; return; }
  [ "$(printf '%s\n' "$err" | wc -l)" -eq 1 ] && [[ "$err" == mc_consistency:* ]] ||
    { echo "$what: not a one-line error: $err"; fail=1; }
}
check_error "bad seed range" --scenario "$SCENARIO" --seeds 5-2 --build-dir "$BUILD" --out "$OUT.bad"
check_error "seeds not a range" --scenario "$SCENARIO" --seeds abc --build-dir "$BUILD" --out "$OUT.bad"
check_error "missing binary" --scenario "$SCENARIO" --seeds 1-2 --build-dir "$OUT.nobuild" --out "$OUT.bad"
cat "$OUT/consistency.md"
exit $fail
