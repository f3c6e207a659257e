#!/usr/bin/python3
"""Unit tests of bench/walk_budget.py on synthetic ensembles whose noise is known: each
realization's ICDF node is x_r(t) = f t + o_r + rho_r t + w_r(t), a frozen offset o_r (variance v0),
a rate of its own rho_r (variance c) and a walk w_r (variance q per unit)."""
import math
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bench"))
import walk_budget as wb  # noqa: E402

STEP = 0.5  # sampling interval, as the run files'
NODES = 4
F = 0.01  # the common drift [d_p per unit]


def ensemble(rng, r, t, v0, q, c=0.0):
    """(len(t), r, NODES): frozen offsets + own rates + walks, on the drift F t."""
    walk = np.cumsum(rng.normal(0.0, math.sqrt(q * STEP), size=(len(t), r, NODES)), axis=0)
    walk -= walk[0]
    offsets = rng.normal(0.0, math.sqrt(v0), size=(1, r, NODES))
    rates = rng.normal(0.0, math.sqrt(c), size=(1, r, NODES))
    return F * t[:, None, None] + offsets + rates * t[:, None, None] + walk


def direct(rng, r, span, v0, q, c=0.0):
    t = np.arange(STEP, span + 1e-9, STEP)
    x = ensemble(rng, r, t, v0, q, c)
    return {"t": t, "t_all": t, "icdf": x, "mean": x.mean(axis=1), "command": ""}


def cpi(rng, r, span, v0, q, healing, window, dt):
    """A members-lift CPI run on the same process: bursts of healing + window sampled, then each
    realization moved by DT times the least-squares slope of the ensemble mean over the window."""
    t_all, xs = [], []
    x = ensemble(rng, r, np.array([0.0]), v0, 0.0)[0]  # the offsets at t = 0
    now, first = 0.0, True
    while now < span - 1e-9:
        burst = 30.0 if first else healing + window  # warm-up 10 + the first burst, as the runs
        first = False
        n = int(round(burst / STEP))
        steps = rng.normal(0.0, math.sqrt(q * STEP), size=(n, r, NODES)) + F * STEP
        traj = x[None] + np.cumsum(steps, axis=0)
        t = now + STEP * np.arange(1, n + 1)
        t_all.extend(t)
        xs.extend(traj)
        fit = t >= t[-1] - window - 1e-9
        slope = np.polyfit(t[fit], traj[fit].mean(axis=1), 1)[0]
        now, x = t[-1], traj[-1]
        if now + dt + healing + window <= span + 1e-9:
            x = x + dt * slope
            now += dt
    t_all = np.array(t_all)
    icdf = np.array(xs)
    return {"t": t_all, "t_all": t_all, "icdf": icdf, "mean": icdf.mean(axis=1),
            "command": f"cpi.healing={healing:g} cpi.window={window:g}"}


