#!/usr/bin/python3
"""Does a lift set a stopped bed moving again (issue 34, item 2)? Takes one realization that is at
rest in a direct checkpoint (U_s = 0.19: its bed defluidized as the heavy spheres gathered at the
bottom), writes its particles as a LAMMPS data file three ways and runs each directly from there:

  stopped     as it is (the contact springs' history is not in a data file: the bed may settle a
              little before it is at rest again);
  swap<k>     k light particles within 1.5 d_p below the light median exchanged with k heavy ones
              within 1.5 d_p above it: what a lift that moves the light ICDF up does, in place (a
              CPI jump changes 100-600 labels of a realization, mostly near the median);
and reports, per run, how long the bed stays at rest or moving (/samples/at_rest) and how far its
light ICDF moves.

    /usr/bin/python3 bench/lift_restart.py CHECKPOINT --realization 0 [--swaps 10 30] [--duration 200]

The checkpoint used (docs/accuracy_vs_cost.md): demo bed, R = 8, seed 101, t = 500, realization 0
at rest since t ~ 269, from `/usr/bin/python3 bench/slope_study.py --realizations 8 --duration 600
--only direct_a` (direct runs write a checkpoint every 100 samples). Writes
bench/results/lift_restart.md. About 5 min per 200 units on one core.
"""
import argparse
import os
import subprocess

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
MEDIAN = 9


def realization(path, r):
    with h5py.File(path, "r") as f:
        n = f["realizations/meta"][:, 2]
        off = np.concatenate([[0], np.cumsum(n)])
        sl = slice(int(off[r]), int(off[r + 1]))
        return (f["realizations/x"][sl], f["realizations/v"][sl], f["realizations/species"][sl],
                f["realizations/tag"][sl], float(f["realizations/time"][r]))


def write_data(path, x, species, tag, lx, ly):
    with open(path, "w") as o:
        o.write(f"one realization's bed\n\n{len(x)} atoms\n2 atom types\n\n0 {lx} xlo xhi\n0 {ly} ylo yhi\n"
                "0 150 zlo zhi\n\nAtoms # sphere\n\n")
        for k in range(len(x)):
            t = int(species[k]) + 1  # species 0 (light, density 1) is type 1
            o.write(f"{tag[k]} {t} 1 {t} {x[k, 0]:.17g} {x[k, 1]:.17g} {x[k, 2]:.17g} 0 0 0\n")


def swapped(x, species, k, seed):
    rng = np.random.default_rng(seed)
    med = np.median(x[species == 0, 2])
    light = np.nonzero((species == 0) & (x[:, 2] > med - 1.5) & (x[:, 2] < med))[0]
    heavy = np.nonzero((species == 1) & (x[:, 2] > med) & (x[:, 2] < med + 1.5))[0]
    out = species.copy()
    out[rng.choice(light, k, replace=False)] = 1
    out[rng.choice(heavy, k, replace=False)] = 0
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("checkpoint")
    p.add_argument("--realization", type=int, default=0)
    p.add_argument("--swaps", type=int, nargs="*", default=[10, 30])
    p.add_argument("--duration", type=float, default=200.0)
    p.add_argument("--efdem", default=os.path.join(HERE, "..", "build", "mpi_driver", "efdem"))
    p.add_argument("--out", default=os.path.join(HERE, "..", "runs", "lift_restart"))
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    x, v, species, tag, t0 = realization(args.checkpoint, args.realization)
    speed = float(np.linalg.norm(v, axis=1).max())
    # The bench scene without its bed block (the bed comes from the data file).
    scene = os.path.join(args.out, "scene.cfg")
    with open(os.path.join(HERE, "scenes", "demo_bed.cfg")) as src, open(scene, "w") as dst:
        dst.writelines(line for line in src if not line.startswith("bed."))
    cases = [("stopped", species)] + [(f"swap{k}", swapped(x, species, k, k)) for k in args.swaps]
    lines = ["# Does a lift set a stopped bed moving again? (issue 34)\n",
             f"Made by `/usr/bin/python3 bench/lift_restart.py {os.path.basename(args.checkpoint)} --realization "
             f"{args.realization} --duration {args.duration:g}`: realization {args.realization} of that checkpoint "
             f"(t = {t0:g}, largest particle speed {speed:.1e} sqrt(g d_p)), run directly for {args.duration:g} "
             "units at U_s = 0.19 from its particles as they are and with k light/heavy labels exchanged across "
             "the light median (within 1.5 d_p), as a lift does.\n",
             "| run | light median at the start [d_p] | at the end | samples at rest | at rest from t = | "
             "largest ICDF change [d_p] |", "|---|---|---|---|---|---|"]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    for name, sp in cases:
        data = os.path.join(args.out, name + ".data")
        write_data(data, x, sp, tag, 7.5, 7.5)
        h5 = os.path.join(args.out, name + ".h5")
        if not os.path.exists(h5):
            with open(os.path.join(args.out, name + ".log"), "w") as log:
                subprocess.check_call(["mpirun", "-np", "1", os.path.abspath(args.efdem), scene, "mode=direct",
                                       "bed.source=lammps_data", f"bed.file={data}",
                                       "gas_drag.superficial_velocity=0.19", f"run.duration={args.duration:g}",
                                       "ensemble.at_rest=simulate", f"output.directory={args.out}",
                                       f"output.prefix={name}"], stdout=log, stderr=subprocess.STDOUT, env=env)
        with h5py.File(h5, "r") as f:
            t, rest, icdf = f["samples/time"][:], f["samples/at_rest"][:, 0], f["samples/icdf"][:, 0, :]
        moving = np.nonzero(rest == 0)[0]
        since = ("-" if rest[-1] == 0 else f"{t[moving[-1] + 1]:g}" if len(moving) else f"{t[0]:g}")
        lines.append(f"| {name} | {icdf[0, MEDIAN]:.2f} | {icdf[-1, MEDIAN]:.2f} | {int(rest.sum())} of {len(rest)} "
                     f"| {since} | {np.abs(icdf - icdf[0]).max():.3f} |")
    text = "\n".join(lines) + "\n"
    print(text)
    with open(os.path.join(HERE, "results", "lift_restart.md"), "w") as f:
        f.write(text)


if __name__ == "__main__":
    main()
