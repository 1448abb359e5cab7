#!/usr/bin/env python3
"""NH∞ against the EKF where the thesis says NH∞ wins (§3.7, §5.9.2, Tables 5.3–5.4,
Figs 5.12–5.13): a γ sweep on some seeds, the chosen γ reported on others
(docs/results/nhinf.md).

    scripts/nhinf_study.py --out DIR [--build-dir build] [--jobs 2]
                           [--tune-seeds 101-106] [--report-seeds 1-20]
                           [--gammas 30,10,3,1,0.5,0.3,0.2,0.1,0.05] [--cases NAME,...]
                           [--analyse-only]

Cases (each filter on the same simulated data per seed):
  slam_gaussian      thesis_loop, UAV1 (210 s, closes its loop at 200 s): centred Gaussian
                     IMU and pixel noise (Figs 5.8/5.10, Table 5.3)
  slam_non_gaussian  the same with centred non-Gaussian noise, IMU and pixels: the heavy-tailed
                     mixture (0.9 N(0, σ1²) + 0.1 N(0, (4σ1)²), same σ) (Figs 5.9/5.11)
  slam_non_centred   the same with non-centred Gaussian pixel noise (a constant offset of
                     0.5 px on u_L, v_L, v_R) (Table 5.4)
  slam_nonlinear     thesis_nonlinear: a tight figure of eight, 60°/s turns, 35° tilts (Fig. 5.13)
  insgps_sharp       cvslam_ins_gps, config/ins_gps/sharp_manoeuvres.yaml (ch. 3, Table 3.2)
  insgps_heavy       cvslam_ins_gps, config/ins_gps/heavy_tailed_gps.yaml: Student-t (ν = 3)
                     GPS errors with a wandering bias (non-Gaussian, non-centred)

For every case: the EKF and NH∞ at each γ of --gammas on the tune seeds; γ* = the γ of the
lowest tune-seed mean position error (SLAM: ATE of UAV1; INS/GPS: position RMS from 10 s).
Then the EKF and NH∞(γ*) on the report seeds: mean ± std, the paired difference EKF − NH∞ with
its standard error, the seeds NH∞ wins, NEES, landmark error mean/std per axis (SLAM), and the
share of updates in which eq. 3.40 failed at the policy's θ and θ was reduced (events.csv).
A run whose folder holds its summary is not run again (an interrupted study resumes).
Writes DIR/study.json and prints Markdown tables (also DIR/tables.md).
"""
import argparse
import csv
import json
import math
import os
import re
import statistics
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

SLAM_CASES = {
    'slam_gaussian': ('config/scenarios/thesis_loop.yaml', {}, ['--agents', '1']),
    'slam_non_gaussian': ('config/scenarios/thesis_loop.yaml',
                          {'imu': {'kind': 'non_gaussian_centred', 'shape': 'mixture'},
                           'pixel_noise': {'kind': 'non_gaussian_centred', 'shape': 'mixture'}},
                          ['--agents', '1']),
    'slam_non_centred': ('config/scenarios/thesis_loop.yaml',
                         {'pixel_noise': {'kind': 'non_centred'}}, ['--agents', '1']),
    'slam_nonlinear': ('config/scenarios/thesis_nonlinear.yaml', {}, []),
}
INSGPS_CASES = {
    'insgps_sharp': 'config/ins_gps/sharp_manoeuvres.yaml',
    'insgps_heavy': 'config/ins_gps/heavy_tailed_gps.yaml',
}
INSGPS_FROM_S = 10.0
# Two-sided 95 % Student-t quantiles by degrees of freedom (paired test over the report seeds).
T95 = {1: 12.71, 2: 4.30, 3: 3.18, 4: 2.78, 5: 2.57, 6: 2.45, 7: 2.36, 8: 2.31, 9: 2.26,
       10: 2.23, 12: 2.18, 15: 2.13, 19: 2.09, 20: 2.09, 24: 2.06, 29: 2.05}


