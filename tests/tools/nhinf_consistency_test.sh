#!/usr/bin/env bash
# What NH∞ does in a SLAM run (docs/results/nhinf.md): a small γ makes the filter more
# conservative — a lower vehicle NEES than the EKF on the same data — at a small cost in
# accuracy; it does not make it consistent under a biased observation model, nor more
# accurate (the thesis's claim, not reproduced). thesis_loop's UAV1, seeds 31-33 (the study
# chose γ on 101-106 and reported on 1-20), NH∞ with γ = 0.1 against the EKF on the same data:
#  - centred Gaussian noise: over the three seeds, NEES ≥ 5 % lower, ATE ≤ 15 % higher
#    (per seed the NEES gap is of the order of the run-to-run spread);
#  - non-centred pixel noise: on every seed NEES ≤ 0.6× the EKF's and still ≥ 10× the χ²
#    mean of 9 (not consistent), ATE ≤ 1.15×.
#   tests/tools/nhinf_consistency_test.sh SOURCE_DIR BUILD_DIR OUT_DIR
set -uo pipefail
ROOT="$1" BUILD="$2" OUT="$3"
source "$(dirname "$0")/python_modules.sh" nhinf_consistency_test
rm -rf "$OUT" && mkdir -p "$OUT"
run() {  # case, seed, filter name, cvslam_run arguments
  local dir="$OUT/$1_$3_$2"
  "$BUILD/tools/cvslam_run" --seed "$2" --out "$dir" --quiet "${@:4}" > "$dir.log" 2>&1 &&
    "$BUILD/tools/cvslam_eval" --run "$dir" --quiet --summary-json "$dir/summary.json" \
      >> "$dir.log" 2>&1 || { cat "$dir.log"; echo "run failed: $1 $3 seed $2"; return 1; }
}
GAUSSIAN=(--scenario "$ROOT/config/scenarios/thesis_loop.yaml" --agents 1)
NONCENTRED=(--scenario "$ROOT/config/scenarios/thesis_loop.yaml" --agents 1 --pixel-noise non_centred)
NHINF=(--filter nhinf --set filter.gamma=0.1)
status=0
for seed in 31 32 33; do
  run gaussian "$seed" ekf "${GAUSSIAN[@]}" --filter ekf & a=$!
  run gaussian "$seed" nhinf "${GAUSSIAN[@]}" "${NHINF[@]}" & b=$!
  wait $a || status=1
  wait $b || status=1
  run noncentred "$seed" ekf "${NONCENTRED[@]}" --filter ekf & a=$!
  run noncentred "$seed" nhinf "${NONCENTRED[@]}" "${NHINF[@]}" & b=$!
  wait $a || status=1
  wait $b || status=1
done
[ $status -eq 0 ] || exit 1
"$PY" - "$OUT" <<'PYEOF'
import json, sys
out, ok = sys.argv[1], True
ratios = {}
for case in ('gaussian', 'noncentred'):
    for seed in (31, 32, 33):
        e, n = (json.load(open(f'{out}/{case}_{f}_{seed}/summary.json'))['agents']['1']
                for f in ('ekf', 'nhinf'))
        print(f"{case} seed {seed}: EKF ATE {e['ate_rmse_m']:.3f} m NEES {e['nees_mean']:.2f}; "
              f"NH∞ γ=0.1 ATE {n['ate_rmse_m']:.3f} m NEES {n['nees_mean']:.2f}")
        ratios.setdefault(case, []).append((e, n))
        if case == 'noncentred':
            ok = ok and n['nees_mean'] <= 0.6 * e['nees_mean'] and n['nees_mean'] >= 90
            ok = ok and n['ate_rmse_m'] <= 1.15 * e['ate_rmse_m']
mean = lambda runs, k, i: sum(r[i][k] for r in runs) / len(runs)
g = ratios['gaussian']
nees, ate = mean(g, 'nees_mean', 1) / mean(g, 'nees_mean', 0), mean(g, 'ate_rmse_m', 1) / mean(g, 'ate_rmse_m', 0)
print(f'gaussian, three seeds: NEES ×{nees:.2f}, ATE ×{ate:.2f} (required ≤ 0.95, ≤ 1.15)')
print('noncentred, every seed: NEES ≤ 0.6× the EKF\'s and ≥ 90, ATE ≤ 1.15×')
sys.exit(0 if ok and nees <= 0.95 and ate <= 1.15 else 1)
PYEOF
