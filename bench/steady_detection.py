#!/usr/bin/python3
"""Can a run tell that a *moving* ensemble has reached its statistically steady end state (issue 34,
item 3: cpi.finish = steady for a fluidized bed)? Two candidate statistics, measured on the run
files the studies already have (CPI and direct, demo bed, R = 4):

  burst z   RMS over the ICDF nodes of a coarse step's slope over RMS of its standard error (the
            members' spread): the slope within its noise when z <~ 1-2. Per CPI step.
  trend z   the same for the slope of a straight line through the last N window means (the mean
            ICDF over each burst's window; for a direct run, over 10-unit windows every 30 units):
            a baseline N bursts long instead of one window. Under no drift its RMS over the nodes
            is about sqrt((N-2)/(N-4)) (Student t, N-2 degrees of freedom) for N > 4, and grows
            without bound for N = 5 (sqrt(3) if the nodes were independent).

    /usr/bin/python3 bench/steady_detection.py                      # the default files below
    /usr/bin/python3 bench/steady_detection.py --bursts 5 run.h5 ...

Writes bench/results/steady_detection.md (default files only).
"""
import argparse
import os
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "scripts"))
import run_files  # noqa: E402

RESULTS = os.path.join(HERE, "results")
DEFAULT = [
    ("U_s 0.19, CPI cpi.accuracy 1.5", "accuracy_study/demo_acc1.5.h5"),
    ("U_s 0.19, CPI members 10 + 10", "slope_study_r4_u0.19_t600/members_h10w10.h5"),
    ("U_s 0.19, CPI mean 10 + 10", "slope_study_r4_u0.19_t600/burst_h10w10.h5"),
    ("U_s 0.19, direct (seed 101)", "slope_study_r4_u0.19_t600/direct_a.h5"),
    ("U_s 0.19, direct (seed 202)", "slope_study_r4_u0.19_t600/direct_b.h5"),
    ("U_s 0.41, CPI members 2 + 20", "slope_study_r4_u0.41_t200/members_h2w20.h5"),
    ("U_s 0.41, direct 300 units (steady after ~150)", "steady_study/direct.h5"),
]


def text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def windows(f):
    """(time, mean ICDF over the window) per CPI burst kept (or 10-unit windows every 30 units of a
    direct run), and the per-burst z of a CPI run (NaN for a direct one)."""
    ts, mean = f["samples/time"][:], run_files.get(f, "samples/mean_icdf")[:]
    if "cpi" in f:
        status = [text(s) for s in f["cpi/status"][:]]
        keep = np.array([s != "rejected" for s in status])
        t_end, window = f["cpi/t_end"][:][keep], f["cpi/window"][:][keep]
        s, se = f["cpi/slope"][:][keep], f["cpi/slope_standard_error"][:][keep]
        z = np.sqrt((s ** 2).mean(axis=1)) / np.sqrt((se ** 2).mean(axis=1))
    else:
        t_end = np.arange(30.0, ts[-1] + 1e-9, 30.0)
        window = np.full(len(t_end), 10.0)
        z = np.full(len(t_end), np.nan)
    tw, xw, zw = [], [], []
    for a, b, zz in zip(t_end, window, z):
        sel = (ts > a - b + 1e-9) & (ts <= a + 1e-9)
        if sel.any() and (not tw or a > tw[-1] + 1e-9):  # a redone burst ends at the same time
            tw.append(a)
            xw.append(mean[sel].mean(axis=0))
            zw.append(zz)
    return np.array(tw), np.array(xw), np.array(zw)


def trend_z(t, x, n):
    """RMS over the nodes of the fitted slope over RMS of its standard error, through the last n
    window means, at each window from the n-th on."""
    out = []
    for k in range(n - 1, len(t)):
        tt, yy = t[k - n + 1:k + 1], x[k - n + 1:k + 1]
        a = np.vstack([np.ones(n), tt - tt.mean()]).T
        coef = np.linalg.lstsq(a, yy, rcond=None)[0]
        resid = yy - a @ coef
        se = np.sqrt((resid ** 2).sum(axis=0) / (n - 2) / ((tt - tt.mean()) ** 2).sum())
        out.append(float(np.sqrt((coef[1] ** 2).mean()) / np.sqrt((se ** 2).mean())))
    return np.array(out)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("files", nargs="*")
    p.add_argument("--bursts", type=int, default=5, help="N of the trend statistic")
    args = p.parse_args()
    files = [(f, f) for f in args.files] or [(label, os.path.join(RESULTS, path)) for label, path in DEFAULT]
    lines = ["# Telling a statistically steady ensemble from a slowly demixing one (issue 34, item 3)\n",
             f"Made by `/usr/bin/python3 bench/steady_detection.py` (N = {args.bursts}). Per run: the per-burst "
             "z of its coarse steps (CPI only) and the trend z through its last N window means, as t:z.\n",
             "| run | burst z (t: z) | trend z over N windows (t: z) |", "|---|---|---|"]
    for label, path in files:
        with h5py.File(path, "r") as f:
            t, x, z = windows(f)
        tz = trend_z(t, x, args.bursts)
        lines.append(f"| {label} | " + (" ".join(f"{a:.0f}:{b:.1f}" for a, b in zip(t, z)) if np.isfinite(z).any()
                                        else "-") + " | "
                     + " ".join(f"{a:.0f}:{b:.1f}" for a, b in zip(t[args.bursts - 1:], tz)) + " |")
    print("\n".join(lines))
    if not args.files:
        with open(os.path.join(RESULTS, "steady_detection.md"), "w") as f:
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
