#!/usr/bin/python3
"""DC cooperation under message loss, Monte-Carlo (docs/cooperation.md "Loss").

    scripts/coop_loss_sweep.py --out DIR [--scenarios A,B] [--seeds 41,42] [--loss-levels 0,20,40]
                               [--loss-seeds 1,2,3] [--config FILE] [--jobs 2] [--build DIR]

Runs `cvslam_run --mode dc` (features, lockstep: deterministic per seed) on every scenario x
scenario seed x loss level x loss seed (`--coop-loss`, `--coop-loss-seed`: each message to
each peer lost independently), evaluates each run with cvslam_eval and writes DIR/results.csv
(one row per run and UAV) and DIR/results.md: per scenario and level, the mean ATE, the mean
relative change of each UAV-run's ATE from its loss-free run (averaged over the loss seeds),
the share of UAV-runs within 10 % of loss-free, exchanges and request timeouts.
"""

import argparse
import concurrent.futures as cf
import json
import os
import re
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run_one(build, scenario, seed, loss, loss_seed, config, out):
    if not os.path.exists(os.path.join(out, "summary.json")):
        cmd = [os.path.join(build, "tools", "cvslam_run"), "--scenario", scenario, "--mode", "dc",
               "--seed", str(seed), "--out", out, "--quiet"]
        if loss > 0:
            cmd += ["--coop-loss", str(loss), "--coop-loss-seed", str(loss_seed)]
        if config:
            cmd += ["--config", config]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            return None, "cvslam_run failed: " + r.stderr.strip().splitlines()[-1]
        open(os.path.join(out, "run.out"), "w").write(r.stdout + r.stderr)
        r = subprocess.run([os.path.join(build, "tools", "cvslam_eval"), "--run", out, "--quiet",
                            "--summary-json", os.path.join(out, "summary.json")],
                           capture_output=True, text=True)
        if r.returncode != 0:
            return None, "cvslam_eval failed: " + r.stderr.strip()
    agents = json.load(open(os.path.join(out, "summary.json")))["agents"]
    log = open(os.path.join(out, "run.out")).read()
    rows = {}
    for a, s in agents.items():
        m = re.search(r"UAV%s \(.*?exchanges (\d+).*?request timeouts (\d+)" % a, log)
        rows[a] = {"ate": s.get("ate_rmse_m"), "exchanges": int(m.group(1)) if m else None,
                   "timeouts": int(m.group(2)) if m else None}
    return rows, None


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", required=True)
    p.add_argument("--scenarios", default="team3_aerial,coop_pair,thesis_loop")
    p.add_argument("--seeds", default="41,42,43,44,45,46")
    p.add_argument("--loss-levels", default="0,20,40")
    p.add_argument("--loss-seeds", default="1,2,3")
    p.add_argument("--config", default="")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--build", default=os.path.join(ROOT, "build"))
    a = p.parse_args()
    try:
        seeds = [int(s) for s in a.seeds.split(",")]
        levels = [float(s) for s in a.loss_levels.split(",")]
        loss_seeds = [int(s) for s in a.loss_seeds.split(",")]
    except ValueError as e:
        sys.exit("coop_loss_sweep.py: %s" % e)
    if levels[0] != 0:
        sys.exit("coop_loss_sweep.py: the first loss level must be 0 (the reference)")
    os.makedirs(a.out, exist_ok=True)
    jobs = []
    for sc in a.scenarios.split(","):
        path = sc if sc.endswith(".yaml") else os.path.join(ROOT, "config", "scenarios", sc + ".yaml")
        if not os.path.exists(path):
            sys.exit("coop_loss_sweep.py: no scenario %s" % path)
        name = os.path.basename(path)[:-5]
        for seed in seeds:
            for loss in levels:
                for ls in (loss_seeds if loss > 0 else [0]):
                    jobs.append((name, path, seed, loss, ls,
                                 os.path.join(a.out, "%s_s%d_l%g_r%d" % (name, seed, loss, ls))))
    results, done = {}, 0
    with cf.ThreadPoolExecutor(a.jobs) as pool:
        futures = {pool.submit(run_one, a.build, j[1], j[2], j[3], j[4], a.config, j[5]): j for j in jobs}
        for f in cf.as_completed(futures):
            j = futures[f]
            rows, err = f.result()
            done += 1
            if err:
                print("%s: %s" % (j[5], err), file=sys.stderr)
                continue
            results[j] = rows
            print("\r%d/%d runs" % (done, len(jobs)), end="", file=sys.stderr)
    print(file=sys.stderr)
    with open(os.path.join(a.out, "results.csv"), "w") as f:
        f.write("scenario,seed,loss,loss_seed,uav,ate_m,exchanges,request_timeouts\n")
        for j, rows in sorted(results.items()):
            for uav, r in sorted(rows.items()):
                f.write("%s,%d,%g,%d,%s,%s,%s,%s\n" % (j[0], j[2], j[3], j[4], uav, r["ate"],
                                                      r["exchanges"], r["timeouts"]))
    lines = ["| scenario | loss % | mean ATE [m] | mean change vs 0 % | UAV-runs within 10 % | "
             "worst change | exchanges | request timeouts |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for sc in dict.fromkeys(j[0] for j in jobs):
        for loss in levels:
            changes, ates, ex, to = [], [], [], []
            for seed in seeds:
                base = results.get(next((j for j in jobs if j[0] == sc and j[2] == seed and j[3] == 0), None))
                runs = [results.get(j) for j in jobs if j[0] == sc and j[2] == seed and j[3] == loss]
                runs = [r for r in runs if r]
                if not base or not runs:
                    continue
                for uav in base:
                    vals = [r[uav]["ate"] for r in runs if r.get(uav) and r[uav]["ate"] is not None]
                    if not vals or base[uav]["ate"] is None:
                        continue
                    m = statistics.mean(vals)
                    ates.append(m)
                    changes.append(100.0 * (m / base[uav]["ate"] - 1.0))
                    ex += [r[uav]["exchanges"] for r in runs if r.get(uav) and r[uav]["exchanges"] is not None]
                    to += [r[uav]["timeouts"] for r in runs if r.get(uav) and r[uav]["timeouts"] is not None]
            if not changes:
                continue
            within = sum(1 for c in changes if abs(c) <= 10.0)
            worst = max(changes, key=abs)
            lines.append("| %s | %g | %.3f | %+.1f %% | %d / %d | %+.1f %% | %.1f | %.1f |" % (
                sc, loss, statistics.mean(ates), statistics.mean(changes), within, len(changes),
                worst, statistics.mean(ex) if ex else float("nan"),
                statistics.mean(to) if to else float("nan")))
    text = "\n".join(lines)
    open(os.path.join(a.out, "results.md"), "w").write(
        "Seeds %s, loss seeds %s, config %s.\n\n%s\n" % (a.seeds, a.loss_seeds, a.config or "default", text))
    print(text)


if __name__ == "__main__":
    main()
