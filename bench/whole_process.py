#!/usr/bin/python3
"""The whole demixing (issue 34, item 4): direct ensembles and CPI runs over the whole process,
until the realizations have stopped demixing (U_s = 0.19) or the bed has reached its statistically
steady state (0.41). One folder per case under bench/results/whole_process/<case>/, one result
file per run (the kept groups of its run file, bench/study_runs.py; not committed) and its
reduction (<run>.json: what the analysis reads, committed, so that a study continues on another
machine), skipped when either is there; an interrupted run continues from its newest checkpoint.

    /usr/bin/python3 bench/whole_process.py --efdem build/mpi_driver/efdem                 # every case
    /usr/bin/python3 bench/whole_process.py --case demo_u0.19_r4 --only direct_a direct_b   # a part
    /usr/bin/python3 bench/whole_process.py --analyse-only

Each case has three direct ensembles with their own seeds (101, 202, 303: the noise floor from three
pairs) and the CPI runs of its CPI list (seed 404 unless a run says otherwise, paired with each
other). "Stopped demixing": from a run's /samples/at_rest where it has it (every particle still at
the end of 4 sample intervals in a row), else as in bench/stop_times.py (the light ICDF never moves
again by more than 1e-6 d_p). Until a case's own direct runs are there, the shorter runs of the
same seeds from an earlier study (EARLIER) stand in, and the comparison covers their span.

Cost (AMD EPYC, 2 cores, R = 4): a demo-bed direct run of 1,000 units 20 min on an idle machine
(50-90 min shared), a CPI run 10-50 min; a tall-bed direct run of 600 units at R = 8 65 min
(2026-12-05, with builds beside it). The tall bed's R = 4 cases take their directs from the R = 8 ones (DIRECTS_FROM): run
`--case tall_u0.41_r8 --only direct_a direct_b direct_c` for both.
"""
import argparse
import json
import math
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import stop_times as st  # noqa: E402
import study_runs as sr  # noqa: E402

MEDIAN = 9  # the node p = 0.5 of the 19-node grid

RESULTS = os.path.join(HERE, "results", "whole_process")
DIRECT = (("direct_a", 101), ("direct_b", 202), ("direct_c", 303))
# The CPI runs: adaptive with the per-jump tolerance of the 600-unit studies (0.16 d_p, bursts
# 10 + 10: about 2x in DEM time there), realizations at rest held (cpi.at_rest = hold, the default)
# and the run ended at the end state (cpi.finish = steady). cpi.accuracy = 1.5 over 1,000 units
# leaves each jump 0.008-0.03 d_p (the budget spread over the horizon): 8 of the first 9 coarse
# steps of such a run were direct bursts (2026-12-04), so it is not a CPI run of this study.
ADAPTIVE = {"cpi.projection": "adaptive", "cpi.tolerance": 0.16, "cpi.healing": 10, "cpi.window": 10,
            "cpi.finish": "steady"}
# members, relabelling where the beds move: the lift of most runs below
MOVING = {**ADAPTIVE, "cpi.lift": "members", "cpi.relabel": "moving"}
# The tall bed's slow-demixing schedule (docs/accuracy_vs_cost.md, issue 33 and "R = 8 over 600
# units"): rank coordinates, healing 2 + window 18, a per-jump tolerance twice the demo bed's.
H2W18 = {"cpi.tolerance": 0.32, "cpi.observable": "ranks", "cpi.healing": 2, "cpi.window": 18}
# ... with the members lifted apart and lights relabelled where lights are (keep_clusters)
KEEP_H2W18 = {**ADAPTIVE, "cpi.lift": "members", "cpi.relabel": "keep_clusters", **H2W18}
SLOW = {
    "members_hold": {**ADAPTIVE, "cpi.lift": "members"},  # each realization kept apart
    "mean_hold": {**ADAPTIVE, "cpi.lift": "mean"},  # the paper's lift, those at rest held
    # members_hold, relabelling where the beds move (no realization came to rest under CPI with
    # every candidate alike: the lifts kick beds that are about to stop, bench/lift_restart.py)
    "members_moving": MOVING,
    # the same with another seed: one draw does not set a default
    "members_moving_s505": {**MOVING, "seed": 505},
    # members_moving in rank coordinates (cpi.observable = ranks: a lift the realizations' own beds
    # can meet; at U_s = 0.41 it removed most of the ICDF lift's error, 2026-12-05)
    "ranks_moving": {**MOVING, "cpi.observable": "ranks"},
    # each realization by its own slope, relabelling where it moves: a bed slowing to rest has a
    # slope near zero, so its lifts change few labels (the kicks that keep CPI beds moving)
    "own_moving": {**ADAPTIVE, "cpi.lift": "own", "cpi.relabel": "moving"},
    # members_moving whose jumps end at t = 250, before the first direct realization stopped
    # (t = 277): no CPI realization stops while it is lifted (2026-12-05), so the run goes on
    # directly from there and the beds come to rest as in a direct run (cpi.jump_until)
    "moving_until250": {**MOVING, "cpi.jump_until": 250},
    # the same with another seed, and with the jumps ended later (the bias against T)
    "moving_until250_s505": {**MOVING, "cpi.jump_until": 250, "seed": 505},
    "moving_until400": {**MOVING, "cpi.jump_until": 400},
    # the tall bed's recipe (examples/tall_bed/scene_u019.cfg: rank coordinates, members lifted
    # apart, lights relabelled where lights are, bursts 2 + 18) at the demo bed's tolerance: whether
    # the lift that kept the tall bed's pace also lets this bed's realizations stop as direct ones do
    "ranks_keep_h2w18": {**KEEP_H2W18, "cpi.tolerance": 0.16},
}
# The tall bed (3,120 spheres, the paper's height at a quarter of its area; bench/scenes/tall_bed.cfg):
# its floor is about three times the demo bed's in d_p (docs/accuracy_vs_cost.md, "The tall bed"), so
# the per-jump tolerances are twice the demo bed's and the accuracy key (one value for every bed,
# issue 34 item 1) runs beside them. U_s = 0.41: rank coordinates (the lift a segregated bed can
# meet, 1.8-2.4x the floor at the demo bed's steady state) and bursts 2 + 20 (the waves' window).


