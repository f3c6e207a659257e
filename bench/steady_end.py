#!/usr/bin/python3
"""The fluidized end state of cpi.finish = steady (issue 34, item 3): the drift test measured on
direct ensembles, and a CPI run that ended at it checked against a long direct time average.

1. The drift test (coarse/equation_free/estimators/drift_test.hpp) on direct ensembles: bursts
   emulated as 10-unit windows every 20 units, each window's members' least-squares slopes per
   ICDF node, the ensemble slope and its standard error (the members' spread / sqrt(R)), pooled
   over the last 4 windows with one inverse-variance weight per window; z = RMS over the nodes of
   pooled slope / pooled standard error. Without drift z is about 1; the run calls the state
   steady at z <= 2 at two checks in a row.
2. With --cpi RUN.h5 --reference DIRECT.h5 --after T: the CPI run's end state (the mean ICDF over
   its samples from the end-state time on, i.e. the bursts the test pooled) against the direct
   run's time average over t >= T, RMS over the nodes; beside it the direct run's own two halves
   of that span against each other (a floor of the same kind: two time averages of one process).

    /usr/bin/python3 bench/steady_end.py                           # section 1 on the committed runs
    /usr/bin/python3 bench/steady_end.py --cpi runs/steady_end/cpi_steady.h5 \\
        --reference bench/results/steady_study/direct.h5 --after 200

Writes bench/results/steady_end.md.
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
DIRECT = [
    ("demo, U_s 0.19, R 8 (seed 101)", "adaptive_study_r8/u0.19/direct_a.h5"),
    ("demo, U_s 0.19, R 8 (seed 202)", "adaptive_study_r8/u0.19/direct_b.h5"),
    ("tall, U_s 0.19, R 4 (seed 101)", "tall_study_r4/u0.19/direct_a.h5"),
    ("tall, U_s 0.19, R 4 (seed 202)", "tall_study_r4/u0.19/direct_b.h5"),
    ("demo, U_s 0.41, R 8 (seed 101)", "adaptive_study_r8/u0.41/direct_a.h5"),
    ("demo, U_s 0.41, R 4, 300 units (seed 101)", "steady_study/direct.h5"),
    ("tall, U_s 0.41, R 4 (seed 101)", "tall_study_r4/u0.41/direct_a.h5"),
]
WINDOW, EVERY, POOL, Z_STEADY, CONFIRM = 10.0, 20.0, 4, 2.0, 2


def members(f):
    """Sample times and the members' ICDFs (samples x R x m), in any run file format."""
    key = "samples/realizations" if "samples/realizations" in f else "samples/icdf"
    return f["samples/time"][:], f[key][:]


def window_slopes(t, x):
    """(centre, ensemble slope, its standard error) of each emulated burst window."""
    out = []
    for t1 in np.arange(t[0] + WINDOW + 10.0, t[-1] + 1e-9, EVERY):
        sel = (t > t1 - WINDOW - 1e-9) & (t <= t1 + 1e-9)
        tt, xx = t[sel], x[sel]
        tc = tt - tt.mean()
        b = np.einsum("n,nrm->rm", tc, xx - xx.mean(axis=0)) / (tc ** 2).sum()
        out.append((t1 - WINDOW / 2, b.mean(axis=0), b.std(axis=0, ddof=1) / np.sqrt(b.shape[0])))
    return out


def pooled_z(nodes):
    """z of the drift test over each run of POOL consecutive windows, at the last one's time."""
    res = []
    for j in range(POOL - 1, len(nodes)):
        use = nodes[j - POOL + 1:j + 1]
        inv = np.array([1.0 / np.mean(se ** 2) for _, _, se in use])
        w = inv / inv.sum()
        s = sum(wi * si for wi, (_, si, _) in zip(w, use))
        var = sum(wi ** 2 * se ** 2 for wi, (_, _, se) in zip(w, use))
        res.append((use[-1][0] + WINDOW / 2, float(np.sqrt(np.mean(s ** 2 / var)))))
    return res


