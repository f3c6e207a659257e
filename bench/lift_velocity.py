#!/usr/bin/python3
"""What a colour lift does to the species' velocities, and what that costs the bursts after it.

1. The slip: in each height band of a direct run's checkpoints, the mean vertical velocity of the
   light and of the heavy spheres, their difference, and the spread of the vertical velocities
   (all realizations pooled; bands of 2 d_p with at least 6 of each species). A lift that keeps
   velocities (cpi.relabel_velocity = kept) gives each particle it turns light the heavy ones'
   mean, and the reverse.
2. The bursts after the lifts: for each CPI run of a whole-process case (bench/whole_process.py,
   its committed reductions), the light ICDF's slope over the first 5 units of each burst's
   sampling grid and over the rest, minus the direct ensembles' over the same times, for the
   lower light nodes (p = 0.05-0.30), over bursts in t = 100-320 (the tall bed's transient at
   U_s = 0.41, where lifts move these nodes most); with two direct ensembles' difference over
   the same windows as the noise to read it against.

    /usr/bin/python3 bench/lift_velocity.py --checkpoints runs/transient_lift/direct_ckpt_*.h5 \\
        --case bench/results/whole_process/tall_u0.41_r8 --runs ranks_tol ranks_tol_counts ranks_velocity \\
        --out bench/results/lift_velocity.md

The checkpoints of bench/results/lift_velocity.md: the demo bed at U_s = 0.41, R = 4, direct, seed
606, checkpoints every 20 units (run files not in git; this makes them again, 3 min on 2 cores):

    mpirun -n 2 build/mpi_driver/efdem examples/demo_small/scene.cfg gas_drag.superficial_velocity=0.41 \\
        ensemble.realizations_per_rank=2 mode=direct seed=606 run.duration=100 checkpoint.interval=40 \\
        checkpoint.keep=10 output.directory=runs/transient_lift output.prefix=direct
"""
import argparse
import json
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import whole_process as wp  # noqa: E402

LOWER = slice(0, 6)  # nodes p = 0.05 .. 0.30 of the 19-node grid
SPAN = (100.0, 320.0)


def slip_table(paths):
    lines = ["| checkpoint | t | band [d_p] | lights | heavies | light mean v_z | heavy mean v_z | slip | spread of v_z |",
             "|---|---|---|---|---|---|---|---|---|"]
    for path in paths:
        with h5py.File(path, "r") as f:
            x, v = f["realizations/x"][:], f["realizations/v"][:]
            species = f["realizations/species"][:].ravel()
            t = float(f["realizations/time"][0])
        z, vz = x[:, 2], v[:, 2]
        for lo in np.arange(0.0, np.ceil(z.max()), 2.0):
            band = (z >= lo) & (z < lo + 2.0)
            light, heavy = band & (species == 0), band & (species == 1)
            if light.sum() < 6 or heavy.sum() < 6:
                continue
            a, b = vz[light].mean(), vz[heavy].mean()
            lines.append(f"| {os.path.basename(path)} | {t:g} | {lo:g}-{lo + 2:g} | {light.sum()} | {heavy.sum()} | "
                         f"{a:.3f} | {b:.3f} | {a - b:.3f} | {vz[band].std():.3f} |")
    return lines


def load(folder, name):
    """A run's grid times, ensemble-mean ICDF and burst index runs, from its reduction
    (whole_process.py)."""
    with open(os.path.join(folder, name + ".json")) as f:
        run = wp.from_reduction(json.load(f))
    return run["t"], run["mean"], bursts(run["t_all"], run["t"])


def bursts(t_all, t):
    """The grid samples T in runs of one burst each: a jump leaves a gap in the full sample times
    T_ALL longer than their spacing (a jump of a few units may not leave one on the grid)."""
    spacing = float(np.median(np.diff(t_all)))
    starts = t_all[np.r_[0, np.nonzero(np.diff(t_all) > 1.5 * spacing)[0] + 1]]
    which = np.searchsorted(starts, t + 1e-9, side="right") - 1
    return [list(np.nonzero(which == k)[0]) for k in range(len(starts)) if np.any(which == k)]


def direct_ensembles(folder):
    """The case's three direct ensembles (load's tuples), their grid times and the mean of their
    ensemble means."""
    directs = [load(folder, n) for n in ("direct_a", "direct_b", "direct_c")]
    return directs, directs[0][0], np.mean([d[1] for d in directs], axis=0)


def slope(x, tt, a, b):
    """The secant slope of X (samples at times TT) between samples A and B."""
    return (x[b] - x[a]) / (tt[b] - tt[a])


def nearest(td, tt):
    """The index of the grid time of TD nearest TT."""
    return int(np.argmin(np.abs(td - tt)))


def early_deficit(t, x, b, td, dmean):
    """The lower nodes' slope over the first grid interval of burst B (sample indices into T, X)
    minus the directs' mean slope DMEAN (at TD) over the same times."""
    i0, i1 = b[0], b[1]
    j0, j1 = nearest(td, t[i0]), nearest(td, t[i1])
    return (slope(x, t, i0, i1) - slope(dmean, td, j0, j1))[LOWER].mean()


