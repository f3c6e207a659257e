#!/usr/bin/python3
"""Does the travelling wave bias the ensemble slope beyond what its standard error says? (issue 16,
waves with an ensemble.) Reads a direct run file (every realization's light ICDF at every sample),
and for windows of several lengths W slid over the run after the transient:

* s_hat: the ensemble-mean least-squares slope over the window; se: the spread of the
  realizations' own slopes / sqrt(R) (what the adaptive controller uses);
* trend: the least-squares slope of the ensemble mean over a long window (--trend, default 40) with
  the same centre: what the slow dynamics does there;
* z = RMS(s_hat - trend) / RMS(se) over windows and p-nodes. z ~ 1: the wave's effect on the slope is
  what se says (the phases of the realizations are independent, so it is noise of the ensemble
  slope, not a bias the controller misses); z >> 1: a bias se does not see.

    /usr/bin/python3 bench/wave_slope_bias.py RUN.h5 [--start 30] [--windows 5 10 15 20] [-o out.md]

z is not exactly 1 even without any bias: the trend itself is estimated (its own noise is counted
in the RMS, about (W/trend)^(3/2) of se for a least-squares slope) and se from R realizations has
a relative scatter of ~1/sqrt(2(R-1)) per node.
"""
import argparse

import h5py
import numpy as np


def ls_slopes(t, y):
    """Least-squares slopes of y (n x ...) against t (n), along axis 0."""
    tc = t - t.mean()
    return np.tensordot(tc, y - y.mean(axis=0), axes=(0, 0)) / np.sum(tc * tc)


def period_mean_slopes(t, y, period):
    """(mean over the last period - mean over the period before) / period, along axis 0."""
    t_end = t[-1]
    late = t > t_end - period + 1e-9
    early = (t > t_end - 2 * period + 1e-9) & ~late
    return (y[late].mean(axis=0) - y[early].mean(axis=0)) / period


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("run")
    ap.add_argument("--start", type=float, default=30.0, help="first window start (after the transient)")
    ap.add_argument("--windows", type=float, nargs="+", default=[5.0, 10.0, 15.0, 20.0])
    ap.add_argument("--trend", type=float, default=40.0)
    ap.add_argument("--period", type=float, help="also the period-mean slope over windows of 2 periods")
    ap.add_argument("-o", "--output")
    a = ap.parse_args()
    with h5py.File(a.run, "r") as f:
        t = f["samples/time"][:]
        icdf = f["samples/icdf"][:]  # samples x R x m
        u = f["parameters"][()]
    u = u.decode() if isinstance(u, bytes) else str(u)
    speed = next((line.split(" = ")[1].split()[0] for line in u.splitlines()
                  if line.startswith("gas_drag.superficial_velocity = ")), "?")
    r = icdf.shape[1]
    mean = icdf.mean(axis=1)
    lines = [f"`{a.run}`: U_s = {speed}, R = {r}, t = {t[0]:g}..{t[-1]:g}, trend window {a.trend:g}", "",
             "| window W | windows | RMS se [d_p/t.u.] | RMS(s_hat - trend) | z |", "|---|---|---|---|---|"]
    cases = [(w, "least squares") for w in a.windows]
    if a.period:
        cases.append((2 * a.period, "period mean"))
    lines[2] = "| window W | estimator | windows | RMS se [d_p/t.u.] | RMS(s_hat - trend) | z |"
    lines[3] = "|---|---|---|---|---|---|"
    for w, estimator in cases:
        se2, dev2, n = [], [], 0
        for t0 in np.arange(a.start, t[-1] - w + 1e-9, w / 2):
            c = t0 + w / 2
            if c - a.trend / 2 < t[0] or c + a.trend / 2 > t[-1]:
                continue
            sel = (t >= t0 - 1e-9) & (t <= t0 + w + 1e-9)
            long = (t >= c - a.trend / 2 - 1e-9) & (t <= c + a.trend / 2 + 1e-9)
            members = ls_slopes(t[sel], icdf[sel]) if estimator == "least squares" else \
                period_mean_slopes(t[sel], icdf[sel], a.period)  # R x m
            s_hat = members.mean(axis=0)
            se = members.std(axis=0, ddof=1) / np.sqrt(r)
            trend = ls_slopes(t[long], mean[long])
            se2.append(np.mean(se ** 2))
            dev2.append(np.mean((s_hat - trend) ** 2))
            n += 1
        if n == 0:
            lines.append(f"| {w:g} | {estimator} | 0 | | | |")
            continue
        rs, rd = np.sqrt(np.mean(se2)), np.sqrt(np.mean(dev2))
        lines.append(f"| {w:g} | {estimator} | {n} | {rs:.4f} | {rd:.4f} | {rd / rs:.2f} |")
    text = "\n".join(lines) + "\n"
    print(text)
    if a.output:
        with open(a.output, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
