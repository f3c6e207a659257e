#!/usr/bin/env python3
"""What a CPI run's jumps add to its error, from the noise of the direct ensembles (issue 34: what
stands between the whole process at U_s = 0.19 and 5x within the noise floor).

The noise, measured. Each realization's offset from its ensemble's mean, d_r(t) = x_r(t) - mean(t)
(light ICDF, per node), has the lag variance

    V(tau) = < (d_r(t + tau) - d_r(t))^2 > = a + q tau + c tau^2

(R/(R-1) corrects for the mean taken from the same realizations; fitted at tau = 5-120). On the
tall bed at U_s = 0.19, V(120) is a sixth of 2 var(d_r): each realization carries an offset that
is nearly frozen (set in the first tens of units), a walk of diffusivity q per realization (the
ensemble mean's is q / R) and a rate of its own (c: its offset grows as rate x t; an ensemble of
the same realizations has their mean rate, so a jump that carries it adds nothing); the fast part
a is 0 there. The frozen offsets make most of the noise floor, but a slope does not see them; the
walk is what a slope measures as motion.

The model of a CPI run. Its frozen offsets and the walk in its bursts are those of a direct
ensemble (an independent one). A jump of DT from the least-squares slope of the last W units of a
burst moves the ensemble mean by DT times the slope, whose error is the walk's increments over
the window: variance 1.2 q / (W R) (the least-squares slope of a walk over W). That error is
correlated with the walk already in the state it extrapolates from (covariance q / R: the slope's
weights sum to zero and, against the times, to one), and the jump stands in for the walk of DT a
direct ensemble makes (q DT / R). So against a direct ensemble each jump adds

    (1.2 q DT^2 / W + 2 q DT - q DT) / R.

Assumed: the walk's directions do not relax (V does not saturate over 120 units; a perturbation
across the bed's expansion did relax, so where jumps err in such directions the model overstates),
and no fast part (a is reported, and a warning printed where it matters: the fast part's share
in a lifted state is not modelled). So at time t, against an independent direct ensemble,

    E[e^2(t)] = var_r(t) (1 / R_cpi + 1 / R_direct) + A(t),    A(t) = the sum over the jumps landed by t,

and e / floor = sqrt(mean_t E[e^2] / mean_t of the floor^2 var_r (1 / R_cpi + 1 / R_direct)) over
the CPI run's samples (what bench/whole_process.py compares), the floor taken from the
realizations' spread (its "spread floor"). What the model leaves out (truncation, the lift's miss,
any bias of the lifted beds) is what a run's measured ratio has beyond the predicted one. The
model is for a slope from one burst's least squares over a fixed window, or its increment there
(cpi.slope = burst, forward Euler): the window and cpi.slope_fit are read from the run's command
(default 10, least squares).

    /usr/bin/python3 bench/walk_budget.py --directs bench/results/tall_study_r4/u0.19/direct_a.h5 \\
        bench/results/tall_study_r4/u0.19/direct_b.h5 --cpi bench/results/tall_study_r4/u0.19/adaptive_tol0.32.h5 ...

The bound. The walk's increments dW(s) in the bursts are all a CPI run knows of the walk; with
slopes linear in the bursts' data and unbiased for a constant drift, its state at t carries them
as sum_s c(s) dW(s), with c(s) = 1 plus what the jumps made of them, and a constant drift f must
come out as f t: integral c(s) ds = t over the DEM time t / S. By Cauchy-Schwarz the walk's
variance, (q / R) integral c(s)^2 ds, is then at least (q / R) t^2 / (t / S) = S q t / R: S times
a direct ensemble's, whatever the window, pooling or order. The bound is attained by the
increment over whole bursts with jumps of one length (c constant). With phi = q t / var_r(t) the
walk's share of the realizations' variance, in expectation

    (e / floor)^2 >= 1 + (S - 1) phi / 2,   and at equal compute (CPI with R against direct with
    R / S)   e_cpi / e_direct >= sqrt(phi + (1 - phi) / S).

Directs and CPI runs are run archives (.h5) or bench/whole_process.py reductions (.json). Prints
the fitted noise, each CPI run's predicted and measured e / spread floor, and for uniform schedules
(bursts of b = healing + W, jumps of DT = (S - 1) b) the ratio the walk alone allows at speed-up S.
"""
import argparse
import json
import math
import os
import re
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import whole_process as wp  # noqa: E402

LAGS = (5.0, 10.0, 20.0, 40.0, 80.0, 120.0)  # units: from the sampling grid of the reductions to a third of 400
SETTLED = 30.0  # the bed's expansion: offsets are still being set before it (docs/accuracy_vs_cost.md)


