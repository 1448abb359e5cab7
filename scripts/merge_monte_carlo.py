#!/usr/bin/env python3
"""What merging costs: a scenario's team run in DC with the starts given and with every start
unknown, over seeds, per UAV (docs/merge.md "What merging costs").

    scripts/merge_monte_carlo.py --scenario FILE --seeds FIRST-LAST --out DIR
                                 [--jobs 2] [--duration S] [--config FILE]
                                 [--build-dir build] [--run-arg=ARG ...] [--analyse-only]

For every seed N: `cvslam_run --mode dc --seed N` into DIR/known/seed_N and the same with
`--starts unknown` into DIR/apart/seed_N, then `cvslam_eval --team-json` on the second. A run
whose folder exists with run.json is not run again (an interrupted sweep resumes).

Per UAV, mean ± std over the seeds: the known-start DC ATE (the figure merging is measured
against), the own-frame ATE with unknown starts, the team-frame ATE (trajectory_team.tum against
the truth in its root's frame, no alignment) over the merged span, the merged share of the
flight, the time of the merge, the vehicle NEES (own frame, 9 dof) both ways, and the ratio of the team-frame ATE to the known-start ATE.
Team-wide: the frame relation's NEES over every verified candidate of every seed (4 dof,
χ²₄ mean 4; candidates of one run share errors, so no band is claimed), the candidates over
χ²₄(0.999), adoptions and wrong adoptions, and the cooperation traffic per UAV.
Writes DIR/summary.json and prints Markdown tables.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split('\n\n')[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('--scenario', required=True)
    p.add_argument('--seeds', required=True, help='FIRST-LAST, e.g. 401-410')
    p.add_argument('--out', required=True)
    p.add_argument('--jobs', type=int, default=2)
    p.add_argument('--duration', type=float)
    p.add_argument('--config')
    p.add_argument('--build-dir', default='build')
    p.add_argument('--run-arg', action='append', default=[],
                   help='an extra cvslam_run argument (repeat; --run-arg=--filter=ekf)')
    p.add_argument('--analyse-only', action='store_true')
    a = p.parse_args()
    try:
        first, last = (int(x) for x in a.seeds.split('-'))
    except ValueError:
        p.error('--seeds must be FIRST-LAST, e.g. 401-410')
    if last < first:
        p.error('--seeds: LAST must not be below FIRST')
    if a.jobs < 1:
        p.error('--jobs must be at least 1')
    a.seed_list = list(range(first, last + 1))
    return a


def run_once(args, seed, starts):
    out = os.path.join(args.out, starts, f'seed_{seed}')
    if os.path.exists(os.path.join(out, 'run.json')):
        return None
    cmd = [os.path.join(args.build_dir, 'tools', 'cvslam_run'), '--quiet', '--scenario',
           args.scenario, '--mode', 'dc', '--seed', str(seed), '--out', out]
    if starts == 'apart':
        cmd += ['--starts', 'unknown']
    if args.duration:
        cmd += ['--duration', str(args.duration)]
    if args.config:
        cmd += ['--config', args.config]
    cmd += args.run_arg
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        return f'seed {seed} ({starts}): cvslam_run failed: {r.stderr.strip().splitlines()[-1:]}'
    print(f'seed {seed} ({starts}): done', file=sys.stderr, flush=True)
    return None


def evaluate(args, seed):
    known = os.path.join(args.out, 'known', f'seed_{seed}')
    apart = os.path.join(args.out, 'apart', f'seed_{seed}')
    ev = os.path.join(args.build_dir, 'tools', 'cvslam_eval')
    for run, flag, name in ((known, '--summary-json', 'summary.json'),
                            (apart, '--summary-json', 'summary.json'),
                            (apart, '--team-json', 'team_summary.json')):
        if not os.path.exists(os.path.join(run, 'run.json')):
            return None
        target = os.path.join(run, name)
        if not os.path.exists(target):
            subprocess.run([ev, '--quiet', '--run', run, flag, target], check=True)
    summary = json.load(open(os.path.join(known, 'summary.json')))
    team = json.load(open(os.path.join(apart, 'team_summary.json')))
    own = json.load(open(os.path.join(apart, 'summary.json')))
    traffic = {}
    for agent in team['agents']:
        stats = json.load(open(os.path.join(apart, f'agent_{agent}', 'stats.json')))
        duration = stats.get('duration_s') or 0.0
        traffic[agent] = stats.get('bytes_sent', 0) / duration if duration > 0 else None
    return summary, own, team, traffic


def mean_std(values):
    v = [x for x in values if x is not None]
    if not v:
        return None, None, 0
    return statistics.mean(v), (statistics.stdev(v) if len(v) > 1 else 0.0), len(v)


def cell(values, fmt='{:.3f}'):
    m, s, n = mean_std(values)
    return '–' if m is None else (fmt + ' ± ' + fmt).format(m, s) + ('' if n == len(values) else f' ({n})')


def main():
    args = parse_args()
    if not args.analyse_only:
        tool = os.path.join(args.build_dir, 'tools', 'cvslam_run')
        if not os.access(tool, os.X_OK):
            sys.exit(f'merge_monte_carlo.py: {tool} not built')
        jobs = [(s, k) for s in args.seed_list for k in ('known', 'apart')]
        with ThreadPoolExecutor(args.jobs) as pool:
            for failure in pool.map(lambda j: run_once(args, *j), jobs):
                if failure:
                    print(failure, file=sys.stderr)
    per_uav, nees, over, adopted, wrong, seeds_done, team_aligned = {}, [], 0, 0, 0, [], []
    for seed in args.seed_list:
        got = evaluate(args, seed)
        if got is None:
            print(f'seed {seed}: a run is missing, left out', file=sys.stderr)
            continue
        summary, own, team, traffic = got
        seeds_done.append(seed)
        team_aligned.append(team['team_ate_aligned_m'])
        for agent, a in team['agents'].items():
            u = per_uav.setdefault(agent, {k: [] for k in (
                'known', 'own', 'team', 'aligned', 'cover', 'merged', 'ratio', 'traffic',
                'nees_known', 'nees_apart')})
            known = summary['agents'][agent]['ate_rmse_m']
            u['known'].append(known)
            u['own'].append(a['own_ate_m'])
            u['team'].append(a['team_ate_m'])
            u['aligned'].append(a['team_ate_aligned_m'])
            u['cover'].append(a['coverage'] if a['coverage'] is not None else 0.0)
            u['merged'].append(a['merged_at_s'])
            u['ratio'].append(a['team_ate_m'] / known if a['team_ate_m'] is not None and known
                              else None)
            u['traffic'].append(traffic[agent])
            u['nees_known'].append(summary['agents'][agent]['nees_mean'])
            u['nees_apart'].append(own['agents'][agent]['nees_mean'])
            rel = a['relations'] or {}
            nees += rel.get('nees', [])
            over += rel.get('over_bound', 0)
            adopted += rel.get('adopted', 0)
            wrong += rel.get('wrong_adopted', 0)
    if not seeds_done:
        sys.exit('merge_monte_carlo.py: no seed has both runs')
    n = len(seeds_done)
    print(f'{args.scenario}, DC, seeds {seeds_done[0]}–{seeds_done[-1]} ({n} runs each way)\n')
    print('| UAV | known-start DC ATE [m] | own-frame ATE, apart [m] | team-frame ATE, apart [m] |'
          ' the same, one SE(3) alignment for the team [m] | merged share of the flight |'
          ' merged at [s] | team / known | vehicle NEES known / apart (9 dof) | traffic [KB/s] |')
    print('|---|---|---|---|---|---|---|---|---|---|')
    for agent in sorted(per_uav, key=int):
        u = per_uav[agent]
        kb = [x / 1000 if x is not None else None for x in u['traffic']]
        print(f"| {agent} | {cell(u['known'])} | {cell(u['own'])} | {cell(u['team'])} | "
              f"{cell(u['aligned'])} | "
              f"{cell(u['cover'], '{:.2f}')} | {cell(u['merged'], '{:.1f}')} | "
              f"{cell(u['ratio'], '{:.2f}')} | {cell(u['nees_known'], '{:.1f}')} / "
              f"{cell(u['nees_apart'], '{:.1f}')} | {cell(kb, '{:.1f}')} |")
    print(f'\nteam ATE after one SE(3) alignment of every merged agent: {cell(team_aligned)} m')
    nm = statistics.mean(nees) if nees else None
    print(f'\nrelation NEES over {len(nees)} verified candidates: mean '
          f"{'–' if nm is None else f'{nm:.2f}'} (χ²₄ mean 4), max "
          f"{max(nees) if nees else float('nan'):.1f}, {over} over χ²₄(0.999); "
          f'{adopted} adoptions, {wrong} wrong (NEES over χ²₄(0.999))')
    out = {'scenario': args.scenario, 'seeds': seeds_done, 'per_uav': per_uav,
           'team_ate_aligned_m': team_aligned,
           'relation_nees': {'count': len(nees), 'mean': nm, 'max': max(nees) if nees else None,
                             'over_999': over},
           'adoptions': adopted, 'wrong_adoptions': wrong}
    with open(os.path.join(args.out, 'summary.json'), 'w') as f:
        json.dump(out, f, indent=1)


if __name__ == '__main__':
    main()
