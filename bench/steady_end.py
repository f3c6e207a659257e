#!/usr/bin/python3
"""The fluidized end state of cpi.finish = steady (issue 34, item 3): the drift test measured on
direct ensembles, and a CPI run that ended at it checked against a long direct time average.

1. The drift test (coarse/equation_free/estimators/drift_test.hpp) on direct ensembles: bursts
   emulated as 10-unit windows every 20 units, each window's members' least-squares slopes per
   ICDF node, the ensemble slope and its standard error (the members' spread / sqrt(R)), pooled
   over the last 4 windows with one inverse-variance weight per window; z = RMS over the nodes of
   pooled slope / pooled standard error. Without drift z is about 1; the run calls the state
   steady at z <= 2 at two checks in a row.
2. With --cpi RUN.h5 --reference DIRECT.h5 --after T: the drift test's z after each accepted burst
   of the CPI run, and its end state (the mean ICDF over the bursts the test pooled; over its last
   --last units when it did not end steady) against the direct run's time average over t >= T,
   RMS over the nodes, beside the floor of two independent ensembles' time averages.

    /usr/bin/python3 bench/steady_end.py                           # section 1 on the committed runs
    /usr/bin/python3 bench/steady_end.py --cpi runs/steady_end/cpi_steady.h5 \\
        --reference bench/results/steady_study/direct.h5 --after 200

The runs of section 2 (demo bed at U_s = 0.41, R = 4 on 2 ranks; run files not in git):

    S="examples/demo_small/scene.cfg gas_drag.superficial_velocity=0.41 ensemble.realizations_per_rank=2"
    C="mode=cpi seed=505 run.duration=400 cpi.projection=adaptive cpi.tolerance=0.32 cpi.healing=2 \
       cpi.window=20 cpi.warmup=10 cpi.finish=steady"
    mpirun -n 2 build/mpi_driver/efdem $S $C output.directory=runs/steady_end output.prefix=cpi_mean
    mpirun -n 2 build/mpi_driver/efdem $S $C cpi.lift=members output.directory=runs/steady_end \
        output.prefix=cpi_members
    mpirun -n 2 build/mpi_driver/efdem $S $C cpi.observable=ranks output.directory=runs/steady_end \
        output.prefix=cpi_ranks            # and with run.duration=800 output.prefix=cpi_ranks_800
    mpirun -n 2 build/mpi_driver/efdem $S mode=direct seed=606 run.duration=300 \
        output.directory=runs/steady_end output.prefix=direct

3. With --hand-off RUN.h5 ...: runs made with cpi.hand_off = steady (the cpi run's end refined by
   the steady solver): the cpi run's end and the solve's answer against the direct time average,
   the solve's band, the time to the end state as efdem states it, and, for every run and the
   direct reference alike, when its state came within a fixed radius of the direct time average
   for good (the same yardstick for all: the kept bursts' ends of a cpi run, every sample of the
   direct run) and the DEM time that took. The runs (as above, plus cpi.hand_off = steady):

    H="$S $C cpi.hand_off=steady steady.tau=20 run.duration=300 output.directory=runs/hand_off"
    mpirun -n 2 build/mpi_driver/efdem $H cpi.observable=ranks output.prefix=ranks_300
    mpirun -n 2 build/mpi_driver/efdem $H cpi.observable=ranks seed=515 output.prefix=ranks_300_s2
    mpirun -n 2 build/mpi_driver/efdem $H output.prefix=icdf_300          # the ICDF, lift mean

Writes bench/results/steady_end.md, or the file --out names (a study beside the committed one).
"""
import argparse
import math
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
# The slowest coarse mode of the demo bed at U_s = 0.41 over tau = 20: mu = exp(-0.044 x 20), the
# direct ensemble's approach rate (docs/steady_states.md, "Measured on the DEM").
MU_041 = 0.42


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
    """z of the drift test over each run of POOL consecutive windows, at the last one's time (as
    DriftTest::z: equal weights when a window has no noise; a component without noise is left
    out when it did not move, and makes z infinite when it did)."""
    res = []
    for j in range(POOL - 1, len(nodes)):
        use = nodes[j - POOL + 1:j + 1]
        v = np.array([np.mean(se ** 2) for _, _, se in use])
        w = np.ones(len(use)) if (v == 0).any() else 1.0 / v
        w = w / w.sum()
        s = sum(wi * si for wi, (_, si, _) in zip(w, use))
        var = sum(wi ** 2 * se ** 2 for wi, (_, _, se) in zip(w, use))
        noisy = var > 0
        if (~noisy & (np.abs(s) > 1e-12)).any():
            z = math.inf
        else:
            z = float(np.sqrt(np.mean(s[noisy] ** 2 / var[noisy]))) if noisy.any() else 0.0
        res.append((use[-1][0] + WINDOW / 2, z))
    return res


