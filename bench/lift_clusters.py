#!/usr/bin/python3
"""How the light spheres of a segregating bed are arranged among the heavy ones at their height,
and what a colour lift's choice of particles does to it (cpi.relabel).

For each checkpoint (every realization in it): each light sphere's neighbours (centres within
1.15 contact distances, periodic in x and y, as coarse::light_neighbour_counts), the fraction
of them that are light, over the light spheres of three rank ranges (the lowest 30 % of the
lights: the lower nodes that lag after a lift, bench/results/lift_velocity.md; the middle 40 %;
the top 30 %). Against the same with the labels shuffled within 0.5-d_p height slices (10
shuffles): the composition profile kept to 0.5 d_p, the arrangement at random. A ratio above 1:
lights gather with lights.

Then lifts of each checkpoint's realizations done here, in Python, as the colour lift does it
(each 0.5-d_p slice of the lowest 30 % of the lights' range gains or loses as many lights as
a shift of the light ranks by SHIFT d_p asks; the fewest switches, drawn at random (cpi.relabel =
any) or by light neighbours (clustered: heavies with the most light neighbours turn light,
lights with the fewest turn heavy), and the new lights' light-neighbour fraction; and a one-way
lift (SHIFT = 1.5: the lower lights up, as a CPI jump moves them, so their slices lose lights):
what each removal leaves of the remaining lights' light-neighbour fraction.

    /usr/bin/python3 bench/lift_clusters.py CHECKPOINT... --out bench/results/lift_clusters.md

The checkpoints of bench/results/lift_clusters.md (run files not in git): the demo bed at U_s =
0.41 (runs/transient_lift/, the command in bench/lift_velocity.py), and the tall bed at 0.41 from
the runs of bench/null_lift.py, copied to runs/lift_clusters/ before a run replaces them:
tall_direct_warmup.h5 = mean_dt3_like's first checkpoint (t = 44, inside its direct warm-up),
tall_mean_dt3_step7.h5 and tall_mean_dt3_clustered_step7.h5 = mean_dt3's and mean_dt3_clustered's
checkpoint 7 (t = 275, after seven lifts without a jump, random and clustered relabelling).
"""
import argparse
import re
import sys

import h5py
import numpy as np
from scipy.spatial import cKDTree

REACH = 1.15  # contact distances (coarse::kNeighbourReach)
SLICE = 0.5  # d_p: the height resolution the shuffle keeps
RANGES = (("lowest 30 %", 0.0, 0.3), ("middle 40 %", 0.3, 0.7), ("top 30 %", 0.7, 1.0))


def realizations(path):
    """(time, x, light flags, v_z) of each realization in a checkpoint, and the box side."""
    with h5py.File(path, "r") as f:
        x, species = f["realizations/x"][:], f["realizations/species"][:].ravel()
        vz = f["realizations/v"][:, 2]
        times = f["realizations/time"][:].ravel()
        scene = f["scene"][()].decode()  # the scene's text: the last domain.lx set is the box's
        found = re.findall(r"^\s*domain\.lx\s*=\s*([0-9.eE+-]+)", scene, flags=re.M)
        lx = float(found[-1]) if found else None
    n = len(x) // len(times)
    return [(float(times[r]), x[r * n:(r + 1) * n], species[r * n:(r + 1) * n] == 0, vz[r * n:(r + 1) * n])
            for r in range(len(times))], lx


def pairs(x, lx):
    tree = cKDTree(np.c_[np.mod(x[:, 0], lx), np.mod(x[:, 1], lx), x[:, 2]], boxsize=[lx, lx, 1e9])
    return tree.query_pairs(REACH, output_type="ndarray")  # diameters 1: contact distance 1


def light_fraction(p, light, who):
    """Over the particles flagged WHO: light neighbours / all neighbours (pooled)."""
    i, j = p[:, 0], p[:, 1]
    num = np.bincount(i, weights=light[j], minlength=len(light)) + np.bincount(j, weights=light[i], minlength=len(light))
    den = np.bincount(i, minlength=len(light)) + np.bincount(j, minlength=len(light))
    return num[who].sum() / max(den[who].sum(), 1)


def shuffled(x, light, rng):
    out = light.copy()
    slab = np.floor(x[:, 2] / SLICE).astype(int)
    for k in np.unique(slab):
        m = np.nonzero(slab == k)[0]
        out[m] = rng.permutation(out[m])
    return out


def rank_range(x, light, lo, hi):
    z = np.sort(x[light, 2])
    a, b = z[int(lo * (len(z) - 1))], z[int(hi * (len(z) - 1))]
    return light & (x[:, 2] >= a) & (x[:, 2] <= b), (a, b)


def neighbour_counts(p, n):
    return np.bincount(p[:, 0], minlength=n) + np.bincount(p[:, 1], minlength=n)


def light_neighbours(p, light):
    i, j = p[:, 0], p[:, 1]
    return np.bincount(i, weights=light[j], minlength=len(light)) + np.bincount(j, weights=light[i], minlength=len(light))