def first_steady(zs):
    quiet = 0
    for t, z in zs:
        quiet = quiet + 1 if z <= Z_STEADY else 0
        if quiet >= CONFIRM:
            return t
    return None


def end_state(args):
    with h5py.File(args.cpi, "r") as f:
        status = run_files.text(f.attrs["end_status"]) if "end_status" in f.attrs else "?"
        t = f["samples/time"][:]
        mean = run_files.get(f, "samples/mean_icdf")[:]
    import re
    m = re.search(r"end state at t = ([0-9.e+-]+)", status)
    if not m:
        return [f"The CPI run did not end at a steady state: {status}"]
    t_end_state = float(m.group(1)) - WINDOW / 2  # since() is the oldest pooled window's centre
    cpi = mean[t >= t_end_state - 1e-9].mean(axis=0)
    with h5py.File(args.reference, "r") as f:
        td, xd = members(f)
    span = td >= args.after - 1e-9
    direct = xd[span].mean(axis=(0, 1))
    half = len(td[span]) // 2
    first, second = xd[span][:half].mean(axis=(0, 1)), xd[span][half:].mean(axis=(0, 1))
    rms = lambda v: float(np.sqrt(np.mean(v ** 2)))  # noqa: E731
    return [
        f"CPI run `{os.path.relpath(args.cpi)}`: {status}",
        "",
        f"| | value |",
        "|---|---|",
        f"| end-state time (oldest pooled window's start) | {t_end_state:.1f} |",
        f"| simulated time at the end | {t[-1]:.1f} |",
        f"| CPI end state (mean ICDF over t >= {t_end_state:.1f}), median node | {cpi[len(cpi) // 2]:.3f} d_p |",
        f"| direct time average over t >= {args.after:g} (`{os.path.relpath(args.reference)}`), median node | "
        f"{direct[len(direct) // 2]:.3f} d_p |",
        f"| RMS over the nodes, CPI end state - direct time average | {rms(cpi - direct):.3f} d_p |",
        f"| RMS over the nodes, the direct span's first half - second half | {rms(first - second):.3f} d_p |",
    ]


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cpi", help="a cpi run that ended with cpi.finish = steady")
    p.add_argument("--reference", help="a long direct run of the same scene (own seed)")
    p.add_argument("--after", type=float, default=200.0, help="time from which the direct run is steady")
    args = p.parse_args()
    lines = ["# The fluidized end state of cpi.finish = steady\n",
             "Made by `/usr/bin/python3 bench/steady_end.py"
             + (f" --cpi {os.path.relpath(args.cpi)} --reference {os.path.relpath(args.reference)} --after {args.after:g}"
                if args.cpi else "") + "`.\n",
             "## 1. The drift test on direct ensembles\n",
             f"Bursts emulated as {WINDOW:g}-unit windows every {EVERY:g} units; pool of {POOL}; t:z at the "
             f"last window's end; steady at z <= {Z_STEADY:g} at {CONFIRM} checks in a row.\n",
             "| run | z (t: z) | first called steady |", "|---|---|---|"]
    for label, path in DIRECT:
        with h5py.File(os.path.join(RESULTS, path), "r") as f:
            t, x = members(f)
        zs = pooled_z(window_slopes(t, x))
        when = first_steady(zs)
        lines.append(f"| {label} | " + " ".join(f"{a:.0f}:{b:.1f}" for a, b in zs) + " | "
                     + (f"t = {when:.0f}" if when is not None else "never") + " |")
    if args.cpi:
        lines += ["", "## 2. A CPI run's end state against a long direct time average\n"] + end_state(args)
    text = "\n".join(lines) + "\n"
    print(text)
    with open(os.path.join(RESULTS, "steady_end.md"), "w") as f:
        f.write(text)


if __name__ == "__main__":
    main()
