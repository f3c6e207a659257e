#!/usr/bin/python3
"""The colour lift offline on the states of checkpoints: every realization lifted to the
ensemble's own coarse state (what a lift at a steady state does: the target is the current mean),
and how far the lifted ensemble's mean lies from it, for each coarse variable (icdf, ranks) and
relabelling rule (cpi.relabel_nodes = matched, random). A lift that meets a feasible target leaves
the mean where it was; what it misses is bias the next burst must heal.

    /usr/bin/python3 bench/lift_offline.py CHECKPOINT.h5 [CHECKPOINT.h5 ...] \\
        [--program build/bench/efdem_lift_offline] [--out bench/results/lift_offline.md]

The checkpoints of docs/accuracy_vs_cost.md ("The count plan"): the tall bed at U_s = 0.41, R = 8,
direct_a of `bench/whole_process.py --case tall_u0.41_r8` at t = 500 and 550
(runs/whole_process/tall_u0.41_r8/direct_a/direct_a_ckpt_0000{1000,1100}.h5; run files are not in
git: the study's command makes them again). --program names another build's program, to compare
versions (a build of an earlier commit: `git worktree add /tmp/old COMMIT`, build
efdem_lift_offline there).
"""
import argparse
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def write_state(checkpoint, path):
    """The particles of every realization, 'x y z species' per line; returns N per realization."""
    with h5py.File(checkpoint, "r") as f:
        x = f["realizations/x"][:]
        species = f["realizations/species"][:]
        meta = f["realizations/meta"][:]
    n = int(meta[0, 2])
    if any(int(row[2]) != n for row in meta) or len(x) != n * len(meta):
        sys.exit(f"{checkpoint}: realizations of different sizes; this reads equal ones only")
    np.savetxt(path, np.column_stack([x, species]), fmt="%.17g")
    return n, len(meta)


def lift(program, state, n, observable, rule):
    out = subprocess.run([program, state, str(n), observable, rule], check=True, capture_output=True,
                         text=True).stdout
    values = {}
    for line in out.splitlines():
        key, *rest = line.split()
        values[key] = [float(v) for v in rest]
    return values


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("checkpoints", nargs="+")
    ap.add_argument("--program", default=os.path.join(HERE, "..", "build", "bench", "efdem_lift_offline"))
    ap.add_argument("--out", default=None, help="write the table here as well as to stdout")
    args = ap.parse_args()
    lines = ["| state | realizations x particles | coarse variable | cpi.relabel_nodes | "
             "mean's miss, RMS over nodes [d_p] | nodes low / high | a member's miss, RMS [d_p] | "
             "labels switched per realization |",
             "|---|---|---|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as tmp:
        for checkpoint in args.checkpoints:
            state = os.path.join(tmp, "state.txt")
            n, r = write_state(checkpoint, state)
            for observable in ("icdf", "ranks"):
                for rule in ("matched", "random"):
                    v = lift(args.program, state, n, observable, rule)
                    miss = np.array(v["node_miss"])
                    lines.append(f"| {os.path.basename(checkpoint)} | {r} x {n} | {observable} | {rule} | "
                                 f"{v['rms_mean_miss'][0]:.3f} | {(miss < -1e-3).sum()} / {(miss > 1e-3).sum()} | "
                                 f"{v['rms_member_miss'][0]:.3f} | {v['switched_per_realization'][0]:.0f} |")
    text = "\n".join(lines) + "\n"
    print(text, end="")
    if args.out:
        with open(args.out, "w") as f:
            f.write(f"Made by `/usr/bin/python3 bench/lift_offline.py {' '.join(args.checkpoints)}`.\n\n" + text)


if __name__ == "__main__":
    main()