def read(path):
    """A run (arrays: t, icdf, mean, t_all) from an archive or a reduction."""
    if path.endswith(".json"):
        with open(path) as f:
            d = json.load(f)
        run = wp.from_reduction(d)
        run["command"] = d.get("study_command", "")
        return run
    run = wp.load_archive(path)
    run["mean"], run["t_all"] = run["icdf"].mean(axis=1), run["t"]
    run["command"] = str(run.get("overrides", ""))
    return run


def lag_variance(runs, lags=LAGS):
    """Per lag: V(tau), mean over the runs, realizations, nodes and start times t >= SETTLED."""
    out = []
    for lag in lags:
        vals = []
        for run in runs:
            t, x = run["t"], run["icdf"]
            d = x - x.mean(axis=1, keepdims=True)
            r = x.shape[1]
            step = float(np.median(np.diff(t)))
            k = int(round(lag / step))
            i = np.nonzero(t[:-k] >= SETTLED)[0]
            vals.append(float(np.mean((d[i + k] - d[i]) ** 2)) * r / (r - 1))
        out.append(float(np.mean(vals)))
    return np.array(out)


def fit_noise(runs):
    """(a, q, c): V(tau) = a + q tau + c tau^2, non-negative least squares over LAGS; the offsets'
    variance (t >= SETTLED); V. c is each realization's own persistent rate (its offset grows as
    rate x t): the ensemble's mean rate is the ensemble's, a direct ensemble of the same
    realizations has it too, so a jump that carries it forward adds no error. Only the walk q does."""
    v = lag_variance(runs)
    lags = np.array(LAGS)
    a, q, c = nnls(np.stack([np.ones_like(lags), lags, lags ** 2], axis=1), v)
    var = float(np.mean([np.mean((r["icdf"] - r["icdf"].mean(axis=1, keepdims=True))[r["t"] >= SETTLED] ** 2)
                         * r["icdf"].shape[1] / (r["icdf"].shape[1] - 1) for r in runs]))
    return float(a), float(q), float(c), var, v


def nnls(m, y):
    """min |m x - y| over x >= 0 (three unknowns: every subset of them, the best feasible one)."""
    best, best_x = float("inf"), np.zeros(m.shape[1])
    for mask in range(1, 2 ** m.shape[1]):
        cols = [k for k in range(m.shape[1]) if mask >> k & 1]
        x, *_ = np.linalg.lstsq(m[:, cols], y, rcond=None)
        if (x >= 0).all():
            res = float(np.sum((m[:, cols] @ x - y) ** 2))
            if res < best:
                best, best_x = res, np.zeros(m.shape[1])
                best_x[cols] = x
    return best_x


def key(command, name, default):
    m = re.search(r"\b" + re.escape(name) + r"=(\S+)", command)
    return float(m.group(1)) if m else default


def jumps(run):
    """(landing time, DT) of every jump: a gap in the samples longer than one sampling interval."""
    t = np.asarray(run["t_all"], dtype=float)
    step = float(np.min(np.diff(t)))
    gaps = np.diff(t) - step
    return [(float(t[k + 1] - step), float(gaps[k])) for k in np.nonzero(gaps > 0.5 * step)[0]]


# Var(slope) W R / q of a walk over a window W, per cpi.slope_fit (dense samples): the
# C++ walk_slope_variance_factor().
SLOPE_VARIANCE = {"least_squares": 1.2, "increment": 1.0}


def jump_variance(dt, q, window, r, factor=SLOPE_VARIANCE["least_squares"]):
    """The variance one jump of DT adds to the ensemble mean beyond a direct ensemble's (above);
    FACTOR: the slope's variance over the window is factor q / (W R), 1.2 for least squares, 1 for
    the increment (cpi.slope_fit = increment). The covariance term is the same for both."""
    return (factor * q * dt * dt / window + q * dt) / r


def floor_bound(speedup, phi):
    """The least e / floor in expectation of a CPI run at DEM-time speed-up SPEEDUP whose slopes
    come from its own bursts, PHI the walk's share of the realizations' variance (the bound above)."""
    return math.sqrt(1.0 + (speedup - 1.0) * phi / 2.0)


def equal_compute_bound(speedup, phi):
    """The least CPI error over a direct ensemble's of R / SPEEDUP realizations (the bound above)."""
    return math.sqrt(phi + (1.0 - phi) / speedup)


def var_r(directs, t):
    """The realizations' variance at the times t (mean over nodes and directs), on the directs' grid."""
    out = []
    for d in directs:
        out.append(np.interp(t, d["t"], wp.realization_variance(d)))
    return np.mean(out, axis=0)