class Noise(unittest.TestCase):
    def test_fit_separates_walk_rates_and_offsets(self):
        # 6 ensembles x 8 realizations x 4 nodes over 400 units, fitted at lags 5-120. Over 30
        # seeds the relative errors scatter with sd 4 % (q), 20 % (c: c tau^2 is 40 % of V at the
        # largest lag, and the quadratic term takes the scatter of the long lags), 11 % (the
        # offsets' variance v0 + q t + c t^2: 192 draws of the offsets, sqrt(2/192) = 10 %) and
        # the fast part a, absent here, up to 0.2 q x 5: the bounds are about 3.5 sd (q 15 %,
        # c 70 %, variance 38 %, a < 0.3 q x 5). A fit of a line alone would put c's share into q
        # (about +40 %) and fail; c = 0 fails by 100 %.
        rng = np.random.default_rng(7)
        v0, q, c = 0.15, 3e-4, 2e-6
        runs = [direct(rng, 8, 400.0, v0, q, c) for _ in range(6)]
        a, q_fit, c_fit, var, _ = wb.fit_noise(runs)
        self.assertLess(abs(q_fit / q - 1.0), 0.15)
        self.assertLess(abs(c_fit / c - 1.0), 0.70)
        mean_t = 0.5 * (wb.SETTLED + 400.0)
        expected = v0 + q * mean_t + c * np.mean(np.arange(wb.SETTLED, 400.0, STEP) ** 2)
        self.assertLess(abs(var / expected - 1.0), 0.38)
        self.assertLess(a, 0.3 * q * 5.0)  # no fast part in these walks

    def test_jump_variance_is_what_a_jump_adds_beyond_a_direct_run(self):
        # 20,000 walks (q = 3e-4) through a window of W = 18 (37 samples) from 0: the jump's state
        # B(W) + DT slope against a direct run's B(W) + B'(DT) (the walk going on for DT = 80).
        # Their variances' difference (about 510 q: 430 q the slope's, 80 q its covariance with
        # B(W) and the walk the jump replaces) against the formula. The Monte Carlo's relative sd
        # is about 1 % (measured over 40 seeds); the continuum 1.2 q / W is 2.6 % above the 37
        # samples' exact 1.169 q / W: 6 % holds both (the largest error over 40 seeds was 5 %).
        # Without the covariance term (80 q) the formula would be 16 % low.
        rng = np.random.default_rng(3)
        q, window, dt, r, draws = 3e-4, 18.0, 80.0, 1, 20000
        n = int(round(window / STEP)) + 1
        t = STEP * np.arange(n)
        walks = np.concatenate([np.zeros((draws, 1)),
                                np.cumsum(rng.normal(0.0, math.sqrt(q * STEP), size=(draws, n - 1)), axis=1)], axis=1)
        slopes = np.polyfit(t, walks.T, 1)[0]
        jumped = walks[:, -1] + dt * slopes
        walked = walks[:, -1] + rng.normal(0.0, math.sqrt(q * dt), size=draws)
        excess = float(np.var(jumped) - np.var(walked))
        self.assertLess(abs(excess / wb.jump_variance(dt, q, window, r) - 1.0), 0.06)

    def test_jumps_are_read_from_the_gaps(self):
        t = np.concatenate([np.arange(0.5, 30.01, 0.5), np.arange(70.5, 90.01, 0.5)])
        self.assertEqual(wb.jumps({"t_all": t}), [(70.0, 40.0)])


def walk_through_cpi(rng, slope, healing, draws, q, burst=20.0, dt=80.0, cycles=4):
    """The ensemble mean's walk (q per unit, from 0) through CYCLES bursts of BURST, each followed by
    a jump of DT from SLOPE: 'increment' (the burst's own increment over its whole length), 'least
    squares' (over the burst after HEALING) or 'pooled' (the mean of the last two bursts' least-squares
    slopes). Returns the state at the end (t = cycles (burst + dt)) of DRAWS independent runs."""
    n = int(round(burst / STEP))
    t = STEP * np.arange(n + 1)
    x, before = np.zeros(draws), None
    for _ in range(cycles):
        steps = rng.normal(0.0, math.sqrt(q * STEP), size=(draws, n))
        traj = np.concatenate([x[:, None], x[:, None] + np.cumsum(steps, axis=1)], axis=1)
        if slope == "increment":
            s = (traj[:, -1] - traj[:, 0]) / burst
        else:
            fit = t >= healing - 1e-9
            s = np.polyfit(t[fit], traj[:, fit].T, 1)[0]
            if slope == "pooled":
                s, before = (s if before is None else 0.5 * (s + before)), s
        x = traj[:, -1] + dt * s
    return x


