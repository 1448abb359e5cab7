#!/usr/bin/env python3
"""How far a real IMU recording strays from what its ground truth says it should read.

Differentiates a EuRoC ground truth (state_groundtruth_estimate0/data.csv layout: timestamp [ns],
p_RS_R, q_RS wxyz, v_RS_R, b_w_RS_S, b_a_RS_S; body = IMU) into the angular rate and specific
force an ideal IMU would measure, subtracts them and the ground truth's biases from the recorded
imu0/data.csv, and prints per axis the RMS of the residual and of its 1 s means, next to what
the white-noise densities of the sensor (σ/√1 s) allow:

  scripts/imu_vs_groundtruth.py --groundtruth GT.csv --imu IMU.csv
      [--gyro-noise-density 1.6968e-4] [--accel-noise-density 2.0e-3] [--gravity 9.81]

Rotor vibration dominates the per-sample residual; the 1 s means are what drives a filter's
drift, and what random_walk_scale / noise_density_scale (config/agent.yaml `ins:`) are for
(docs/results/euroc_recorded.md "Real IMU noise"). The ground truth's own errors (its
velocity is itself an estimate) count in the residual too: read the figures as upper bounds.
"""
import argparse
import sys

import numpy as np


def quat_to_matrix(q):
    """Rotation matrices (N×3×3) from unit quaternions (N×4, w x y z)."""
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1)], -2)


def log_so3(R):
    """Rotation vectors of rotation matrices (N×3×3), for small and moderate angles."""
    c = np.clip((np.trace(R, axis1=1, axis2=2) - 1) / 2, -1, 1)
    a = np.arccos(c)
    s = np.where(a < 1e-9, 1.0, a / np.maximum(np.sin(a), 1e-12))
    v = np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]], -1)
    return 0.5 * s[:, None] * v


def interp(t, T, X):
    return np.stack([np.interp(t, T, X[:, k]) for k in range(X.shape[1])], -1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--groundtruth", required=True)
    ap.add_argument("--imu", required=True)
    ap.add_argument("--gyro-noise-density", type=float, default=1.6968e-4)
    ap.add_argument("--accel-noise-density", type=float, default=2.0e-3)
    ap.add_argument("--gravity", type=float, default=9.81)
    a = ap.parse_args()
    try:
        g = np.loadtxt(a.groundtruth, delimiter=",", comments="#", ndmin=2)
        m = np.loadtxt(a.imu, delimiter=",", comments="#", ndmin=2)
    except (OSError, ValueError) as e:
        sys.exit(f"imu_vs_groundtruth.py: {e}")
    if g.shape[1] < 17 or m.shape[1] < 7 or len(g) < 400 or len(m) < 400:
        sys.exit("imu_vs_groundtruth.py: need a EuRoC ground truth with biases (17 columns) and "
                 "an imu0/data.csv (7 columns), each over 2 s at least")
    tg, tm = g[:, 0] * 1e-9, m[:, 0] * 1e-9
    R = quat_to_matrix(g[:, 4:8])
    dt = np.diff(tg)
    omega = log_so3(np.einsum("nji,njk->nik", R[:-1], R[1:])) / dt[:, None]  # body rate
    accel_world = np.diff(g[:, 8:11], axis=0) / dt[:, None]
    grav = np.array([0.0, 0.0, -a.gravity])  # the ground truth's world is z-up
    f_body = np.einsum("nji,nj->ni", R[:-1], accel_world - grav)
    tmid = 0.5 * (tg[:-1] + tg[1:])
    sel = (tm > tmid[0] + 1) & (tm < tmid[-1] - 1)
    t = tm[sel]
    res_gyro = m[sel, 1:4] - interp(t, tg, g[:, 11:14]) - interp(t, tmid, omega)
    res_accel = m[sel, 4:7] - interp(t, tg, g[:, 14:17]) - interp(t, tmid, f_body)
    rate = 1.0 / np.median(np.diff(t))
    k = max(1, int(round(rate)))
    for name, r, density, unit in (("gyro", res_gyro, a.gyro_noise_density, "rad/s"),
                                   ("accel", res_accel, a.accel_noise_density, "m/s²")):
        means = np.stack([np.convolve(r[:, i], np.ones(k) / k, "valid") for i in range(3)], -1)
        per_sample = np.sqrt((r ** 2).mean(0))
        one_s = means.std(0)
        print(f"{name}: per-sample RMS {np.array2string(per_sample, precision=4)} {unit}; "
              f"1 s means σ {np.array2string(one_s, precision=5)} {unit}, "
              f"{one_s.max() / density:.1f}× the density's {density:.3g} (σ/√1 s)")


if __name__ == "__main__":
    main()
