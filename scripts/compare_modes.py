#!/usr/bin/python3
"""Single vs DC vs CC comparison runs (thesis §6.6.7): runs cvslam_run in each mode on
scenarios x seeds x sensing, evaluates every run with cvslam_eval (the agents' records; in cc
mode they hold the ground station's estimates) and writes, in OUT:
  results.csv   one row per run and UAV: ATE, RPE, NEES, bytes/s per UAV and of the ground
                station, CPU ms per step of the agent and of the ground station
  results.md    the same as Markdown tables per scenario, seed-means, and per UAV whether
                CC <= DC <= single holds
  ate_<scenario>_<sensing>.png       bar chart of the seed-mean ATE per mode and UAV
  error_<scenario>_<sensing>_s<seed>.png  position error over time per mode, per UAV

  scripts/compare_modes.py --scenarios thesis_loop,team3_aerial --seeds 1,2,3 --out runs/cmp
"""

import argparse
import concurrent.futures
import csv
import json
import math
import os
import subprocess
import sys

MODES = ["single", "dc", "cc"]


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scenarios", default="thesis_loop,team3_aerial,coop_pair,team5",
                   help="comma-separated names in config/scenarios/ (or YAML paths)")
    p.add_argument("--seeds", default="1,2,3,4,5", help="comma-separated seeds")
    p.add_argument("--sensing", default="features", help="features, images or both (comma list)")
    p.add_argument("--modes", default=",".join(MODES))
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--build-dir", default="build")
    p.add_argument("--config", default="config/agent.yaml")
    p.add_argument("--jobs", type=int, default=2, help="runs in parallel")
    p.add_argument("--extra", default="", help="extra cvslam_run arguments (one string)")
    p.add_argument("--no-plots", action="store_true")
    return p.parse_args()


def scenario_path(name):
    return name if name.endswith(".yaml") else os.path.join("config", "scenarios", name + ".yaml")


def scenario_name(name):
    return os.path.splitext(os.path.basename(name))[0]


def run_one(args, scenario, seed, sensing, mode):
    name = f"{scenario_name(scenario)}-{sensing}-s{seed}-{mode}"
    run_dir = os.path.join(args.out, "runs", name)
    cmd = [os.path.join(args.build_dir, "tools", "cvslam_run"), "--quiet", "--config", args.config,
           "--scenario", scenario_path(scenario), "--mode", mode, "--seed", str(seed),
           "--sensing", sensing, "--out", run_dir] + args.extra.split()
    log = run_dir + ".log"
    os.makedirs(os.path.dirname(log), exist_ok=True)
    with open(log, "w") as f:
        rc = subprocess.call(cmd, stdout=f, stderr=subprocess.STDOUT)
    if rc != 0:
        return name, None, f"cvslam_run failed ({rc}), see {log}"
    summary = run_dir + "/summary.json"
    rc = subprocess.call([os.path.join(args.build_dir, "tools", "cvslam_eval"), "--run", run_dir,
                          "--summary-json", summary], stdout=subprocess.DEVNULL)
    if rc != 0:
        return name, None, f"cvslam_eval failed ({rc})"
    with open(summary) as f:
        s = json.load(f)
    gs = {}
    gs_stats = os.path.join(run_dir, "ground_station", "stats.json")
    if os.path.exists(gs_stats):
        with open(gs_stats) as f:
            gs = json.load(f)
    return name, {"summary": s, "gs": gs, "dir": run_dir}, None


def rows_of(scenario, seed, sensing, mode, result):
    rows = []
    gs = result["gs"]
    for uav, a in sorted(result["summary"]["agents"].items(), key=lambda kv: int(kv[0])):
        # CC: the agent records the ground station's estimate where its batch was accepted and
        # its own elsewhere; the CC figure is the ground station's only over that share.
        coverage = None
        if mode == "cc":
            gs_agent = gs.get("agents", {}).get(uav, {})
            steps = a.get("steps") or 0
            coverage = gs_agent.get("batches", 0) / steps if steps else 0.0
        rows.append({
            "coverage": coverage,
            "scenario": scenario_name(scenario), "sensing": sensing, "seed": seed, "mode": mode,
            "uav": int(uav), "ate_m": a.get("ate_rmse_m"), "rpe_m_per_10m": a.get("rpe_m_per_10m"),
            "nees": a.get("nees_mean"), "bytes_per_s_uav": a.get("bytes_sent_per_s", 0.0),
            "bytes_per_s_gs": gs.get("bytes_received_per_s", ""),
            "agent_ms_median": a.get("frame_time_ms_median"),
            "gs_ms_median": gs.get("step_ms_median", ""), "gs_ms_p95": gs.get("step_ms_p95", ""),
            "gs_state_size_max": gs.get("state_size_max", ""),
        })
    return rows