def with_accuracy(keys, a):
    """KEYS with the whole trajectory's accuracy a (cpi.accuracy) instead of a per-jump tolerance."""
    return {**{k: v for k, v in keys.items() if k != "cpi.tolerance"}, "cpi.accuracy": a}


TALL_SLOW = {
    "members_moving": {**MOVING, "cpi.tolerance": 0.32},
    "ranks_moving": {**MOVING, "cpi.tolerance": 0.32, "cpi.observable": "ranks"},
    # Over 400 units at R = 4 the tolerance 0.32 was spent on the slope's noise (89 % of the
    # budget, mean DT 38 for 2.35x; docs/accuracy_vs_cost.md "The tall bed"): the slope pooled over
    # the last 4 bursts (cpi.slope = pooled, issue 33), toward the 5x a mean DT of 80 would give
    "members_pooled": {**MOVING, "cpi.tolerance": 0.32, "cpi.slope": "pooled"},
    # the two levers the demo bed measured at U_s = 0.19 (docs/accuracy_vs_cost.md, issue 33 and
    # "R = 8 over 600 units"): healing 2 + window 18 (the same burst, the slope's error 0.74x: no
    # post-lift transient found there) and rank coordinates (longer jumps, fewer rejections)
    "ranks_h2w18": {**MOVING, **H2W18},
    # the same with the whole trajectory's accuracy instead of a per-jump tolerance (issue 34 item
    # 1): a = 1.5 allows sqrt(1 + a^2 / 2) = 1.46 floors, where bench/walk_budget.py's noise model
    # of this bed (R = 4, 400 units) expects 1.37 floors at 4.4x (docs/error_control.md §7)
    "ranks_accuracy_h2w18": with_accuracy({**MOVING, **H2W18}, 1.5),
    # ranks_h2w18 with the window's increment for its slope (cpi.slope_fit = increment): this bed's
    # noise is a walk with no fast part (bench/walk_budget.py), where the increment has 1/1.2 of
    # least squares' variance and what a jump of 80 adds beyond a direct ensemble falls to 0.86 of
    # least squares' (docs/error_control.md §7)
    "ranks_inc_h2w18": {**MOVING, **H2W18, "cpi.slope_fit": "increment"},
    # ranks_h2w18 whose jumps add the curvature pooled over the last four bursts' slopes
    # (cpi.curvature = pooled): its jumps 3-6 were charged no truncation (each within its noise)
    # while all undershot the accelerating demixing, 0.28 d_p in the median together, about one
    # floor (docs/accuracy_vs_cost.md, the tall bed against two directs)
    "ranks_curv_h2w18": {**MOVING, **H2W18, "cpi.curvature": "pooled"},
    # The bursts after ranks_h2w18's and ranks_curv_h2w18's lifts moved the middle of the light ICDF
    # at 0.4-0.8 of the directs' pace over the same 15 units, less as the lifts grew (800-2,000
    # labels): the lift, not truncation, sets the late lag. At U_s = 0.41 keep_clusters (lights
    # added where lights are, lone ones taken first) kept the lifted beds' pace
    "ranks_keep_h2w18": {**KEEP_H2W18},
    # the same with another seed: at R = 4 it came within 1.27 floors at 3.03x, its end state
    # -0.1 s.e. off (2026-12-07); one draw does not set a default
    "ranks_keep_h2w18_s505": {**KEEP_H2W18, "seed": 505},
    # ranks_keep_h2w18 with the bursts' pooled curvature added to every jump: with relabel = moving
    # the lifted beds' pace hid what the curvature adds (ranks_curv_h2w18); keep_clusters keeps
    # the pace, and its error still grew late (1.52 floors in the last quarter), where the replay
    # of the jumps on the directs' mean put forward Euler's undershoot at about one floor
    "ranks_keep_curv_h2w18": {**KEEP_H2W18, "cpi.curvature": "pooled"},
    # the same with another seed: at R = 8 it came within 1.07 floors at 2.75x, the late quarters'
    # growth of keep_clusters alone gone (seed 404, 2026-12-07); one draw does not set a default
    "ranks_keep_curv_h2w18_s505": {**KEEP_H2W18, "cpi.curvature": "pooled", "seed": 505},
    # ranks_keep_h2w18 with the window's increment for its slope (ranks_inc_h2w18's lever, never
    # run on a bed): the slope nearest the bound of docs/error_control.md §7, 1/1.2 of least
    # squares' variance on a walk, once the lift no longer slows the beds
    "ranks_keep_inc_h2w18": {**KEEP_H2W18, "cpi.slope_fit": "increment"},
    # ranks_keep_h2w18 with the whole trajectory's accuracy instead of the per-jump tolerance (one
    # value for every bed, issue 34 item 1): with the lifts no longer slowing the beds, whether
    # a = 1.5 (1.46 floors stated) finds the jumps the hand-set 0.32 d_p did
    "ranks_keep_acc_h2w18": with_accuracy(KEEP_H2W18, 1.5),
    # ranks_keep_inc_h2w18 charged every jump's truncation 0 (each curvature after a jump within its
    # noise) and its jumps grew to 106 across the accelerating middle, 1.51 floors: the same with
    # the hidden truncation charged from the line through the pooled bursts' slopes
    # (cpi.noisy_curvature = pooled, docs/error_control.md §3)
    "ranks_keep_inc_noisy_h2w18": {**KEEP_H2W18, "cpi.slope_fit": "increment",
                                   "cpi.noisy_curvature": "pooled"},
}
WAVES = {"cpi.projection": "adaptive", "cpi.healing": 2, "cpi.window": 20, "cpi.finish": "steady",
         "cpi.observable": "ranks"}
