#!/usr/bin/python3
"""Prints the thesis chapter-5 tables from the runs of scripts/thesis_experiments.sh.

usage: thesis_tables.py OUT_DIR

Reads OUT_DIR/<run>/summary.json (cvslam_eval) and the run records (states.csv, truth.csv,
events.csv, stats.json) and prints markdown tables:
  1. accuracy and loop closing per UAV, filter and map (thesis Figs. 5.8-5.16)
  2. map management: state size, knearest vs full (thesis §5.9.3)
  3. landmark error mean/std per axis, EKF vs NH-inf, centred and non-centred noise
     (thesis Tables 5.3, 5.4)
  4. estimated vs true uncertainty and Rco per state, 1 and 10 observation passes, NEES
     (thesis Tables 5.1, 5.2)
"""
import json
import os
import sys

import numpy as np

STATES = ["x", "y", "z", "u", "v", "w", "roll", "pitch", "yaw"]


def load_csv(path):
    return np.genfromtxt(path, delimiter=",", names=True)


def position_error(agent_dir):
    s = load_csv(os.path.join(agent_dir, "states.csv"))
    t = load_csv(os.path.join(agent_dir, "truth.csv"))
    e = np.sqrt((s["x"] - t["x"]) ** 2 + (s["y"] - t["y"]) ** 2 + (s["z"] - t["z"]) ** 2)
    return s["t"], e


def loop_closure(agent_dir):
    """(t of the first applied loop closure, mean error 2 s before, mean error 0.5-2.5 s after)."""
    ev = load_csv(os.path.join(agent_dir, "events.csv"))
    hits = ev["t"][ev["loop_closure"] > 0]
    if hits.size == 0:
        return None, None, None
    t_lc = float(hits[0])
    t, e = position_error(agent_dir)
    before = e[(t >= t_lc - 2.0) & (t < t_lc)]
    after = e[(t >= t_lc + 0.5) & (t <= t_lc + 2.5)]
    return t_lc, float(before.mean()), float(after.mean()) if after.size else None


def state_sizes(agent_dir):
    with open(os.path.join(agent_dir, "stats.json")) as f:
        stats = json.load(f)
    frames = stats["frames"]
    sizes = frames["state_size"] if isinstance(frames, dict) else [fr["state_size"] for fr in frames]
    return np.asarray(sizes)


def runs(out):
    return sorted(d for d in os.listdir(out) if os.path.isfile(os.path.join(out, d, "summary.json")))


def summary(out, run):
    with open(os.path.join(out, run, "summary.json")) as f:
        return json.load(f)


def fmt(x, nd=3):
    return "n/a" if x is None else f"{x:.{nd}f}"


def main():
    if len(sys.argv) != 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        return 0 if len(sys.argv) == 2 else 2
    out = sys.argv[1]
    if not os.path.isdir(out):
        print(f"thesis_tables.py: no such folder: {out}", file=sys.stderr)
        return 1

    print("## 1. Accuracy and loop closing\n")
    print("| run | UAV | ATE [m] | INS ATE [m] | ATE/INS | NEES | loop at [s] | error before [m] | error after [m] | max state |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for run in runs(out):
        if run.startswith("lm_"):
            continue
        sm = summary(out, run)
        for aid, a in sorted(sm["agents"].items()):
            t_lc, before, after = loop_closure(os.path.join(out, run, f"agent_{aid}"))
            ratio = a["ate_rmse_m"] / a["ins_ate_rmse_m"] if a.get("ins_ate_rmse_m") else None
            print(f"| {run} | {aid} | {fmt(a['ate_rmse_m'])} | {fmt(a.get('ins_ate_rmse_m'), 1)} | "
                  f"{fmt(100 * ratio, 2) + ' %' if ratio is not None else 'n/a'} | {fmt(a['nees_mean'], 1)} | "
                  f"{fmt(t_lc, 1)} | {fmt(before)} | {fmt(after)} | {a['max_state_size']} |")

    print("\n## 2. Map management: state size (9 + 3 x landmarks in the state)\n")
    print("| run | UAV | state at 30 s | at 100 s | at end | max | landmarks mapped |")
    print("|---|---|---|---|---|---|---|")
    for run in runs(out):
        if "sparse" not in run:
            continue
        sm = summary(out, run)
        for aid, a in sorted(sm["agents"].items()):
            sizes = state_sizes(os.path.join(out, run, f"agent_{aid}"))
            at = lambda k: sizes[min(k, sizes.size - 1)]
            print(f"| {run} | {aid} | {at(300)} | {at(1000)} | {sizes[-1]} | {sizes.max()} | {a.get('landmarks', 'n/a')} |")

    print("\n## 3. Landmark error [m], mean and std per axis (thesis Tables 5.3, 5.4)\n")
    print("| run | UAV | x mean | x std | y mean | y std | z mean | z std |")
    print("|---|---|---|---|---|---|---|---|")
    for run in runs(out):
        if not (run.startswith("lm_") or run.startswith("loop_")):
            continue  # loop_*: centred Gaussian noise; lm_*_noncentred: non-centred
        sm = summary(out, run)
        for aid, a in sorted(sm["agents"].items()):
            m, s = a["landmark_error_mean_m"], a["landmark_error_std_m"]
            print(f"| {run} | {aid} | " + " | ".join(f"{fmt(m[i])} | {fmt(s[i])}" for i in range(3)) + " |")

    print("\n## 4. Estimated vs true uncertainty and Rco (thesis Tables 5.1, 5.2)\n")
    print("Estimated: mean filter sigma; true: RMS error; Rco: min over the run of their ratio")
    print("(cvslam_eval, averaged over --co-window frames).\n")
    for run in runs(out):
        if run not in ("loop_ekf", "passes10_ekf"):
            continue  # 1 observation pass (the default) and 10
        sm = summary(out, run)
        for aid, a in sorted(sm["agents"].items()):
            print(f"**{run}, UAV{aid}** (NEES {fmt(a['nees_mean'], 1)}, position NEES "
                  f"{fmt(a.get('nees_position_mean'), 1)})\n")
            print("| state | estimated | true | Rco |")
            print("|---|---|---|---|")
            for st in STATES:
                print(f"| {st} | {fmt(a['sigma_mean'][st], 4)} | {fmt(a['true_sigma_mean'][st], 4)} | "
                      f"{fmt(a['rco'][st], 4)} |")
            print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