def first_steady(zs):
    quiet = 0
    for t, z in zs:
        quiet = quiet + 1 if z <= Z_STEADY else 0
        if quiet >= CONFIRM:
            return t
    return None


def cpi_pooled_z(f):
    """The drift test's z after each accepted burst of a CPI run (a redone burst counted once)."""
    status = [run_files.text(v) for v in f["cpi/status"][:]]
    s, se, t_end = f["cpi/slope"][:], f["cpi/slope_standard_error"][:], f["cpi/t_end"][:]
    nodes, seen = [], set()
    for k, st in enumerate(status):
        if st in ("projected", "burst_only") and t_end[k] not in seen:
            seen.add(t_end[k])
            nodes.append((t_end[k] - WINDOW / 2, s[k], se[k]))
    return pooled_z(nodes)


def reference_average(args):
    """The direct run's time average over t >= --after, the floor of two independent ensembles'
    time averages, and R. Two independent ensembles of R: their time averages differ by sqrt(2) x
    the members' spread of their own time averages / sqrt(R) (the members' levels are nearly
    frozen, so averaging over time does not shrink it; halves of one run share them and would
    understate it)."""
    with h5py.File(args.reference, "r") as f:
        td, xd = members(f)
    span = xd[td >= args.after - 1e-9]
    r = span.shape[1]
    floor = float(np.sqrt(2.0 * np.mean(span.mean(axis=0).var(axis=0, ddof=1)) / r))
    return span.mean(axis=(0, 1)), floor, r


def end_state(args, path):
    """The CPI run's end state (over the bursts the drift test pooled; when it did not end at a
    steady state, over its last --last time units) against the direct run's time average."""
    import re
    with h5py.File(path, "r") as f:
        status = run_files.text(f.attrs["end_status"])
        t = f["samples/time"][:]
        mean = run_files.get(f, "samples/mean_icdf")[:]
        zs = cpi_pooled_z(f)
    m = re.search(r"end state at t = ([0-9.e+-]+)", status)
    since = float(m.group(1)) - WINDOW / 2 if m else t[-1] - args.last
    cpi = mean[t >= since - 1e-9].mean(axis=0)
    direct, floor, r = reference_average(args)
    rms = float(np.sqrt(np.mean((cpi - direct) ** 2)))
    mid = len(cpi) // 2
    return [
        f"CPI run `{os.path.relpath(path)}`: {status}",
        "",
        "The drift test's z after each of its accepted bursts (t: z): "
        + " ".join(f"{a:.0f}:{b:.1f}" for a, b in zs),
        "",
        "| | value |",
        "|---|---|",
        f"| CPI state: mean ICDF over t >= {since:.1f} ("
        + ("the pooled bursts" if m else f"its last {args.last:g} units: no steady end") + f"), median | {cpi[mid]:.3f} d_p |",
        f"| direct time average over t >= {args.after:g} (`{os.path.relpath(args.reference)}`, R = {r}), median | "
        f"{direct[mid]:.3f} d_p |",
        f"| RMS over the nodes, CPI - direct | {rms:.3f} d_p |",
        f"| floor: two independent ensembles' time averages, sqrt(2) x members' spread / sqrt(R) | {floor:.3f} d_p |",
        f"| CPI - direct in floors | {rms / floor:.1f} |",
    ]


