#!/usr/bin/env bash
# The ideal EKF (cvslam_run --linearise-at-truth: every Jacobian at the true state) is
# consistent on team3_aerial: over seeds 51-60 (not used to choose any default), 40 s, features,
# each UAV's mean vehicle and position NEES lie inside the χ² 95 % band of the 10 runs
# (scripts/mc_consistency.py). This checks the filter's models against the simulator's — noise
# densities, discretisation, the augmentation of new landmarks, the map's bookkeeping — apart
# from linearisation, which the shipped filter adds (docs/results/ideal_ekf.md).
# In both, the global yaw stays unobservable: no UAV's yaw σ ever falls below its initial value
# (an ideal EKF on the error state's coordinates, whose Jacobians at the true attitude mixed two
# charts, took it from 1° to 0.4°: docs/results/ideal_ekf.md).
# With `shipped`, the same runs of the shipped filter (the invariant error chart,
# docs/filter.md): its mean vehicle NEES must lie in the band too (the additive chart with
# first estimates and the constraint measured 11.7 / 13.9 / 15.7 against [6.6, 11.8]).
#   tests/tools/ideal_ekf_test.sh SOURCE_DIR BUILD_DIR OUT_DIR [shipped]
set -uo pipefail
ROOT="$1" BUILD="$2" OUT="$3" MODE="${4:-ideal}"
source "$(dirname "$0")/python_modules.sh" ideal_ekf_test numpy matplotlib
rm -rf "$OUT"
FAILED=0
RUN_ARGS=(--run-arg=--linearise-at-truth) GROUPS_CHECKED="vehicle position"
[ "$MODE" = shipped ] && RUN_ARGS=() GROUPS_CHECKED="vehicle"
"$PY" "$ROOT/scripts/mc_consistency.py" --scenario "$ROOT/config/scenarios/team3_aerial.yaml" \
  --seeds 51-60 --duration 40 --jobs 2 --build-dir "$BUILD" --out "$OUT" \
  "${RUN_ARGS[@]}" > "$OUT.log" 2>&1 ||
  { cat "$OUT.log"; echo "mc_consistency.py failed"; exit 1; }
"$PY" - "$OUT/consistency.md" $GROUPS_CHECKED <<'PYEOF' || FAILED=1
import re, sys
text = open(sys.argv[1]).read()
sections = re.split(r'^## UAV(\d+)$', text, flags=re.M)[1:]
agents = dict(zip(sections[0::2], sections[1::2]))
ok = sorted(agents) == ['1', '2', '3']
for a, body in sorted(agents.items()):
    for group in sys.argv[2:]:
        m = re.search(r'^\| ' + group + r' \| \d \| ([0-9.]+) \| \[([0-9.]+), ([0-9.]+)\] \| ([0-9.]+)',
                      body, re.M)
        if not m:
            print(f'UAV{a}: no {group} row'); ok = False; continue
        mean, lo, hi, inside = (float(g) for g in m.groups())
        print(f'UAV{a} {group}: mean NEES {mean} in band [{lo}, {hi}]? {lo <= mean <= hi}, '
              f'{inside} % of the time in it')
        if not lo <= mean <= hi:
            ok = False
if not ok:
    print(text)
sys.exit(0 if ok else 1)
PYEOF
"$PY" - "$OUT" <<'PYEOF' || FAILED=1
import csv, glob, math, os, sys
worst = (math.inf, '')
for path in sorted(glob.glob(os.path.join(sys.argv[1], 'runs', 'seed_*', 'agent_*', 'states.csv'))):
    rows = list(csv.DictReader(open(path)))
    s0 = math.sqrt(float(rows[0]['var_yaw']))
    ratio = min(math.sqrt(float(r['var_yaw'])) for r in rows) / s0
    worst = min(worst, (ratio, os.path.relpath(path, sys.argv[1])))
if not worst[1]:
    print('no states.csv under ' + sys.argv[1]); sys.exit(1)
print(f'smallest yaw σ over its initial value: {worst[0]:.4f} ({worst[1]})')
sys.exit(0 if worst[0] >= 0.99 else 1)
PYEOF
exit "$FAILED"
