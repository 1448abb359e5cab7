#!/usr/bin/env python3
"""Compares the run records of two scripts/regression_runs.sh outputs (or any two run folders).

    scripts/compare_runs.py BEFORE_DIR AFTER_DIR

Every trajectory (*.tum), states.csv, truth.csv, landmarks.csv, events.csv, coop.csv and
frontend.csv under BEFORE_DIR must be byte-identical under AFTER_DIR, except frontend.csv's
wall-time columns (front_end_ms, association_ms, filter_ms), which differ between two runs of
one binary. Exit status 0 when all match, 1 when any differs or is missing, 2 on bad usage.
"""
import os
import sys

RECORDS = ('.tum', 'states.csv', 'truth.csv', 'landmarks.csv', 'events.csv', 'coop.csv',
           'frontend.csv')
WALL_TIME_COLUMNS = ('front_end_ms', 'association_ms', 'filter_ms')


def without_wall_time(lines):
    """frontend.csv rows with the wall-time columns removed (by the header's names)."""
    if not lines:
        return lines
    header = lines[0].split(',')
    drop = {i for i, name in enumerate(header) if name in WALL_TIME_COLUMNS}
    return [','.join(f for i, f in enumerate(line.split(',')) if i not in drop) for line in lines]


def main(argv):
    if len(argv) != 3 or not all(os.path.isdir(d) for d in argv[1:]):
        print('usage: compare_runs.py BEFORE_DIR AFTER_DIR (two folders)', file=sys.stderr)
        return 2
    before, after = argv[1], argv[2]
    same = differ = 0
    for root, _, files in sorted(os.walk(before)):
        for name in sorted(files):
            if not name.endswith(RECORDS):
                continue
            a = os.path.join(root, name)
            rel = os.path.relpath(a, before)
            b = os.path.join(after, rel)
            if not os.path.exists(b):
                print(f'missing: {rel}')
                differ += 1
                continue
            with open(a) as fa, open(b) as fb:
                la, lb = fa.read().splitlines(), fb.read().splitlines()
            if name == 'frontend.csv':
                la, lb = without_wall_time(la), without_wall_time(lb)
            if la == lb:
                same += 1
            else:
                print(f'differs: {rel}')
                differ += 1
    print(f'compare_runs: {same} identical, {differ} differ or missing')
    return 0 if differ == 0 and same > 0 else 1


if __name__ == '__main__':
    sys.exit(main(sys.argv))
