#!/usr/bin/env python3
"""Monte-Carlo consistency of a scenario: NEES per state group against the χ² band, Rco per state.

    scripts/mc_consistency.py --scenario FILE --seeds FIRST-LAST --out DIR [--mode single|dc|cc]
                              [--sensing features|images] [--jobs 2] [--duration S]
                              [--config FILE] [--build-dir build] [--run-arg=ARG ...]
                              [--runs-only | --analyse-only]

Runs `cvslam_run --seed N` for every seed N of the range (up to --jobs at a time) into
DIR/runs/seed_<N>/ (a run goes to seed_<N>.tmp first and is renamed when it completed, so an
interrupted sweep resumes: a seed whose folder has states.csv for every agent of its run.json
is not run again), then analyses the ensemble of N runs per agent (agent_<id>/states.csv
against agent_<id>/truth.csv; the ground station's folder of --mode cc is ignored).

Method (Bar-Shalom, Li & Kirubarajan, "Estimation with applications to tracking", §5.4; the
thesis §5.7.3). The error of run r at time t is e = x̂ − x (9 states: position NED, body
velocity, ZYX Euler roll pitch yaw; angle errors wrapped to (−π, π]); rows of states.csv and
truth.csv are matched by t rounded to 1e-4 s. For each state group g of d states
(position 3, velocity 3, tilt = roll+pitch 2, yaw 1, vehicle 9; with bias states, from
agent_<id>/biases.csv: accelerometer bias 3, gyro bias 3) the NEES of a run is
ε_g = e_gᵀ P_gg⁻¹ e_g with P_gg the group's block of the recorded covariance (a step whose
block is not positive definite is left out). The ensemble NEES at t is the mean of ε_g over
the N runs; if the filter is consistent, N·ε̄_g ~ χ²(N·d), so ε̄_g lies in the two-sided 95 %
band [χ²_0.025(N d)/N, χ²_0.975(N d)/N] at 95 % of the time stamps. The quantiles come from
the Wilson–Hilferty approximation χ²_p(k) ≈ k (1 − 2/(9k) + z_p √(2/(9k)))³ (relative error
below 1 % for k ≥ 10; scipy is not needed). Reported per group: the mean over time of ε̄_g,
the band for N runs, and the percentage of time stamps inside (and above: optimistic) it.
The band of N runs holds only for independent runs. Runs that share an error source are not:
every run of a UAV that plays one recorded IMU (euroc_mh03_hall's UAV3) has the same IMU noise,
and their mean NEES then fluctuates like one run's. The table also gives the percentage of time
stamps inside the band of one run, [χ²_0.025(d), χ²_0.975(d)] (which contains the band of N
runs), the bound that holds for such runs.

Rco (thesis §5.7.3; common/eval/src/metrics.cpp consistencyDegree): per run, cvslam_eval
defines co_i(t) = σ_i(t) / σ_true,i(t) with σ_i = √P_ii and σ_true,i the RMS of the true error
e_i over a window of steps (default one step: |e_i(t)|), and Rco_i = min over t of co_i(t)
(Rco ≤ 1: at some time the filter claimed less uncertainty than its error). Over the
Monte-Carlo ensemble the window is the N runs at the same t instead of steps in time:
    co_i(t) = √(mean_r σ_i,r(t)²) / √(mean_r e_i,r(t)²),   Rco_i = min over t of co_i(t),
where steps with an ensemble RMS error below 1e-9 (e.g. t = 0, where every run starts on the
truth) are skipped, as metrics.cpp does.

The final map's landmark NEES (landmarks.csv: estimate, the diagonal of its covariance, the true
point) is reported per agent as the mean over landmarks and runs (3 expected).

Writes DIR/consistency.md (a table per agent, printed too), DIR/consistency.csv (the time
series: per agent and t, the runs used, ε̄ and band per group, co per state) and
DIR/nees_agent<id>.png (ε̄ per group over time, log y axis, band shaded). Exit status 0 on
success, 2 on bad usage (missing binary, bad seed range), 1 when runs fail or nothing can be
analysed.
"""
import argparse
import concurrent.futures
import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VEHICLE = ['x', 'y', 'z', 'u', 'v', 'w', 'roll', 'pitch', 'yaw']
BIASES = ['ba_x', 'ba_y', 'ba_z', 'bg_x', 'bg_y', 'bg_z']
STATES = VEHICLE + BIASES
ANGLES = (6, 7, 8)
GROUPS = [('position', slice(0, 3)), ('velocity', slice(3, 6)), ('tilt', slice(6, 8)),
          ('yaw', slice(8, 9)), ('vehicle', slice(0, 9)), ('accel bias', slice(9, 12)),
          ('gyro bias', slice(12, 15))]
