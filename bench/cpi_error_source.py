#!/usr/bin/python3
"""Where does the CPI error come from? (issue 16: lifting, restriction, healing, warm-up or the
projection.) A resumable measurement on the 1,000-sphere demo bed at U_s = 0.19, R = 4, 200 time
units, burst = healing 10 + window 10, every ensemble with its own seeds.

    /usr/bin/python3 bench/cpi_error_source.py --efdem build/mpi_driver/efdem --out runs/cpi_error_source

Runs (one folder each under --out; a run whose .h5 has end_status "completed" is not repeated, so
a later session reruns the command and it continues where it stopped), most informative first:

  direct_a, direct_b     mode=direct, seeds 101, 202: the noise floor is their difference
  cpi_dt40               seed 303, DT = 40 (the issue's number)
  cpi_dt0                seed 303, DT = 0: bursts only, never a lift (the loop alone; and, since
                         it is a direct ensemble sampled in bursts, a third floor member that shares
                         cpi_dt40's initial beds: a paired comparison)
  cpi_lift_only          seed 303, DT = 0.5 (one sampling interval): a lift every burst, almost no
                         projection: the cost of lifting + healing alone
  cpi_dt40_heal20        DT = 40, healing 20
  cpi_dt40_warm40        DT = 40, warm-up 40
  direct_c               mode=direct, seed 404: a 3-way floor

--deadline HH:MM (UTC) starts no run that, by the wall times of the runs already made, would end
after it. --analyse-only skips the runs; --partial also analyses unfinished run files (up to their
last sample, marked as such; the floor and the errors then use whichever direct ensembles have a
sample at each time). Results and conclusion: docs/cpi_error_source.md. The analysis (error against the direct ensembles at the
CPI run's own sample times, its time profile, per node, per phase of the burst, the lift
diagnostics) is written as analysis.md, analysis.json and error_vs_time.png into --out.
"""
import argparse
import datetime as dt_
import json
import math
import os
import shutil
import subprocess
import sys
import warnings

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

SCENE = os.path.join(HERE, "scenes", "demo_bed.cfg")  # the demo bed without the demo's cpi block
BASE = {"gas_drag.superficial_velocity": 0.19, "run.duration": 200, "cpi.healing": 10, "cpi.window": 10,
        "ensemble.realizations_per_rank": 2}
NP = 2

# (name, mode, seed, extra overrides, what it tests); the order is the order of the runs.
RUNS = [
    ("direct_a", "direct", 101, {}, "noise floor, member 1"),
    ("direct_b", "direct", 202, {}, "noise floor, member 2"),
    ("cpi_dt40", "cpi", 303, {"cpi.dt": 40}, "the issue's DT = 40"),
    ("cpi_dt0", "cpi", 303, {"cpi.dt": 0}, "bursts only, no lift: the loop itself"),
    ("cpi_lift_only", "cpi", 303, {"cpi.dt": 0.5}, "a lift every burst, DT = one sample: lifting + healing"),
    ("cpi_dt40_heal20", "cpi", 303, {"cpi.dt": 40, "cpi.healing": 20}, "DT = 40, healing 20"),
    ("cpi_dt40_warm40", "cpi", 303, {"cpi.dt": 40, "cpi.warmup": 40}, "DT = 40, warm-up 40"),
    ("direct_c", "direct", 404, {}, "noise floor, member 3"),
]
DIRECT = [r[0] for r in RUNS if r[1] == "direct"]


def h5_path(out, name):
    return os.path.join(out, name, name + ".h5")


def completed(out, name):
    try:
        with h5py.File(h5_path(out, name), "r") as f:
            s = f.attrs.get("end_status", b"")
            s = s.decode() if isinstance(s, bytes) else str(s)
            return s.startswith("completed")
    except (OSError, KeyError):
        return False


def wall(out, name):
    with h5py.File(h5_path(out, name), "r") as f:
        return float(f.attrs["wall_seconds"]), float(f.attrs["dem_time"])


def estimate_seconds(out, mode, overrides):
    """Wall time of a run from those already made (direct: their mean; CPI: scaled by its DEM time)."""
    made = [wall(out, r[0]) for r in RUNS if r[1] == "direct" and completed(out, r[0])]
    per_unit = np.mean([w / d for w, d in made]) if made else 480.0 / 200.0
    if mode == "direct":
        return per_unit * 200
    dt = float(overrides.get("cpi.dt", 20))
    heal = float(overrides.get("cpi.healing", 10))
    warm = float(overrides.get("cpi.warmup", 10))
    burst = heal + 10
    t, micro = warm, warm
    while 200 - t >= burst - 1e-9:
        t += burst
        micro += burst
        left = 200 - t
        t += left if left <= dt else (max(0.0, left - burst) if left - dt < burst else dt)
    return per_unit * micro