TALL_WAVES = {
    "ranks_tol": {**WAVES, "cpi.tolerance": 0.64},
    # ranks_tol again after the colour lift's count plan changed (the nearest feasible counts,
    # 2026-12-06): ranks_tol's lifts mixed the segregating bed (every node low, the lag of its
    # middle quarters); same keys, the efdem version is the difference
    "ranks_tol_counts": {**WAVES, "cpi.tolerance": 0.64},
    "ranks_accuracy": {**WAVES, "cpi.accuracy": 1.5},
    # ranks_tol_counts whose relabelled particles take their new species' mean vertical velocity:
    # in the bursts after ranks_tol_counts' lifts (t = 100-320) the lower light nodes rose 0.03 d_p
    # per unit slower than the directs' over the first 5 units, 0.011 slower after (of 0.07; two
    # directs differ by 0.005): a relabelled particle keeps its old species' drift
    # (bench/lift_velocity.py)
    "ranks_velocity": {**WAVES, "cpi.tolerance": 0.64, "cpi.relabel_velocity": "species"},
    # ranks_velocity's slope deficit stayed (-0.025 d_p per unit over the first 5 units after a
    # lift, -0.013 after): ranks_tol_counts with 8 units of healing, so that the slope is fitted
    # after most of it (the burst 8 + 20)
    "ranks_heal8": {**WAVES, "cpi.tolerance": 0.64, "cpi.healing": 8},
    # the lights of a direct bed gather with lights (bench/results/lift_clusters.md) and a random
    # relabelling puts new lights among heavies, alone: ranks_tol_counts with the lift adding
    # lights where lights are and taking away the lone ones
    "ranks_clustered": {**WAVES, "cpi.tolerance": 0.64, "cpi.relabel": "clustered"},
    # clustered overshot (2.13 floors, the lower nodes 2 d_p ahead at t = 300: the lifted beds
    # more clustered than the direct ones); the new lights with the lights' own neighbourhoods
    "ranks_like": {**WAVES, "cpi.tolerance": 0.64, "cpi.relabel": "like_lights"},
    # ranks_like's first bursts after a lift were as slow as the random relabelling's: a jump's
    # lifts mostly remove lights from the lower bed, and like_lights removes them at random;
    # keep_clusters removes the lone lights first (bench/results/lift_clusters.md section 4)
    "ranks_keep": {**WAVES, "cpi.tolerance": 0.64, "cpi.relabel": "keep_clusters"},
    # ranks_keep came within 1.26 floors, but half its jumps were rejected on the lift error
    # (0.3-0.45 d_p at DT = 19-22: the projected ranks asked for more lights than particles in the
    # pure-light top, and the lift moved them to neighbouring intervals). The same with the rank
    # repair that keeps every interval's lights within its particles (rank_observable.hpp, from
    # the commit after 49ff997 on), then with another seed (one draw does not set a default)
    "ranks_keep_fill": {**WAVES, "cpi.tolerance": 0.64, "cpi.relabel": "keep_clusters"},
    "ranks_keep_s505": {**WAVES, "cpi.tolerance": 0.64, "cpi.relabel": "keep_clusters", "seed": 505},
    # Both repaired runs' jumps were limited by the tolerance on the curvature (truncation 0.35-0.47
    # d_p of the 0.64, the slope's noise 0.10-0.13, the lift's miss 0.01-0.03; ranks_keep_s505's
    # controller record): docs/error_control.md says a second-order projection is what helps there.
    # ranks_keep_fill with projective Adams-Bashforth 2 (paired with it: seed 404)
    "ranks_keep_ab2": {**WAVES, "cpi.tolerance": 0.64, "cpi.relabel": "keep_clusters",
                       "cpi.integrator": "adams_bashforth2"},
    # ranks_keep_ab2 kept the error (1.32 floors) but its jumps stayed short (1.59x): AB2's
    # truncation is judged from a noisier divided difference. ranks_keep_fill whose jumps add the
    # curvature pooled over the last bursts' slopes (cpi.curvature = pooled, the lever that took
    # the late growth out of the tall bed at U_s = 0.19): forward Euler's nodes, the knee's
    # curvature added instead of charged
    "ranks_keep_curv": {**WAVES, "cpi.tolerance": 0.64, "cpi.relabel": "keep_clusters",
                        "cpi.curvature": "pooled"},
}
# case: scene, U_s, duration, R, the CPI runs (name: keys beyond the case's own). The R = 4 cases of
# the tall bed run no direct ensembles of their own: each R = 8 direct ensemble of the same bed and
# U_s is two independent R = 4 ones (realization r's seed depends on the run's seed and r only, not on
# R: whole_process direct_a's realizations 0 and 1 stop at the same times as the R = 8 study's), so
# three R = 8 directs give three floors' worth of pairs at R = 8 and six R = 4 ensembles (DIRECTS_FROM).
CASES = {
    "demo_u0.19_r4": ("demo_bed.cfg", 0.19, 1000.0, 4, SLOW),
    "tall_u0.41_r4": ("tall_bed.cfg", 0.41, 600.0, 4, TALL_WAVES),
    "tall_u0.19_r4": ("tall_bed.cfg", 0.19, 600.0, 4, TALL_SLOW),
    "tall_u0.41_r8": ("tall_bed.cfg", 0.41, 600.0, 8, TALL_WAVES),
    "tall_u0.19_r8": ("tall_bed.cfg", 0.19, 600.0, 8, TALL_SLOW),
}
DIRECTS_FROM = {"tall_u0.41_r4": "tall_u0.41_r8", "tall_u0.19_r4": "tall_u0.19_r8"}
EARLIER = {"demo_u0.19_r4": "slope_study_r4_u0.19_t600"}


