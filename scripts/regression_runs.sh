#!/usr/bin/env bash
# Runs a fixed set of cvslam_run commands (features and images, single and DC, EKF and NH∞,
# k-nearest and full map, four scenarios) with one build, for a byte-for-byte comparison of
# two builds' results after a refactoring (scripts/compare_runs.py). ≈ 8 min on 2 cores,
# most of it the full-map run.
#
#   scripts/regression_runs.sh [--build-dir build] [--attitude euler] --out DIR
#   scripts/compare_runs.py BEFORE_DIR AFTER_DIR
# --attitude: passed to every run (cvslam_run --attitude), e.g. euler to compare the thesis's
# model with a build from before the rotation error state.
set -euo pipefail
cd "$(dirname "$0")/.."

BUILD=build
EXTRA=()
OUT=
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) BUILD=${2:?--build-dir needs a value}; shift 2 ;;
    --attitude) EXTRA=(--attitude "${2:?--attitude needs a value}"); shift 2 ;;
    --out) OUT=${2:?--out needs a value}; shift 2 ;;
    -h|--help) sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "regression_runs.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[ -n "$OUT" ] || { echo "regression_runs.sh: --out DIR is required (try --help)" >&2; exit 2; }
RUN="$BUILD/tools/cvslam_run"
[ -x "$RUN" ] || { echo "regression_runs.sh: $RUN not built" >&2; exit 2; }
mkdir -p "$OUT"

failed=0
run() {  # name, then cvslam_run arguments
  local name=$1; shift
  echo "regression_runs.sh: $name"
  if ! "$RUN" --quiet --config config/agent.yaml "${EXTRA[@]}" --out "$OUT/$name" "$@" > "$OUT/$name.log" 2>&1; then
    echo "regression_runs.sh: $name FAILED (see $OUT/$name.log)" >&2
    failed=1
  fi
}
S=config/scenarios
run loop_single --scenario $S/thesis_loop.yaml --mode single
run loop_dc     --scenario $S/thesis_loop.yaml --mode dc
run loop_nhinf  --scenario $S/thesis_loop.yaml --mode single --filter nhinf --duration 80
run loop_full   --scenario $S/thesis_loop.yaml --mode single --map full --passes 2 --duration 60
run team3_dc    --scenario $S/team3_aerial.yaml --mode dc
run team3_fast  --scenario $S/team3_aerial.yaml --mode dc --ci fast --one-way
run pair_dc     --scenario $S/coop_pair.yaml --mode dc
run mh03        --scenario $S/euroc_mh03_hall.yaml --mode single --duration 40
run sparse      --scenario $S/thesis_loop_sparse.yaml --mode dc --duration 100
run team3_img   --scenario $S/team3_aerial.yaml --mode dc --sensing images --detector orb --duration 15
run loop_img    --scenario $S/thesis_loop.yaml --mode single --sensing images --duration 10
exit $failed