def run_one(args, name, mode, seed, extra):
    if completed(args.out, name):
        print(f"  {name}: done before, skipped", flush=True)
        return True
    if args.deadline:
        est = estimate_seconds(args.out, mode, extra)
        end = dt_.datetime.now(dt_.timezone.utc) + dt_.timedelta(seconds=est)
        if end > args.deadline:
            print(f"  {name}: not started: it would take about {est / 60:.0f} min and end after the deadline "
                  f"{args.deadline:%H:%M} UTC", flush=True)
            return False
    over = {**BASE, "seed": seed, **extra}
    return sr.run_case(args.efdem, NP, SCENE, args.out, name, mode, over)


# ----------------------------------------------------------------------------------------------
# Analysis


def readable(out, name):
    """The run file to read: the file itself when complete, else (with --partial) a copy of the
    file being written, read up to its last flushed sample."""
    if completed(out, name):
        return h5_path(out, name)
    src = h5_path(out, name)
    if not os.path.exists(src):
        return None
    dst = os.path.join(out, name, name + ".partial-copy.h5")
    shutil.copyfile(src, dst)
    try:
        with h5py.File(dst, "r") as f:
            if len(f["samples/time"]) < 2:
                return None
    except (OSError, KeyError):
        return None
    return dst


def load(out, name):
    path = readable(out, name)
    with h5py.File(path, "r") as f:
        d = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
        d["t"] = f["samples/time"][:]
        d["mean"] = run_files.get(f, "samples/mean_icdf")[:]
        d["var"] = f["samples/variance"][:]
        d["icdf"] = f["samples/icdf"][:]
        if "samples/com" in f:
            d["com"] = f["samples/com"][:]
        d["p"] = f["p"][:]
        params = f["parameters"][()]
        d["params"] = params.decode() if isinstance(params, bytes) else str(params)
        if "cpi" in f:
            d["cpi"] = {k: f["cpi"][k][:] for k in f["cpi"].keys() if isinstance(f["cpi"][k], h5py.Dataset)}
    d["name"] = name
    d["partial"] = not completed(out, name)
    if d["partial"]:
        # An unfinished run: its cost is what it has spent so far.
        d.setdefault("end_status", f"incomplete (stopped or still running at t = {d['t'][-1]:g})")
        d.setdefault("wall_seconds", math.nan)
        d.setdefault("simulated_time", float(d["t"][-1]))
        d.setdefault("dem_time", math.nan)
    return d


def param(d, key, default=None):
    for line in d["params"].splitlines():
        if line.startswith(key + " = "):
            return line.split(" = ", 1)[1].split("   [")[0].strip()
    return default


def lifts(d):
    """(time the lifted state starts at, DT) of every lift the run made."""
    c = d.get("cpi")
    if not c:
        return []
    st = [s.decode() if isinstance(s, bytes) else str(s) for s in c["status"]]
    return [(float(te + dt), float(dt)) for te, dt, s in zip(c["t_end"], c["dt"], st) if s == "projected"]


def ref_value(ref, key, t):
    """ref[key] (n x m) at the sample times t; NaN where the run has no sample at t (an
    unfinished run, or a CPI run between its bursts)."""
    t = np.asarray(t, float)
    out = np.full((len(t), ref[key].shape[1]), np.nan)
    idx = np.minimum(np.searchsorted(ref["t"], t - 1e-6), len(ref["t"]) - 1)
    ok = np.abs(ref["t"][idx] - t) < 1e-6
    out[ok] = ref[key][idx[ok]]
    return out


def nanmean0(stack):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", category=RuntimeWarning)
        return np.nanmean(np.stack(stack), axis=0)


def ref_mean(directs, t):
    """The direct ensembles' means averaged over those that have a sample at t (n x m)."""
    return nanmean0([ref_value(d, "mean", t) for d in directs])


def compare(run, directs, t):
    """Squared differences at the samples t (each n x m, NaN where undefined):
    err2: the run's ensemble mean minus a direct ensemble's, averaged over the direct ensembles
          that have a sample at t (each is an independent reference: an unbiased R-ensemble
          scores, in expectation, the floor);
    emp2: the difference of two direct ensembles, averaged over the pairs present at t: the
          empirical noise floor;
    se2:  2/R times the direct ensembles' variance across realizations: the expectation of emp2
          for independent ensembles of R (defined wherever one direct ensemble is)."""
    mean = ref_value(run, "mean", t)
    R = int(run["realizations"])
    means = [ref_value(d, "mean", t) for d in directs]
    err2 = nanmean0([(mean - m) ** 2 for m in means])
    pairs = [(means[i] - means[j]) ** 2 for i in range(len(means)) for j in range(i + 1, len(means))]
    emp2 = nanmean0(pairs) if pairs else np.full_like(mean, np.nan)
    se2 = nanmean0([ref_value(d, "var", t) for d in directs]) * 2.0 / R
    return err2, emp2, se2


