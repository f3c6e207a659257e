#!/usr/bin/python3
"""Compare the coarse steady state of mode = steady (bench/steady_study.sh) with the time average
of a direct ensemble after complete demixing, node by node, against the noise of both.

    /usr/bin/python3 bench/steady_compare.py runs/steady_study [--run newton_gaps] [--from 150] [--block 20] [-o fig.png]

Reported (RMS over the ICDF nodes, d_p): the difference Newton - direct average; the Newton
answer's noise (SE of Phi_tau at the answer per node); the direct average's standard error per
node from block means (blocks of --block time units, so that correlated samples are not counted
as independent); the band both give together. DEM time is per realization.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts"))
import run_files  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("folder")
    ap.add_argument("--from", dest="t_from", type=float, default=150.0)
    ap.add_argument("--block", type=float, default=20.0)
    ap.add_argument("-o", "--output")
    ap.add_argument("--run", default="newton", help="the steady run's prefix in the folder (newton, newton_gaps)")
    a = ap.parse_args()
    try:
        with run_files.open_run(os.path.join(a.folder, "direct.h5"), ["samples/time"]) as d:
            t, mean = d["samples/time"][:], run_files.get(d, "samples/mean_icdf")[:]
            p = d["p"][:]
            R = int(d.attrs["realizations"])
            direct_dem = float(d.attrs.get("dem_time", t[-1]))
        with run_files.open_run(os.path.join(a.folder, a.run + ".h5"), ["steady/iterate/residual"]) as n:
            s = n["steady"]
            it = s["iterate"]
            # A run still going (or cut short) has no /steady/best yet: its best iterate so far.
            residuals = it["residual"][:]
            best = int(np.argmin(residuals))
            x = s["best"][:] if "best" in s else it["x"][best]
            noise, residual = it["noise"][best], float(residuals[best])
            tau = float(s.attrs["tau"])
            status = run_files.text(s.attrs.get("end_status", "running"))
            newton_dem = float(n.attrs.get("dem_time", 0.0))
            # The products' noise is recorded since efdem 70b6021 (NaN before).
            eig = [(s["eigenvalue_real"][k], s["eigenvalue_rate"][k], s["eigenvalue_residual"][k],
                    s["eigenvalue_noise"][k] if "eigenvalue_noise" in s else float("nan"))
                   for k in range(len(s["eigenvalue_real"]))] if "eigenvalue_real" in s else []
    except run_files.UsageError as e:
        run_files.fail("steady_compare.py", e)
    sel = t >= a.t_from
    avg = mean[sel].mean(axis=0)
    per_block = max(1, int(round(a.block / (t[1] - t[0]))))
    nb = sel.sum() // per_block
    blocks = mean[sel][: nb * per_block].reshape(nb, per_block, -1).mean(axis=1)
    se_direct = blocks.std(axis=0, ddof=1) / np.sqrt(nb)
    n_nodes = len(x)
    se_newton = noise / np.sqrt(n_nodes)  # RMS per node of the SE vector
    diff = x - avg
    rms = np.sqrt(np.mean(diff ** 2))
    band = np.sqrt(se_newton ** 2 + np.mean(se_direct ** 2))
    print(f"{a.run}: {status}")
    print(f"direct: R = {R}, time average over t >= {a.t_from:g} ({sel.sum()} samples, {nb} blocks of {a.block:g})")
    print(f"RMS({a.run} - direct average) = {rms:.3f} d_p; its noise of Phi {se_newton:.3f}, direct s.e. "
          f"{np.sqrt(np.mean(se_direct ** 2)):.3f}, together {band:.3f} d_p: ratio {rms / band:.2f}")
    print(f"largest node difference {np.abs(diff).max():.3f} d_p at p = {p[np.argmax(np.abs(diff))]:.2f}")
    print(f"DEM time per realization: {a.run} {newton_dem:.0f} (warm-up included), direct {direct_dem:.0f}")
    # The direct ensemble's own slowest decay rate near the steady state: a log-linear fit of
    # the distance of its mean height from the final average, over the part of the approach
    # where that distance is well above the noise (between 20x and 3x the block s.e.).
    h = mean.mean(axis=1)
    dist = np.abs(h - avg.mean())
    floor = np.sqrt(np.mean(se_direct ** 2))
    fit = (dist < 20 * floor * np.sqrt(nb)) & (dist > 3 * floor * np.sqrt(nb)) & (t < a.t_from)
    if fit.sum() >= 10:
        slope = np.polyfit(t[fit], np.log(dist[fit]), 1)[0]
        print(f"direct approach to the steady state: rate {slope:.4f} per time unit over t in "
              f"[{t[fit].min():.0f}, {t[fit].max():.0f}] (mean height within {dist[fit].min():.2f}..{dist[fit].max():.2f} d_p)")
    for re, rate, res, noise_mu in eig:
        print(f"eigenvalue mu = {re:.4f}, rate {rate:.4f} per time unit (residual {res:.2g}, products' noise {noise_mu:.2g})")
    # The answer's own band: a solve that stops at |F| <= 2 |SE| leaves x off the steady state by
    # |x - x*| <= |J_F^-1| (|F| + |e|) ~ (|F| + |SE|) / (1 - mu) along the slowest mode (docs/
    # steady_states.md), mu = e^(rate tau) from the direct ensemble's approach rate: the SE of Phi
    # alone ('Newton noise' above) is the band of Phi(x), not of x.
    band_x = None
    if fit.sum() >= 10:
        mu = float(np.exp(slope * tau))
        band_x = (residual + noise) / (1.0 - mu) / np.sqrt(n_nodes)
        together = np.sqrt(band_x ** 2 + np.mean(se_direct ** 2))
        print(f"answer's band (|F| + |SE|)/(1 - mu)/sqrt(n) = ({residual:.3f} + {noise:.3f})/(1 - {mu:.2f})/sqrt({n_nodes}) "
              f"= {band_x:.3f} d_p per node; with the direct s.e. {together:.3f}: ratio {rms / together:.2f}")
    if a.output:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4.2))
        ax.fill_between(p, avg - 2 * se_direct, avg + 2 * se_direct, alpha=0.3, label="direct time average ± 2 s.e.")
        ax.plot(p, avg, label=f"direct ensemble (R = {R}), t ≥ {a.t_from:g}")
        what = "Newton best iterate (not converged)" if status.startswith("not converged") else "Newton steady state"
        if band_x is not None:  # the answer's own band (RMS per node), not only Phi's noise
            ax.errorbar(p, x, yerr=band_x, fmt="o", ms=3, capsize=2, label=what + " ± its band (|F| + |SE|)/(1 - μ)/√n")
        else:
            ax.errorbar(p, x, yerr=2 * se_newton, fmt="o", ms=3, capsize=2, label=what + " ± 2 noise of Φ")
        ax.set(xlabel="p [-]", ylabel=r"light-particle height $Q_L(p)$ [$d_p$]",
               title=f"coarse steady state vs direct: RMS {rms:.2f} $d_p$")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(a.output, dpi=110)
        print(f"wrote {a.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