def hand_off_state(args, path):
    """A run with cpi.hand_off = steady: the cpi run's state where it handed over (the mean ICDF
    over its last --last units) and the steady solve's answer (the mean ICDF over the second half
    of the solve's last evaluation of Phi_tau: the recorded light ICDF, comparable whatever
    cpi.observable the solve worked in), each against the direct run's time average, beside the
    floor of two independent ensembles' time averages."""
    with h5py.File(path, "r") as f:
        status = run_files.text(f.attrs["end_status"])
        t = f["samples/time"][:]
        mean = run_files.get(f, "samples/mean_icdf")[:]
        s = f["steady"]
        t_hand, tau = float(s.attrs["hand_off_time"]), float(s.attrs["tau"])
        r_final, noise = s["iterate/residual"][-1], s["iterate/noise"][-1]
        evaluations, solve_dem = int(s.attrs["evaluations"]), float(s.attrs["dem_time"])
        dem_total = float(f.attrs["dem_time"])
        # The time to the end state as efdem states it (runs made before it did: the same rule,
        # coarse::arrival_time, from the kept bursts' end states and the answer, in the solve's
        # coordinates).
        if "end_state_time" in s.attrs:
            reached = float(s.attrs["end_state_time"])
        else:
            status_k = [run_files.text(v) for v in f["cpi/status"][:]]
            kept = [k for k, st in enumerate(status_k) if st in ("projected", "burst_only")]
            radius = math.sqrt(2.0) * 2.0 * noise  # steady.noise_factor = 2 (the default)
            reached = arrival(f["cpi/t_end"][kept], f["cpi/x_end"][kept], s["x"][:], radius)
        m = s["x"].shape[0]
    before = (t <= t_hand + 1e-9) & (t >= t_hand - args.last - 1e-9)
    cpi = mean[before].mean(axis=0)
    last = t > t[-1] - tau / 2 + 1e-9
    solved = mean[last].mean(axis=0)
    direct, floor, r = reference_average(args)
    with h5py.File(args.reference, "r") as f:
        td = f["samples/time"][:]
    rms = lambda a: float(np.sqrt(np.mean((a - direct) ** 2)))  # noqa: E731
    return [
        f"Run `{os.path.relpath(path)}`: {status}",
        "",
        "| | RMS from the direct time average [d_p] | in floors |",
        "|---|---|---|",
        f"| cpi run's end: mean ICDF over t = {t_hand - args.last:g}-{t_hand:g} | {rms(cpi):.3f} | {rms(cpi) / floor:.1f} |",
        f"| steady solve ({evaluations} evaluations of Phi_{tau:g}, {solve_dem:g} of DEM time; final "
        f"|F| = {r_final:.3f}, noise {noise:.3f}): mean ICDF over the last evaluation's second half "
        f"| {rms(solved):.3f} | {rms(solved) / floor:.1f} |",
        f"| floor: two independent ensembles' time averages (direct R = {r}, t >= {args.after:g}) | {floor:.3f} | 1 |",
        f"| the solve's band per node, (\\|F\\| + noise) / (1 - mu) / sqrt(m), mu = {MU_041:g} (the direct "
        f"ensemble's approach rate, docs/steady_states.md) | {(r_final + noise) / (1 - MU_041) / math.sqrt(m):.3f} | "
        f"{(r_final + noise) / (1 - MU_041) / math.sqrt(m) / floor:.1f} |",
        "",
        "Time to the end state (the first kept burst from which every later one lies within sqrt(2) x 2 x "
        f"the noise of the answer): " + (f"t = {reached:g}" if math.isfinite(reached) else "not reached by the bursts")
        + ".",
        "",
        f"DEM time per realization: {dem_total - solve_dem:.0f} for the cpi run (its warm-up and bursts; the "
        f"solve's one-sample warm-up included), {solve_dem:.0f} for the solve, {dem_total:.0f} in all, for "
        f"{t_hand:g} time units of the process (the direct reference: {td[-1]:g} units).",
    ]


# Radii [d_p, norm over the 19 nodes] within which a state counts as at the direct time average:
# 0.8 = sqrt(2) x 2 x the ICDF's noise norm at R = 4 (0.28: the ICDF solve's own threshold), i.e.
# 0.18 d_p per node; 0.5 (0.11 per node) for a stricter look.
RADII = (0.8, 0.5)