def runs_of(case):
    """name -> (mode, overrides) of every run of CASE, directs first (none for a case whose directs
    are the halves of another's, DIRECTS_FROM)."""
    scene, us, duration, realizations, cpi = CASES[case]
    base = {"gas_drag.superficial_velocity": us, "run.duration": duration, "cpi.warmup": 10,
            "ensemble.realizations_per_rank": realizations // 2}
    out = {} if case in DIRECTS_FROM else {name: ("direct", {**base, "seed": seed}) for name, seed in DIRECT}
    out.update({name: ("cpi", {**base, "seed": 404, **extra}) for name, extra in cpi.items()})
    return out


def halves(run, realizations):
    """The two independent ensembles of REALIZATIONS in a direct run of twice as many: realizations
    0..R-1 and R..2R-1, each with its own mean (every realization of a direct run is used)."""
    out = []
    for k in range(2):
        sel = slice(k * realizations, (k + 1) * realizations)
        h = dict(run, icdf=run["icdf"][:, sel, :], mean=run["icdf"][:, sel, :].mean(axis=1),
                 stops=run["stops"][sel], quiet=run["quiet"][sel])
        h["particle_steps"] = float("nan")  # the run's are not split by realization
        out.append(h)
    return out


def make(args, case):
    make_runs(args.efdem, os.path.join(HERE, "scenes", CASES[case][0]), runs_of(case),
              os.path.join(args.results, case), os.path.join(args.out, case), args.only, case)


def make_runs(efdem, scene, runs, results, work, only=None, label=""):
    """Each run of RUNS (name -> (mode, overrides)) not in ONLY's exclusion whose reduction is not
    in RESULTS yet: made (or continued) in WORK, archived and reduced into RESULTS."""
    for name, (mode, overrides) in runs.items():
        if only and name not in only:
            continue
        if os.path.exists(os.path.join(results, name + ".json")):
            print(f"  {label}/{name}: done before (its reduction is there), skipped", flush=True)
            continue
        archive = os.path.join(results, name + ".h5")
        if sr.ensure(os.path.abspath(efdem), 2, scene, work, name, mode, overrides, archive,
                     label=f"{label}/{name}"):
            write_reduction(archive, os.path.join(results, name + ".json"),
                            os.path.join(work, name, name + ".log"))


# What the analysis reads of a run, kept in git beside the analysis (<case>/<run>.json): a study
# spans more machines than one (a tall-bed direct ensemble of 600 units is 2 h on 2 cores), and the
# run files and archives stay on the machine that made them. The reduction: the run's attributes,
# every sample time (the DEM time a run spent), each realization's stop times (from the full
# samples), and the light ICDF of every realization at the samples on a GRID-unit grid (3 decimals:
# 1e-3 d_p, 40x below the smallest floor measured, 0.039 d_p at the demo bed's steady state). The
# errors and floors are RMS over these samples: every 10th of a 0.5-unit sampling, which over a
# quarter of a 600-unit span leaves 30 samples of a trajectory that moves on a scale of tens of units.
GRID = 5.0
KEPT_ATTRIBUTES = ("end_status", "simulated_time", "dem_time", "particle_steps", "wall_seconds",
                   "resumed_wall_seconds", "git_commit", "study_command")


def load_archive(path, log=None):
    with h5py.File(path, "r") as f:
        d = {k: sr.text(v) if isinstance(v, (bytes, str)) else v for k, v in f.attrs.items()}
        d["t"], d["icdf"] = f["samples/time"][:], f["samples/icdf"][:]
        d["rest"] = f["samples/at_rest"][:] if "samples/at_rest" in f else None
        d["lifts"] = lift_records(f)
    # Before efdem kept a restarted run's earlier wall time (resumed_wall_seconds), wall_seconds
    # was the last process's alone: a run its LOG shows restarted has an unknown wall time.
    if "resumed_wall_seconds" not in d and log and os.path.exists(log):
        with open(log, errors="replace") as f:
            if any("restarted from" in line for line in f):
                d["resumed_wall_seconds"] = float("nan")
    return d


def wall_known(run):
    """Whether RUN's wall_seconds is its whole run loop's (not a restart's last process alone)."""
    resumed = run.get("resumed_wall_seconds", 0.0)
    return resumed is not None and math.isfinite(float(resumed))


def lift_records(f):
    """Every kept jump of a CPI run file F (open): [its step's t_start, DT, labels its lift switched
    per lifted realization]; [] for a direct run. t_start is when the step's burst began: the burst
    after the jump for the multistep integrator (adaptive runs, and fixed-DT ones with any of its
    keys), the burst before it for the plain fixed-DT forward Euler (docs/output.md /cpi/t_start)."""
    if "cpi/status" not in f or "cpi/lift_changed" not in f:
        return []
    c = f["cpi"]
    status = [sr.text(s) for s in c["status"][:]]
    changed = c["lift_changed"][:].astype(float)
    lifted = np.maximum((changed > 0).sum(axis=1), 1)
    return [[round(float(c["t_start"][k]), 6), round(float(c["dt"][k]), 6), round(float(changed[k].sum() / lifted[k]), 2)]
            for k in range(len(status)) if status[k] == "projected"]


def reduce_run(full):
    """The reduction (above) of a run loaded by load_archive."""
    t = full["t"]
    on_grid = np.abs(t / GRID - np.round(t / GRID)) < 1e-6
    out = {k: (float(full[k]) if k not in ("end_status", "git_commit", "study_command") else full[k])
           for k in KEPT_ATTRIBUTES if k in full}
    if "resumed_wall_seconds" in out and not math.isfinite(out["resumed_wall_seconds"]):
        out["resumed_wall_seconds"] = None  # unknown (JSON has no NaN)
    def finite(xs):  # a realization still moving at the end: null (JSON has no NaN)
        return [float(x) if np.isfinite(x) else None for x in xs]

    out.update(t_all=[round(float(x), 6) for x in t], stops=finite(stops(full)), quiet=finite(demixing_stops(full)),
               lifts=full.get("lifts", []),
               t=[round(float(x), 6) for x in t[on_grid]],
               icdf=np.round(full["icdf"][on_grid].astype(float), 3).tolist())
    return out


def from_reduction(d):
    """A run as the analysis reads it (arrays) from its reduction."""
    run = dict(d)
    run["t_all"], run["t"] = np.asarray(d["t_all"]), np.asarray(d["t"])
    run["icdf"] = np.asarray(d["icdf"], dtype=float).reshape(len(d["t"]), len(d["stops"]), -1)
    run["mean"] = run["icdf"].mean(axis=1)
    run["stops"], run["quiet"] = (np.array([np.nan if x is None else x for x in d[k]]) for k in ("stops", "quiet"))
    return run


def write_reduction(archive, dest, log=None):
    tmp = dest + ".part"
    with open(tmp, "w") as f:
        json.dump(reduce_run(load_archive(archive, log)), f, separators=(",", ":"), allow_nan=False)
        f.write("\n")
    os.replace(tmp, dest)


def load(folder, name, earlier=None):
    """Run NAME of the case in FOLDER for the analysis: its reduction (written from its archive
    when it has none yet), or None. EARLIER: an earlier study's archive that stands in."""
    reduction, archive = os.path.join(folder, name + ".json"), os.path.join(folder, name + ".h5")
    if not os.path.exists(reduction) and sr.archived(archive):
        write_reduction(archive, reduction)
    if os.path.exists(reduction):
        with open(reduction) as f:
            return from_reduction(json.load(f))
    if earlier and sr.archived(earlier):
        return from_reduction(reduce_run(load_archive(earlier)))
    return None


def stops(run):
    """Per realization: when it came to rest for good (NaN: moving at the end). From
    /samples/at_rest where the run has it, else from its ICDF (bench/stop_times.py)."""
    if run["rest"] is None:
        return st.stop_times(run["t"], run["icdf"])
    out = []
    for r in range(run["rest"].shape[1]):
        moving = np.nonzero(run["rest"][:, r] == 0)[0]
        out.append(float("nan") if len(moving) and moving[-1] == len(run["t"]) - 1
                   else float(run["t"][moving[-1] + 1] if len(moving) else run["t"][0]))
    return out


# "Stopped demixing" without being at rest: the light ICDF of a realization moves by less than
# QUIET d_p (the largest change of any node) over every later window of WINDOW units. Direct
# realizations at U_s = 0.19 pass through three regimes (R = 8, 600 units, 2026-12-05): moving, a
# node changes by 1e-2 to 1e-1 d_p in 10 units; creeping, 1e-5 to 1e-3 for hundreds of units with
# particles still moving (never at rest); at rest, 0. A creeping realization moves its ICDF by at
# most 1e-4 d_p per unit: 0.1 d_p over 1,000 units, below the floor (0.23): it has stopped demixing.
WINDOW, QUIET = 10.0, 1e-3


def demixing_stops(run):
    """Per realization: from when its light ICDF moved by less than QUIET in every full window of
    contiguous samples (a CPI run's bursts) to the end (NaN: it still moved in the last one)."""
    t, q = run["t"], run["icdf"]
    dt = float(np.median(np.diff(t)))
    out = []
    for r in range(q.shape[1]):
        since, first = float("nan"), 0
        ends = []
        for k in range(len(t)):
            if k > 0 and t[k] - t[k - 1] > 1.5 * dt:
                first = k  # a jump: a new burst starts
            if t[k] - t[first] < WINDOW - 1e-6:
                continue
            lo = int(np.searchsorted(t, t[k] - WINDOW - 1e-6))
            w = q[max(lo, first):k + 1, r, :]
            ends.append((float(t[k]), float((w.max(axis=0) - w.min(axis=0)).max()) <= QUIET))
        for tk, quiet in reversed(ends):
            if not quiet:
                break
            since = tk
        out.append(since)
    return out


def whole_run_steps(directs, run, duration):
    """Whether the particle-steps of the directs and of RUN cover the same process: the directs ran
    their whole duration, and RUN did too or ended at its end state."""
    return (all(float(d["simulated_time"]) >= duration - 1e-6 for d in directs)
            and (float(run["simulated_time"]) >= duration - 1e-6 or run["end_state"]))


def held_to(run, t):
    """The run's ensemble mean at the times t; past its last sample a run that ended at its end
    state is held there (nothing changes in an end state)."""
    idx = np.searchsorted(run["t"], t - 1e-6)
    ok = idx < len(run["t"])
    out = np.empty((len(t), run["mean"].shape[1]))
    out[ok] = run["mean"][idx[ok]]
    out[~ok] = run["mean"][-1] if run["end_state"] else np.nan
    exact = ok & (np.abs(run["t"][np.minimum(idx, len(run["t"]) - 1)] - t) < 1e-6)
    out[ok & ~exact] = np.nan
    return out


def rms(a, b, t, window, at=None):
    """RMS of a - b over the nodes and the samples t in WINDOW where both are finite (and AT, a mask
    over t, holds)."""
    sel = (t >= window[0]) & (t < window[1]) & np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1)
    if at is not None:
        sel &= at
    return math.sqrt(float(np.mean((a[sel] - b[sel]) ** 2))) if sel.any() else float("nan")