Z_975 = 1.959963984540054
MIN_TRUE_SIGMA = 1e-9


class UsageError(Exception):
    """Bad input: reported as one line, exit status 2."""


def parse_args(argv):
    p = argparse.ArgumentParser(
        description='Monte-Carlo consistency: NEES per state group against the χ² 95 % band '
                    'of N runs, Rco per state (see the module docstring for the method).')
    p.add_argument('--scenario', required=True, help='scenario YAML (config/scenarios/*.yaml)')
    p.add_argument('--seeds', required=True, help='seed range FIRST-LAST, e.g. 201-210')
    p.add_argument('--out', required=True, help='output folder (runs/ and the reports)')
    p.add_argument('--mode', default='single', choices=['single', 'dc', 'cc'])
    p.add_argument('--sensing', default='features', choices=['features', 'images'],
                   help='features (true ids) or images (rendered, through the front end)')
    p.add_argument('--jobs', type=int, default=2, help='parallel cvslam_run processes')
    p.add_argument('--duration', type=float, help='simulate only the first S seconds')
    p.add_argument('--config', help='agent configuration (default: config/agent.yaml)')
    p.add_argument('--build-dir', default='build', help='build folder with tools/cvslam_run')
    p.add_argument('--run-arg', action='append', default=[], metavar='ARG',
                   help='one more cvslam_run argument (repeatable), e.g. '
                        '--run-arg=--linearise-at-truth for the ideal EKF')
    only = p.add_mutually_exclusive_group()
    only.add_argument('--runs-only', action='store_true', help='run the seeds, no analysis')
    only.add_argument('--analyse-only', action='store_true', help='analyse the existing runs')
    return p.parse_args(argv)


def parse_seeds(text):
    """FIRST-LAST (or a single seed) -> list of seeds; UsageError otherwise."""
    m = re.fullmatch(r'\s*(\d+)\s*(?:-\s*(\d+)\s*)?', text)
    if not m:
        raise UsageError(f"--seeds must be FIRST-LAST (e.g. 201-210), not '{text}'")
    first, last = int(m.group(1)), int(m.group(2) or m.group(1))
    if last < first:
        raise UsageError(f'--seeds {text}: the last seed is below the first')
    return list(range(first, last + 1))


# ---------------------------------------------------------------- running the seeds

def run_complete(folder, args=None):
    """True when the run folder's run.json lists agents that all have states.csv and truth.csv
    (and, given args, was run with their mode and duration: another run is not resumed)."""
    try:
        with open(os.path.join(folder, 'run.json')) as f:
            run = json.load(f)
        agents = run['agents']
    except (OSError, ValueError, KeyError):
        return False
    if args is not None and (run.get('mode') != args.mode or
                             run.get('sensing', 'features') != args.sensing or (
            args.duration is not None and run.get('duration_s') != args.duration)):
        return False
    return bool(agents) and all(
        os.path.isfile(os.path.join(folder, f'agent_{a}', name))
        for a in agents for name in ('states.csv', 'truth.csv'))


def run_seed(args, exe, seed):
    """One cvslam_run into runs/seed_<seed>.tmp, renamed on success. Returns (seed, error)."""
    final = os.path.join(args.out, 'runs', f'seed_{seed}')
    tmp = final + '.tmp'
    shutil.rmtree(tmp, ignore_errors=True)
    cmd = [exe, '--scenario', args.scenario, '--out', tmp, '--seed', str(seed), '--quiet',
           '--mode', args.mode, '--sensing', args.sensing]
    if args.duration is not None:
        cmd += ['--duration', str(args.duration)]
    if args.config:
        cmd += ['--config', args.config]
    cmd += args.run_arg
    log = final + '.log'
    with open(log, 'w') as f:
        rc = subprocess.call(cmd, stdout=f, stderr=subprocess.STDOUT)
    if rc != 0 or not run_complete(tmp):
        return seed, f'cvslam_run exited {rc} (see {log})'
    shutil.rmtree(final, ignore_errors=True)
    os.rename(tmp, final)
    return seed, None