def arrival(t, x, target, radius):
    """The first t[k] from which every x[j >= k] lies within radius of target (NaN: never), the
    rule of coarse::arrival_time."""
    since = math.nan
    for k in range(len(t) - 1, -1, -1):
        if np.linalg.norm(x[k] - target) > radius:
            break
        since = float(t[k])
    return since


def arrivals(args, paths):
    """When each run's state came within RADII of the direct time average for good, and at what
    DEM time per realization (a cpi run: its warm-up and every burst up to then, rejected ones
    included)."""
    with h5py.File(args.reference, "r") as f:
        td, xd = f["samples/time"][:], run_files.get(f, "samples/mean_icdf")[:]
    target = xd[td >= args.after - 1e-9].mean(axis=0)
    head = " | ".join(f"within {r:g} ({r / math.sqrt(len(target)):.2f} per node): t / DEM time" for r in RADII)
    lines = [f"| run | {head} |", "|---|" + "---|" * len(RADII)]
    cells = [f"{arrival(td, xd, target, r):.0f} / {arrival(td, xd, target, r):.0f}" for r in RADII]
    lines.append(f"| direct (`{os.path.relpath(args.reference)}`, every sample) | " + " | ".join(cells) + " |")
    for path in paths:
        with h5py.File(path, "r") as f:
            c = f["cpi"]
            status = [run_files.text(v) for v in c["status"][:]]
            t_end, burst, t0 = c["t_end"][:], c["burst_length"][:], float(c["t_start"][0])
            t, x = f["samples/time"][:], run_files.get(f, "samples/mean_icdf")[:]
        ends = np.array([t_end[k] for k, st in enumerate(status) if st in ("projected", "burst_only")])
        states = x[[int(np.argmin(np.abs(t - e))) for e in ends]]
        row = []
        for r in RADII:
            a = arrival(ends, states, target, r)
            dem = t0 + sum(burst[k] for k in range(len(status)) if t_end[k] <= a + 1e-9) if math.isfinite(a) else math.nan
            row.append("never" if not math.isfinite(a) else f"{a:.0f} / {dem:.0f}")
        lines.append(f"| `{os.path.relpath(path)}` (kept bursts' ends) | " + " | ".join(row) + " |")
    return lines


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cpi", nargs="*", default=[], help="cpi runs made with cpi.finish = steady")
    p.add_argument("--reference", help="a long direct run of the same scene (own seed)")
    p.add_argument("--after", type=float, default=200.0, help="time from which the direct run is steady")
    p.add_argument("--last", type=float, default=100.0, help="span of a CPI run without a steady end")
    p.add_argument("--hand-off", nargs="*", default=[], help="cpi runs made with cpi.hand_off = steady")
    p.add_argument("--out", default=os.path.join(RESULTS, "steady_end.md"),
                   help="where the Markdown goes (default bench/results/steady_end.md)")
    args = p.parse_args()
    lines = ["# The fluidized end state of cpi.finish = steady\n",
             "Made by `/usr/bin/python3 bench/steady_end.py"
             + (f" --cpi {' '.join(os.path.relpath(c) for c in args.cpi)}" if args.cpi else "")
             + (f" --hand-off {' '.join(os.path.relpath(c) for c in args.hand_off)}" if args.hand_off else "")
             + (f" --reference {os.path.relpath(args.reference)} --after {args.after:g}"
                if args.cpi or args.hand_off else "")
             + (f" --out {os.path.relpath(args.out)}"
                if os.path.abspath(args.out) != os.path.join(RESULTS, "steady_end.md") else "")
             + "`.\n",
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
        lines += ["", "## 2. CPI runs' end states against a long direct time average\n"]
        for path in args.cpi:
            lines += end_state(args, path) + [""]
    if args.hand_off:
        lines += ["", "## 3. cpi.hand_off = steady: the cpi run's end refined by the steady solver\n"]
        for path in args.hand_off:
            lines += hand_off_state(args, path) + [""]
        lines += ["### When each run reached the direct time average\n"] + arrivals(args, args.hand_off) + [""]
    text = "\n".join(lines) + "\n"
    print(text)
    with open(args.out, "w") as f:
        f.write(text)


if __name__ == "__main__":
    main()