def compare(directs, run, q):
    """(predicted, measured) e / spread floor of the CPI run RUN over its samples on the directs'
    grid from SETTLED on, the window its slopes were fitted over and its jumps."""
    r_cpi, r_dir = run["icdf"].shape[1], directs[0]["icdf"].shape[1]
    command = run.get("command", run.get("study_command", ""))
    window = key(command, "cpi.window", 10.0)
    fit = re.search(r"\bcpi\.slope_fit=(\S+)", command)
    factor = SLOPE_VARIANCE[fit.group(1) if fit else "least_squares"]
    span = min(float(d["t"][-1]) for d in directs)
    grid = directs[0]["t"][(directs[0]["t"] <= span + 1e-6)]
    x = wp.held_to(dict(run, end_state=False), grid)
    ok = np.isfinite(x).all(axis=1) & (grid >= SETTLED)
    t = grid[ok]
    means = [wp.held_to(dict(d, end_state=False), t) for d in directs]
    measured_e2 = np.mean([np.mean((x[ok] - m) ** 2, axis=1) for m in means], axis=0)
    floor2 = var_r(directs, t) * (1.0 / r_cpi + 1.0 / r_dir)
    landed = jumps(run)
    added = np.array([sum(jump_variance(dt, q, window, r_cpi, factor) for land, dt in landed if land <= s + 1e-6)
                      for s in t])
    return (math.sqrt(float(np.mean(floor2 + added)) / float(np.mean(floor2))),
            math.sqrt(float(np.mean(measured_e2)) / float(np.mean(floor2))), window, len(landed))


def uniform(directs, q, span, r, healing, window, speedup):
    """A schedule of jumps of DT = (S - 1) b after bursts of b from SETTLED on, the last jump
    shortened to land at the end of SPAN as the integrators do: its e / floor at its last sample
    and RMS over its samples (the directs' grid points in its first SETTLED units and its bursts,
    as bench/whole_process.py compares), the error at equal compute RMS over the same samples (CPI
    with R realizations against a direct ensemble of R / S', each against the mean of infinitely
    many: var_r / R + A against S' var_r / R), and S', the schedule's own speed-up over SPAN."""
    b = healing + window
    dt = (speedup - 1.0) * b
    landings, now = [], SETTLED  # (landing time, DT)
    while now < span - 1e-6:
        jump = min(dt, span - now)
        landings.append((now + jump, jump))
        now += jump + b
    grid = directs[0]["t"][(directs[0]["t"] >= SETTLED - 1e-6) & (directs[0]["t"] <= span + 1e-6)]
    sampled = [t for t in grid if t <= SETTLED + 1e-6 or any(land < t <= land + b + 1e-6 for land, _ in landings)]
    if landings[-1][0] >= span - 1e-6 and (not sampled or sampled[-1] < span - 1e-6):
        sampled.append(span)  # the run ends on its last landing: its state there is its result
    ts = np.array(sampled)
    added = np.array([sum(jump_variance(j, q, window, r) for land, j in landings if land <= t + 1e-6) for t in ts])
    actual = span / (SETTLED + sum(min(b, span - land) for land, _ in landings if land < span - 1e-6))
    own = var_r(directs, ts) / r
    e2 = 2.0 * own + added
    equal = math.sqrt(float(np.mean(own + added)) / float(np.mean(actual * own)))
    return (math.sqrt(e2[-1] / (2.0 * own[-1])), math.sqrt(float(np.mean(e2)) / float(np.mean(2.0 * own))), equal,
            actual)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--directs", nargs="+", required=True)
    ap.add_argument("--cpi", nargs="*", default=[])
    ap.add_argument("--healing", type=float, default=2.0, help="the uniform schedules' healing")
    ap.add_argument("--window", type=float, default=18.0, help="the uniform schedules' window")
    ap.add_argument("--plot", help="PNG: predicted e / floor against S, the CPI runs as measured")
    ap.add_argument("--title", default="", help="the plot's title")
    args = ap.parse_args()
    for path in args.directs + args.cpi:
        if not os.path.isfile(path) or not path.endswith((".h5", ".json")):
            sys.exit(f"walk_budget: {path}: not a run archive (.h5) or reduction (.json) file")
    directs = [read(p) for p in args.directs]
    for path, d in zip(args.directs, directs):
        if d["icdf"].shape[1] < 2 or float(d["t"][-1]) < SETTLED + LAGS[-1]:
            sys.exit(f"walk_budget: {path}: {d['icdf'].shape[1]} realization(s) over {float(d['t'][-1]):g} units; "
                     f"the noise fit needs >= 2 realizations and >= {SETTLED + LAGS[-1]:g} units "
                     f"(offsets settle by t = {SETTLED:g}, lags up to {LAGS[-1]:g})")
    a, q, c, var, v = fit_noise(directs)
    r = directs[0]["icdf"].shape[1]
    span = min(float(d["t"][-1]) for d in directs)
    print(f"directs: {len(directs)} of R = {r}, span {span:g}; offsets' variance {var:.4f} d_p^2 (sd {math.sqrt(var):.3f})")
    print("V(tau) [d_p^2]: " + ", ".join(f"{lag:g}: {x:.4f}" for lag, x in zip(LAGS, v))
          + f"  (2 var = {2 * var:.4f}); fit a = {a:.4f}, q = {q:.2e} d_p^2 per unit, c = {c:.2e} d_p^2 per unit^2")
    if a > 0.25 * q * args.window:
        print(f"warning: a fast part (a = {a:.4f} d_p^2) beside the walk over a window ({q * args.window:.4f}): "
              "the model leaves it out, and its predictions are for the walk alone")
    if args.cpi:
        print("\n| CPI run | window | jumps | DEM-time speed-up | e / spread floor predicted (noise only) | measured |")
        print("|---|---|---|---|---|---|")
    points = []
    for path in args.cpi:
        run = read(path)
        pred, meas, window, n = compare(directs, run, q)
        points.append((os.path.basename(path), speedup_of(run), pred, meas))
        print(f"| {os.path.basename(path)} | {window:g} | {n} | {points[-1][1]:.2f} | {pred:.2f} | {meas:.2f} |")
    print(f"\nUniform schedules (healing {args.healing:g} + window {args.window:g}, R = {r}, over {span:g} units): "
          "e / floor at the end and RMS over the span; at equal compute, CPI's error over a direct ensemble's of R / S")
    for s in (2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 14.0):
        end, whole, equal, actual = uniform(directs, q, span, r, args.healing, args.window, s)
        print(f"  DT = {(s - 1) * (args.healing + args.window):g} (S = {actual:.2f} over the span): {end:.2f} at the end, "
              f"{whole:.2f} over the span; at equal compute {equal:.2f}")
    phi = q * span / float(var_r(directs, np.array([span]))[0])
    print(f"\nThe bound at t = {span:g} (the walk's share of the variance phi = {phi:.2f}): e / floor at the end >= "
          + ", ".join(f"{floor_bound(s, phi):.2f} at {s:g}x" for s in (2.0, 3.0, 5.0, 10.0))
          + "; at equal compute >= " + ", ".join(f"{equal_compute_bound(s, phi):.2f} at {s:g}x" for s in (2.0, 5.0))
          + f" (-> {math.sqrt(phi):.2f})")
    if args.plot:
        plot(args, directs, q, span, r, points)