def t95(dof):
    keys = sorted(k for k in T95 if k <= dof)
    return T95[keys[-1]] if keys else T95[1]


def seed_range(text):
    m = re.fullmatch(r'(\d+)-(\d+)', text)
    if not m or int(m.group(1)) > int(m.group(2)):
        raise argparse.ArgumentTypeError(f"expected FIRST-LAST, got '{text}'")
    return list(range(int(m.group(1)), int(m.group(2)) + 1))


def gamma_list(text):
    try:
        values = [float(v) for v in text.split(',')]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got '{text}'")
    if not values or any(not v > 0 for v in values):
        raise argparse.ArgumentTypeError('every γ must be > 0')
    return values


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split('\n\n')[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('--out', required=True)
    p.add_argument('--build-dir', default='build')
    p.add_argument('--jobs', type=int, default=2)
    p.add_argument('--tune-seeds', type=seed_range, default=seed_range('101-106'))
    p.add_argument('--report-seeds', type=seed_range, default=seed_range('1-20'))
    p.add_argument('--gammas', type=gamma_list, default=gamma_list('30,10,3,1,0.5,0.3,0.2,0.1,0.05'))
    p.add_argument('--cases', default=','.join(list(SLAM_CASES) + list(INSGPS_CASES)))
    p.add_argument('--analyse-only', action='store_true')
    a = p.parse_args()
    a.cases = a.cases.split(',')
    unknown = [c for c in a.cases if c not in SLAM_CASES and c not in INSGPS_CASES]
    if unknown:
        p.error(f"unknown case(s) {', '.join(unknown)}")
    if set(a.tune_seeds) & set(a.report_seeds):
        p.error('the tune and report seeds overlap: γ must be reported on seeds it was not chosen on')
    return a


def filter_tag(gamma):
    return 'ekf' if gamma is None else f'nhinf_g{gamma:g}'


# ---------------------------------------------------------------- SLAM runs (cvslam_run)

def derived_scenario(args, case):
    """The case's scenario file: the original, or a copy with its noise kinds changed."""
    path, noise, _ = SLAM_CASES[case]
    if not noise:
        return os.path.join(ROOT, path)
    with open(os.path.join(ROOT, path)) as f:
        scenario = yaml.safe_load(f)
    for agent in scenario['agents']:
        for section, keys in noise.items():
            agent.setdefault(section, {}).update(keys)
    scenario['name'] = f"{scenario['name']}_{case}"
    out = os.path.join(args.out, 'scenarios', f'{case}.yaml')
    os.makedirs(os.path.dirname(out), exist_ok=True)
    with open(out, 'w') as f:
        f.write(f'# {path} with the noise of nhinf_study.py case {case}\n')
        yaml.safe_dump(scenario, f, sort_keys=False)
    return out


def theta_reduced_share(run_dir):
    rows = list(csv.DictReader(open(os.path.join(run_dir, 'agent_1', 'events.csv'))))
    updated = [r for r in rows if int(r['updated']) > 0]
    return sum(int(r['theta_reduced']) for r in updated) / max(len(updated), 1)


def run_slam(args, case, scenario, seed, gamma):
    d = os.path.join(args.out, case, filter_tag(gamma), f'seed_{seed}')
    summary = os.path.join(d, 'summary.json')
    if not os.path.exists(summary):
        if args.analyse_only:
            return None
        tools = os.path.join(args.build_dir, 'tools')
        cmd = [os.path.join(tools, 'cvslam_run'), '--scenario', scenario, '--seed', str(seed),
               '--out', d, '--quiet'] + SLAM_CASES[case][2]
        cmd += ['--filter', 'ekf'] if gamma is None else \
            ['--filter', 'nhinf', '--set', f'filter.gamma={gamma:g}']
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        subprocess.run([os.path.join(tools, 'cvslam_eval'), '--run', d, '--quiet',
                        '--summary-json', summary], check=True, stdout=subprocess.DEVNULL)
    a = json.load(open(summary))['agents']['1']
    return {'pos': a['ate_rmse_m'], 'nees': a['nees_mean'], 'nees_pos': a['nees_position_mean'],
            'lm_mean': a['landmark_error_mean_m'], 'lm_std': a['landmark_error_std_m'],
            'lm_rms': a['landmark_error_rms_m'], 'theta_reduced': theta_reduced_share(d)}


# ---------------------------------------------------------------- INS/GPS runs (cvslam_ins_gps)

def derived_insgps_config(args, case, gamma):
    with open(os.path.join(ROOT, INSGPS_CASES[case])) as f:
        config = yaml.safe_load(f)
    config['filters']['run'] = ['ekf'] if gamma is None else ['nhinf']
    if gamma is not None:
        config['filters']['nhinf']['gamma'] = gamma
    out = os.path.join(args.out, 'configs', f'{case}_{filter_tag(gamma)}.yaml')
    os.makedirs(os.path.dirname(out), exist_ok=True)
    with open(out, 'w') as f:
        f.write(f'# {INSGPS_CASES[case]} as nhinf_study.py runs it\n')
        yaml.safe_dump(config, f, sort_keys=False)
    return out


def parse_insgps_table(text, name):
    """The first statistics row of filter `name` in cvslam_ins_gps's Markdown output."""
    header = None
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip('|').split('|')]
        if cells and cells[0] == 'filter':
            header = cells
        elif header and cells and cells[0] == name and len(cells) == len(header):
            row = dict(zip(header, cells))
            if 'pos RMS (m)' in row:
                return row
    raise RuntimeError(f'cvslam_ins_gps printed no statistics row for {name}')


