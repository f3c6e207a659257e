#!/usr/bin/python3
"""How far apart do realizations that share one settled bed get (bed.read.shared, issue 35)?

Three direct ensembles of the demo bed (examples/demo_small, R = 4 on 2 ranks), each over DURATION:
  own      every realization from its own settled bed (bed.write, then bed.read: the same run
           as settling them in place);
  shared   every realization from realization 0's bed, with bed.read.velocity_rms = 0.05;
  permuted the same, and bed.permute_species = true (a fresh random mixture each).
Printed: the spread of the light ICDF across realizations (its variance over the ensemble, the
mean over the nodes) of `shared` and `permuted` as a fraction of `own`'s, by time window. An
ensemble of independent realizations has 1; a spread below it means the realizations are still
correlated, and the ensemble's standard error is too small by the square root of the ratio.

    /usr/bin/python3 bench/shared_bed_spread.py [--u 0.19] [--duration 40] [--out runs/shared_bed]
"""
import argparse
import os
import subprocess

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, ".."))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--efdem", default=os.path.join(ROOT, "build", "mpi_driver", "efdem"))
    p.add_argument("--u", type=float, default=0.19, help="gas_drag.superficial_velocity")
    p.add_argument("--duration", type=float, default=40)
    p.add_argument("--out", default=os.path.join(ROOT, "runs", "shared_bed"))
    args = p.parse_args()
    out = os.path.abspath(args.out)
    beds = os.path.join(out, "beds", "demo.data")
    scene = os.path.join(ROOT, "examples", "demo_small", "scene.cfg")
    common = [f"gas_drag.superficial_velocity={args.u}", "mode=direct", f"run.duration={args.duration}",
              f"output.directory={out}", "observe.bed=false", "output.overwrite=true"]
    shared = [f"bed.read={os.path.join(out, 'beds', 'demo_r0000.data')}", "bed.read.shared=true",
              "bed.read.velocity_rms=0.05"]
    bed = [f"bed.read={beds}"] if os.path.exists(os.path.join(out, "beds", "demo_r0003.data")) \
        else [f"bed.write={beds}"]  # the beds do not depend on U_s: settled once for every --u
    runs = {"own": bed, "shared": shared, "permuted": shared + ["bed.permute_species=true"]}
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    icdf = {}
    for name, extra in runs.items():
        prefix = f"{name}_u{args.u:g}"
        path = os.path.join(out, prefix + ".h5")
        if not os.path.exists(path):
            cmd = ["mpirun", "-np", "2", "--oversubscribe", args.efdem, scene, *common, *extra,
                   f"output.prefix={prefix}"]
            print(" ".join(cmd), flush=True)
            os.makedirs(out, exist_ok=True)
            with open(os.path.join(out, prefix + ".log"), "w") as log:
                subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT, env=env, check=True)
        with h5py.File(path, "r") as f:
            t = f["samples/time"][()]
            icdf[name] = f["samples/icdf"][()]  # sample, realization, node

    def spread(x):
        return x.var(axis=1, ddof=1).mean(axis=1)

    own = spread(icdf["own"])
    print(f"U_s = {args.u:g}: ICDF spread across R = {icdf['own'].shape[1]} realizations, "
          f"as a fraction of the own-bed ensemble's ({own.mean():.3g} d_p^2 on average)")
    print("window         shared   permuted")
    edges = [0, 2, 5, 10, 20, 40, 80, 160]
    for lo, hi in zip(edges, edges[1:]):
        m = (t > lo) & (t <= hi)
        if m.any():
            print(f"({lo:3d}, {hi:3d}]   {spread(icdf['shared'])[m].mean() / own[m].mean():8.3f}"
                  f"   {spread(icdf['permuted'])[m].mean() / own[m].mean():8.3f}")


if __name__ == "__main__":
    main()