def speedup_of(run):
    """Simulated time over DEM time: the samples' span over the time they were sampled in."""
    t = np.asarray(run["t_all"], dtype=float)
    step = float(np.min(np.diff(t)))
    return float(t[-1]) / (len(t) * step)


def plot(args, directs, q, span, r, points):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    speedups = np.linspace(1.25, 16.0, 60)  # nominal (DT = (S - 1) b); drawn at the schedule's own S
    fig, ax = plt.subplots(figsize=(7, 4.2))
    splits = [(args.healing, args.window, "-")] + ([(10.0, 10.0, "--")] if (args.healing, args.window) != (10.0, 10.0) else [])
    for healing, window, style in splits:
        curve = [uniform(directs, q, span, r, healing, window, s) for s in speedups]
        ax.plot([c[3] for c in curve], [c[1] for c in curve], "k" + style,
                label=f"noise alone, bursts {healing:g} + {window:g}: e / floor (RMS over the span)")
        if style == "-":
            ax.plot([c[3] for c in curve], [c[2] for c in curve], color="0.45", ls="-.", label="noise alone: CPI's error / direct's at equal compute")
    for k, (name, s, pred, meas) in enumerate(points):
        ax.plot([s], [meas], "o", color=f"C{k % 8}", label=f"{name}: measured")
        ax.plot([s], [pred], "o", mfc="none", color=f"C{k % 8}", label=f"{name}: predicted for its jumps")
    ax.axhline(1.0, color="0.6", lw=0.8)
    ax.set_xlabel("DEM-time speed-up S")
    ax.set_ylabel("error / noise floor (from the spread)")
    ax.set_title(args.title or f"{len(directs)} direct ensemble(s) of R = {r}, {span:g} units", fontsize=10)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    fig.savefig(args.plot, dpi=120, bbox_inches="tight")


if __name__ == "__main__":
    main()
