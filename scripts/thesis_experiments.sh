#!/usr/bin/env bash
# Runs the thesis chapter-5 experiments with cvslam_run + cvslam_eval and prints the tables
# (scripts/thesis_tables.py). Several minutes on 2 cores (the full stochastic map dominates).
#
#   scripts/thesis_experiments.sh [--build-dir build] [--out runs/thesis] [--seed N] [--no-full]
set -euo pipefail
cd "$(dirname "$0")/.."

BUILD=build
OUT=runs/thesis
SEED=2010
FULL=true
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) BUILD=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    --seed) SEED=$2; shift 2 ;;
    --no-full) FULL=false; shift ;;
    -h|--help) sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "thesis_experiments.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
done
for tool in cvslam_run cvslam_eval; do
  [ -x "$BUILD/tools/$tool" ] || { echo "thesis_experiments.sh: $BUILD/tools/$tool not built (run scripts/test.sh)" >&2; exit 1; }
done
mkdir -p "$OUT"

run() {  # name, then cvslam_run arguments
  local name=$1; shift
  echo "== $name: cvslam_run $*"
  rm -rf "${OUT:?}/$name"
  "$BUILD/tools/cvslam_run" --seed "$SEED" --quiet --out "$OUT/$name" "$@" | sed -n 1,3p
  "$BUILD/tools/cvslam_eval" --run "$OUT/$name" --co-window 10 --quiet \
    --summary-json "$OUT/$name/summary.json"
}

LOOP=config/scenarios/thesis_loop.yaml
SPARSE=config/scenarios/thesis_loop_sparse.yaml
for f in ekf nhinf; do
  run "loop_${f}" --scenario $LOOP --filter $f
  run "lm_${f}_noncentred" --scenario $LOOP --filter $f --pixel-noise non_centred
  run "sparse_${f}_knearest" --scenario $SPARSE --filter $f --map knearest
  if $FULL; then run "sparse_${f}_full" --scenario $SPARSE --filter $f --map full; fi
done
run passes10_ekf --scenario $LOOP --filter ekf --passes 10

/usr/bin/python3 scripts/thesis_tables.py "$OUT" | tee "$OUT/tables.md"
echo "tables written to $OUT/tables.md"