def summarize(err2, emp2, se2):
    """RMS error over the samples with a reference, x the spread-based floor there, and on the
    samples where two direct ensembles exist, x the empirical floor."""
    v = ~np.isnan(err2).any(axis=1)
    out = dict(samples=int(v.sum()))
    if not v.any():
        return out
    out["error"] = float(np.sqrt(np.mean(err2[v])))
    out["floor_se"] = float(np.sqrt(np.mean(se2[v])))
    out["x_floor_se"] = out["error"] / out["floor_se"]
    w = v & ~np.isnan(emp2).any(axis=1)
    out["samples_emp"] = int(w.sum())
    if w.any():
        out["error_emp_samples"] = float(np.sqrt(np.mean(err2[w])))
        out["floor_emp"] = float(np.sqrt(np.mean(emp2[w])))
        out["x_floor_emp"] = out["error_emp_samples"] / out["floor_emp"]
    return out


def burst_phase(run, t_sel):
    """Time since the start of the burst each sample belongs to (0 < phase <= burst)."""
    starts = np.asarray(run["cpi"]["t_start"], float)
    k = np.searchsorted(starts, t_sel - 1e-9) - 1
    return t_sel - starts[np.clip(k, 0, len(starts) - 1)]


def lift_diagnostics(run, directs):
    """Per lift: the error of the lifted target against the direct ensembles at the lifted time
    (what the projection delivered), of the first sample after it, at the end of healing and of
    the burst; the error of the projected increment DT*slope against the directs' increment over
    the same DT; the drift of the run away from its lifted target beyond the directs' drift over
    the same time (a lifted state that relaxes), and its share along the projected increment;
    the spread between realizations right after the lift; particles recoloured."""
    c = run["cpi"]
    heal = float(param(run, "cpi.healing", 10))
    win = float(param(run, "cpi.window", 10))
    st = [s.decode() if isinstance(s, bytes) else str(s) for s in c["status"]]
    out = []
    for k, s in enumerate(st):
        if s != "projected":
            continue
        tl = float(c["t_end"][k] + c["dt"][k])
        te = float(c["t_end"][k])
        ref_tl, ref_te = ref_mean(directs, [tl])[0], ref_mean(directs, [te])[0]
        if np.isnan(ref_tl).any() or np.isnan(ref_te).any():
            continue
        msg = c["lift_message"][k]
        row = dict(t_end=te, dt=float(c["dt"][k]), t_lift=tl, changed=float(np.mean(c["lift_changed"][k])),
                   lift_dev=float(np.nanmax(c["lift_max_deviation"][k])),
                   lift_dev_mean=float(np.nanmean(c["lift_max_deviation"][k])),
                   lift_message=msg.decode() if isinstance(msg, bytes) else str(msg),
                   repair=float(c["repair_max_adjustment"][k]),
                   refs=int(sum(not np.isnan(ref_value(d, "mean", [tl])).any() for d in directs)))
        xp, xe = c["x_projected"][k], c["x_end"][k]
        inc, inc_ref = xp - xe, ref_tl - ref_te
        row["x_end_err"] = float(np.sqrt(np.mean((xe - ref_te) ** 2)))
        row["target_err"] = float(np.sqrt(np.mean((xp - ref_tl) ** 2)))
        row["increment_err"] = float(np.sqrt(np.mean((inc - inc_ref) ** 2)))
        row["increment_rms"] = float(np.sqrt(np.mean(inc ** 2)))
        row["increment_ref_rms"] = float(np.sqrt(np.mean(inc_ref ** 2)))
        row["increment_signed"] = float(np.mean(inc - inc_ref))
        for label, dtau in (("first", 0.5), ("healed", heal), ("burst_end", heal + win)):
            tt = tl + dtau
            m_run = ref_value(run, "mean", [tt])[0]
            m_ref = ref_mean(directs, [tt])[0]
            if np.isnan(m_run).any() or np.isnan(m_ref).any():
                continue
            excess = (m_run - xp) - (m_ref - ref_tl)
            row[label + "_err"] = float(np.sqrt(np.mean((m_run - m_ref) ** 2)))
            row[label + "_drift_excess"] = float(np.sqrt(np.mean(excess ** 2)))
            row[label + "_signed_drift_excess"] = float(np.mean(excess))
            row[label + "_increment_share"] = float(np.dot(excess, inc) / max(np.dot(inc, inc), 1e-30))
            if label == "first":
                row["spread_after"] = float(np.sqrt(np.mean(ref_value(run, "var", [tt])[0])))
                row["first_excess_per_node"] = excess.tolist()
        out.append(row)
    return out