def run_all(args, seeds):
    """Runs the seeds not yet complete, --jobs at a time, printing progress. Returns failures."""
    exe = os.path.join(args.build_dir, 'tools', 'cvslam_run')
    if not os.access(exe, os.X_OK):
        raise UsageError(f'{exe} not found or not executable (give --build-dir)')
    os.makedirs(os.path.join(args.out, 'runs'), exist_ok=True)
    todo = [s for s in seeds
            if not run_complete(os.path.join(args.out, 'runs', f'seed_{s}'), args)]
    print(f'mc_consistency: {len(seeds) - len(todo)} of {len(seeds)} seeds already run, '
          f'running {len(todo)} ({args.jobs} at a time)', flush=True)
    failed = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futures = [pool.submit(run_seed, args, exe, s) for s in todo]
        for done, fut in enumerate(concurrent.futures.as_completed(futures), 1):
            seed, error = fut.result()
            print(f'  [{done}/{len(todo)}] seed {seed}: {error or "done"}', flush=True)
            if error:
                failed.append(seed)
    return failed


# ---------------------------------------------------------------- reading one run

def read_csv_rows(path):
    """{t rounded to 1e-4: row dict} of a states.csv or truth.csv."""
    with open(path, newline='') as f:
        return {round(float(r['t']), 4): r for r in csv.DictReader(f)}


def covariance(row, names):
    """The covariance of a states.csv (or biases.csv) row of the states `names`: variances
    and upper-triangle covariances cov_i_j (absent: 0)."""
    n = len(names)
    P = np.zeros((n, n))
    for i in range(n):
        P[i, i] = float(row['var_' + names[i]])
        for j in range(i + 1, n):
            c = row.get(f'cov_{i}_{j}')
            if c not in (None, ''):
                P[i, j] = P[j, i] = float(c)
    return P


def group_nees(e, P):
    """NEES of each group of GROUPS (NaN where the group's block is not positive definite)."""
    out = []
    for _, sl in GROUPS:
        es, Ps = e[sl], P[sl, sl]
        if not np.all(np.isfinite(es)):
            out.append(math.nan)
            continue
        try:
            L = np.linalg.cholesky(Ps)
        except np.linalg.LinAlgError:
            out.append(math.nan)
            continue
        y = np.linalg.solve(L, es)
        out.append(float(y @ y))
    return out


def read_agent_run(folder):
    """{t: (nees per group, error [15], variance [15])} of one agent of one run. The bias
    entries come from biases.csv (estimate, covariance and true_* columns); NaN when the run
    has no bias states or no true biases (their groups' NEES is then NaN)."""
    states = read_csv_rows(os.path.join(folder, 'states.csv'))
    truth = read_csv_rows(os.path.join(folder, 'truth.csv'))
    bias_path = os.path.join(folder, 'biases.csv')
    biases = read_csv_rows(bias_path) if os.path.isfile(bias_path) else {}
    out = {}
    for t, r in states.items():
        g = truth.get(t)
        if g is None:
            continue
        e = np.full(len(STATES), math.nan)
        e[:9] = [float(r[n]) - float(g[n]) for n in VEHICLE]
        for k in ANGLES:
            e[k] = math.remainder(e[k], 2 * math.pi)
        P = np.zeros((len(STATES), len(STATES)))
        P[:9, :9] = covariance(r, VEHICLE)
        b = biases.get(t)
        if b is not None:
            e[9:] = [float(b[n]) - float(b['true_' + n]) for n in BIASES]
            P[9:, 9:] = covariance(b, BIASES)
        out[t] = (group_nees(e, P), e, np.diag(P).copy())
    return out


