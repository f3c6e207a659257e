#!/usr/bin/python3
"""Unit tests of the plots' intervals (scripts/ensemble_bands.py) and layout (scripts/plot_layout.py)
on synthetic data (issue 35, item 6): the intervals cover what they say, R = 1 has none, labels do
not overprint, a legend beside the axes covers none of them."""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))
import ensemble_bands as eb  # noqa: E402
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import plot_layout  # noqa: E402


def overlap(a, b):
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


class Intervals(unittest.TestCase):
    def test_half_width_of_four_is_student_t(self):
        # t(0.975, 3) = 3.182 in every table (4 significant figures, so within 5e-4 of the exact
        # 3.18245): with s = 2 and R = 4, s / sqrt(R) = 1 and the half-width is t itself. 1e-3
        # accepts the table's rounding and rejects 1.96 (the normal quantile) by a factor 600.
        self.assertAlmostEqual(float(eb.half_width(4.0, 4)), 3.182, delta=1e-3)
        # Per sample R as a column: (samples, nodes) variances, R = 4 and 9 (t(0.975, 8) = 2.306).
        h = eb.half_width(np.full((2, 3), 9.0), np.array([[4], [9]]))
        np.testing.assert_allclose(h, [[3.182 * 1.5] * 3, [2.306 * 1.0] * 3], atol=1e-3)

    def test_one_realization_has_no_interval(self):
        self.assertTrue(np.isnan(eb.half_width(0.0, 1)))
        mean, half = eb.sample_half_width([[1.0, 3.0, np.nan], [2.0, np.nan, np.nan]])
        np.testing.assert_allclose(mean, [2.0, 2.0])
        self.assertTrue(np.isfinite(half[0]) and np.isnan(half[1]))
        self.assertTrue(np.isnan(eb.welch_half_width(1.0, 1, 1.0, 4)))
        self.assertTrue(np.isnan(eb.exact_coverage_of_other_band(1, 4)))

    def test_coverage_of_the_mean_of_four_is_95_percent(self):
        # 200,000 ensembles of 4 normal realizations: the share whose interval holds the true mean
        # has sd sqrt(0.95 x 0.05 / 2e5) = 4.9e-4; 0.003 is 6 sd. 1.96 s / 2 would cover 0.855.
        x = np.random.default_rng(35).normal(size=(200_000, 4))
        mean, half = eb.sample_half_width(x)
        self.assertAlmostEqual(np.mean(np.abs(mean) <= half), 0.95, delta=0.003)

    def test_welch_interval_of_a_difference_covers_about_95_percent(self):
        # Two independent ensembles of 4 and 8 with spreads 1 and 2: Welch's interval is
        # approximate; its coverage here is within 0.01 of 95 % (sd of the estimate 4.9e-4).
        rng = np.random.default_rng(36)
        a, b = rng.normal(size=(200_000, 4)), 2 * rng.normal(size=(200_000, 8))
        half = eb.welch_half_width(a.var(axis=1, ddof=1), 4, b.var(axis=1, ddof=1), 8)
        self.assertAlmostEqual(np.mean(np.abs(a.mean(axis=1) - b.mean(axis=1)) <= half), 0.95, delta=0.01)

    def test_exact_coverage_of_the_other_band_matches_a_simulation(self):
        # An exact, independent ensemble's mean inside the direct ensemble's interval (R = 4, 4):
        # the formula's share against 200,000 simulated pairs (sd 7e-4; 0.004 is 6 sd).
        rng = np.random.default_rng(37)
        d, c = rng.normal(size=(200_000, 4)), rng.normal(size=(200_000, 4))
        mean, half = eb.sample_half_width(d)
        simulated = np.mean(np.abs(c.mean(axis=1) - mean) <= half)
        self.assertAlmostEqual(eb.exact_coverage_of_other_band(4, 4), simulated, delta=0.004)


class Layout(unittest.TestCase):
    # Six points within a few pixels of each other (like tol0.08 / tol0.16 of the adaptive study)
    # and two far ones.
    xs = [1.00, 1.01, 1.02, 1.00, 1.01, 1.03, 3.0, 0.2]
    ys = [1.00, 1.01, 0.99, 1.02, 0.98, 1.00, 4.0, 0.5]
    names = ["tol0.16", "tol0.08", "tol0.32", "tol0.16_members", "fixed_dt40", "fixed_dt80", "far", "low"]

    def figure(self):
        fig, ax = plt.subplots(figsize=(6, 4), dpi=100)
        ax.plot(self.xs, self.ys, "o")
        ax.plot([0, 4], [1, 1], "k--")
        ax.set_xlim(0, 4)
        ax.set_ylim(0, 5)
        return fig, ax

    def test_labels_at_a_fixed_offset_overprint(self):
        # What the plots did: the same offset for every label. The check below must see it.
        fig, ax = self.figure()
        anns = [ax.annotate(n, (x, y), xytext=(3, 3), textcoords="offset points", fontsize=7)
                for x, y, n in zip(self.xs, self.ys, self.names)]
        boxes = plot_layout.label_boxes(anns)
        self.assertTrue(any(overlap(a, b) for i, a in enumerate(boxes) for b in boxes[i + 1:]))
        plt.close(fig)

    def test_placed_labels_overprint_neither_labels_nor_points(self):
        fig, ax = self.figure()
        fig.tight_layout()
        anns = plot_layout.place_labels(ax, self.xs, self.ys, self.names)
        boxes = plot_layout.label_boxes(anns)
        pts = ax.transData.transform(np.column_stack([self.xs, self.ys]))
        frame = ax.get_window_extent()
        for i, a in enumerate(boxes):
            for b in boxes[i + 1:]:
                self.assertFalse(overlap(a, b), f"labels {a} and {b} overlap")
            for x, y in pts:
                self.assertFalse(overlap(a, (x - 3, y - 3, x + 3, y + 3)), f"label {a} covers the point {x, y}")
            self.assertTrue(frame.x0 <= a[0] and a[2] <= frame.x1 and frame.y0 <= a[1] and a[3] <= frame.y1)
        self.assertEqual(sorted(a.get_text() for a in anns), sorted(self.names))
        plt.close(fig)

    def test_legend_beside_the_axes_covers_no_data(self):
        for side in ("right", "bottom"):
            fig, ax = self.figure()
            handles = [plot_layout.text_entry(f"a long key line number {k} that says what a code means")
                       for k in range(12)]
            legend = plot_layout.legend_beside(fig, handles, side=side)
            fig.canvas.draw()
            lb, ab = legend.get_window_extent(), ax.get_window_extent()
            self.assertFalse(overlap((lb.x0, lb.y0, lb.x1, lb.y1), (ab.x0, ab.y0, ab.x1, ab.y1)), side)
            # Inside the figure: nothing is cut off.
            self.assertTrue(lb.x0 >= 0 and lb.y0 >= 0 and lb.x1 <= fig.bbox.x1 + 1 and lb.y1 <= fig.bbox.y1 + 1, side)
            plt.close(fig)


if __name__ == "__main__":
    unittest.main()