def deficit_table(folder, runs, runs_folder=None):
    """FOLDER: the case with the direct ensembles; RUNS_FOLDER (default FOLDER): the CPI runs'."""
    runs_folder = runs_folder or folder
    directs, td, dmean = direct_ensembles(folder)

    def at(tt):
        return nearest(td, tt)

    lines = ["| CPI run | bursts | direct slope, lower nodes [d_p/unit] | CPI - direct, first 5 units | CPI - direct, rest | "
             "direct_a - direct_b, first 5 / rest (noise) |",
             "|---|---|---|---|---|---|"]
    for name in runs:
        if not os.path.exists(os.path.join(runs_folder, name + ".json")):
            lines.append(f"| {name} | (no reduction yet) | | | | |")
            continue
        t, x, runs_of = load(runs_folder, name)
        early, late, noise_e, noise_l, ref = [], [], [], [], []
        for b in runs_of[1:]:  # the first stretch is the warm-up's direct run
            if len(b) < 3 or t[b[0]] < SPAN[0] or t[b[-1]] > SPAN[1]:
                continue
            i0, i1, i2 = b[0], b[1], b[-1]
            j0, j1, j2 = at(t[i0]), at(t[i1]), at(t[i2])
            early.append(early_deficit(t, x, b, td, dmean))
            late.append((slope(x, t, i1, i2) - slope(dmean, td, j1, j2))[LOWER].mean())
            a, bb = directs[0][1], directs[1][1]
            noise_e.append((slope(a, td, j0, j1) - slope(bb, td, j0, j1))[LOWER].mean())
            noise_l.append((slope(a, td, j1, j2) - slope(bb, td, j1, j2))[LOWER].mean())
            ref.append(slope(dmean, td, j0, j2)[LOWER].mean())
        def pm(a):  # mean +- its standard error over the bursts
            return f"{np.mean(a):+.3f} +- {np.std(a, ddof=1) / np.sqrt(len(a)):.3f}"

        lines.append(f"| {name} | {len(early)} | {np.mean(ref):.3f} | {pm(early)} | {pm(late)} | "
                     f"{pm(noise_e)} / {pm(noise_l)} |")
    return lines


def lift_cost_table(folder, runs):
    """Per kept jump in the span: the lower nodes' slope over the first 5 units of the burst after
    its lift, minus the directs' mean over the same times, against the labels the lift switched per
    realization; a least-squares line through all of them (deficit = a + c x labels / 1000)."""
    _, td, dmean = direct_ensembles(folder)
    rows, pts = [], []
    for name in runs:
        reduction = os.path.join(folder, name + ".json")
        if not os.path.exists(reduction):
            continue
        with open(reduction) as f:
            records = json.load(f).get("lifts")
        if records is None:  # a reduction made before it kept its lifts: from the archive
            archive = os.path.join(folder, name + ".h5")
            if not os.path.exists(archive):
                continue
            with h5py.File(archive, "r") as f:
                records = wp.lift_records(f)
        t, x, runs_of = load(folder, name)
        for b in runs_of[1:]:
            if len(b) < 2 or t[b[0]] < SPAN[0] or t[b[-1]] > SPAN[1]:
                continue
            # the first grid sample of a burst from r[0] (its samples start one interval after it)
            match = [r for r in records if r[0] - 1e-6 <= t[b[0]] <= r[0] + 5.0 + 1e-6]
            if not match:
                continue
            d = early_deficit(t, x, b, td, dmean)
            _, dt, labels = match[0]
            pts.append((labels, d))
            rows.append(f"| {name} | {t[b[0]]:g} | {dt:g} | {labels:.0f} | {d:+.3f} |")
    lines = ["| CPI run | burst from t | DT of the jump before | labels switched per realization | "
             "CPI - direct, first 5 units [d_p/unit] |", "|---|---|---|---|---|"] + rows
    if len(pts) >= 3:
        a = np.array(pts)
        A = np.c_[np.ones(len(a)), a[:, 0] / 1000.0]
        coef, *_ = np.linalg.lstsq(A, a[:, 1], rcond=None)
        dof = len(a) - 2
        s2 = float(np.sum((a[:, 1] - A @ coef) ** 2)) / max(dof, 1)
        se = np.sqrt(np.diag(s2 * np.linalg.inv(A.T @ A)))
        r = np.corrcoef(a[:, 0], a[:, 1])[0, 1]
        lines += ["", f"Line through the {len(a)} lifts: deficit = {coef[0]:+.4f} (+- {se[0]:.4f}) "
                  f"{coef[1]:+.4f} (+- {se[1]:.4f}) x labels / 1000 [d_p/unit]; correlation {r:+.2f}; "
                  f"labels {a[:, 0].min():.0f}-{a[:, 0].max():.0f} per realization."]
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--checkpoints", nargs="*", default=[])
    ap.add_argument("--case", help="a case folder of bench/whole_process.py's results")
    ap.add_argument("--runs", nargs="*", default=[])
    ap.add_argument("--cost-runs", nargs="*", default=None,
                    help="section 3's runs, one lift method (default: --runs)")
    ap.add_argument("--out")
    args = ap.parse_args()
    text = [f"Made by `/usr/bin/python3 bench/lift_velocity.py {' '.join(sys.argv[1:])}`.", ""]
    if args.checkpoints:
        text += ["## 1. The species' vertical velocities in a direct run", ""] + slip_table(args.checkpoints) + [""]
    if args.case:
        text += [f"## 2. The lower light nodes' slope in the bursts after lifts ({os.path.basename(args.case)}, "
                 f"bursts in t = {SPAN[0]:g}-{SPAN[1]:g}, nodes p = 0.05-0.30)", ""] + deficit_table(args.case, args.runs) + [""]
        text += ["## 3. Per lift: the first 5 units' deficit against the labels the lift switched "
                 "(the runs whose reduction keeps its lifts)", ""] + lift_cost_table(
            args.case, args.runs if args.cost_runs is None else args.cost_runs) + [""]
    out = "\n".join(text)
    print(out)
    if args.out:
        with open(args.out, "w") as f:
            f.write(out)


if __name__ == "__main__":
    main()