def run_insgps(args, case, config, seed, gamma):
    d = os.path.join(args.out, case, filter_tag(gamma), f'seed_{seed}')
    summary = os.path.join(d, 'summary.json')
    if not os.path.exists(summary):
        if args.analyse_only:
            return None
        os.makedirs(d, exist_ok=True)
        tool = os.path.join(args.build_dir, 'tools', 'cvslam_ins_gps')
        out = subprocess.run([tool, '--config', config, '--seed', str(seed),
                              '--from', str(INSGPS_FROM_S)],
                             check=True, capture_output=True, text=True).stdout
        row = parse_insgps_table(out, 'ekf' if gamma is None else 'nhinf')
        json.dump({k: row[k] for k in row if k != 'filter'}, open(summary, 'w'), indent=1)
    row = json.load(open(summary))
    return {'pos': float(row['pos RMS (m)']), 'max': float(row['max (m)']),
            'nees': float(row['mean NEES']),
            'sigma': [float(row[k]) for k in ('σx (m)', 'σy (m)', 'σz (m)')]}


# ---------------------------------------------------------------- the study

def runner_for(args, case):
    """run(case, seed, gamma) for the case's tool, its inputs written once."""
    if case in SLAM_CASES:
        scenario = derived_scenario(args, case)
        return lambda c, s, g: run_slam(args, c, scenario, s, g)
    configs = {g: derived_insgps_config(args, case, g) for g in [None] + args.gammas}
    return lambda c, s, g: run_insgps(args, c, configs[g], s, g)


def run_jobs(args, jobs, results, phase):
    """Runs (case, seed, gamma, run) jobs on --jobs workers into results[(case, seed, gamma)]."""
    done = 0
    with ThreadPoolExecutor(max_workers=max(args.jobs, 1)) as pool:
        futures = [(c, s, g, pool.submit(r, c, s, g)) for c, s, g, r in jobs]
        for c, s, g, f in futures:
            results[(c, s, g)] = f.result()
            done += 1
            if done % 20 == 0 or done == len(futures):
                print(f'  {phase}: {done}/{len(futures)} runs', file=sys.stderr, flush=True)


