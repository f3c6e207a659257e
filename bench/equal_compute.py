#!/usr/bin/python3
"""What accuracy costs in compute (issue 34, item 5): the error of direct ensembles of R = 1, 2, 4,
8, 16 realizations and of the CPI runs of a study, against the infinite-ensemble mean, as a
function of the DEM compute each spent — the user's choice between direct with R and CPI with
S x R realizations at one budget of core-hours.

    /usr/bin/python3 bench/equal_compute.py                      # the four slope studies
    /usr/bin/python3 bench/equal_compute.py bench/results/slope_study_r8_u0.19_t200
    /usr/bin/python3 bench/equal_compute.py --out docs/equal_compute_whole_process \
        bench/results/whole_process/tall_u0.41_r8+bench/results/whole_process/tall_u0.41_r4

Reads the run files a study of bench/slope_study.py made (direct_a/b/c.h5: three direct ensembles
with their own seeds, and its CPI runs; the run files are not in git, the study's command in its
analysis.md regenerates them), or the reductions bench/whole_process.py keeps in git (NAME.json:
each realization's ICDF on a 5-unit grid; preferred where a run has both, so that every run of a
study is costed alike, by its particle-steps). A study given as DIRECTS+CPI takes the direct runs from the
folder DIRECTS and the CPI runs from both (bench/whole_process.py keeps its R = 4 CPI runs of the
tall bed beside the R = 8 directs whose halves are their floor). Writes docs/equal_compute.md and
docs/equal_compute.png.

How:
* The three direct ensembles are independent draws of the same process (same bed, own seeds), so
  their 3R realizations pooled are one ensemble of N = 3R. A direct ensemble of S is a random
  subset of them; its error against the truth is estimated against the mean of the other N - S,
  whose own noise (the members' variance / (N - S)) is subtracted from the squared error
  (scripts/accuracy_metrics.py: subset_errors). Averaged over 200 subsets: a smooth curve.
* A CPI run (independent seed) is compared with the mean of all N at its own sample times, the
  reference's noise var/N subtracted the same way (error_against_truth).
* Compute: realization x DEM time units (deterministic: wall times on this shared machine vary
  3x between identical runs under other load); for CPI the lift and restriction add their share
  of the run's wall time. Core-seconds: x the cost of one realization-unit in the least loaded
  direct run of the study (stated per study, with the CPU).
* Direct's error at compute C follows e(C) = sqrt(var x T / C) (independent realizations; the
  subsets check it), var the members' variance at the CPI run's sample times and T the span.
  For each CPI run: the ratio of direct's error at CPI's compute to CPI's error ("error ratio at
  equal compute", > 1: CPI wins) and the compute direct needs for CPI's error over CPI's compute
  ("compute ratio at equal error", var T / e^2 / C).
Both over the whole span and over its last quarter (where the end state is).
"""
import argparse
import glob
import json
import math
import os
import platform
import re
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "scripts"))
import accuracy_metrics as am  # noqa: E402
import run_files  # noqa: E402

sys.path.insert(0, HERE)
import study_runs as sr  # noqa: E402

DIRECTS = ("direct_a", "direct_b", "direct_c")
STUDIES = ("slope_study_r4_u0.19_t600", "slope_study_r8_u0.19_t600", "slope_study_r8_u0.19_t200", "slope_study_r4_u0.41_t200",
           "slope_study_r8_u0.41_t200")


def cpu():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.machine()


def load(path):
    if path.endswith(".json"):
        return load_reduction(path)
    with h5py.File(path, "r") as f:
        a = f.attrs
        return {"t": f["samples/time"][:], "mean": run_files.get(f, "samples/mean_icdf")[:], "icdf": f["samples/icdf"][:],
                "realizations": int(a["realizations"]), "ranks": int(a["ranks"]),
                "dem_time": float(a["dem_time"]), "wall": float(a["wall_seconds"]),
                "overhead": float(a["lift_seconds"]) + float(a["restrict_seconds"]),
                "mode": sr.text(a["mode"]), "status": sr.text(a.get("end_status", ""))}


def load_reduction(path):
    """A run as bench/whole_process.py keeps it in git (NAME.json: each realization's ICDF on a
    5-unit grid, DEM time, particle-steps, wall time; the run files themselves are not kept). The
    lift's and restriction's share of the wall time is not in it: 0 here (1-3 % in the runs that
    have it). Compute is counted in particle-steps (`particle_steps`: a rejected jump's burst and a
    realization paused at rest count as they cost), converted to realization-units by the study."""
    with open(path) as f:
        d = json.load(f)
    icdf = np.array(d["icdf"], dtype=float)
    ranks = re.search(r"-np (\d+)", d.get("study_command", ""))
    name = os.path.basename(path)[:-5]
    return {"t": np.array(d["t"], dtype=float), "mean": np.nanmean(icdf, axis=1), "icdf": icdf,
            "realizations": icdf.shape[1], "ranks": int(ranks.group(1)) if ranks else 2,
            "dem_time": float(d["dem_time"]), "wall": float(d["wall_seconds"]), "overhead": 0.0,
            "particle_steps": float(d.get("particle_steps") or "nan"),
            "mode": "direct" if name in DIRECTS else "cpi", "status": d.get("end_status", "")}


