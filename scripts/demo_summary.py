#!/usr/bin/python3
"""The demo's summary (scripts/demo.sh): a direct and a CPI run of the same scene compared at the
same times, and what the CPI run cost, each number labelled with what it is.

    /usr/bin/python3 scripts/demo_summary.py DIRECT.h5 CPI.h5

* Agreement, over the sample times both runs recorded (CPI records its bursts only) and every
  node of the light-particle ICDF: the RMS difference of the two ensemble means; the share of CPI
  points inside the direct ensemble's 95 % Student-t interval of its mean at the same time
  (mean +- t(0.975, R - 1) sqrt(var / R), scripts/ensemble_bands.py); and the share inside Welch's
  95 % Student-t interval of the difference of the two means (both ensembles' noise,
  Welch-Satterthwaite degrees of freedom; about 95 % if CPI were exact). With independent seeds
  and equal spreads, an exact CPI would lie inside the direct interval for fewer of the points
  (the difference of two such means has sqrt(1 + R_direct / R_cpi) times the standard error of
  one): the summary prints that share for the two R (R = 4 and 4: 89 %). A run of one
  realization has no interval: the summary says so instead of a share.
  Beside them the noise floor of this comparison: the RMS difference two exact, independent
  ensembles of these sizes would show, sqrt(mean(se_direct^2 + se_cpi^2)) from the two
  ensembles' own spreads, and CPI's RMS difference as a multiple of it.
* Cost: the DEM-time speed-up of CPI (simulated time / DEM time per realization, the gain of the
  jumps kept; rejected ones are paid for) and the wall-time ratio direct / CPI of the run loops
  (and of the whole runs, settling of the beds included), which also carries the coarse layer's
  overhead and the machine's load. Only runs of equal spans are compared: a ratio of wall times
  over different spans says nothing about CPI.

Exit 2 with a message for missing or unsuitable files (not efdem run files, modes other than
direct then cpi, other p-grids, no common sample time, different simulated spans).
"""
import sys

import numpy as np

import ensemble_bands
import run_files

NEEDED = ["p", "samples/time", "samples/mean_icdf", "samples/variance"]


def load(path, mode):
    f = run_files.open_run(path, NEEDED)
    with f:
        got = run_files.text(f.attrs["mode"])
        if got != mode:
            raise run_files.UsageError(f"{path}: a {got} run; expected the {mode} run here "
                                       "(arguments: DIRECT.h5 CPI.h5)")
        run = {k: run_files.get(f, k)[:] for k in NEEDED}
        run["realizations_used"] = run_files.realizations_per_sample(f)
        for k in ("realizations", "simulated_time", "dem_time", "wall_seconds", "particle_steps"):
            if k not in f.attrs:
                raise run_files.UsageError(f"{path}: no '{k}' attribute (end_status "
                                           f"'{run_files.text(f.attrs.get('end_status', '?'))}': did the run end?)")
            run[k] = float(f.attrs[k])
        # Run files before settling was timed have neither: the run loop is all that is known.
        run["settling_wall_seconds"] = float(f.attrs.get("settling_wall_seconds", np.nan))
        run["total_wall_seconds"] = float(f.attrs.get("total_wall_seconds", np.nan))
        run["end_status"] = run_files.text(f.attrs.get("end_status", "?"))
        run["seed"] = int(f.attrs.get("seed", 0))
        run["species"] = run_files.text(f.attrs.get("observed_species", "light"))
        run["controller"] = run_files.text(f["cpi/controller_summary"][()]) if "cpi/controller_summary" in f else ""
        dt = f["cpi/dt"][:] if "cpi/dt" in f else np.zeros(0)
        status = [run_files.text(s) for s in f["cpi/status"][:]] if "cpi/status" in f else [""] * len(dt)
        run["jumps"] = int(sum(1 for d, s in zip(dt, status) if d > 0 and s != "rejected"))
        run["rejected"] = int(sum(1 for s in status if s == "rejected"))
    return run


def agreement(d, c):
    """Direct d and CPI c at their common sample times: dict of the numbers, or UsageError."""
    if d["p"].shape != c["p"].shape or not np.allclose(d["p"], c["p"]):
        raise run_files.UsageError("the two runs have different p-grids (observe.quantiles): not comparable node by node")
    common, i_d, i_c = np.intersect1d(np.round(d["samples/time"], 6), np.round(c["samples/time"], 6),
                                      return_indices=True)
    if len(common) == 0:
        raise run_files.UsageError("the two runs share no sample time (other observe.interval or time spans)")
    md, mc = d["samples/mean_icdf"][i_d], c["samples/mean_icdf"][i_c]
    # The realizations in each mean at each common time, as a column against the nodes.
    n_d, n_c = d["realizations_used"][i_d][:, None], c["realizations_used"][i_c][:, None]
    var_d, var_c = d["samples/variance"][i_d], c["samples/variance"][i_c]  # unbiased (R - 1) variances
    se_d, se_c = np.sqrt(var_d / n_d), np.sqrt(var_c / n_c)
    diff = mc - md
    ok = np.isfinite(diff)  # a mean is NaN only where no realization was left
    if not ok.any():
        raise run_files.UsageError("no finite ensemble mean at the common sample times")
    floor = np.sqrt(se_d ** 2 + se_c ** 2)  # RMS difference of two exact independent ensembles
    band_d = ensemble_bands.half_width(var_d, n_d)  # NaN where the direct run has one realization
    band_diff = ensemble_bands.welch_half_width(var_d, n_d, var_c, n_c)
    return {
        "times": len(common), "t_first": float(common[0]), "t_last": float(common[-1]),
        "points": int(ok.sum()),
        "rms": float(np.sqrt(np.mean(diff[ok] ** 2))),
        "floor": float(np.sqrt(np.mean(floor[ok] ** 2))),
        "inside_direct_band": share_inside(diff[ok], band_d[ok]),
        "inside_difference_band": share_inside(diff[ok], band_diff[ok]),
        "exact_inside_direct_band": ensemble_bands.exact_coverage_of_other_band(d["realizations"], c["realizations"]),
    }


