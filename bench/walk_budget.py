#!/usr/bin/env python3
"""What a CPI run's jumps add to its error, from the noise of the direct ensembles (issue 34: what
stands between the whole process at U_s = 0.19 and 5x within the noise floor).

The noise, measured. Each realization's offset from its ensemble's mean, d_r(t) = x_r(t) - mean(t)
(light ICDF, per node), has the lag variance

    V(tau) = < (d_r(t + tau) - d_r(t))^2 > = a + q tau

(R/(R-1) corrects for the mean taken from the same realizations). On the tall bed at U_s = 0.19
V grows linearly in tau out to 160 units and stays far below 2 var(d_r): each realization carries
an offset that is nearly frozen (set in the first tens of units) plus a slow walk of diffusivity q,
plus a small fast part a. The frozen offsets make most of the noise floor, but a slope does not see
them; the walk is what a slope measures as motion.

The model of a CPI run. Its frozen offsets and the walk in its bursts are those of a direct
ensemble of the same R (an independent one). A jump of DT from a slope fitted over a window W
(least squares over N samples) moves the ensemble mean by DT times the slope, whose error is the
walk's increments over the window: variance 1.2 q / (W R) (the least-squares slope of a walk of
diffusivity q over W; of white noise of variance a / 2 per sample, 12 (a / 2) / (N W^2)). That
error is correlated with the walk already in the state it extrapolates from (covariance q / R:
the weights of a least-squares slope sum, against the times, to one), and the jump stands in for
DT of walk a direct ensemble makes (q DT / R). So against a direct ensemble each jump adds

    (1.2 q DT^2 / W + 2 q DT - q DT + 6 a DT^2 / (N W^2)) / R

and nothing contracts it (V linear: no decay measured over the span). So at time t, against an
independent direct ensemble,

    E[e^2(t)] = 2 var_r(t) / R + A(t),    A(t) = the sum over the jumps landed by t,

and e / floor = sqrt(mean_t E[e^2] / mean_t 2 var_r / R) over the samples compared, the floor taken
from the realizations' spread (bench/whole_process.py's "spread floor"). What the model leaves out
(truncation, the lift's miss, any bias of the lifted beds) is what a run's measured ratio has
beyond the predicted one.

    /usr/bin/python3 bench/walk_budget.py --directs bench/results/tall_study_r4/u0.19/direct_a.h5 \\
        bench/results/tall_study_r4/u0.19/direct_b.h5 --cpi bench/results/tall_study_r4/u0.19/adaptive_tol0.32.h5 ...

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
            i = np.nonzero((t[:-k] >= SETTLED) & (t[k:] <= t[-1]))[0]
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


def jump_variance(dt, a, q, window, step, r):
    """The variance one jump of DT adds to the ensemble mean beyond a direct ensemble's (above)."""
    n = window / step + 1.0
    return (1.2 * q * dt * dt / window + q * dt + 6.0 * a * dt * dt / (n * window * window)) / r


def var_r(directs, t):
    """The realizations' variance at the times t (mean over nodes and directs), on the directs' grid."""
    out = []
    for d in directs:
        v = (d["icdf"].var(axis=1, ddof=1)).mean(axis=1)
        out.append(np.interp(t, d["t"], v))
    return np.mean(out, axis=0)


def compare(directs, run, a, q):
    """(predicted, measured) e / spread floor of the CPI run RUN over the directs' grid samples."""
    r = run["icdf"].shape[1]
    window = key(run.get("command", run.get("study_command", "")), "cpi.window", 10.0)
    step = float(np.min(np.diff(np.asarray(run["t_all"], dtype=float))))
    span = min(float(d["t"][-1]) for d in directs)
    grid = directs[0]["t"][(directs[0]["t"] <= span + 1e-6)]
    x = wp.held_to(dict(run, end_state=False), grid)
    ok = np.isfinite(x).all(axis=1) & (grid >= SETTLED)
    t = grid[ok]
    means = [wp.held_to(dict(d, end_state=False), t) for d in directs]
    measured_e2 = np.mean([np.mean((x[ok] - m) ** 2, axis=1) for m in means], axis=0)
    v = var_r(directs, t)
    added = np.array([sum(jump_variance(dt, a, q, window, step, r) for land, dt in jumps(run) if land <= s + 1e-6)
                      for s in t])
    floor2 = 2.0 * v / r
    return (math.sqrt(float(np.mean(floor2 + added)) / float(np.mean(floor2))),
            math.sqrt(float(np.mean(measured_e2)) / float(np.mean(floor2))), window, len(jumps(run)))