def analyse(args):
    names = [r[0] for r in RUNS if completed(args.out, r[0]) or (args.partial and readable(args.out, r[0]))]
    runs = {n: load(args.out, n) for n in names}
    directs = [runs[n] for n in DIRECT if n in runs]
    if not directs:
        print("analysis: no direct ensemble yet")
        return None
    warm_default = float(param(directs[0], "cpi.warmup", 10))
    res = dict(runs={}, floor={}, machine=machine(),
               date=f"{dt_.datetime.now(dt_.timezone.utc):%Y-%m-%d %H:%M} UTC",
               directs={d["name"]: dict(t_last=float(d["t"][-1]), partial=bool(d["partial"])) for d in directs})
    # The floor over every direct sample after warm-up.
    t_dir = np.unique(np.concatenate([d["t"] for d in directs]))
    t_all = t_dir[t_dir > warm_default + 1e-9]
    err2, emp2, se2 = compare(directs[0], directs, t_all)
    fl = summarize(emp2, emp2, se2)  # the empirical floor itself against the spread-based one
    res["floor"]["all"] = dict(samples=fl["samples"], floor_emp=fl.get("error", math.nan),
                               floor_se_at_those=fl.get("floor_se", math.nan),
                               floor_se_all=float(np.sqrt(np.mean(se2[~np.isnan(se2).any(axis=1)]))),
                               samples_se=int((~np.isnan(se2).any(axis=1)).sum()))
    res["floor"]["pairs"] = []
    for i in range(len(directs)):
        for j in range(i + 1, len(directs)):
            a, b = ref_value(directs[i], "mean", t_all), ref_value(directs[j], "mean", t_all)
            v = ~np.isnan(a - b).any(axis=1)
            if v.any():
                res["floor"]["pairs"].append((directs[i]["name"], directs[j]["name"], am.rms_error(a[v], b[v]),
                                              int(v.sum())))
    v = t_dir > warm_default
    var_all = np.concatenate([d["var"][d["t"] > warm_default] for d in directs])
    res["floor"]["spread"] = float(np.sqrt(np.mean(var_all)))
    # How realizations differ: the share of their ICDF deviation from the ensemble mean that is a
    # uniform shift in height (the same at every node: a bed-to-bed offset), and the spread of
    # their centres of mass (all particles).
    devs = np.concatenate([d["icdf"][d["t"] > warm_default] - d["mean"][d["t"] > warm_default][:, None, :]
                           for d in directs])
    shift = devs.mean(axis=2, keepdims=True)
    res["floor"]["shift_share"] = float(np.mean(shift ** 2) / np.mean(devs ** 2))
    com = [d["com"][d["t"] > warm_default] - d["com"][d["t"] > warm_default].mean(axis=1, keepdims=True)
           for d in directs if "com" in d]
    res["floor"]["com_spread"] = float(np.sqrt(np.mean(np.concatenate(com) ** 2))) if com else math.nan
    # How noisy is the floor itself? (1) The autocorrelation of a realization's deviation from its
    # ensemble mean (over all nodes and realizations): if it stays near 1 over the run, each
    # realization's offset is frozen and two ensembles differ by one draw per node, not by an
    # average over many samples. (2) The three ways of splitting each direct ensemble's four
    # realizations into two halves give pseudo-floors (RMS of the difference of the R = 2 half
    # means over sqrt 2, which has the expectation of the R = 4 floor): their range is the
    # draw-to-draw spread of a floor measured from one pair of ensembles.
    acf, splits = {}, []
    for d in directs:
        sel = d["t"] > warm_default
        x = d["icdf"][sel]
        if x.shape[1] < 4 or len(x) < 40:
            continue
        dev = x - x.mean(axis=1, keepdims=True)
        n = len(x)
        for lag_t in (10, 20, 40, 80, 120, 160):
            lag = int(round(lag_t / 0.5))
            if lag < n - 20:
                acf.setdefault(lag_t, []).append(float((dev[:n - lag] * dev[lag:]).mean() / (dev * dev).mean()))
        for a_, b_ in (([0, 1], [2, 3]), ([0, 2], [1, 3]), ([0, 3], [1, 2])):
            diff = x[:, a_].mean(axis=1) - x[:, b_].mean(axis=1)
            splits.append((d["name"], float(np.sqrt(np.mean(diff ** 2)) / math.sqrt(2)), float(d["t"][sel][-1])))
    res["floor"]["deviation_acf"] = {str(k): float(np.mean(v)) for k, v in acf.items()}
    res["floor"]["split_floors"] = splits
    # Forward Euler's truncation error on the direct ensembles' smoothed trajectory: a quadratic
    # x(t) = a + b t + c t^2 fitted per node to their pooled mean after warm-up; a jump DT from a
    # least-squares slope over the window W ending at t_end misses x(t_end + DT) by
    # -c DT (DT + W), whatever t_end: the deterministic part of the projection error.
    tm = t_all[~np.isnan(ref_mean(directs, t_all)).any(axis=1)]
    xm = ref_mean(directs, tm)
    coef = np.polyfit(tm, xm, 2)  # 3 x m, highest power first
    c2 = coef[0]
    win = float(param(directs[0], "cpi.window", 10))
    res["floor"]["truncation"] = {str(dtp): float(np.sqrt(np.mean((c2 * dtp * (dtp + win)) ** 2)))
                                  for dtp in (20, 40, 80, 160)}
    res["floor"]["truncation_fit_until"] = float(tm[-1])
    se_t = np.sqrt(np.nanmean(se2, axis=1))
    profiles = {"floor: sqrt(2 var/R) of the direct ensembles": (t_all, se_t)}
    if len(directs) > 1:
        profiles["floor: direct pairs"] = (t_all, np.sqrt(np.nanmean(emp2, axis=1)))
    node_profiles, budget_profiles = {}, {}
    for n in names:
        d = runs[n]
        spec = next(r for r in RUNS if r[0] == n)
        row = dict(what=spec[4] + (f" [{d['end_status']}]" if d["partial"] else ""), mode=d["mode"],
                   seed=int(d["seed"]), wall=float(d["wall_seconds"]), dem_time=float(d["dem_time"]),
                   simulated=float(d["simulated_time"]),
                   speedup=float(d["simulated_time"]) / float(d["dem_time"]) if d["dem_time"] > 0 else math.nan,
                   t_last=float(d["t"][-1]), partial=bool(d["partial"]))
        warm = float(param(d, "cpi.warmup", warm_default))
        t_run = d["t"][d["t"] > warm + 1e-9]
        if d["mode"] == "direct":
            others = [x for x in directs if x["name"] != n]
            if others:
                row["after_warmup"] = summarize(*compare(d, others, t_run))
            res["runs"][n] = row
            continue
        lf = lifts(d)
        first_lift = lf[0][0] if lf else math.inf
        row["lifts_made"] = len(lf)
        sets = {"after_warmup": t_run, "before_first_lift": t_run[t_run < first_lift - 1e-9],
                "after_first_lift": t_run[t_run >= first_lift - 1e-9]}
        for label, t_sel in sets.items():
            if len(t_sel) == 0:
                continue
            e2, m2, s2 = compare(d, directs, t_sel)
            row[label] = summarize(e2, m2, s2)
            if label == "after_warmup":
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", category=RuntimeWarning)
                    profiles[n] = (t_sel, np.sqrt(np.nanmean(e2, axis=1)))
                    node_profiles[n] = np.sqrt(np.nanmean(e2, axis=0) / np.nanmean(s2, axis=0))
                    row["per_node_x_floor_se"] = node_profiles[n].tolist()
                    bias = ref_value(d, "mean", t_sel) - ref_mean(directs, t_sel)
                    row["bias_per_node"] = np.nanmean(bias, axis=0).tolist()
                    row["bias_samples"] = int((~np.isnan(bias).any(axis=1)).sum())
        if lf and len(sets["after_first_lift"]):
            t_sel = sets["after_first_lift"]
            phase = burst_phase(d, t_sel)
            heal = float(param(d, "cpi.healing", 10))
            e2, m2, s2 = compare(d, directs, t_sel)
            row["by_phase"] = []
            for lo, hi in [(0, 2), (2, 5), (5, heal), (heal, heal + 10)]:
                m = (phase > lo + 1e-9) & (phase <= hi + 1e-9) & ~np.isnan(e2).any(axis=1)
                if m.any():
                    row["by_phase"].append(dict(lo=lo, hi=hi, samples=int(m.sum()),
                                                error=float(np.sqrt(np.mean(e2[m]))),
                                                floor_se=float(np.sqrt(np.mean(s2[m])))))
            row["lifts"] = lift_diagnostics(d, directs)
            idx = np.searchsorted(d["t"], t_sel - 1e-6)
            row["spread_after_lifts"] = float(np.sqrt(np.mean(d["var"][idx])))
            row["spread_directs_there"] = float(np.sqrt(np.nanmean(nanmean0(
                [ref_value(x, "var", t_sel) for x in directs]))))
        # The projection-noise budget: if the error were the floor plus the noise of the jumps'
        # slopes (DT times the slope's standard error from the members' own slopes, accumulated
        # over the jumps made so far, offsets never relaxing), err^2(t) = se2(t) + sum_k (DT_k s_k)^2.
        c = d.get("cpi")
        if lf and c is not None and "slope_standard_error" in c:
            st = [x.decode() if isinstance(x, bytes) else str(x) for x in c["status"]]
            jumps = [(float(c["t_end"][k] + c["dt"][k]), float(c["dt"][k]) * np.asarray(c["slope_standard_error"][k]))
                     for k in range(len(st)) if st[k] == "projected"]
            t_sel = sets["after_warmup"]
            e2, _, s2 = compare(d, directs, t_sel)
            acc = np.zeros_like(s2)
            for tl, v in jumps:
                acc[t_sel >= tl - 1e-9] += v ** 2
            ok = ~np.isnan(e2).any(axis=1)
            for label, m in (("after_warmup", ok), ("after_first_lift", ok & (t_sel >= first_lift - 1e-9))):
                if m.any():
                    pred = float(np.sqrt(np.mean((s2 + acc)[m])))
                    row.setdefault("budget", {})[label] = dict(
                        samples=int(m.sum()), measured=float(np.sqrt(np.mean(e2[m]))), predicted=pred,
                        projection_part=float(np.sqrt(np.mean(acc[m]))), floor_part=float(np.sqrt(np.mean(s2[m]))))
            budget_profiles[n] = (t_sel, np.sqrt(np.nanmean(s2 + acc, axis=1)))
            row["jump_noise"] = [dict(t_lift=tl, dt_se_rms=float(np.sqrt(np.mean(v ** 2)))) for tl, v in jumps]
        # Paired with cpi_dt0 (same seed 303, same initial beds, never lifted): what the lifts
        # changed, without the seed-to-seed noise until the trajectories decorrelate.
        if n != "cpi_dt0" and "cpi_dt0" in runs and lf:
            e2, _, _ = compare(d, [runs["cpi_dt0"]], sets["after_first_lift"])
            v = ~np.isnan(e2).any(axis=1)
            if v.any():
                row["paired_vs_dt0"] = dict(error=float(np.sqrt(np.mean(e2[v]))), samples=int(v.sum()))
        res["runs"][n] = row
    plot(args, runs, profiles, node_profiles, budget_profiles)
    with open(os.path.join(args.out, "analysis.json"), "w") as f:
        json.dump(res, f, indent=1, default=float)
    write_md(args, res)
    return res


