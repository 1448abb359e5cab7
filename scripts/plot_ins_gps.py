#!/usr/bin/env python3
"""Figures of a cvslam_ins_gps run folder (thesis Figs. 3.9-3.10, docs/ins_gps.md).

usage: plot_ins_gps.py OUT_DIR

Reads OUT_DIR/<filter>.csv and OUT_DIR/gps.csv written by `cvslam_ins_gps --out OUT_DIR` and
writes
  fig_z_ukf_sdre.png   z (down) position of truth, GPS, UKF and SDRE (Fig. 3.9)
  fig_trajectory.png   3D trajectory: truth, GPS, and every filter's estimate (Fig. 3.10)
  fig_errors.png       position error norm of every filter over time (outages shaded)
"""
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ORDER = ["kf", "ekf", "ukf", "sdre", "nhinf"]


def load(path):
    return np.genfromtxt(path, delimiter=",", names=True)


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plot_ins_gps.py OUT_DIR")
    out = sys.argv[1]
    gps_path = os.path.join(out, "gps.csv")
    if not os.path.exists(gps_path):
        sys.exit(f"plot_ins_gps.py: no {gps_path} (run cvslam_ins_gps --out {out})")
    gps = load(gps_path)
    tracks = {}
    for name in ORDER:
        path = os.path.join(out, name + ".csv")
        if os.path.exists(path):
            tracks[name] = load(path)
    if not tracks:
        sys.exit(f"plot_ins_gps.py: no filter CSV in {out}")
    truth = next(iter(tracks.values()))

    # Fig. 3.9: z position, UKF vs SDRE (height up for readability: -z).
    fig, ax = plt.subplots(figsize=(9, 4))
    ax.plot(gps["t"], -gps["z"], ".", ms=2, color="0.6", label="GPS")
    ax.plot(truth["t"], -truth["z_true"], "k-", lw=1.5, label="truth")
    for name, style in (("ukf", "b-"), ("sdre", "r--")):
        if name in tracks:
            ax.plot(tracks[name]["t"], -tracks[name]["z"], style, lw=1, label=name.upper())
    ax.set_xlabel("t [s]")
    ax.set_ylabel("height −z [m]")
    ax.set_title("Height estimate, UKF vs SDRE (thesis Fig. 3.9)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "fig_z_ukf_sdre.png"), dpi=120)

    # Fig. 3.10: 3D trajectories (east, north, height).
    fig = plt.figure(figsize=(8, 7))
    ax = fig.add_subplot(projection="3d")
    ax.plot(truth["y_true"], truth["x_true"], -truth["z_true"], "k-", lw=2, label="truth")
    ax.scatter(gps["y"], gps["x"], -gps["z"], s=3, c="0.6", label="GPS")
    for name, d in tracks.items():
        ax.plot(d["y"], d["x"], -d["z"], lw=1, label=name.upper())
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.set_zlabel("height [m]")
    ax.set_title("UAV trajectory and estimates (thesis Fig. 3.10)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "fig_trajectory.png"), dpi=120)

    # Position error norms; GPS gaps longer than 3 fix periods shaded as outages.
    fig, ax = plt.subplots(figsize=(9, 4))
    t_gps = gps["t"]
    if len(t_gps) > 1:
        period = np.median(np.diff(t_gps))
        for a, b in zip(t_gps[:-1], t_gps[1:]):
            if b - a > 3 * period:
                ax.axvspan(a, b, color="orange", alpha=0.2)
    for name, d in tracks.items():
        e = np.sqrt((d["x"] - d["x_true"]) ** 2 + (d["y"] - d["y_true"]) ** 2 +
                    (d["z"] - d["z_true"]) ** 2)
        ax.semilogy(d["t"], np.maximum(e, 1e-3), lw=1, label=name.upper())
    ax.set_xlabel("t [s]")
    ax.set_ylabel("‖p̂ − p‖ [m]")
    ax.set_title("Position error (GPS outages shaded)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "fig_errors.png"), dpi=120)
    print("wrote", ", ".join(sorted(os.path.basename(p) for p in glob.glob(os.path.join(out, "fig_*.png")))))


if __name__ == "__main__":
    main()
