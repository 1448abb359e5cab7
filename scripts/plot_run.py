#!/usr/bin/python3
"""Thesis-style figures from a cvslam run folder (docs/run_format.md).

usage: /usr/bin/python3 scripts/plot_run.py DIR [--out PLOTS_DIR] [--agents 1,2] [--dpi N]

Writes PNGs into DIR/plots/ (or --out):
  agent_<id>_position.png   true / estimated x, y, z against time, ±3σ envelope (INS clipped)
                            (thesis figures 5.3, 6.x)
  agent_<id>_errors.png     estimation error of the 9 vehicle states with ±3σ (estimated vs
                            true uncertainty, §5.7.3)
  trajectories.png          every agent's true / estimated path in the N-E plane, plus the
                            final landmarks, scaled to the paths
  trajectories_ins.png      the same with the INS dead reckoning, scaled to everything
  landmark_uncertainty.png  mean landmark σ of the state over time (when recorded)
  state_size.png            filter state length over time
  nees.png                  NEES per step against the 95 % χ² band (when states+truth exist)

Uses Debian's python3-matplotlib and python3-numpy (docs/architecture.md). Exit status 1 with a
one-line error on a missing folder or malformed file.
"""

import argparse
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

STATES = ["x", "y", "z", "u", "v", "w", "roll", "pitch", "yaw"]
UNITS = ["m", "m", "m", "m/s", "m/s", "m/s", "rad", "rad", "rad"]


class RunError(Exception):
    pass


def read_csv(path):
    """Numeric CSV with a header line -> dict column -> 1-D array (None if file absent)."""
    if not os.path.exists(path):
        return None
    with open(path) as f:
        header = f.readline().strip().lstrip("#").split(",")
    header = [h.strip() for h in header]
    try:
        data = np.loadtxt(path, delimiter=",", skiprows=1, comments="#", ndmin=2)
    except ValueError as e:
        raise RunError(f"{path}: {e}")
    if data.size and data.shape[1] != len(header):
        raise RunError(f"{path}: {data.shape[1]} columns but {len(header)} names in the header")
    if data.size == 0:
        data = np.zeros((0, len(header)))
    return {name: data[:, i] for i, name in enumerate(header)}


def read_tum(path):
    if not os.path.exists(path):
        return None
    try:
        data = np.loadtxt(path, comments="#", ndmin=2)
    except ValueError as e:
        raise RunError(f"{path}: {e}")
    if data.size and data.shape[1] != 8:
        raise RunError(f"{path}: expected 8 columns 't x y z qx qy qz qw'")
    return data.reshape(-1, 8)


def read_json(path):
    if not os.path.exists(path):
        return None
    try:
        with open(path) as f:
            return json.load(f)
    except ValueError as e:
        raise RunError(f"{path}: {e}")


def as_float(values):
    return np.array([np.nan if v is None else v for v in values], dtype=float)


def load_agent(run_dir, agent_id):
    d = os.path.join(run_dir, f"agent_{agent_id}")
    return {
        "id": agent_id,
        "states": read_csv(os.path.join(d, "states.csv")),
        "truth": read_csv(os.path.join(d, "truth.csv")),
        "traj": read_tum(os.path.join(d, "trajectory.tum")),
        "ins": read_tum(os.path.join(d, "ins_trajectory.tum")),
        "landmarks": read_csv(os.path.join(d, "landmarks.csv")),
        "stats": read_json(os.path.join(d, "stats.json")),
    }


def agent_ids(run_dir):
    if not os.path.isdir(run_dir):
        raise RunError(f"{run_dir}: no such run folder")
    ids = []
    for name in os.listdir(run_dir):
        if name.startswith("agent_") and name[6:].isdigit():
            ids.append(int(name[6:]))
    if not ids:
        raise RunError(f"{run_dir}: no agent_<id> folders")
    return sorted(ids)


def wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def span(values, margin=0.1):
    """(lo, hi) over the finite entries of the given arrays, widened by margin of the range, or
    None when there are none. Axes are scaled to the estimate and the truth: INS dead reckoning
    can run hundreds of metres away, and would shrink the tracks to a blob (it is clipped)."""
    finite = [np.asarray(v, float)[np.isfinite(v)] for v in values if v is not None and len(v)]
    finite = [v for v in finite if len(v)]
    if not finite:
        return None
    lo = min(v.min() for v in finite)
    hi = max(v.max() for v in finite)
    pad = max(margin * (hi - lo), 0.5)
    return lo - pad, hi + pad