MIN_COVERAGE = 0.95  # a CC figure over less of the flight is flagged


def short_coverage(r):
    return r["mode"] == "cc" and r["coverage"] is not None and r["coverage"] < MIN_COVERAGE


def fmt(x, digits=3):
    if x is None or x == "":
        return "–"
    return f"{x:.{digits}f}" if isinstance(x, float) else str(x)


def mean(xs):
    xs = [x for x in xs if x is not None and not (isinstance(x, float) and math.isnan(x))]
    return sum(xs) / len(xs) if xs else float("nan")


def write_markdown(path, rows, command):
    groups = {}
    for r in rows:
        groups.setdefault((r["scenario"], r["sensing"]), []).append(r)
    with open(path, "w") as f:
        f.write("# Single vs DC vs CC\n\nMade by:\n\n```\n" + command + "\n```\n\n")
        f.write("ATE, RPE [m per 10 m], NEES (9 dof, mean) per run and UAV; bytes/s a UAV sends "
                "(dc: cooperation messages; cc: observation batches to the ground station) and "
                "the ground station receives; median CPU ms per step of the agent's own filter "
                "and of the ground station (median / p95).\n\n")
        for (scenario, sensing), rs in sorted(groups.items()):
            f.write(f"## {scenario}, {sensing}\n\n")
            f.write("| seed | mode | UAV | ATE [m] | RPE | NEES | B/s UAV | B/s GS | agent ms | GS ms (p95) |\n")
            f.write("|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n")
            for r in sorted(rs, key=lambda r: (r["seed"], MODES.index(r["mode"]), r["uav"])):
                gs_ms = "–" if r["gs_ms_median"] == "" else f"{r['gs_ms_median']:.2f} ({r['gs_ms_p95']:.2f})"
                flag = f" † ({100 * r['coverage']:.0f} %)" if short_coverage(r) else ""
                f.write(f"| {r['seed']} | {r['mode']} | {r['uav']} | {fmt(r['ate_m'])}{flag} | "
                        f"{fmt(r['rpe_m_per_10m'])} | {fmt(r['nees'], 1)} | {fmt(r['bytes_per_s_uav'], 0)} | "
                        f"{fmt(r['bytes_per_s_gs'], 0)} | {fmt(r['agent_ms_median'], 2)} | {gs_ms} |\n")
            if any(short_coverage(r) for r in rs):
                f.write(f"\n† the ground station estimated this UAV over less than "
                        f"{100 * MIN_COVERAGE:.0f} % of its frames (accepted batches / frames): "
                        f"the rest of the figure is the agent's own estimate.\n")
            f.write("\nSeed-mean per UAV:\n\n| UAV | ATE single | ATE dc | ATE cc | NEES cc | CC ≤ DC ≤ single |\n")
            f.write("|---:|---:|---:|---:|---:|---|\n")
            for uav in sorted({r["uav"] for r in rs}):
                m = {mode: mean([r["ate_m"] for r in rs if r["uav"] == uav and r["mode"] == mode]) for mode in MODES}
                nees = mean([r["nees"] for r in rs if r["uav"] == uav and r["mode"] == "cc"])
                ok = m["cc"] <= m["dc"] <= m["single"]
                f.write(f"| {uav} | {fmt(m['single'])} | {fmt(m['dc'])} | {fmt(m['cc'])} | {fmt(nees, 1)} | "
                        f"{'yes' if ok else 'no'} |\n")
            f.write("\n")


