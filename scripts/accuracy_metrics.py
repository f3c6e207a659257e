"""Error and cost metrics of a CPI run against a direct (brute-force) ensemble (issue 9).

Pure functions on arrays, unit-tested on synthetic data in tests/scripts/test_accuracy_metrics.py.
Heights in d_p, times in sqrt(d_p/g), wall times in seconds.
"""
import math

import numpy as np


def align(t_ref, values_ref, t):
    """values_ref (n_ref x m, sampled at t_ref) linearly interpolated to the times t (n x m).
    Times outside [t_ref[0], t_ref[-1]] are dropped: returns (mask of kept t, values)."""
    t_ref = np.asarray(t_ref, float)
    t = np.asarray(t, float)
    keep = (t >= t_ref[0] - 1e-9) & (t <= t_ref[-1] + 1e-9)
    v = np.empty((int(keep.sum()), values_ref.shape[1]))
    for j in range(values_ref.shape[1]):
        v[:, j] = np.interp(t[keep], t_ref, values_ref[:, j])
    return keep, v


def rms_error(mean, mean_ref):
    """RMS over all samples and p-nodes of mean - mean_ref [d_p]."""
    d = np.asarray(mean, float) - np.asarray(mean_ref, float)
    return float(np.sqrt(np.mean(d * d)))


def standard_error(variance, realizations):
    """RMS over samples and nodes of the standard error of an ensemble mean, sqrt(var/R) [d_p]."""
    return float(np.sqrt(np.mean(np.asarray(variance, float) / realizations)))


def normalized_error(mean, mean_ref, var_ref, r_ref, var_cpi=None, r_cpi=None):
    """RMS error divided by the standard error expected of the difference of two independent
    ensemble means, sqrt(var_ref/R_ref + var_cpi/R_cpi) (the reference's alone when the CPI
    variance is not given). About 1 when CPI is right within noise."""
    noise = np.asarray(var_ref, float) / r_ref
    if var_cpi is not None:
        noise = noise + np.asarray(var_cpi, float) / r_cpi
    return rms_error(mean, mean_ref) / float(np.sqrt(np.mean(noise)))


def split_floors(members):
    """How far two halves of one ensemble lie apart, for every way of splitting its R members
    (R even; members: samples x R x m) into two halves with member 0 in the first:
    RMS over samples and nodes of mean(half 1) - mean(half 2), one value per split
    (C(R-1, R/2-1) of them: 35 for R = 8). Each is a noise floor of two independent ensembles
    of R/2; their range is the draw-to-draw scatter of one such floor, and divided by sqrt(2)
    they estimate the floor of two ensembles of R (Var(D_a - D_b) = 2 var/R)."""
    import itertools

    members = np.asarray(members, float)
    r = members.shape[1]
    if r < 2 or r % 2:
        raise ValueError(f"split_floors needs an even number of members >= 2, not {r}")
    out = []
    for rest in itertools.combinations(range(1, r), r // 2 - 1):
        first = [0, *rest]
        second = [k for k in range(r) if k not in first]
        out.append(rms_error(members[:, first].mean(axis=1), members[:, second].mean(axis=1)))
    return np.array(out)


def speedup(sim_time, wall, realizations, ref_sim_time, ref_wall, ref_realizations):
    """Effective speed-up: simulated realization-time per wall second of the run, against that
    of the direct ensemble (both on the same ranks), i.e. against a direct ensemble of equal R."""
    rate = sim_time * realizations / wall
    ref_rate = ref_sim_time * ref_realizations / ref_wall
    return rate / ref_rate


def predicted_projection_noise(dt_projective, window, samples_in_window, sigma):
    """The noise a projective step adds: DT/W sqrt(12/n) sigma (physics.md §10), sigma the
    standard deviation of one sample of the (ensemble-mean) coarse variable [d_p]."""
    if window <= 0 or samples_in_window < 2:
        return math.nan
    return dt_projective / window * math.sqrt(12.0 / samples_in_window) * sigma


def temporal_noise(t, values, window):
    """RMS residual of `values` (n x m) about least-squares lines fitted over consecutive
    windows of length `window` [d_p]: the sample-to-sample noise a slope estimate sees. (The
    spread between realizations is not it: a bed-to-bed offset that stays put does not disturb
    a slope.)"""
    t = np.asarray(t, float)
    values = np.asarray(values, float)
    res = []
    start = t[0]
    while start + window <= t[-1] + 1e-9:
        sel = (t >= start - 1e-9) & (t <= start + window + 1e-9)
        if sel.sum() >= 3:
            tt = t[sel]
            for j in range(values.shape[1]):
                c = np.polyfit(tt, values[sel, j], 1)
                res.append(values[sel, j] - np.polyval(c, tt))
        start += window
    if not res:
        return math.nan
    r = np.concatenate(res)
    return float(np.sqrt(np.mean(r * r)))


def pareto_front(points):
    """Indices of the (cost, error) points not dominated by another (lower cost and error)."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], math.inf
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def error_against_truth(mean, members_ref):
    """RMS over samples and nodes of mean - mu, mu the infinite-ensemble mean, estimated against a
    reference ensemble (members_ref: samples x N x m, independent of `mean`): E|x - m_ref|^2 =
    E|x - mu|^2 + var/N, so e^2 = RMS^2(x - m_ref) - mean(var)/N, var the members' unbiased
    variance per sample and node. Clipped at 0 (an estimate below the reference's own noise)."""
    members_ref = np.asarray(members_ref, float)
    n = members_ref.shape[1]
    if n < 2:
        raise ValueError(f"error_against_truth needs a reference of >= 2 members, not {n}")
    ref = members_ref.mean(axis=1)
    var = members_ref.var(axis=1, ddof=1)
    e2 = rms_error(mean, ref) ** 2 - float(np.mean(var)) / n
    return math.sqrt(max(e2, 0.0))


def subset_errors(members, size, draws=200, seed=1):
    """The error against the infinite-ensemble mean of a direct ensemble of `size` realizations,
    from random subsets of one larger ensemble (members: samples x N x m): each subset's mean
    against the mean of the other N - size members, corrected for their noise as in
    error_against_truth (with the variance of all N). Returns the RMS over `draws` subsets (all
    C(N, size) when fewer) of that error, i.e. sqrt(E e^2)."""
    import itertools

    members = np.asarray(members, float)
    n = members.shape[1]
    if not 1 <= size <= n - 2:
        raise ValueError(f"subset_errors: size {size} must be in [1, N - 2] = [1, {n - 2}]")
    var = float(np.mean(members.var(axis=1, ddof=1)))
    combos = list(itertools.combinations(range(n), size)) if math.comb(n, size) <= draws else None
    rng = np.random.default_rng(seed)
    e2 = []
    for k in range(len(combos) if combos else draws):
        pick = list(combos[k]) if combos else sorted(rng.choice(n, size, replace=False))
        rest = [i for i in range(n) if i not in pick]
        d = members[:, pick].mean(axis=1) - members[:, rest].mean(axis=1)
        e2.append(float(np.mean(d * d)) - var / (n - size))
    return math.sqrt(max(float(np.mean(e2)), 0.0))