def plot_position(agent, out, dpi):
    st, tr, ins, traj = agent["states"], agent["truth"], agent["ins"], agent["traj"]
    if st is None and traj is None:
        return None
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(9, 8))
    for k, (ax, name) in enumerate(zip(axes, STATES[:3])):
        if tr is not None and len(tr["t"]):
            ax.plot(tr["t"], tr[name], "k-", lw=1.2, label="true")
        if ins is not None and len(ins):
            ax.plot(ins[:, 0], ins[:, 1 + k], "g:", lw=1.2, label="INS")
        if st is not None and len(st["t"]):
            ax.plot(st["t"], st[name], "b-", lw=1.0, label="estimated")
            var = st.get("var_" + name)
            if var is not None:
                s3 = 3 * np.sqrt(np.maximum(var, 0))
                ax.fill_between(st["t"], st[name] - s3, st[name] + s3, color="b", alpha=0.15,
                                label="±3σ")
        elif traj is not None:
            ax.plot(traj[:, 0], traj[:, 1 + k], "b-", lw=1.0, label="estimated")
        lim = span([tr[name] if tr is not None else None,
                    st[name] if st is not None else None,
                    traj[:, 1 + k] if st is None and traj is not None else None])
        if lim is not None:
            ax.set_ylim(*lim)
        ax.set_ylabel(f"{name} [m]")
        ax.grid(True, alpha=0.3)
    axes[0].legend(loc="best", fontsize=8)
    axes[0].set_title(f"agent {agent['id']}: position (NED)")
    axes[-1].set_xlabel("t [s]")
    path = os.path.join(out, f"agent_{agent['id']}_position.png")
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def plot_errors(agent, out, dpi):
    st, tr = agent["states"], agent["truth"]
    if st is None or tr is None or not len(st["t"]) or not len(tr["t"]):
        return None
    # Nearest truth sample for every estimate (both sorted; run writers use the same times).
    idx = np.clip(np.searchsorted(tr["t"], st["t"]), 0, len(tr["t"]) - 1)
    prev = np.clip(idx - 1, 0, len(tr["t"]) - 1)
    idx = np.where(np.abs(tr["t"][prev] - st["t"]) < np.abs(tr["t"][idx] - st["t"]), prev, idx)
    fig, axes = plt.subplots(3, 3, sharex=True, figsize=(12, 8))
    for k, name in enumerate(STATES):
        ax = axes[k // 3][k % 3]
        err = st[name] - tr[name][idx]
        if k >= 6:
            err = wrap(err)
        ax.plot(st["t"], err, "b-", lw=0.8, label="error")
        var = st.get("var_" + name)
        if var is not None:
            s3 = 3 * np.sqrt(np.maximum(var, 0))
            ax.plot(st["t"], s3, "r--", lw=0.8, label="±3σ")
            ax.plot(st["t"], -s3, "r--", lw=0.8)
        ax.set_title(f"{name} [{UNITS[k]}]", fontsize=9)
        ax.grid(True, alpha=0.3)
    axes[0][0].legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("t [s]")
    fig.suptitle(f"agent {agent['id']}: estimation error and 3σ bounds")
    path = os.path.join(out, f"agent_{agent['id']}_errors.png")
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def plot_trajectories(agents, out, dpi, with_ins=False):
    """The N-E plane scaled to the true and estimated paths; with_ins draws the INS dead
    reckoning too, in its own figure (trajectories_ins.png) scaled to everything."""
    fig, ax = plt.subplots(figsize=(8, 8))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    east, north = [], []
    for n, a in enumerate(agents):
        c = colors[n % len(colors)]
        # North up, East right: plot (y = East, x = North).
        if a["truth"] is not None and len(a["truth"]["t"]):
            ax.plot(a["truth"]["y"], a["truth"]["x"], "--", color=c, lw=1, label=f"{a['id']} true")
            east.append(a["truth"]["y"])
            north.append(a["truth"]["x"])
        if a["traj"] is not None and len(a["traj"]):
            east.append(a["traj"][:, 2])
            north.append(a["traj"][:, 1])
        if with_ins and a["ins"] is not None and len(a["ins"]):
            ax.plot(a["ins"][:, 2], a["ins"][:, 1], ":", color=c, lw=1, label=f"{a['id']} INS")
        if a["traj"] is not None and len(a["traj"]):
            ax.plot(a["traj"][:, 2], a["traj"][:, 1], "-", color=c, lw=1.2,
                    label=f"{a['id']} estimated")
        lm = a["landmarks"]
        if lm is not None and len(lm["id"]):
            ax.plot(lm["y"], lm["x"], "+", color=c, ms=4, label=f"{a['id']} landmarks")
            if "true_x" in lm:
                ax.plot(lm["true_y"], lm["true_x"], ".", color="k", ms=2)
    ax.set_xlabel("East [m]")
    ax.set_ylabel("North [m]")
    e_lim, n_lim = span(east), span(north)
    if not with_ins and e_lim is not None and n_lim is not None:
        # Equal scale on both axes, centred on the tracks.
        half = max(e_lim[1] - e_lim[0], n_lim[1] - n_lim[0]) / 2
        ec, nc = sum(e_lim) / 2, sum(n_lim) / 2
        ax.set_xlim(ec - half, ec + half)
        ax.set_ylim(nc - half, nc + half)
        ax.set_aspect("equal", adjustable="box")
    else:
        ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    ax.set_title("INS dead reckoning against the estimates (N-E plane)" if with_ins
                 else "trajectories (N-E plane)")
    path = os.path.join(out, "trajectories_ins.png" if with_ins else "trajectories.png")
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def frames(agent, key):
    s = agent["stats"]
    if not s or "frames" not in s or "t_s" not in s["frames"] or key not in s["frames"]:
        return None
    t = as_float(s["frames"]["t_s"])
    v = as_float(s["frames"][key])
    if len(t) != len(v):
        raise RunError(f"agent_{agent['id']}/stats.json: frames.{key} and frames.t_s differ in length")
    return (t, v) if np.isfinite(v).any() else None


def plot_frames(agents, key, ylabel, title, name, out, dpi):
    series = [(a["id"], frames(a, key)) for a in agents]
    series = [(i, s) for i, s in series if s is not None]
    if not series:
        return None
    fig, ax = plt.subplots(figsize=(9, 4))
    for i, (t, v) in series:
        ax.plot(t, v, lw=1.0, label=f"agent {i}")
    ax.set_xlabel("t [s]")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    path = os.path.join(out, name)
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def nees_series(agent):
    st, tr = agent["states"], agent["truth"]
    if st is None or tr is None or not len(st["t"]) or not len(tr["t"]):
        return None
    if any(("var_" + n) not in st for n in STATES):
        return None
    idx = np.clip(np.searchsorted(tr["t"], st["t"]), 0, len(tr["t"]) - 1)
    out = []
    for r in range(len(st["t"])):
        e = np.array([st[n][r] - tr[n][idx[r]] for n in STATES])
        e[6:] = wrap(e[6:])
        P = np.diag([st["var_" + n][r] for n in STATES])
        for i in range(9):
            for j in range(i + 1, 9):
                key = f"cov_{i}_{j}"
                if key in st:
                    P[i, j] = P[j, i] = st[key][r]
        try:
            np.linalg.cholesky(P)
        except np.linalg.LinAlgError:
            out.append(np.nan)
            continue
        out.append(float(e @ np.linalg.solve(P, e)))
    return st["t"], np.array(out)


def plot_nees(agents, out, dpi):
    series = [(a["id"], nees_series(a)) for a in agents]
    series = [(i, s) for i, s in series if s is not None]
    if not series:
        return None
    fig, ax = plt.subplots(figsize=(9, 4))
    for i, (t, v) in series:
        ax.plot(t, v, lw=0.8, label=f"agent {i}")
    # 95 % two-sided band of χ²(9) for a single step.
    ax.axhline(2.70, color="r", ls="--", lw=0.8)
    ax.axhline(19.02, color="r", ls="--", lw=0.8, label="χ²(9) 95 %")
    ax.axhline(9.0, color="k", ls=":", lw=0.8)
    ax.set_yscale("log")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("NEES")
    ax.set_title("normalised estimation error squared (vehicle state)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    path = os.path.join(out, "nees.png")
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def main(argv):
    p = argparse.ArgumentParser(
        description="Thesis-style figures from a cvslam run folder (PNGs into DIR/plots/).")
    p.add_argument("run", metavar="DIR", help="run folder with agent_<id>/ sub-folders")
    p.add_argument("--out", help="output folder (default DIR/plots)")
    p.add_argument("--agents", help="comma-separated agent ids (default: all)")
    p.add_argument("--dpi", type=int, default=110)
    args = p.parse_args(argv)
    try:
        ids = agent_ids(args.run)
        if args.agents:
            wanted = [int(x) for x in args.agents.split(",")]
            missing = [i for i in wanted if i not in ids]
            if missing:
                raise RunError(f"{args.run}: no agent_{missing[0]} folder")
            ids = wanted
        out = args.out or os.path.join(args.run, "plots")
        os.makedirs(out, exist_ok=True)
        agents = [load_agent(args.run, i) for i in ids]
        written = []
        for a in agents:
            written += [plot_position(a, out, args.dpi), plot_errors(a, out, args.dpi)]
        written.append(plot_trajectories(agents, out, args.dpi))
        if any(a["ins"] is not None and len(a["ins"]) for a in agents):
            written.append(plot_trajectories(agents, out, args.dpi, with_ins=True))
        written.append(plot_frames(agents, "landmark_sigma_mean_m", "mean landmark σ [m]",
                                   "landmark uncertainty in the state", "landmark_uncertainty.png",
                                   out, args.dpi))
        written.append(plot_frames(agents, "state_size", "state length", "filter state size",
                                   "state_size.png", out, args.dpi))
        written.append(plot_nees(agents, out, args.dpi))
    except (RunError, ValueError, KeyError) as e:
        print(f"plot_run: {e}", file=sys.stderr)
        return 1
    for w in written:
        if w:
            print(w)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