def machine():
    try:
        for line in subprocess.run(["lscpu"], capture_output=True, text=True).stdout.splitlines():
            if line.startswith("Model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "?"


def smooth(y, k=5):
    """Running mean over k samples, NaN-aware and without edge bias."""
    y = np.asarray(y, float)
    ok = ~np.isnan(y)
    w = np.ones(k)
    num = np.convolve(np.where(ok, y, 0.0), w, mode="same")
    den = np.convolve(ok.astype(float), w, mode="same")
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(ok, num / den, np.nan)


def plot(args, runs, profiles, node_profiles, budget_profiles):
    fig, axes = plt.subplots(2, 1, figsize=(10, 8.5), dpi=80, gridspec_kw=dict(height_ratios=[3, 2]))
    ax = axes[0]
    for i, (n, (t, e)) in enumerate(profiles.items()):
        if n.startswith("floor"):
            ax.plot(t, smooth(e, 9), color="k" if "pairs" in n else "grey", lw=1.5, alpha=0.6,
                    ls="-" if "pairs" in n else "--", label=f"{n} (4.5-unit running mean)")
            continue
        col = f"C{i}"
        # CPI samples only in bursts: plot burst by burst, no line across the jumps.
        gaps = np.where(np.diff(t) > 0.75)[0] + 1
        for j, (tt, ee) in enumerate(zip(np.split(t, gaps), np.split(e, gaps))):
            ax.plot(tt, ee, color=col, lw=1, marker=".", ms=2, label=n if j == 0 else None)
        if n in budget_profiles:
            tb, eb = budget_profiles[n]
            for j, (tt, ee) in enumerate(zip(np.split(tb, np.where(np.diff(tb) > 0.75)[0] + 1),
                                             np.split(eb, np.where(np.diff(tb) > 0.75)[0] + 1))):
                ax.plot(tt, ee, color=col, lw=1, ls="--",
                        label=f"{n}: predicted, floor + accumulated DT x slope s.e." if j == 0 else None)
        if n == "cpi_dt40":
            for tl, _ in lifts(runs[n]):
                ax.axvline(tl, color=col, ls=":", lw=0.8)
    ax.set_ylabel("RMS over nodes: mean ICDF - direct [$d_p$]")
    ax.set_xlabel(r"t [$\sqrt{d_p/g}$]  (dotted: the lifts of cpi_dt40)")
    ax.set_title("CPI error against the direct ensembles (demo bed, U_s = 0.19, R = 4, independent seeds)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    ax = axes[1]
    p = runs[next(iter(runs))]["p"]
    for n, v in node_profiles.items():
        ax.plot(p, v, marker="o", ms=3, color=f"C{list(profiles).index(n)}", label=n)
    ax.axhline(1, color="grey", lw=1)
    ax.set_xlabel("p (ICDF node), samples after warm-up")
    ax.set_ylabel("error / floor sqrt(2 var/R), per node")
    ax.grid(alpha=0.3)
    if node_profiles:
        ax.legend(fontsize=7, ncol=3)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "error_vs_time.png"))
    plt.close(fig)