def lift(x, light, p, shift, how, rng):
    """Each SLICE of the lower lights' range takes the light count the slice SHIFT d_p lower has
    (a lift that raises the lower lights by SHIFT), the fewest switches; returns the new labels
    and the flags of the particles turned light."""
    out = light.copy()
    z = x[:, 2]
    _, (a, b) = rank_range(x, light, 0.0, 0.3)
    count = light_neighbours(p, light)
    for lo in np.arange(a, b, SLICE):
        here = (z >= lo) & (z < lo + SLICE)
        below = (z >= lo - shift) & (z < lo - shift + SLICE)
        # the wanted light fraction of this slice: that of the slice SHIFT lower (the lights move up)
        want = int(round(light[below].mean() * here.sum())) if below.any() else int(light[here].sum())
        excess = int(light[here].sum()) - want
        if excess == 0:
            continue
        cand = np.nonzero(here & (light if excess > 0 else ~light))[0]
        cand = rng.permutation(cand)
        if how == "clustered":  # lights with fewest light neighbours off, heavies with most on
            key = count[cand] if excess > 0 else -count[cand]
            cand = cand[np.argsort(key, kind="stable")]
        out[cand[:abs(excess)]] = excess < 0
    return out, out & ~light


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("checkpoints", nargs="+")
    ap.add_argument("--lx", type=float, help="box side when a checkpoint does not say (7.5 for both beds here)")
    ap.add_argument("--shift", type=float, default=-0.5, help="the lift's shift of the lower lights [d_p]; "
                    "negative lowers them (a realization ahead of the mean)")
    ap.add_argument("--out")
    args = ap.parse_args()
    rng = np.random.default_rng(1)
    rng_oneway = np.random.default_rng(3)  # its own stream: sections 1-3 as without section 4
    lines = [f"Made by `/usr/bin/python3 bench/lift_clusters.py {' '.join(sys.argv[1:])}`.", "",
             "## 1. The lights' neighbours: the light fraction, direct against shuffled in 0.5-d_p slices", "",
             "| checkpoint | t | realizations | lights | light fraction of neighbours | shuffled | ratio |",
             "|---|---|---|---|---|---|---|"]
    lifted = ["", f"## 2. A lift of the lowest 30 % of the lights by {args.shift:g} d_p: the new lights' light fraction of neighbours", "",
              "| checkpoint | t | new lights per realization | random (any) | clustered | the lights already there |",
              "|---|---|---|---|---|---|"]
    oneway = ["", "## 4. A one-way lift, as a jump's: the lower lights up by 1.5 d_p (their slices lose lights); "
              "the light fraction of the neighbours of the lowest 30 % of the lights that stay light", "",
              "| checkpoint | t | lights removed per realization | before | random (any) | clustered (lone lights first) |",
              "|---|---|---|---|---|---|"]
    velocity = ["", "## 3. The lowest 30 % of the lights: vertical velocity [sqrt(g d_p)] less the mean of those in "
                "its 1-d_p slice, by the light fraction of its neighbours (mean +- standard error (lights))", "",
                "| checkpoint | t | below 1/3 | 1/3-2/3 | 2/3 and above | correlation |", "|---|---|---|---|---|---|"]
    for path in args.checkpoints:
        reals, lx = realizations(path)
        lx = lx or args.lx
        rows = {name: ([], []) for name, _, _ in RANGES}
        new = {"any": [], "clustered": [], "native": [], "count": []}
        speed = []
        stay = {"any": [], "clustered": [], "removed": []}
        for t, x, light, vz in reals:
            p = pairs(x, lx)
            for name, lo, hi in RANGES:
                who, _ = rank_range(x, light, lo, hi)
                rows[name][0].append(light_fraction(p, light, who))
                rows[name][1].append(np.mean([light_fraction(p, shuffled(x, light, rng), who) for _ in range(10)]))
            for how in ("any", "clustered"):
                lab, turned = lift(x, light, p, args.shift, how, rng)
                new[how].append(light_fraction(p, lab.astype(float), turned))
            who, _ = rank_range(x, light, 0.0, 0.3)
            new["native"].append(light_fraction(p, light.astype(float), who))
            new["count"].append(int(turned.sum()))
            for how in ("any", "clustered"):
                lab, _ = lift(x, light, p, 1.5, how, rng_oneway)
                stay[how].append(light_fraction(p, lab.astype(float), who & lab))
            stay["removed"].append(int((light & ~lab).sum()))
            # each lower light's v_z less the mean of the lower lights in its 1-d_p slice
            frac = light_neighbours(p, light.astype(float)) / np.maximum(neighbour_counts(p, len(light)), 1)
            slab = np.floor(x[:, 2]).astype(int)
            for k in np.unique(slab[who]):
                m = who & (slab == k) & (neighbour_counts(p, len(light)) > 0)
                if m.sum() >= 4:
                    speed.extend(zip(frac[m], vz[m] - vz[m].mean()))
        name_ = path.split("/")[-1]
        for name, _, _ in RANGES:
            a, b = np.mean(rows[name][0]), np.mean(rows[name][1])
            lines.append(f"| {name_} | {reals[0][0]:.0f} | {len(reals)} | {name} | {a:.3f} | {b:.3f} | {a / b:.2f} |")
        a = np.array(speed)
        cells = [a[(a[:, 0] >= lo) & (a[:, 0] < hi), 1] for lo, hi in ((0, 1 / 3), (1 / 3, 2 / 3), (2 / 3, 1.01))]
        velocity.append(f"| {name_} | {reals[0][0]:.0f} | " + " | ".join(
            f"{c.mean():+.3f} +- {c.std(ddof=1) / np.sqrt(len(c)):.3f} ({len(c)})" for c in cells) +
            f" | {np.corrcoef(a[:, 0], a[:, 1])[0, 1]:.2f} |")
        oneway.append(f"| {name_} | {reals[0][0]:.0f} | {np.mean(stay['removed']):.0f} | {np.mean(new['native']):.3f} | "
                      f"{np.mean(stay['any']):.3f} | {np.mean(stay['clustered']):.3f} |")
        lifted.append(f"| {name_} | {reals[0][0]:.0f} | {np.mean(new['count']):.0f} | {np.mean(new['any']):.3f} | "
                      f"{np.mean(new['clustered']):.3f} | {np.mean(new['native']):.3f} |")
    text = "\n".join(lines + lifted + velocity + oneway) + "\n"
    print(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