def run_paths(folder):
    """The runs of FOLDER: their reductions (NAME.json, bench/whole_process.py) where there are any,
    else their run files (NAME.h5): one cost accounting for every run of a study."""
    h5 = {os.path.basename(p)[:-3]: p for p in glob.glob(os.path.join(folder, "*.h5"))}
    js = {os.path.basename(p)[:-5]: p for p in glob.glob(os.path.join(folder, "*.json")) if not p.endswith("analysis.json")}
    return {**h5, **js}


def members_at(t_ref, members, t):
    """members (samples at t_ref x R x m) interpolated to the times t that lie inside t_ref's span:
    (mask of kept t, samples x R x m)."""
    keep = None
    out = []
    for r in range(members.shape[1]):
        keep, v = am.align(t_ref, members[:, r, :], t)
        out.append(v)
    return keep, np.stack(out, axis=1)


def analyse_study(spec):
    folder, *cpi_folders = spec.split("+")
    name = os.path.basename(os.path.normpath(folder))
    if cpi_folders:
        name = os.path.basename(os.path.dirname(os.path.normpath(folder))) + "_" + name
    paths = run_paths(folder)
    directs = [load(paths[d]) for d in DIRECTS if d in paths]
    if len(directs) < 3:
        print(f"{name}: {len(directs)} direct run file(s) or reduction(s), 3 needed; skipped")
        return None
    t = directs[0]["t"]
    if any(len(d["t"]) != len(t) or np.max(np.abs(d["t"] - t)) > 1e-9 for d in directs):
        raise SystemExit(f"{name}: the direct runs' sample times differ; cannot pool them")
    pool = np.concatenate([d["icdf"] for d in directs], axis=1)
    n = pool.shape[1]
    span = float(t[-1] - t[0])
    last = t >= t[0] + 0.75 * span
    cost = min(d["wall"] * d["ranks"] / (d["realizations"] * d["dem_time"]) for d in directs)
    # Particle-steps of one realization-unit: the directs' largest (a direct realization paused at
    # rest costs less; none is at U_s = 0.41), for runs whose reduction counts particle-steps.
    unit = max((d.get("particle_steps", math.nan) / (d["realizations"] * d["dem_time"]) for d in directs),
               default=math.nan)
    sizes = [s for s in (1, 2, 4, 8, 16) if s <= n - 2]
    direct = {s: {"compute": s * span, "e": am.subset_errors(pool, s),
                  "e_last": am.subset_errors(pool[last], s)} for s in sizes}
    cpi = {}
    for path in sorted(p for f in [folder, *cpi_folders] for p in run_paths(f).values()):
        run_name = os.path.splitext(os.path.basename(path))[0]
        if run_name in DIRECTS:
            continue
        if os.path.dirname(path) != os.path.normpath(folder):  # runs of a second folder: named by it
            run_name += f" ({os.path.basename(os.path.dirname(path))})"
        r = load(path)
        if r["mode"] != "cpi" or not r["status"].startswith("completed"):
            continue
        keep, ref = members_at(t, pool, r["t"])
        r["t"], r["mean"] = r["t"][keep], r["mean"][keep]
        var = float(np.mean(ref.var(axis=1, ddof=1)))
        sel = r["t"] >= t[0] + 0.75 * span
        var_last = float(np.mean(ref[sel].var(axis=1, ddof=1)))
        compute = r["realizations"] * r["dem_time"] * (1.0 + r["overhead"] / r["wall"])
        if math.isfinite(r.get("particle_steps", math.nan)) and math.isfinite(unit):
            compute = r["particle_steps"] / unit  # what it cost, rejected bursts included
        # A run that ended early (at its end state) is held against direct over its own span.
        span_r = min(span, float(r["t"][-1] - t[0]))
        e = am.error_against_truth(r["mean"], ref)
        e_last = am.error_against_truth(r["mean"][sel], ref[sel])
        cpi[run_name] = {
            "R": r["realizations"], "compute": compute, "e": e, "e_last": e_last,
            "error_ratio": math.sqrt(var * span_r / compute) / e if e > 0 else math.inf,
            "error_ratio_last": math.sqrt(var_last * span_r / compute) / e_last if e_last > 0 else math.inf,
            "compute_ratio": var * span_r / e ** 2 / compute if e > 0 else math.inf,
            "compute_ratio_last": var_last * span_r / e_last ** 2 / compute if e_last > 0 else math.inf}
    return {"name": name, "N": n, "span": span, "cost": cost, "direct": direct, "cpi": cpi,
            "var": float(np.mean(pool.var(axis=1, ddof=1))), "var_last": float(np.mean(pool[last].var(axis=1, ddof=1)))}


