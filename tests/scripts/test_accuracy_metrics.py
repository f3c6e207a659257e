#!/usr/bin/python3
"""Unit tests of scripts/accuracy_metrics.py on synthetic data (issue 9)."""
import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))
import accuracy_metrics as am  # noqa: E402


class Metrics(unittest.TestCase):
    def test_align_interpolates_and_drops_outside(self):
        t_ref = np.array([0.0, 1.0, 2.0])
        v = np.array([[0.0, 10.0], [1.0, 20.0], [2.0, 30.0]])
        keep, a = am.align(t_ref, v, [0.5, 1.0, 3.0])
        self.assertEqual(list(keep), [True, True, False])
        np.testing.assert_allclose(a, [[0.5, 15.0], [1.0, 20.0]])

    def test_rms_error_exact(self):
        # A constant offset c on every node and sample has RMS error |c|.
        ref = np.random.default_rng(1).normal(size=(40, 19))
        self.assertAlmostEqual(am.rms_error(ref + 0.3, ref), 0.3, places=14)
        self.assertEqual(am.rms_error(ref, ref), 0.0)

    def test_subset_errors_scale_as_one_over_root_size(self):
        # 24 members of pure noise (sd 1), 200 samples x 19 nodes: an ensemble of S has error
        # 1/sqrt(S) against the true mean (0). Each draw's e^2 averages 3,800 values (relative sd
        # of e^2 ~ sqrt(2/3800) = 2.3 %), 200 draws average further: 3 % on the RMS is > 3 sd.
        m = np.random.default_rng(3).normal(size=(200, 24, 19))
        for size in (1, 2, 4, 8, 16):
            self.assertAlmostEqual(am.subset_errors(m, size) * math.sqrt(size), 1.0, delta=0.03)
        with self.assertRaises(ValueError):
            am.subset_errors(m, 23)

    def test_error_against_truth_removes_the_references_noise(self):
        # An independent ensemble of 8 against a reference of 24 (both sd-1 noise): the raw RMS is
        # sqrt(1/8 + 1/24) = 0.408, the estimate against the truth 1/sqrt(8) = 0.354. One draw of
        # 3,800 values: the estimate's relative sd is ~2.5 %, so 7 % is about 3 sd.
        rng = np.random.default_rng(4)
        ref = rng.normal(size=(200, 24, 19))
        x = rng.normal(size=(200, 8, 19)).mean(axis=1)
        self.assertAlmostEqual(am.rms_error(x, ref.mean(axis=1)), math.sqrt(1 / 8 + 1 / 24), delta=0.03)
        self.assertAlmostEqual(am.error_against_truth(x, ref) * math.sqrt(8), 1.0, delta=0.07)
        # A bias b adds in quadrature: b = 0.5 on every node gives sqrt(1/8 + 0.25) = 0.612.
        self.assertAlmostEqual(am.error_against_truth(x + 0.5, ref), math.sqrt(1 / 8 + 0.25), delta=0.03)

    def test_split_floors_count_and_scale(self):
        # 8 members of pure noise (sd 1), 400 samples x 19 nodes: 35 splits, each the RMS of a
        # difference of two means of 4, whose sd is sqrt(2/4) = 0.707; with 7,600 values per
        # split the RMS is within 3 % of it (its relative sd is ~1/sqrt(2 x 7,600) = 0.8 %).
        rng = np.random.default_rng(5)
        f = am.split_floors(rng.normal(size=(400, 8, 19)))
        self.assertEqual(len(f), 35)
        self.assertTrue(np.all(np.abs(f / math.sqrt(0.5) - 1.0) < 0.03))
        # A member offset that persists (frozen, as in a packed bed) makes the splits differ:
        # member 0 shifted by 2 moves every split's floor by ~2/4 in one direction.
        x = rng.normal(scale=0.01, size=(50, 8, 3))
        x[:, 0] += 2.0
        np.testing.assert_allclose(am.split_floors(x), 0.5, atol=0.01)
        with self.assertRaises(ValueError):
            am.split_floors(np.zeros((3, 3, 2)))

    def test_normalized_error_of_pure_noise_is_about_one(self):
        # Two independent ensembles of R realizations of the same truth: the difference of their
        # means has variance 2 var/R, so the normalized error is ~1 (within 10 % for 19 x 400
        # nodes and samples: the relative s.e. of an RMS over 7600 values is ~1 %).
        rng = np.random.default_rng(7)
        R, var = 8, 0.25
        truth = np.linspace(0, 10, 19)[None, :] + np.zeros((400, 1))
        a = truth + rng.normal(scale=math.sqrt(var / R), size=truth.shape)
        b = truth + rng.normal(scale=math.sqrt(var / R), size=truth.shape)
        v = np.full(truth.shape, var)
        e = am.normalized_error(a, b, v, R, v, R)
        self.assertAlmostEqual(e, 1.0, delta=0.1)
        # A bias of 3 standard errors shows as ~sqrt(1 + 9) = 3.2.
        e_biased = am.normalized_error(a + 3 * math.sqrt(2 * var / R), b, v, R, v, R)
        self.assertAlmostEqual(e_biased, math.sqrt(10.0), delta=0.3)

    def test_standard_error(self):
        self.assertAlmostEqual(am.standard_error(np.full((3, 4), 4.0), 16), 0.5)

    def test_speedup_accounting(self):
        # Direct: 4 realizations x 100 time units in 400 s. CPI: same R, 100 time units in 80 s
        # -> 5x. CPI with 2 realizations in 40 s covers half the realization-time: 5x too.
        self.assertAlmostEqual(am.speedup(100, 80, 4, 100, 400, 4), 5.0)
        self.assertAlmostEqual(am.speedup(100, 40, 2, 100, 400, 4), 5.0)
        self.assertAlmostEqual(am.speedup(100, 400, 4, 100, 400, 4), 1.0)

    def test_predicted_projection_noise(self):
        # DT = W: the projection error is sqrt(12/n) sigma; n = 12 gives sigma itself.
        self.assertAlmostEqual(am.predicted_projection_noise(10, 10, 12, 0.2), 0.2)
        self.assertAlmostEqual(am.predicted_projection_noise(80, 10, 12, 0.2), 1.6)
        self.assertTrue(math.isnan(am.predicted_projection_noise(10, 0, 12, 0.2)))

    def test_temporal_noise(self):
        # A linear trend plus white noise of s.d. 0.1: residuals about the local lines have an
        # RMS of 0.1 sqrt((n-2)/n) (two fitted parameters per window of n = 21 samples): 0.095,
        # within 5 % for 20 x 19 x 21 residuals. A pure trend has no temporal noise.
        rng = np.random.default_rng(3)
        t = np.arange(0, 200.01, 0.5)
        trend = 0.05 * t[:, None] + np.linspace(0, 5, 19)[None, :]
        self.assertAlmostEqual(am.temporal_noise(t, trend, 10.0), 0.0, places=10)
        noisy = trend + rng.normal(scale=0.1, size=trend.shape)
        self.assertAlmostEqual(am.temporal_noise(t, noisy, 10.0), 0.1 * math.sqrt(19 / 21), delta=0.005)

    def test_pareto_front(self):
        pts = [(1, 5), (2, 3), (3, 4), (4, 1), (5, 1)]
        self.assertEqual(am.pareto_front(pts), [0, 1, 3])


if __name__ == "__main__":
    unittest.main()
