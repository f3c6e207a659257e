#!/usr/bin/python3
"""The pace of the lifted beds: how far the middle of the light ICDF rises in each CPI burst after a
lift, against the direct ensembles' mean over the same times (docs/accuracy_vs_cost.md, "Adding the
bursts' curvature to every jump").

Reads the reductions bench/whole_process.py keeps in git (<case>/<run>.json: the realizations' light
ICDF on a 5-unit grid), so it runs without the runs' files:

    /usr/bin/python3 bench/lift_pace.py bench/results/whole_process/tall_u0.19_r8
    /usr/bin/python3 bench/lift_pace.py bench/results/whole_process/tall_u0.19_r4 \
        --directs bench/results/whole_process/tall_u0.19_r8   # R = 4 runs, the R = 8 directs

For every CPI run of the case (a .json with lifts), each burst after a lift: the mean over the nodes
p = 0.25-0.75 of the ensemble mean's rise from the burst's first to its last grid sample, the same
for the directs' mean at those times, their ratio, and how far the directs' own rises lie apart
there (the noise such a difference is judged against).
"""
import argparse
import glob
import json
import os

import numpy as np

MIDDLE = slice(4, 15)  # p = 0.25-0.75 of the 19-node grid p = 0.05-0.95


def load(path):
    with open(path) as f:
        d = json.load(f)
    return np.array(d["t"]), np.array(d["icdf"]).mean(axis=1), d


def bursts(t, step=5.0):
    """Runs of consecutive grid samples: the CPI run's bursts."""
    out, cur = [], [0]
    for i in range(1, len(t)):
        if abs(t[i] - t[i - 1] - step) < 1e-6:
            cur.append(i)
        else:
            out.append(cur)
            cur = [i]
    out.append(cur)
    return out


def rise(t, x, a, b):
    i, j = np.argmin(abs(t - a)), np.argmin(abs(t - b))
    return (x[j, MIDDLE] - x[i, MIDDLE]).mean()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("case", help="a case folder of bench/results/whole_process")
    ap.add_argument("--directs", help="take the direct ensembles from this case folder instead "
                    "(an R = 4 case's are the halves of its R = 8 case's)")
    args = ap.parse_args()
    directs, cpis = [], []
    for folder in {args.case, args.directs or args.case}:
        for path in sorted(glob.glob(os.path.join(folder, "*.json"))):
            t, x, d = load(path)
            if d.get("lifts"):
                if folder == args.case:
                    cpis.append((os.path.basename(path)[:-5], t, x))
            elif folder == (args.directs or args.case):
                directs.append((os.path.basename(path)[:-5], t, x))
    if len(directs) < 2:
        raise SystemExit(f"{args.case}: {len(directs)} direct ensemble(s); the comparison needs two or more")
    td = directs[0][1]
    mean = sum(x for _, _, x in directs) / len(directs)
    for name, t, x in cpis:
        print(f"{name}: burst after a lift | CPI rise | directs' rise | ratio | directs apart [d_p]")
        for s in bursts(t)[1:]:
            a, b = t[s[0]], t[s[-1]]
            cpi, direct = rise(t, x, a, b), rise(td, mean, a, b)
            apart = np.ptp([rise(td, xd, a, b) for _, _, xd in directs])
            print(f"  {a:.0f}-{b:.0f} | {cpi:.3f} | {direct:.3f} | {cpi / direct:.2f} | {apart:.3f}")


if __name__ == "__main__":
    main()
