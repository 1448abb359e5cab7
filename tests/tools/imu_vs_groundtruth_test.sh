#!/usr/bin/env bash
# scripts/imu_vs_groundtruth.py on an analytic flight (a level 10 m circle at 1 rad/s, 30 s at
# 200 Hz, biases in the ground truth): an IMU with only its datasheet's white noise reads ≈ 1×
# the density on its 1 s means; one with a slow 0.05 m/s² wander reads ≫ 1×; bad input fails.
# Without numpy: skipped (77), or failed under CI=true (tests/tools/ci_facility.sh).
set -uo pipefail
SRC="$1" OUT="$2"
source "$(dirname "$0")/python_modules.sh" imu_vs_groundtruth_test numpy
rm -rf "$OUT" && mkdir -p "$OUT" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
"$PY" - "$OUT" <<'PYEOF' || fail "generator"
import sys, numpy as np
out = sys.argv[1]
rng = np.random.default_rng(7)
t = np.arange(0, 30, 0.005); w = 1.0; r = 10.0
psi = w * t + np.pi / 2
p = np.stack([r * np.cos(w * t), r * np.sin(w * t), 5 + 0 * t], -1)
v = np.stack([-r * w * np.sin(w * t), r * w * np.cos(w * t), 0 * t], -1)
a = -w * w * np.stack([p[:, 0], p[:, 1], 0 * t], -1)
q = np.stack([np.cos(psi / 2), 0 * t, 0 * t, np.sin(psi / 2)], -1)
bw, ba = np.array([0.01, -0.02, 0.03]), np.array([0.1, -0.05, 0.08])
c, s = np.cos(psi), np.sin(psi)
f_world = a + np.array([0, 0, 9.81])
f_body = np.stack([c * f_world[:, 0] + s * f_world[:, 1], -s * f_world[:, 0] + c * f_world[:, 1],
                   f_world[:, 2]], -1)
omega = np.stack([0 * t, 0 * t, w + 0 * t], -1)
ns = (t * 1e9).astype(np.int64) + 1403715000000000000
gt = np.column_stack([ns, p, q, v, np.tile(bw, (len(t), 1)), np.tile(ba, (len(t), 1))])
np.savetxt(f"{out}/gt.csv", gt, delimiter=",", fmt=["%d"] + ["%.9f"] * 16, header="gt", comments="#")
sd = np.sqrt(200.0)
gyro = omega + bw + rng.normal(0, 1.6968e-4 * sd, omega.shape)
accel = f_body + ba + rng.normal(0, 2.0e-3 * sd, f_body.shape)
np.savetxt(f"{out}/white.csv", np.column_stack([ns, gyro, accel]), delimiter=",",
           fmt=["%d"] + ["%.9f"] * 6, header="imu", comments="#")
accel[:, 0] += 0.05 * np.sin(2 * np.pi * 0.3 * t)
np.savetxt(f"{out}/wander.csv", np.column_stack([ns, gyro, accel]), delimiter=",",
           fmt=["%d"] + ["%.9f"] * 6, header="imu", comments="#")
PYEOF
run() { "$PY" "$SRC/scripts/imu_vs_groundtruth.py" --groundtruth "$OUT/gt.csv" --imu "$1"; }
factor() { sed -n "s/^$1:.* \([0-9.]*\)× the density.*/\1/p"; }
white=$(run "$OUT/white.csv") || fail "white run: $white"
echo "$white"
wander=$(run "$OUT/wander.csv") || fail "wander run"
echo "$wander"
"$PY" - "$(echo "$white" | factor accel)" "$(echo "$white" | factor gyro)" \
  "$(echo "$wander" | factor accel)" <<'PYEOF' || fail "factors"
import sys
wa, wg, xa = map(float, sys.argv[1:4])
assert wa < 3.0 and wg < 3.0, (wa, wg)   # white noise alone: near 1× (differentiation adds some)
assert xa > 10.0, xa                     # a 0.05 m/s² wander is 0.035 σ: ≈ 17×
PYEOF
if "$PY" "$SRC/scripts/imu_vs_groundtruth.py" --groundtruth "$OUT/missing.csv" --imu "$OUT/white.csv" \
    2>"$OUT/err.txt"; then fail "missing file accepted"; fi
grep -q "imu_vs_groundtruth.py:" "$OUT/err.txt" || fail "no one-line error: $(cat "$OUT/err.txt")"
echo "imu_vs_groundtruth_test: ok"