def realization_variance(run):
    """Per sample: the realizations' unbiased variance at a node, mean over the nodes."""
    return run["icdf"].var(axis=1, ddof=1).mean(axis=1)


def spread_floor(directs, window, times=None):
    """sqrt(2 var_r / R), var_r the realizations' variance at a node, mean over the directs, the
    nodes and their samples in WINDOW (those at TIMES only, when given)."""
    out = []
    for d in directs:
        sel = (d["t"] >= window[0]) & (d["t"] < window[1])
        if times is not None:
            sel &= np.isin(np.round(d["t"], 6), np.round(times, 6))
        if sel.any() and d["icdf"].shape[1] > 1:
            out.append(2.0 * float(np.mean(realization_variance(d)[sel])) / d["icdf"].shape[1])
    return math.sqrt(float(np.mean(out))) if out else float("nan")


def error_to(x, means, t, windows):
    """e per window: the RMS of X (an ensemble mean at the times t, NaN where it has no sample)
    minus each direct ensemble's mean (MEANS), averaged in square over the directs."""
    return {w: math.sqrt(np.mean([rms(x, m, t, w) ** 2 for m in means])) for w in windows}


def floors(directs, means, t, windows, at=None):
    """The noise floors per window, at the samples t where AT (a mask over t) holds: the pairs'
    (the mean over pairs of directs of the RMS between their means) and the spread's
    (spread_floor). A CPI run samples only in its bursts and the floor grows with t, so its e is
    divided by the floors at its own samples (AT = where it has one), as bench/walk_budget.py does."""
    pairs = [(i, j) for i in range(len(means)) for j in range(i + 1, len(means))]
    pair = {w: float(np.mean([rms(means[i], means[j], t, w, at) for i, j in pairs])) if pairs
            else float("nan") for w in windows}
    spread = {w: spread_floor(directs, w, None if at is None else t[at]) for w in windows}
    return pair, spread