def share_inside(diff, half):
    """The share of the differences inside +- half, or NaN where no point has an interval
    (one realization)."""
    has = np.isfinite(half)
    return float(np.mean(np.abs(diff[has]) <= half[has])) if has.any() else float("nan")


def percent(share, none):
    return f"{100 * share:.0f} %" if np.isfinite(share) else none


def ratio(a, b):
    return a / b if b > 0 and np.isfinite(a) and np.isfinite(b) else np.nan


def equal_spans(d, c):
    """UsageError unless both runs simulated the same span (up to round-off)."""
    a, b = d["simulated_time"], c["simulated_time"]
    if abs(a - b) > 1e-6 * max(1.0, abs(a), abs(b)):
        raise run_files.UsageError(
            f"the direct run simulated {a:.6g} time units and the CPI run {b:.6g}: their wall times and "
            "costs compare only over equal spans (run both with the same run.duration)")


def summary(d, c):
    """The summary's lines (a list of str)."""
    equal_spans(d, c)
    a = agreement(d, c)
    lines = []
    for name, r in (("direct", d), ("cpi", c)):
        settle = ("" if np.isnan(r["settling_wall_seconds"]) else
                  f" + {r['settling_wall_seconds']:.0f} s settling the beds = {r['total_wall_seconds']:.0f} s")
        jumps = (f", {r['jumps']} projective jump(s) kept, {r['rejected']} rejected (a rejected jump's burst is "
                 "paid for)" if name == "cpi" else "")
        lines.append(f"{name:>6}: R = {r['realizations']:.0f}, seed {r['seed']}, {r['end_status']}; simulated "
                     f"{r['simulated_time']:.4g} time units with {r['dem_time']:.4g} of DEM per realization{jumps}; "
                     f"wall {r['wall_seconds']:.0f} s run{settle}")
    lines.append(f"agreement at the {a['times']} sample times both recorded (t = {a['t_first']:.4g} .. "
                 f"{a['t_last']:.4g}; CPI samples only its bursts), {a['points']} (time, node) points of the "
                 f"{d['species']} ICDF:")
    if d["seed"] == c["seed"]:
        lines.append(f"  (both runs have seed {d['seed']}: they share their noise until CPI's first jump, which "
                     "flatters the agreement; the demo gives CPI its own seed)")
    lines.append(f"  RMS difference of the ensemble means (CPI - direct): {a['rms']:.3f} d_p")
    lines.append(f"  noise floor of this comparison (RMS difference of two exact independent ensembles of these "
                 f"sizes, from their own spread): {a['floor']:.3f} d_p; CPI's difference is "
                 f"{ratio(a['rms'], a['floor']):.2f}x the floor")
    no_band = "no interval (R = 1: one realization has no spread)"
    lines.append(f"  CPI inside the direct ensemble's 95 % Student-t interval of its mean: "
                 f"{percent(a['inside_direct_band'], no_band)} of points (an exact CPI with independent seeds and "
                 f"equal spread: {percent(a['exact_inside_direct_band'], 'no interval')})")
    lines.append(f"  CPI inside Welch's 95 % Student-t interval of the difference of the two means: "
                 f"{percent(a['inside_difference_band'], no_band)} (an exact CPI: about 95 %)")
    lines.append(f"cost: DEM-time speed-up of CPI (simulated / DEM time) {ratio(c['simulated_time'], c['dem_time']):.2f}x; "
                 f"wall-time ratio direct / CPI {ratio(d['wall_seconds'], c['wall_seconds']):.2f}x for the run loops, "
                 f"{ratio(d['total_wall_seconds'], c['total_wall_seconds']):.2f}x for the whole runs (settling included)")
    if c["controller"]:
        lines.append(c["controller"])
    return lines


def main(argv):
    if len(argv) != 2:
        run_files.fail("demo_summary", f"expected 2 arguments, got {len(argv)}\n"
                                       "usage: /usr/bin/python3 scripts/demo_summary.py DIRECT.h5 CPI.h5")
    try:
        lines = summary(load(argv[0], "direct"), load(argv[1], "cpi"))
    except run_files.UsageError as e:
        run_files.fail("demo_summary", e)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