def chosen_gamma(args, results, case):
    """γ* of a case: the lowest tune-seed mean position error among the NH∞ runs."""
    best, best_pos = None, float('inf')
    for g in args.gammas:
        runs = [results.get((case, s, g)) for s in args.tune_seeds]
        runs = [r['pos'] for r in runs if r]
        if runs and statistics.mean(runs) < best_pos:
            best, best_pos = g, statistics.mean(runs)
    return best


def run_all(args):
    """The γ sweep on the tune seeds, then the EKF and NH∞(γ*) on the report seeds."""
    runners = {case: runner_for(args, case) for case in args.cases}
    results = {}
    run_jobs(args, [(c, s, g, runners[c]) for c in args.cases for s in args.tune_seeds
                    for g in [None] + args.gammas], results, 'γ sweep')
    chosen = {c: chosen_gamma(args, results, c) for c in args.cases}
    run_jobs(args, [(c, s, g, runners[c]) for c in args.cases for s in args.report_seeds
                    for g in (None, chosen[c]) if chosen[c] is not None], results, 'report')
    return results


def mean_std(values):
    values = [v for v in values if v is not None and math.isfinite(v)]
    if not values:
        return float('nan'), float('nan')
    return statistics.mean(values), statistics.stdev(values) if len(values) > 1 else 0.0


def analyse(args, results):
    study = {'tune_seeds': args.tune_seeds, 'report_seeds': args.report_seeds,
             'gammas': args.gammas, 'cases': {}}
    for case in args.cases:
        sweep = []
        for g in [None] + args.gammas:
            runs = [results.get((case, s, g)) for s in args.tune_seeds]
            runs = [r for r in runs if r]
            if not runs:
                continue
            entry = {'gamma': g, 'pos': mean_std([r['pos'] for r in runs]),
                     'nees': mean_std([r['nees'] for r in runs])}
            if 'theta_reduced' in runs[0]:
                entry['theta_reduced'] = statistics.mean(r['theta_reduced'] for r in runs)
            sweep.append(entry)
        best = chosen_gamma(args, results, case)
        if best is None:
            continue
        ekf = [results.get((case, s, None)) for s in args.report_seeds]
        nh = [results.get((case, s, best)) for s in args.report_seeds]
        pairs = [(e, n) for e, n in zip(ekf, nh) if e and n]
        diff = [e['pos'] - n['pos'] for e, n in pairs]
        d_mean, d_std = mean_std(diff)
        se = d_std / math.sqrt(len(diff)) if len(diff) > 1 else float('nan')
        report = {'gamma': best, 'seeds': len(pairs), 'diff_mean': d_mean, 'diff_se': se,
                  'nhinf_wins': sum(1 for d in diff if d > 0),
                  'significant': len(diff) > 1 and abs(d_mean) > t95(len(diff) - 1) * se}
        for tag, runs in (('ekf', [e for e, _ in pairs]), ('nhinf', [n for _, n in pairs])):
            r = {'pos': mean_std([x['pos'] for x in runs]),
                 'nees': mean_std([x['nees'] for x in runs])}
            if 'lm_mean' in runs[0]:
                r['lm_mean'] = [statistics.mean(x['lm_mean'][k] for x in runs) for k in range(3)]
                r['lm_std'] = [statistics.mean(x['lm_std'][k] for x in runs) for k in range(3)]
                r['lm_rms'] = mean_std([x['lm_rms'] for x in runs])
                r['theta_reduced'] = statistics.mean(x['theta_reduced'] for x in runs)
                r['nees_pos'] = mean_std([x['nees_pos'] for x in runs])
            else:
                r['max'] = mean_std([x['max'] for x in runs])
                r['sigma'] = [statistics.mean(x['sigma'][k] for x in runs) for k in range(3)]
            report[tag] = r
        study['cases'][case] = {'sweep': sweep, 'report': report}
    return study