def analyse_case(args, case):
    scene, us, duration, realizations, cpi = CASES[case]
    folder = os.path.join(args.results, case)
    runs, shorter = {}, []
    if case in DIRECTS_FROM:  # the halves of the R = 2R directs of another case
        source = os.path.join(args.results, DIRECTS_FROM[case])
        for name, _ in DIRECT:
            run = load(source, name)
            if run is not None:
                for k, h in enumerate(halves(run, realizations)):
                    runs[f"{name}{k}"] = h
    for name in runs_of(case):
        earlier = os.path.join(HERE, "results", EARLIER.get(case, "-"), name + ".h5")
        run = load(folder, name, earlier if name.startswith("direct") else None)
        if run is not None:
            runs[name] = run
            if not os.path.exists(os.path.join(folder, name + ".json")):
                shorter.append(f"{name} from {EARLIER[case]}")
    for run in runs.values():
        run["end_state"] = "end state at" in run["end_status"]
    direct_names = [n for n in runs if n.startswith("direct")]
    directs = [runs[n] for n in direct_names]
    if not directs:
        return None, []
    # The comparison's span: the run's duration, or less while some direct is shorter.
    span = min([duration] + [float(d["t_all"][-1]) for d in directs])
    t = directs[0]["t"][directs[0]["t"] <= span + 1e-6]
    interval = float(directs[0]["t_all"][1] - directs[0]["t_all"][0])  # the sampling's, not the grid's
    quarters = [(span * k / 4, span * (k + 1) / 4 + 1e-6) for k in range(4)]
    whole = (0.0, span + 1e-6)
    means = [held_to(d, t) for d in directs]
    pairs = [(i, j) for i in range(len(directs)) for j in range(i + 1, len(directs))]
    # The floor a model gives from the realizations' spread: two independent ensembles of R differ
    # by sqrt(2) standard errors of the mean, sqrt(2 var_r / R). A check beside the pairs' floor, and
    # the only one while a case has a single direct ensemble (rule: the stated floor is the pairs').
    floor, spread = floors(directs, means, t, quarters + [whole])

    def state_at(run, when):
        """Each realization's median light height at the last sample at or before `when`."""
        k = int(np.searchsorted(run["t"], when + 1e-6)) - 1
        return run["icdf"][k, :, MEDIAN]

    # The end state of the direct ensembles: every realization's median light height at the end
    # of the span, pooled over the ensembles (their own seeds: independent), with its standard error.
    direct_medians = np.concatenate([state_at(d, span) for d in directs])
    d_mean, d_se = float(direct_medians.mean()), float(direct_medians.std(ddof=1) / math.sqrt(len(direct_medians)))
    direct_stops = [s for d in directs for s in d["stops"]]
    direct_quiet = [s for d in directs for s in d["quiet"]]
    last_stop = max(direct_stops) if all(np.isfinite(direct_stops)) else float("nan")
    summary = {"case": case, "span": span, "floor": floor[whole], "floor_quarters": [floor[w] for w in quarters],
               "spread_floor": spread[whole],
               "direct_end_median": d_mean, "direct_end_median_se": d_se,
               "direct_stopped": int(np.isfinite(direct_stops).sum()), "direct_realizations": len(direct_stops),
               "direct_all_at_rest_at": last_stop, "direct_stopped_demixing": direct_quiet, "cpi": {},
               "runs": sorted(runs)}
    lines = [f"## {case}: {scene.split('_')[0]} bed, U_s = {us}, R = {realizations}, {duration:g} time units\n",
             (f"**Compared over t = 0-{span:g} only** (directs still short: {', '.join(shorter)}).\n"
              if span < duration - 1e-6 else ""),
             f"Direct ensembles: {len(directs)} ({', '.join(direct_names)}"
             + (f": the halves of {DIRECTS_FROM[case]}'s" if case in DIRECTS_FROM else "") + "); noise "
             f"floor (RMS between two direct ensembles' mean ICDF, mean over {len(pairs)} pair(s)): "
             f"{floor[whole]:.3f} d_p over the span, by quarter " + " / ".join(f"{floor[w]:.3f}" for w in quarters)
             + f" (from the realizations' spread, sqrt(2 var_r / R): {spread[whole]:.3f} d_p, by quarter "
             + " / ".join(f"{spread[w]:.3f}" for w in quarters) + "). Each CPI run's e is divided by "
             "these floors taken at its own samples (it samples only in its bursts, and the floor grows "
             "with t).\n",
             f"Direct realizations at rest for good by the end of their runs: {summary['direct_stopped']} of "
             f"{len(direct_stops)} (stop times "
             + ", ".join("moving" if not np.isfinite(x) else f"{x:g}" for x in direct_stops) + "). "
             f"State at t = {span:g} (median light height, pooled): {d_mean:.2f} +- {d_se:.2f} d_p.\n",
             f"Direct realizations that stopped demixing (light ICDF moving < {QUIET:g} d_p per {WINDOW:g} units "
             f"to the end of the run, at rest or not): {int(np.isfinite(direct_quiet).sum())} of {len(direct_quiet)} "
             "(since " + ", ".join("moving" if not np.isfinite(x) else f"{x:g}" for x in direct_quiet) + ").\n",
             f"| CPI run | ended | e / floor by quarter | e / floor (/ spread floor) | median at t = {span:g} [d_p] | off the "
             "directs' [s.e.] | realizations at rest (stop times) | stopped demixing (since) | DEM-time speed-up "
             "over the span | to the end state: direct / CPI DEM time | wall-time speed-up | DEM time per realization | "
             "stops expected if they came with DEM time (P of none) | particle-steps: the directs' mean / the run's |",
             "|---" * 14 + "|"]
    for name in cpi:
        if name not in runs:
            continue
        run = runs[name]
        x = held_to(run, t)
        e = error_to(x, means, t, quarters + [whole])
        f_at, s_at = floors(directs, means, t, quarters + [whole], np.isfinite(x).all(axis=1))
        med = state_at(run, span)
        c_mean, c_se = float(med.mean()), float(med.std(ddof=1) / math.sqrt(len(med)))
        off = (c_mean - d_mean) / math.sqrt(d_se ** 2 + c_se ** 2)
        cpi_stops, cpi_quiet = run["stops"], run["quiet"]
        # DEM time within the span: a CPI run samples only in its bursts.
        dem = float(np.sum(run["t_all"] <= span + 1e-6)) * interval
        speed = min(span, float(run["t_all"][-1])) / dem
        # DEM time to the end state: a direct ensemble's is when its last realization came to rest.
        to_end = (last_stop / float(run["dem_time"])) if run["end_state"] and np.isfinite(last_stop) else float("nan")
        # Do stops come with DEM time (a bed must run so long before it can freeze)? Then a CPI
        # realization would stop as often as a direct one that ran as long: the share of direct
        # realizations that had stopped demixing by the CPI run's DEM time per realization.
        dem_each = float(run["dem_time"])
        share = float(np.mean([np.isfinite(q) and q <= dem_each for q in direct_quiet]))
        expected, p_none = share * len(cpi_quiet), (1.0 - share) ** len(cpi_quiet)
        # The compute: a direct run pauses its realizations at rest (ensemble.at_rest = pause), so
        # over a whole process its particle-steps, not its DEM time, are what it cost.
        steps_ratio = (np.mean([float(d["particle_steps"]) for d in directs]) / float(run["particle_steps"])
                       if whole_run_steps(directs, run, duration) else float("nan"))
        whole_run = span >= duration - 1e-6
        # Not where a restart left only its last process's wall time (wall_known).
        walled = whole_run and wall_known(run) and all(wall_known(d) for d in directs)
        wall = (np.mean([float(d["wall_seconds"]) / float(d["simulated_time"]) for d in directs])
                * float(run["simulated_time"]) / float(run["wall_seconds"])) if walled else float("nan")
        ended = (f"end state at {float(run['t_all'][-1]):g}" if run["end_state"]
                 else f"{float(run['simulated_time']):g} (duration)")
        summary["cpi"][name] = {"e_over_floor": e[whole] / f_at[whole],
                                "e_over_spread_floor": e[whole] / s_at[whole], "e_over_floor_quarters":
                                [e[w] / f_at[w] for w in quarters],
                                "e_over_floor_all_samples": e[whole] / floor[whole],
                                "floor_at_samples": f_at[whole], "median": c_mean, "median_se": c_se,
                                "off_se": off, "stops": [float(x) for x in cpi_stops],
                                "stopped_demixing": [float(x) for x in cpi_quiet],
                                "speedup_dem": speed,
                                "speedup_to_end_state": to_end, "speedup_wall": wall, "end_status": run["end_status"],
                                "dem_time_each": dem_each, "stops_expected_by_dem_time": expected,
                                "p_no_stop_by_dem_time": p_none, "particle_steps_ratio": steps_ratio}
        lines.append(f"| {name} | {ended} | " + " / ".join(f"{e[w] / f_at[w]:.2f}" for w in quarters)
                     + f" | {e[whole] / f_at[whole]:.2f} ({e[whole] / s_at[whole]:.2f}) | {c_mean:.2f} +- {c_se:.2f} | {off:+.1f} | "
                     f"{int(np.isfinite(cpi_stops).sum())} of {len(cpi_stops)} ("
                     + ", ".join("moving" if not np.isfinite(x) else f"{x:g}" for x in cpi_stops)
                     + f") | {int(np.isfinite(cpi_quiet).sum())} of {len(cpi_quiet)} ("
                     + ", ".join("moving" if not np.isfinite(x) else f"{x:g}" for x in cpi_quiet)
                     + f") | {speed:.2f} | {to_end:.2f} | " + (f"{wall:.2f}" if walled else "-")
                     + f" | {dem_each:g} | {expected:.1f} ({p_none:.2g}) | {steps_ratio:.2f} |")
    lines.append("")
    lines.append(noise_model_line(directs, {n: runs[n] for n in cpi if n in runs}))
    # While some directs are short, the state at the end of the run against those that got there.
    full = [d for d in directs if float(d["t_all"][-1]) >= duration - 1e-6]
    if span < duration - 1e-6 and full:
        med = np.concatenate([state_at(d, duration) for d in full])
        f_mean, f_se = float(med.mean()), float(med.std(ddof=1) / math.sqrt(len(med)))
        out = []
        for name in cpi:
            if name in runs and float(runs[name]["t_all"][-1]) >= duration - 1e-6 or (
                    name in runs and runs[name]["end_state"]):
                c = state_at(runs[name], duration)
                c_mean, c_se = float(c.mean()), float(c.std(ddof=1) / math.sqrt(len(c)))
                out.append(f"{name} {c_mean:.2f} +- {c_se:.2f} ({(c_mean - f_mean) / math.hypot(f_se, c_se):+.1f} s.e.)")
        lines.append(f"At t = {duration:g}, against the {len(full)} direct ensemble(s) that got there ({len(med)} "
                     f"realizations, median light height {f_mean:.2f} +- {f_se:.2f} d_p): " + "; ".join(out) + ".\n")
    plot(folder, case, t, directs, {n: runs[n] for n in cpi if n in runs})
    return summary, lines