class Bound(unittest.TestCase):
    def test_no_slope_from_the_bursts_carries_the_walk_below_s_times(self):
        # Bursts of 20, jumps of 80: S = 5 over 400 units. The bound (walk_budget.py's docstring):
        # the walk's variance at t is at least S q t, attained by the increment over whole bursts.
        # 20,000 draws: a variance's relative sd is sqrt(2 / 20000) = 1 %; the bounds are 3 sd.
        # Measured when written: increment 5.02, least squares over the whole burst 5.56, over
        # 2 + 18 5.95, pooled over two bursts 6.47 (pooling a walk's slopes weighs the earlier
        # burst's increments twice: further from uniform, so worse).
        q, draws, speedup, t_end = 3e-4, 20000, 5.0, 400.0
        tol = 3.0 * math.sqrt(2.0 / draws)
        rng = np.random.default_rng(5)
        ratio = {(slope, h): float(np.var(walk_through_cpi(rng, slope, h, draws, q))) / (q * t_end)
                 for slope, h in (("increment", 0.0), ("least squares", 0.0), ("least squares", 2.0),
                                  ("pooled", 2.0))}
        for key, r in ratio.items():
            self.assertGreater(r, speedup * (1.0 - tol), key)
        self.assertLess(abs(ratio[("increment", 0.0)] / speedup - 1.0), tol)  # attained: the bound is tight
        # Least squares over a whole burst of a walk: 1.2 q / W, its excess over the increment's
        # 0.2 q DT^2 / W per jump (4 x 0.2 x 6400 / 20 = 256 q, i.e. 0.64 q t): 5.64.
        self.assertLess(abs(ratio[("least squares", 0.0)] / (speedup + 0.64) - 1.0), tol)
        # What the docs derive from it: at S = 5 and phi = 0.52 (the tall bed at t = 600), at
        # least 1.43 floors and 0.78 of direct's error at equal compute.
        self.assertAlmostEqual(wb.floor_bound(5.0, 0.52), math.sqrt(1.0 + 4.0 * 0.52 / 2.0), places=12)
        self.assertAlmostEqual(round(wb.floor_bound(5.0, 0.52), 2), 1.43)
        self.assertAlmostEqual(round(wb.equal_compute_bound(5.0, 0.52), 2), 0.78)


class Input(unittest.TestCase):
    def test_bad_files_are_named(self):
        script = os.path.join(os.path.dirname(__file__), "..", "..", "bench", "walk_budget.py")
        with tempfile.TemporaryDirectory() as tmp:
            missing = os.path.join(tmp, "direct_a.h5")
            out = subprocess.run([sys.executable, script, "--directs", missing], capture_output=True, text=True)
            self.assertNotEqual(out.returncode, 0)
            self.assertIn(missing, out.stderr)
            self.assertNotIn("Traceback", out.stderr)


class Prediction(unittest.TestCase):
    def test_predicted_error_is_the_mean_measured_one(self):
        # 300 replicas: 4 direct ensembles and one CPI run (R = 8, bursts 2 + 18, 3 jumps of 80
        # over 330 units) each, the walk of the tall bed at U_s = 0.19 (q = 3e-4) with small frozen
        # offsets (v0 = 0.02), so that the jumps' part (about 1.8 floors^2) is resolved. The mean
        # of the measured (e / floor)^2 against the mean predicted: each replica's measured value
        # scatters (3 jumps, 4 directs), so the bound is 4 standard errors of the mean difference
        # (about 0.34) plus 5 % (0.14) for the continuum slope variance and the floor taken from the
        # directs' spread. The prediction is 2.78 against a measured 2.80 here; a q off by 1.5x or
        # 1/1.5x moves it by 0.9 and 0.6, outside the bound (about 0.48; checked when written, and
        # over 6 seeds the difference stayed within 0.03). Leaving out a jump's covariance term
        # (0.3 here) is within it: the test above is the one that catches that.
        rng = np.random.default_rng(11)
        v0, q = 0.02, 3e-4
        pred, meas = [], []
        for _ in range(300):
            directs = [direct(rng, 8, 330.0, v0, q) for _ in range(4)]
            p, m, window, n_jumps = wb.compare(directs, cpi(rng, 8, 330.0, v0, q, 2.0, 18.0, 80.0), q)
            self.assertEqual((window, n_jumps), (18.0, 3))
            pred.append(p * p)
            meas.append(m * m)
        diff = np.array(meas) - np.array(pred)
        bound = 4.0 * diff.std(ddof=1) / math.sqrt(len(diff)) + 0.05 * np.mean(pred)
        self.assertLess(abs(diff.mean()), bound)
        self.assertGreater(np.mean(pred), 2.0)  # the jumps' share is most of it


if __name__ == "__main__":
    unittest.main()