def fmt(x, spec=".3f"):
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def write_md(args, res):
    fl = res["floor"]
    lines = [f"Direct ensembles: " + ", ".join(f"{k} (to t = {v['t_last']:g}{', unfinished' if v['partial'] else ''})"
                                              for k, v in res["directs"].items()),
             f"Floor, empirical (direct pairs, {fl['all']['samples']} samples after warm-up): "
             f"{fmt(fl['all']['floor_emp'])} d_p; spread-based sqrt(2 var/R) at those samples "
             f"{fmt(fl['all']['floor_se_at_those'])}, over all {fl['all']['samples_se']} direct samples "
             f"{fmt(fl['all']['floor_se_all'])}. Pairs: " +
             ", ".join(f"{a}-{b} {e:.3f} ({n} samples)" for a, b, e, n in fl["pairs"]),
             f"Spread between realizations {fl['spread']:.3f} d_p; share of it that is a uniform height shift "
             f"{fl['shift_share']:.2f}; spread of the realizations' centres of mass {fl['com_spread']:.3f} d_p.",
             "Autocorrelation of a realization's deviation from its ensemble mean at lag: " +
             ", ".join(f"{k}: {v:.2f}" for k, v in fl["deviation_acf"].items()),
             f"Forward-Euler truncation per jump on the direct ensembles' quadratic trend (fit to t = "
             f"{fl['truncation_fit_until']:g}, RMS over nodes): " +
             ", ".join(f"DT = {k}: {v:.3f}" for k, v in fl["truncation"].items()) + " d_p",
             "Pseudo-floors from the three half-splits of each direct ensemble (expectation: the R = 4 floor): " +
             ", ".join(f"{n} {v:.3f} (to t = {tl:g})" for n, v, tl in fl["split_floors"]), "",
             "| run | what | samples | error [d_p] | floor sqrt(2var/R) | x floor | samples with 2 directs: n, error, "
             "empirical floor, x floor | before first lift: n, error, x floor | after first lift: n, error, x floor "
             "| DEM-time speed-up |", "|---|" + "---|" * 9]
    for n, r in res["runs"].items():
        a = r.get("after_warmup", {})
        emp = (f"{a['samples_emp']}, {fmt(a.get('error_emp_samples'))}, {fmt(a.get('floor_emp'))}, "
               f"{fmt(a.get('x_floor_emp'), '.2f')}") if a.get("samples_emp") else "-"
        cells = []
        for key in ("before_first_lift", "after_first_lift"):
            b = r.get(key)
            cells.append(f"{b['samples']}, {fmt(b.get('error'))}, {fmt(b.get('x_floor_se'), '.2f')}"
                         if b and b.get("samples") else "-")
        lines.append(f"| {n} | {r['what']} | {a.get('samples', 0)} | {fmt(a.get('error'))} | {fmt(a.get('floor_se'))} "
                     f"| {fmt(a.get('x_floor_se'), '.2f')} | {emp} | {cells[0]} | {cells[1]} | "
                     f"{fmt(r['speedup'], '.2f')} |")
    for n, r in res["runs"].items():
        if "by_phase" not in r:
            continue
        lines += ["", f"**{n}** ({r['lifts_made']} lifts)", ""]
        lines.append("By phase of the burst (time since the burst began; samples after the first lift): " +
                     "; ".join(f"({b['lo']:g}, {b['hi']:g}]: n = {b['samples']}, error {b['error']:.3f}, "
                               f"x{b['error'] / b['floor_se']:.2f}" for b in r["by_phase"]))
        if "paired_vs_dt0" in r:
            lines.append(f"Against cpi_dt0 (the same seed, never lifted), after the first lift: "
                         f"{r['paired_vs_dt0']['error']:.3f} d_p over {r['paired_vs_dt0']['samples']} samples.")
        lines.append(f"Mean bias per node (run - directs, d_p, p = 0.05 ... 0.95; {r.get('bias_samples')} samples): " +
                     " ".join(f"{b:+.2f}" for b in r["bias_per_node"]))
        for label, b in r.get("budget", {}).items():
            lines.append(f"Projection-noise budget ({label}, {b['samples']} samples): measured {b['measured']:.3f} d_p, "
                         f"predicted sqrt(floor^2 + sum (DT s.e.)^2) = {b['predicted']:.3f} (floor part "
                         f"{b['floor_part']:.3f}, accumulated jump noise {b['projection_part']:.3f}): "
                         f"measured/predicted {b['measured'] / b['predicted']:.2f}")
        if r.get("jump_noise"):
            lines.append("Noise of each jump, DT x slope s.e. (RMS over nodes): " +
                         ", ".join(f"t = {j['t_lift']:g}: {j['dt_se_rms']:.3f}" for j in r["jump_noise"]))
        lines.append("Error / floor per node: " + " ".join(f"{b:.1f}" for b in r["per_node_x_floor_se"]))
        lines.append(f"Spread between realizations in the samples after lifts {r['spread_after_lifts']:.3f} d_p "
                     f"(direct ensembles at those times {r['spread_directs_there']:.3f}).")
        lines += ["", "| t_lift | DT | refs | recoloured per realization | lift: max deviation (max, mean) | "
                  "x_end err | increment err (rms DT slope, rms direct) | target err | err 0.5 after | "
                  "err end of healing | err end of burst | drift excess 0.5, healed, end | share of the increment "
                  "0.5, healed, end | spread 0.5 after |", "|---|" + "---|" * 13]
        for L in r["lifts"]:
            g = L.get
            lines.append(f"| {L['t_lift']:g} | {L['dt']:g} | {L['refs']} | {L['changed']:.0f} | "
                         f"{L['lift_dev']:.3f}, {L['lift_dev_mean']:.3f} | {L['x_end_err']:.3f} | "
                         f"{L['increment_err']:.3f} ({L['increment_rms']:.3f}, {L['increment_ref_rms']:.3f}) | "
                         f"{L['target_err']:.3f} | {fmt(g('first_err'))} | {fmt(g('healed_err'))} | "
                         f"{fmt(g('burst_end_err'))} | {fmt(g('first_drift_excess'))}, {fmt(g('healed_drift_excess'))}, "
                         f"{fmt(g('burst_end_drift_excess'))} | {fmt(g('first_increment_share'), '+.2f')}, "
                         f"{fmt(g('healed_increment_share'), '+.2f')}, {fmt(g('burst_end_increment_share'), '+.2f')} | "
                         f"{fmt(g('spread_after'))} |")
    with open(os.path.join(args.out, "analysis.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--efdem", default=os.path.join(HERE, "..", "build", "mpi_driver", "efdem"))
    ap.add_argument("--out", default=os.path.join(HERE, "..", "runs", "cpi_error_source"))
    ap.add_argument("--only", nargs="*", help="run only these (the analysis uses every completed run)")
    ap.add_argument("--deadline", help="HH:MM UTC: start no run that would end after it")
    ap.add_argument("--analyse-only", action="store_true")
    ap.add_argument("--runs-only", action="store_true")
    ap.add_argument("--partial", action="store_true",
                    help="also analyse unfinished run files (up to their last sample), marked as such")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    if args.deadline:
        now = dt_.datetime.now(dt_.timezone.utc)
        hh, mm = map(int, args.deadline.split(":"))
        args.deadline = now.replace(hour=hh, minute=mm, second=0, microsecond=0)
        if args.deadline < now - dt_.timedelta(hours=12):
            args.deadline += dt_.timedelta(days=1)
    if not args.analyse_only:
        args.efdem = os.path.abspath(args.efdem)
        for name, mode, seed, extra, _ in RUNS:
            if args.only and name not in args.only:
                continue
            run_one(args, name, mode, seed, extra)
    if not args.runs_only:
        analyse(args)


if __name__ == "__main__":
    main()