def noise_model_line(directs, cpis):
    """The noise model of bench/walk_budget.py on this case: the directs' fitted noise and each
    CPI run's predicted e / spread floor (noise only) beside its measured one."""
    import walk_budget as wb  # it imports this module: here, not at the top
    a, q, c, var, _ = wb.fit_noise(directs)
    parts = []
    for name, run in cpis.items():
        predicted, measured, _, jumps = wb.compare(directs, run, q)
        # the model is for one burst's least-squares slope over a fixed window
        other = [k for k in ("cpi.slope=pooled", "cpi.integrator=adams_bashforth2", "cpi.window_auto=true",
                             "cpi.healing_auto=true") if k in run.get("study_command", "")]
        parts.append(f"{name} {predicted:.2f} ({measured:.2f}, {jumps} jumps"
                     + (f"; not the model's slope: {', '.join(other)}" if other else "") + ")")
    return (f"Noise model (bench/walk_budget.py; docs/error_control.md §7): offsets' variance {var:.3f} d_p^2, "
            f"walk q = {q:.2e} d_p^2 per unit, own rates c = {c:.1e}, fast part a = {a:.4f}; e / spread floor "
            "predicted from noise alone (measured, jumps): " + ("; ".join(parts) if parts else "no CPI run yet")
            + ". Truncation and the lift's miss come on top; at U_s = 0.41 the offsets relax within tens of "
            "units and the model overstates.\n")