def read_map_nees(folder):
    """(mean NEES, landmarks) of the final map of one agent of one run: landmarks.csv rows with
    a true position, e = p̂ − p, NEES = Σ_xyz e²/var (the file has the diagonal of each
    landmark's covariance only); None without such rows."""
    path = os.path.join(folder, 'landmarks.csv')
    if not os.path.isfile(path):
        return None
    values = []
    with open(path, newline='') as f:
        for r in csv.DictReader(f):
            if r.get('true_x') in (None, '', 'nan'):
                continue
            nees = 0.0
            for a in 'xyz':
                var = float(r['var_' + a])
                if not var > 0.0:
                    break
                nees += (float(r[a]) - float(r['true_' + a])) ** 2 / var
            else:
                values.append(nees)
    return (float(np.mean(values)), len(values)) if values else None


# ---------------------------------------------------------------- ensemble statistics

def chi2_quantile(p_z, k):
    """Wilson–Hilferty χ² quantile for k dof at the standard normal quantile p_z."""
    h = 2.0 / (9.0 * k)
    return k * max(0.0, 1.0 - h + p_z * math.sqrt(h)) ** 3


def mean_nees_band(n_runs, dof):
    """Two-sided 95 % band of the mean NEES of n_runs runs with dof states each."""
    k = n_runs * dof
    return chi2_quantile(-Z_975, k) / n_runs, chi2_quantile(Z_975, k) / n_runs


def ensemble_series(runs):
    """Per common time stamp of the runs of one agent: mean NEES per group, runs used, co.

    Returns dict of arrays: t [T], nees [T, 5], n [T, 5], lo/hi [T, 5], co [T, 9].
    """
    times = sorted(set.intersection(*(set(r) for r in runs)))
    T, G = len(times), len(GROUPS)
    nees, n = np.full((T, G), math.nan), np.zeros((T, G), dtype=int)
    S = len(STATES)
    lo, hi, co = np.full((T, G), math.nan), np.full((T, G), math.nan), np.full((T, S), math.nan)
    for k, t in enumerate(times):
        eps = np.array([r[t][0] for r in runs])          # runs x groups
        err = np.array([r[t][1] for r in runs])          # runs x states
        var = np.array([r[t][2] for r in runs])
        for g, (_, sl) in enumerate(GROUPS):
            valid = eps[:, g][np.isfinite(eps[:, g])]
            n[k, g] = len(valid)
            if len(valid):
                nees[k, g] = valid.mean()
                lo[k, g], hi[k, g] = mean_nees_band(len(valid), sl.stop - sl.start)
        rms_err = np.sqrt(np.mean(err ** 2, axis=0))
        sigma = np.sqrt(np.mean(np.maximum(var, 0.0), axis=0))
        ok = np.isfinite(rms_err) & (rms_err >= MIN_TRUE_SIGMA)
        co[k, ok] = sigma[ok] / rms_err[ok]
    return {'t': np.array(times), 'nees': nees, 'n': n, 'lo': lo, 'hi': hi, 'co': co}


def summarise(series):
    """Per group: dof, mean NEES over time, band for the full ensemble, % in band, % above;
    and Rco per state."""
    rows = []
    n_max = int(series['n'].max()) if series['n'].size else 0
    for g, (name, sl) in enumerate(GROUPS):
        x = series['nees'][:, g]
        ok = np.isfinite(x)
        inside = ok & (x >= series['lo'][:, g]) & (x <= series['hi'][:, g])
        above = ok & (x > series['hi'][:, g])
        lo1, hi1 = mean_nees_band(1, sl.stop - sl.start)
        inside_one = ok & (x >= lo1) & (x <= hi1)
        steps = max(1, int(ok.sum()))
        rows.append({'group': name, 'dof': sl.stop - sl.start,
                     'mean': float(np.mean(x[ok])) if ok.any() else math.nan,
                     'band': mean_nees_band(max(1, n_max), sl.stop - sl.start),
                     'in': 100.0 * inside.sum() / steps, 'above': 100.0 * above.sum() / steps,
                     'in_one': 100.0 * inside_one.sum() / steps})
    co = series['co']
    rco = [float(np.nanmin(co[:, s])) if np.isfinite(co[:, s]).any() else math.nan
           for s in range(len(STATES))]
    return rows, rco