def table(s):
    lines = [f"### {s['name']}: {s['N']} direct realizations pooled, {s['span']:g} time units\n",
             f"One realization-unit cost {s['cost']:.2f} core-s in the least loaded direct run "
             f"(the study's machine; this table made on {cpu()}).\n",
             "| direct R | compute [realization-units] | core-s | e (whole) [d_p] | e (last quarter) [d_p] "
             "| sqrt(var T / C) whole / last |",
             "|---" * 6 + "|"]
    for size, d in s["direct"].items():
        pred = math.sqrt(s["var"] * s["span"] / d["compute"])
        pred_last = math.sqrt(s["var_last"] * s["span"] / d["compute"])
        lines.append(f"| {size} | {d['compute']:.0f} | {d['compute'] * s['cost']:.0f} | {d['e']:.3f} | "
                     f"{d['e_last']:.3f} | {pred:.3f} / {pred_last:.3f} |")
    lines += ["", "| CPI run | R | compute | core-s | e (whole) | e (last quarter) | error ratio at equal compute "
              "whole / last | compute ratio at equal error whole / last |", "|---" * 8 + "|"]
    for name, c in s["cpi"].items():
        lines.append(f"| {name} | {c['R']} | {c['compute']:.0f} | {c['compute'] * s['cost']:.0f} | {c['e']:.3f} | "
                     f"{c['e_last']:.3f} | {c['error_ratio']:.2f} / {c['error_ratio_last']:.2f} | "
                     f"{c['compute_ratio']:.2f} / {c['compute_ratio_last']:.2f} |")
    return "\n".join(lines) + "\n"


def plot(studies, path):
    cols = min(2, len(studies))
    rows = (len(studies) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(6.2 * cols, 4.6 * rows), squeeze=False)
    for ax in axes.flat[len(studies):]:
        ax.set_visible(False)
    for ax, s in zip(axes.flat, studies):
        c = np.array([d["compute"] for d in s["direct"].values()])
        ax.loglog(c, [d["e"] for d in s["direct"].values()], "ko-", label="direct, R = " +
                  ", ".join(str(k) for k in s["direct"]))
        grid = np.geomspace(c.min() * 0.8, c.max() * 1.25, 50)
        ax.loglog(grid, np.sqrt(s["var"] * s["span"] / grid), "k:", lw=1, label="sqrt(var T / C)")
        for name, r in s["cpi"].items():
            ax.loglog([r["compute"]], [r["e"]], "o", label=f"{name} (R {r['R']})")
        ax.set_title(s["name"].replace("slope_study_", "").replace("whole_process_", "whole process, "), fontsize=9)
        ax.set_xlabel("DEM compute [realization x time units]")
        ax.set_ylabel("RMS error against the ensemble's mean [d_p]")
        ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("folders", nargs="*", help="study folders (default: the four slope studies in bench/results)")
    p.add_argument("--out", default=os.path.join(HERE, "..", "docs", "equal_compute"),
                   help="writes OUT.md and OUT.png")
    args = p.parse_args()
    folders = args.folders or ["+".join(os.path.join(HERE, "results", f) for f in s.split("+")) for s in STUDIES]
    studies = [s for s in (analyse_study(f) for f in folders) if s]
    if not studies:
        raise SystemExit("equal_compute: no study with three direct run files")
    command = " ".join(["/usr/bin/python3 bench/equal_compute.py"] + (
        ["--out", os.path.relpath(args.out, os.path.join(HERE, ".."))] if args.folders else []) +
        [os.path.relpath(f, os.path.join(HERE, "..")) for f in args.folders])
    text_ = (f"# Error at equal compute: direct ensembles and CPI\n\nMade by `{command}` "
             "from the studies' runs: their reductions (NAME.json, in git) where a study keeps them, "
             "else their run files (regenerate those with the command in each study's analysis.md). "
             "Compute of a run with a reduction: its particle-steps. Method: the script's docstring.\n\n" + "\n".join(table(s) for s in studies))
    with open(args.out + ".md", "w") as f:
        f.write(text_)
    plot(studies, args.out + ".png")
    print(text_)


if __name__ == "__main__":
    main()