def plot(folder, case, t, directs, cpis):
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for k, d in enumerate(directs):
        drawn = ax.plot(d["t"], d["icdf"][:, :, MEDIAN], color="0.75", lw=0.6)
        if k == 0:
            drawn[0].set_label("direct realizations")
        ax.plot(d["t"], d["mean"][:, MEDIAN], color="k", lw=1.2, label="direct ensembles' means" if k == 0 else None)
    for (name, run), colour in zip(cpis.items(), ("C0", "C3", "C2", "C1")):
        ax.plot(run["t"], run["mean"][:, MEDIAN], color=colour, lw=1.5, label=f"CPI {name}")
        ax.plot(run["t"], run["icdf"][:, :, MEDIAN], color=colour, lw=0.5, alpha=0.5, ls="none", marker=".", ms=1)
    ax.set_xlabel("t [sqrt(d_p/g)]")
    ax.set_ylabel("median light height [d_p]")
    ax.set_title(case)
    ax.legend(fontsize=8)
    fig.tight_layout()
    os.makedirs(folder, exist_ok=True)
    fig.savefig(os.path.join(folder, "whole_process.png"), dpi=120)
    plt.close(fig)


FROZEN = "before the analysis kept reductions"


def frozen(section):
    """Whether SECTION was made from run archives no longer kept (its first lines say so)."""
    if not os.path.exists(section):
        return False
    with open(section) as f:
        return FROZEN in f.read(2000)


def remade(folder, names):
    """What a frozen section's closing line says of each run re-made since (NAMES, reductions in
    FOLDER): a direct run by name; a CPI run with its median light height at its last sample
    (mean +- standard error over its realizations), how many came to rest, its DEM-time speed-up."""
    out = []
    for name in names:
        run = load(folder, name)
        if run is None or name.startswith("direct"):
            out.append(name)
            continue
        median = run["icdf"][-1, :, MEDIAN]
        se = float(np.std(median, ddof=1) / np.sqrt(len(median))) if len(median) > 1 else float("nan")
        rest = int(np.sum(np.isfinite(run["stops"])))
        out.append(f"{name} (median at t = {run['t'][-1]:g}: {np.mean(median):.2f} +- {se:.2f} d_p, "
                   f"{rest} of {len(median)} at rest, {run['simulated_time'] / run['dem_time']:.2f}x in DEM time)")
    return out


def keep_frozen(section, names):
    """SECTION as it was, with one closing line naming the runs re-made so far (NAMES)."""
    with open(section) as f:
        text = f.read()
    marker = "\n*Re-made so far (reductions in git, the section above stands until all its directs are):"
    text = text.split(marker)[0].rstrip("\n") + "\n" + marker + " " + ", ".join(names) + ".*\n"
    with open(section, "w") as f:
        f.write(text)


def analyse(args):
    """Each case's section (<case>/analysis.md) and summary from the runs it has; a case none of
    whose runs is here keeps the section and summary an earlier analysis wrote. analysis.md and
    analysis.json gather them."""
    out = ["# The whole demixing (issue 34)\n",
           "Made by `/usr/bin/python3 bench/whole_process.py --efdem build/mpi_driver/efdem` (resumable; "
           "`--analyse-only` redoes this page from the runs' reductions, <case>/<run>.json). e: RMS over the "
           f"ICDF nodes and the samples on a {GRID:g}-unit grid of the CPI run's ensemble mean minus each direct "
           "ensemble's, averaged in square over the directs; a run that ended at its end state is held there to "
           "the end of the span. Wall-time speed-ups are from a shared 2-core AMD EPYC machine whose load "
           "varies: the DEM-time ones are the measure.\n"]
    path = os.path.join(args.results, "analysis.json")
    summary = {}
    if os.path.exists(path):
        with open(path) as f:
            summary = json.load(f)
    for case in CASES:
        section = os.path.join(args.results, case, "analysis.md")
        s, lines = analyse_case(args, case)
        folder = os.path.join(args.results, case)
        made = [n for n in runs_of(case) if os.path.exists(os.path.join(folder, n + ".json"))]
        if made and frozen(section) and (s is None or sum(n.startswith("direct") for n in s["runs"]) < len(DIRECT)):
            # A section made from archives that are gone (FROZEN) stands until the case's directs
            # are all made again; what is made so far is named under it.
            keep_frozen(section, remade(folder, made))
            s = None
        if s:
            summary[case] = s
            with open(section, "w") as f:
                f.write("\n".join(lines) + "\n")
        if os.path.exists(section):
            with open(section) as f:
                out.append(f.read())
    os.makedirs(args.results, exist_ok=True)
    with open(os.path.join(args.results, "analysis.md"), "w") as f:
        f.write("\n".join(out))
    with open(path + ".part", "w") as f:  # a failed dump never leaves half a summary
        json.dump(summary, f, indent=1, default=float)
    os.replace(path + ".part", path)
    print("\n".join(out))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--efdem", default=os.path.join(HERE, "..", "build", "mpi_driver", "efdem"))
    p.add_argument("--out", default=os.path.join(HERE, "..", "runs", "whole_process"), help="working folder")
    p.add_argument("--results", default=RESULTS)
    p.add_argument("--case", nargs="*", choices=sorted(CASES), help="these cases only (default: all)")
    p.add_argument("--only", nargs="*", help="these runs only")
    p.add_argument("--analyse-only", action="store_true")
    args = p.parse_args()
    if not args.analyse_only:
        for case in args.case or CASES:
            make(args, case)
    analyse(args)


if __name__ == "__main__":
    main()