# ---------------------------------------------------------------- reports

def recorded_imu_agents(scenario):
    """Ids of the scenario's agents that play a recorded IMU (imu.recording) — the same IMU
    noise in every run. Empty when the file cannot be read or PyYAML is missing (the report
    then only lacks the remark)."""
    try:
        import yaml
    except ImportError:
        return set()
    try:
        with open(scenario) as f:
            agents = (yaml.safe_load(f) or {}).get('agents') or []
    except (OSError, yaml.YAMLError, AttributeError):
        return set()
    return {a.get('id') for a in agents
            if isinstance(a, dict) and isinstance(a.get('imu'), dict) and a['imu'].get('recording')}


def markdown(args, n_runs, results):
    """The consistency.md text: a NEES table and an Rco row per agent."""
    lines = [f'# Monte-Carlo consistency: {os.path.basename(args.scenario)}, mode {args.mode}, '
             f'{args.sensing}, {n_runs} runs (seeds {args.seeds})', '',
             'Mean NEES over runs at each time stamp against the two-sided χ² 95 % band of the '
             'mean of N runs; mean = time average; "in one-run band": the share of time '
             'inside the band of one run, the bound for runs that are not independent (one '
             'recorded IMU played in every run); Rco_i = min over t of '
             '√(mean σ_i²)/√(mean e_i²) over the runs (scripts/mc_consistency.py).', '']
    recorded = recorded_imu_agents(args.scenario)
    for agent, (rows, rco, map_nees) in results.items():
        lines += [f'## UAV{agent}', '']
        if agent in recorded:
            lines += [f'UAV{agent} plays a recorded IMU (imu.recording) in every run: its runs '
                      'share their IMU noise and are not independent, so the band that holds '
                      'for them is the one-run band (last column).', '']
        lines += ['| group | dof | mean NEES | 95 % band | % of time in band | % above band '
                  '| % in one-run band |',
                  '|---|---:|---:|---|---:|---:|---:|']
        for r in rows:
            if not math.isfinite(r['mean']):
                continue  # no such states in these runs (no bias states or true biases)
            lines.append(f"| {r['group']} | {r['dof']} | {r['mean']:.3f} | "
                         f"[{r['band'][0]:.3f}, {r['band'][1]:.3f}] | {r['in']:.1f} | "
                         f"{r['above']:.1f} | {r['in_one']:.1f} |")
        shown = [i for i, v in enumerate(rco) if i < 9 or math.isfinite(v)]
        lines += ['', '| Rco | ' + ' | '.join(STATES[i] for i in shown) + ' |',
                  '|---|' + '---:|' * len(shown),
                  '| Rco | ' + ' | '.join(f'{rco[i]:.3f}' for i in shown) + ' |', '']
        if map_nees:
            means = [m for m, _ in map_nees]
            lines += [f'Final map, landmark NEES (3 dof; diagonal of each landmark covariance, '
                      f'landmarks.csv): mean {np.mean(means):.2f} over {len(means)} runs '
                      f'(per run {min(means):.2f}–{max(means):.2f}; '
                      f'{np.mean([n for _, n in map_nees]):.0f} landmarks per run).', '']
    return '\n'.join(lines)


def write_csv(path, all_series):
    """consistency.csv: per agent and time stamp, runs used, NEES and band per group, co."""
    header = ['agent', 't']
    for name, _ in GROUPS:
        header += [f'n_{name}', f'nees_{name}', f'lo_{name}', f'hi_{name}']
    header += [f'co_{s}' for s in STATES]
    with open(path, 'w', newline='') as f:
        w = csv.writer(f)
        w.writerow(header)
        for agent, s in all_series.items():
            for k, t in enumerate(s['t']):
                row = [agent, f'{t:.4f}']
                for g in range(len(GROUPS)):
                    row += [s['n'][k, g]] + [f'{s[c][k, g]:.6g}' for c in ('nees', 'lo', 'hi')]
                row += [f'{v:.6g}' for v in s['co'][k]]
                w.writerow(row)


