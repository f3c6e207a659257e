"""The 95 % interval of an ensemble mean that the plot and summary scripts draw and count, in one
place so that every figure and number means the same thing.

An efdem ensemble has few realizations (the demo: R = 4), so the interval is Student-t's, not the
normal one: the mean of R realizations +- t(0.975, R - 1) s / sqrt(R), s the realizations' sample
standard deviation. With R = 4, t(0.975, 3) = 3.182; 1.96 in its place would cover about 86 %.
The run file's /samples/variance is already the unbiased (sample, divisor R - 1) variance
(docs/output.md; coarse/equation_free/ensemble_statistics.hpp), so s^2 is read as it is. R is the
realizations in the mean at each sample (/samples/realizations_used: R less those a failure
dropped). A single realization has no spread: no interval (NaN), and the plots say so.

Needs Debian's python3-scipy (scripts/install_deps.sh installs it).
"""
import numpy as np
from scipy import stats

LEVEL = 0.95
# What a band is, for legends and summaries (the plots append R).
BAND_LABEL = "95 % Student-t interval of the mean of R realizations"
NO_BAND_LABEL = "R = 1: no band (one realization has no spread)"


def t_quantile(dof):
    """t(0.975, dof), the two-sided 95 % quantile of Student's t; NaN where dof < 1."""
    dof = np.asarray(dof, dtype=float)
    with np.errstate(invalid="ignore"):
        return np.where(dof >= 1, stats.t.ppf(0.5 + LEVEL / 2, np.maximum(dof, 1)), np.nan)


def half_width(variance, realizations):
    """Half-width t(0.975, R - 1) sqrt(variance / R) of the 95 % interval of the mean of R
    realizations whose sample (unbiased) variance is `variance`; NaN where R < 2. Broadcasts:
    variance (samples, nodes) with R per sample as (samples, 1), or scalars."""
    R = np.asarray(realizations, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        return t_quantile(R - 1) * np.sqrt(np.asarray(variance, dtype=float) / np.where(R >= 2, R, np.nan))


def welch_half_width(var_a, n_a, var_b, n_b):
    """Half-width of Welch's 95 % interval of the difference of two independent means (sample
    variances var_a, var_b of n_a, n_b realizations): t(0.975, nu) sqrt(var_a/n_a + var_b/n_b),
    nu the Welch-Satterthwaite degrees of freedom. NaN where either ensemble has one realization."""
    n_a, n_b = (np.where(np.asarray(n, dtype=float) >= 2, np.asarray(n, dtype=float), np.nan) for n in (n_a, n_b))
    with np.errstate(invalid="ignore", divide="ignore"):
        qa, qb = np.asarray(var_a) / n_a, np.asarray(var_b) / n_b
        nu = (qa + qb) ** 2 / (qa ** 2 / (n_a - 1) + qb ** 2 / (n_b - 1))
        # Both variances 0 (identical realizations): any nu gives 0; take the smaller ensemble's.
        nu = np.where(qa + qb > 0, nu, np.minimum(n_a, n_b) - 1)
        return t_quantile(nu) * np.sqrt(qa + qb)


def exact_coverage_of_other_band(n_band, n_other):
    """The share of points at which the mean of an independent, exact ensemble of n_other
    realizations falls inside the 95 % interval of an ensemble of n_band (same spread, normal
    noise): the difference over the band's standard error is sqrt(1 + n_band / n_other) times a
    Student-t variable with n_band - 1 degrees of freedom. R = 4 and 4: 0.89. NaN if n_band < 2."""
    if n_band < 2 or n_other < 1:
        return float("nan")
    q = float(t_quantile(n_band - 1)) / np.sqrt(1.0 + n_band / n_other)
    return float(2 * stats.t.cdf(q, n_band - 1) - 1)


def sample_half_width(rows):
    """Rows (samples, realizations), NaN for a dropped realization: the mean over the finite
    entries of each sample, and the half-width of its 95 % interval (NaN with fewer than 2)."""
    rows = np.asarray(rows, dtype=float)
    n = np.sum(np.isfinite(rows), axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.nansum(rows, axis=1) / np.where(n > 0, n, np.nan)
        var = np.nansum((rows - mean[:, None]) ** 2, axis=1) / np.where(n > 1, n - 1, np.nan)
    return mean, half_width(var, n)
