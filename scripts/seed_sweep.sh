#!/usr/bin/env bash
# Runs one scenario over several seeds with one configuration and prints the ATE and the
# vehicle NEES (mean over the agents of each run, then mean ± std over the seeds), e.g. to
# compare `ins.attitude: error_state` with `euler` (docs/filter.md) or to tune a default on
# seeds the tests do not use.
#
#   scripts/seed_sweep.sh --scenario FILE --seeds FIRST-LAST [--config FILE] [--mode M]
#                         [--attitude error_state|euler] [--build-dir build] [--duration S]
#                         --out DIR
# Prints one line per seed and a summary line; DIR/<seed>/ keeps each run and summary.json.
set -euo pipefail
cd "$(dirname "$0")/.."

BUILD=build CONFIG=config/agent.yaml MODE=single SCENARIO= SEEDS= OUT= DURATION=() ATTITUDE=()
while [ $# -gt 0 ]; do
  case "$1" in
    --scenario) SCENARIO=${2:?--scenario needs a value}; shift 2 ;;
    --seeds) SEEDS=${2:?--seeds needs a value}; shift 2 ;;
    --config) CONFIG=${2:?--config needs a value}; shift 2 ;;
    --mode) MODE=${2:?--mode needs a value}; shift 2 ;;
    --build-dir) BUILD=${2:?--build-dir needs a value}; shift 2 ;;
    --duration) DURATION=(--duration "${2:?--duration needs a value}"); shift 2 ;;
    --attitude) ATTITUDE=(--attitude "${2:?--attitude needs a value}"); shift 2 ;;
    --out) OUT=${2:?--out needs a value}; shift 2 ;;
    -h|--help) sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "seed_sweep.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[ -n "$SCENARIO" ] && [ -n "$OUT" ] || { echo "seed_sweep.sh: --scenario and --out are required (try --help)" >&2; exit 2; }
[[ "$SEEDS" =~ ^([0-9]+)-([0-9]+)$ ]] || { echo "seed_sweep.sh: --seeds must be FIRST-LAST, e.g. 101-105" >&2; exit 2; }
FIRST=${BASH_REMATCH[1]} LAST=${BASH_REMATCH[2]}
for tool in cvslam_run cvslam_eval; do
  [ -x "$BUILD/tools/$tool" ] || { echo "seed_sweep.sh: $BUILD/tools/$tool not built" >&2; exit 2; }
done
mkdir -p "$OUT"
for seed in $(seq "$FIRST" "$LAST"); do
  dir="$OUT/$seed"
  if ! "$BUILD/tools/cvslam_run" --quiet --config "$CONFIG" --scenario "$SCENARIO" --mode "$MODE" \
      --seed "$seed" "${DURATION[@]}" "${ATTITUDE[@]}" --out "$dir" > "$OUT/$seed.log" 2>&1; then
    echo "seed $seed: cvslam_run failed (see $OUT/$seed.log)"
    continue
  fi
  "$BUILD/tools/cvslam_eval" --quiet --run "$dir" --summary-json "$dir/summary.json"
done
python3 - "$OUT" "$FIRST" "$LAST" <<'PY'
import json, os, statistics, sys
out, first, last = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
ates, nees = [], []
for seed in range(first, last + 1):
    path = os.path.join(out, str(seed), 'summary.json')
    if not os.path.exists(path):
        print(f'seed {seed}: no summary (run failed)')
        continue
    agents = json.load(open(path))['agents'].values()
    a = statistics.mean(x['ate_rmse_m'] for x in agents)
    n = statistics.mean(x['nees_mean'] for x in agents)
    ates.append(a)
    nees.append(n)
    print(f'seed {seed}: ATE {a:.3f} m  NEES {n:.1f}')
sd = lambda v: statistics.stdev(v) if len(v) > 1 else 0.0
if ates:
    print(f'summary: {len(ates)} seeds  ATE {statistics.mean(ates):.3f} ± {sd(ates):.3f} m  '
          f'NEES {statistics.mean(nees):.1f} ± {sd(nees):.1f} (median {statistics.median(nees):.1f})')
PY