def plot_agent(path, agent, series, n_runs):
    """nees_agent<id>.png: mean NEES per group over time, log y axis, 95 % band shaded."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(GROUPS), 1, sharex=True, figsize=(8, 14))
    t = series['t']
    for g, (ax, (name, sl)) in enumerate(zip(axes, GROUPS)):
        x = np.where(series['nees'][:, g] > 0, series['nees'][:, g], np.nan)
        ax.fill_between(t, series['lo'][:, g], series['hi'][:, g], color='tab:green',
                        alpha=0.25, label='χ² 95 % band')
        ax.axhline(sl.stop - sl.start, color='tab:green', lw=0.8, ls='--', label='dof')
        ax.plot(t, x, color='tab:blue', lw=1.0, label='mean NEES')
        ax.set_yscale('log')
        ax.set_ylabel(f'{name} ({sl.stop - sl.start})')
        ax.grid(True, which='both', alpha=0.3)
    axes[0].legend(loc='upper right', fontsize=8)
    axes[0].set_title(f'UAV{agent}: NEES over {n_runs} runs')
    axes[-1].set_xlabel('t [s]')
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


# ---------------------------------------------------------------- analysis driver

def load_runs(args, seeds):
    """{agent id: [per-run dict]}, {agent id: [final-map NEES]} and the number of complete
    runs of the seeds."""
    per_agent, maps, used = {}, {}, 0
    for s in seeds:
        folder = os.path.join(args.out, 'runs', f'seed_{s}')
        if not run_complete(folder):
            continue
        with open(os.path.join(folder, 'run.json')) as f:
            agents = json.load(f)['agents']
        for a in agents:
            agent_dir = os.path.join(folder, f'agent_{a}')
            per_agent.setdefault(a, []).append(read_agent_run(agent_dir))
            m = read_map_nees(agent_dir)
            if m is not None:
                maps.setdefault(a, []).append(m)
        used += 1
    return per_agent, maps, used


def analyse(args, seeds):
    """Reads the runs, writes consistency.md/.csv and the plots; returns the exit status."""
    per_agent, maps, n_runs = load_runs(args, seeds)
    if n_runs == 0:
        print(f'mc_consistency: no complete run of seeds {args.seeds} under '
              f'{os.path.join(args.out, "runs")}', file=sys.stderr)
        return 1
    results, all_series = {}, {}
    for agent, runs in sorted(per_agent.items()):
        series = ensemble_series(runs)
        if len(series['t']) == 0:
            print(f'mc_consistency: UAV{agent}: no time stamp common to its runs',
                  file=sys.stderr)
            return 1
        all_series[agent] = series
        results[agent] = summarise(series) + (maps.get(agent, []),)
        plot_agent(os.path.join(args.out, f'nees_agent{agent}.png'), agent, series, len(runs))
    text = markdown(args, n_runs, results)
    with open(os.path.join(args.out, 'consistency.md'), 'w') as f:
        f.write(text + '\n')
    write_csv(os.path.join(args.out, 'consistency.csv'), all_series)
    print(text)
    print(f'mc_consistency: wrote {args.out}/consistency.md, consistency.csv, '
          f'nees_agent<id>.png')
    return 0


def main(argv):
    args = parse_args(argv)
    try:
        seeds = parse_seeds(args.seeds)
        if args.jobs < 1:
            raise UsageError('--jobs must be at least 1')
        if not args.analyse_only and not os.path.isfile(args.scenario):
            raise UsageError(f'scenario {args.scenario} not found')
        if args.config is None and os.path.isfile(os.path.join(ROOT, 'config', 'agent.yaml')):
            args.config = os.path.join(ROOT, 'config', 'agent.yaml')
        failed = [] if args.analyse_only else run_all(args, seeds)
    except UsageError as e:
        print(f'mc_consistency: {e}', file=sys.stderr)
        return 2
    if failed:
        print(f'mc_consistency: {len(failed)} seed(s) failed: '
              f'{", ".join(map(str, failed))}', file=sys.stderr)
    if args.runs_only:
        return 1 if failed else 0
    status = analyse(args, seeds)
    return status or (1 if failed else 0)


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