def fmt(ms, digits=3):
    return f'{ms[0]:.{digits}f} ± {ms[1]:.{digits}f}'


def tables(study):
    lines = []
    lines.append(f"Tune seeds {study['tune_seeds'][0]}–{study['tune_seeds'][-1]}, report seeds "
                 f"{study['report_seeds'][0]}–{study['report_seeds'][-1]}.\n")
    lines.append('## γ sweep (tune seeds): position error [m] and NEES, mean ± std\n')
    lines.append('| case | filter | position error [m] | NEES | θ reduced (eq. 3.40) |')
    lines.append('|---|---|---|---|---|')
    for case, c in study['cases'].items():
        for e in c['sweep']:
            name = 'EKF' if e['gamma'] is None else f"NH∞ γ = {e['gamma']:g}"
            star = ' **(γ*)**' if e['gamma'] == c['report']['gamma'] else ''
            red = f"{100 * e['theta_reduced']:.0f} %" if 'theta_reduced' in e else 'n/a'
            lines.append(f"| {case} | {name}{star} | {fmt(e['pos'])} | {fmt(e['nees'], 2)} | {red} |")
    lines.append('\n## EKF against NH∞(γ*) on the report seeds\n')
    lines.append('| case | γ* | EKF position [m] | NH∞ position [m] | EKF − NH∞ [m] (± s.e.) | '
                 'NH∞ better on | significant (95 %) | EKF NEES | NH∞ NEES |')
    lines.append('|---|---|---|---|---|---|---|---|---|')
    for case, c in study['cases'].items():
        r = c['report']
        lines.append(f"| {case} | {r['gamma']:g} | {fmt(r['ekf']['pos'])} | {fmt(r['nhinf']['pos'])} "
                     f"| {r['diff_mean']:+.4f} ± {r['diff_se']:.4f} | {r['nhinf_wins']}/{r['seeds']} "
                     f"| {'yes' if r['significant'] else 'no'} | {fmt(r['ekf']['nees'], 2)} "
                     f"| {fmt(r['nhinf']['nees'], 2)} |")
    lines.append('\n## Landmark error [m] per axis, seed means of the per-run mean and std '
                 '(thesis Tables 5.3, 5.4)\n')
    lines.append('| case | filter | x mean | x std | y mean | y std | z mean | z std | rms | θ reduced |')
    lines.append('|---|---|---|---|---|---|---|---|---|---|')
    for case, c in study['cases'].items():
        r = c['report']
        if 'lm_mean' not in r['ekf']:
            continue
        for tag, name in (('ekf', 'EKF'), ('nhinf', f"NH∞ γ = {r['gamma']:g}")):
            x = r[tag]
            cells = ' | '.join(f'{m:.3f} | {s:.3f}' for m, s in zip(x['lm_mean'], x['lm_std']))
            lines.append(f"| {case} | {name} | {cells} | {x['lm_rms'][0]:.3f} "
                         f"| {100 * x['theta_reduced']:.0f} % |")
    return '\n'.join(lines) + '\n'


def main():
    args = parse_args()
    for tool in ('cvslam_run', 'cvslam_eval', 'cvslam_ins_gps'):
        if not os.access(os.path.join(args.build_dir, 'tools', tool), os.X_OK):
            sys.exit(f'nhinf_study.py: {args.build_dir}/tools/{tool} not built (run scripts/test.sh)')
    os.makedirs(args.out, exist_ok=True)
    try:
        results = run_all(args)
    except subprocess.CalledProcessError as e:
        sys.exit(f'nhinf_study.py: {" ".join(e.cmd)} failed with exit {e.returncode}')
    study = analyse(args, results)
    json.dump(study, open(os.path.join(args.out, 'study.json'), 'w'), indent=1)
    text = tables(study)
    open(os.path.join(args.out, 'tables.md'), 'w').write(text)
    print(text)


if __name__ == '__main__':
    main()