def plot(args, rows, results):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("compare_modes.py: matplotlib missing, no plots", file=sys.stderr)
        return
    groups = {}
    for r in rows:
        groups.setdefault((r["scenario"], r["sensing"]), []).append(r)
    for (scenario, sensing), rs in groups.items():
        uavs = sorted({r["uav"] for r in rs})
        fig, ax = plt.subplots(figsize=(1.8 + 1.2 * len(uavs), 3.2))
        width = 0.8 / len(MODES)
        for k, mode in enumerate(MODES):
            vals = [mean([r["ate_m"] for r in rs if r["uav"] == u and r["mode"] == mode]) for u in uavs]
            ax.bar([i + (k - 1) * width for i in range(len(uavs))], vals, width, label=mode)
        ax.set_xticks(range(len(uavs)))
        ax.set_xticklabels([f"UAV{u}" for u in uavs])
        ax.set_ylabel("seed-mean ATE [m]")
        ax.set_title(f"{scenario} ({sensing})")
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(args.out, f"ate_{scenario}_{sensing}.png"), dpi=110)
        plt.close(fig)
    for (scenario, sensing, seed), by_mode in results.items():
        uavs = sorted({int(u) for res in by_mode.values() for u in res["summary"]["agents"]})
        fig, axes = plt.subplots(len(uavs), 1, figsize=(7, 1.8 * len(uavs)), sharex=True, squeeze=False)
        for i, uav in enumerate(uavs):
            ax = axes[i][0]
            for mode in MODES:
                if mode not in by_mode:
                    continue
                t, e = position_error(os.path.join(by_mode[mode]["dir"], f"agent_{uav}"))
                ax.plot(t, e, label=mode, lw=0.9)
            ax.set_ylabel(f"UAV{uav} [m]")
        axes[0][0].legend(loc="upper left", fontsize=7)
        axes[-1][0].set_xlabel("t [s]")
        fig.suptitle(f"position error, {scenario} ({sensing}), seed {seed}")
        fig.tight_layout()
        fig.savefig(os.path.join(args.out, f"error_{scenario}_{sensing}_s{seed}.png"), dpi=100)
        plt.close(fig)


def position_error(agent_dir):
    def load(name):
        with open(os.path.join(agent_dir, name)) as f:
            return {row["t"]: row for row in csv.DictReader(f)}
    est, truth = load("states.csv"), load("truth.csv")
    t, e = [], []
    for key, s in est.items():
        g = truth.get(key)
        if g is None:
            continue
        t.append(float(key))
        e.append(math.sqrt(sum((float(s[c]) - float(g[c])) ** 2 for c in "xyz")))
    return t, e


def main():
    args = parse_args()
    os.makedirs(args.out, exist_ok=True)
    scenarios = [s for s in args.scenarios.split(",") if s]
    seeds = [int(s) for s in args.seeds.split(",") if s]
    sensings = ["features", "images"] if args.sensing == "both" else args.sensing.split(",")
    modes = args.modes.split(",")
    for m in modes:
        if m not in MODES:
            print(f"compare_modes.py: unknown mode '{m}'", file=sys.stderr)
            return 2
    for s in scenarios:
        if not os.path.exists(scenario_path(s)):
            print(f"compare_modes.py: no scenario {scenario_path(s)}", file=sys.stderr)
            return 2
    jobs = [(sc, seed, sen, mode) for sc in scenarios for sen in sensings for seed in seeds for mode in modes]
    rows, results, failed = [], {}, 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = {pool.submit(run_one, args, *job): job for job in jobs}
        for fut in concurrent.futures.as_completed(futures):
            sc, seed, sen, mode = futures[fut]
            name, res, err = fut.result()
            if err:
                print(f"compare_modes.py: {name}: {err}", file=sys.stderr)
                failed += 1
                continue
            print(f"compare_modes.py: {name} done", file=sys.stderr)
            new_rows = rows_of(sc, seed, sen, mode, res)
            for r in new_rows:
                if short_coverage(r):
                    print(f"compare_modes.py: {name}: UAV{r['uav']}'s CC figure covers only "
                          f"{100 * r['coverage']:.1f} % of its frames (ground station's accepted "
                          f"batches)", file=sys.stderr)
            rows.extend(new_rows)
            results.setdefault((scenario_name(sc), sen, seed), {})[mode] = res
    rows.sort(key=lambda r: (r["scenario"], r["sensing"], r["seed"], MODES.index(r["mode"]), r["uav"]))
    with open(os.path.join(args.out, "results.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()) if rows else ["scenario"])
        w.writeheader()
        w.writerows(rows)
    command = "scripts/compare_modes.py " + " ".join(sys.argv[1:])
    write_markdown(os.path.join(args.out, "results.md"), rows, command)
    if not args.no_plots:
        plot(args, rows, results)
    print(f"compare_modes.py: {len(rows)} rows in {args.out}/results.csv, results.md", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