def uniform(directs, a, q, span, r, healing, window, step, speedup):
    """For jumps of DT = (S - 1) b after bursts of b, from SETTLED on, the last jump shortened to
    land at the end of SPAN as the integrators do: e / floor at the end of SPAN and RMS over it
    (against the directs' own spread); the error at equal compute, RMS over the span: CPI with R
    realizations against a direct ensemble of R / S', each against the mean of infinitely many
    (var_r / R + A against S' var_r / R); S', the schedule's speed-up over SPAN (the first SETTLED
    units and the bursts run by the DEM)."""
    b = healing + window
    dt = (speedup - 1.0) * b
    landings, now = [], SETTLED  # (landing time, DT)
    while now < span - 1e-9:
        jump = min(dt, span - now)
        landings.append((now + jump, jump))
        now += jump + b
    ts = np.arange(SETTLED, span + 1e-6, 5.0)
    added = np.array([sum(jump_variance(j, a, q, window, step, r) for land, j in landings if land <= t + 1e-9)
                      for t in ts])
    # the schedule's own speed-up: the first SETTLED units and the bursts are DEM time
    actual = span / (SETTLED + sum(min(b, span - land) for land, _ in landings if land < span - 1e-9))
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
    step = float(np.min(np.diff(np.asarray(directs[0]["t_all"], dtype=float))))
    print(f"directs: {len(directs)} of R = {r}, span {span:g}; offsets' variance {var:.4f} d_p^2 (sd {math.sqrt(var):.3f})")
    print("V(tau) [d_p^2]: " + ", ".join(f"{lag:g}: {x:.4f}" for lag, x in zip(LAGS, v))
          + f"  (2 var = {2 * var:.4f}); fit a = {a:.4f}, q = {q:.2e} d_p^2 per unit, c = {c:.2e} d_p^2 per unit^2")
    if args.cpi:
        print("\n| CPI run | window | jumps | DEM-time speed-up | e / spread floor predicted (noise only) | measured |")
        print("|---|---|---|---|---|---|")
    points = []
    for path in args.cpi:
        run = read(path)
        pred, meas, window, n = compare(directs, run, a, q)
        points.append((os.path.basename(path), speedup_of(run), pred, meas))
        print(f"| {os.path.basename(path)} | {window:g} | {n} | {points[-1][1]:.2f} | {pred:.2f} | {meas:.2f} |")
    print(f"\nUniform schedules (healing {args.healing:g} + window {args.window:g}, R = {r}, over {span:g} units): "
          "e / floor at the end and RMS over the span; at equal compute, CPI's error over a direct ensemble's of R / S")
    for s in (2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 14.0):
        end, whole, equal, actual = uniform(directs, a, q, span, r, args.healing, args.window, step, s)
        print(f"  DT = {(s - 1) * (args.healing + args.window):g} (S = {actual:.2f} over the span): {end:.2f} at the end, "
              f"{whole:.2f} over the span; at equal compute {equal:.2f}")
    if args.plot:
        plot(args, directs, a, q, span, r, step, points)


def speedup_of(run):
    """Simulated time over DEM time: the samples' span over the time they were sampled in."""
    t = np.asarray(run["t_all"], dtype=float)
    step = float(np.min(np.diff(t)))
    return float(t[-1]) / (len(t) * step)


def plot(args, directs, a, q, span, r, step, points):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    speedups = np.linspace(1.25, 16.0, 60)  # nominal (DT = (S - 1) b); drawn at the schedule's own S
    fig, ax = plt.subplots(figsize=(7, 4.2))
    splits = [(args.healing, args.window, "-")] + ([(10.0, 10.0, "--")] if (args.healing, args.window) != (10.0, 10.0) else [])
    for healing, window, style in splits:
        curve = [uniform(directs, a, q, span, r, healing, window, step, s) for s in speedups]
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
