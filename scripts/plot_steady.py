#!/usr/bin/python3
"""Plot what an efdem run of mode = steady or mode = continuation found (docs/steady_states.md).

* steady: the residual |F| of every iterate against the DEM time it cost, with the noise
  level the solve stops at; the initial guess and the answer (best iterate) as ICDFs;
* continuation: the segregation measure (mean light-particle height) with its error bar and
  the leading coarse eigenvalue's rate log|mu|/tau along the branch, against the parameter
  (filled markers: stable, mu inside the unit circle; open: unstable).

    /usr/bin/python3 scripts/plot_steady.py RUN.h5 -o steady.png
    /usr/bin/python3 scripts/plot_steady.py BRANCH_A.h5 BRANCH_B.h5 -o branch.png   (one diagram)

Needs Debian's python3-matplotlib, python3-h5py and python3-numpy (run it with /usr/bin/python3).
Exit code 2 with a message for a file that is missing, not a run file, or not of these modes.
"""
import argparse
import contextlib
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import run_files  # noqa: E402

try:
    import h5py  # noqa: F401
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError as e:
    sys.exit(f"plot_steady.py: {e}; run it with /usr/bin/python3 (Debian python3-matplotlib python3-h5py)")


def plot_steady(f, name, out):
    it = f["steady/iterate"]
    fig, (ax_r, ax_x) = plt.subplots(1, 2, figsize=(11, 4.2))
    t, r, noise = it["dem_time"][:], it["residual"][:], it["noise"][:]
    ax_r.semilogy(t, r, "o-", label=r"$|F|$ at each iterate")
    ax_r.semilogy(t, 2 * noise, "--", color="0.4", label=r"stopping level $2\,|SE(F)|$")
    ax_r.set(xlabel=r"DEM time after the warm-up [$\sqrt{d_p/g}$]", ylabel=r"$|F| = |\Phi_\tau(X) - X|$ [$d_p$]",
             title=f"{name}: {run_files.text(f['steady'].attrs.get('solver', '?'))} iterates")
    p = f["p"][:]
    if "x0" in f["steady"]:
        ax_x.plot(p, f["steady/x0"][:], label="initial guess (end of warm-up)")
    if "best" in f["steady"]:
        ax_x.plot(p, f["steady/best"][:], lw=2, label="steady state (best iterate)")
    ax_x.set(xlabel="p [-]", ylabel=r"light-particle height $Q_L(p)$ [$d_p$]", title="coarse steady state")
    status = run_files.text(f["steady"].attrs.get("end_status", ""))
    fig.suptitle(status[:140], fontsize=8)
    for ax in (ax_r, ax_x):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def plot_branch(runs, out):
    """runs: (file, name) of one or more continuation runs in the same parameter, on one diagram."""
    fig, (ax_m, ax_e) = plt.subplots(1, 2, figsize=(11, 4.2))
    reasons = []
    held_labelled = False  # one legend entry for the crosses, whichever run has them
    for k, (f, name) in enumerate(runs):
        b = f["branch"]
        if "parameter" not in b or len(b["parameter"]) == 0:
            raise run_files.UsageError(f"{name}: /branch has no points (end status "
                                       f"'{run_files.text(f.attrs.get('end_status', '?'))}')")
        color = f"C{k}"
        lam = b["parameter"][:]
        par = run_files.text(b.attrs.get("parameter", "parameter"))
        tau = float(f["steady"].attrs["tau"]) if "steady" in f and "tau" in f["steady"].attrs else float("nan")
        label = f"{name} (tau = {tau:g})" if len(runs) > 1 else "mean of the ICDF nodes (bound on its s.e.)"
        ax_m.errorbar(lam, b["mean_height"][:], yerr=b["mean_height_error"][:], fmt="o-", capsize=3, color=color,
                      label=label)
        # /branch/from_last_point is recorded since the predictor fallback (efdem, 2026-12-03).
        if "from_last_point" in b:
            held = b["from_last_point"][:] == 1
            if held.any():
                ax_m.plot(lam[held], b["mean_height"][:][held], "x", ms=10, color="k",
                          label=None if held_labelled else "corrector started from the last point")
                held_labelled = True
        rate = b["leading_rate"][:]
        mu = np.hypot(b["leading_real"][:], b["leading_imag"][:])
        stable = mu < 1
        ax_e.plot(lam, rate, "-", color=color)
        ax_e.plot(lam[stable], rate[stable], "o", color=color, label=r"stable ($|\mu| < 1$)" if k == 0 else None)
        ax_e.plot(lam[~stable], rate[~stable], "o", mfc="none", color=color,
                  label=r"unstable ($|\mu| \geq 1$)" if k == 0 else None)
        # The rate's upper end, log(|mu| + residual + products' noise)/tau: how close to 0 (neutral)
        # the mode may be. /branch/leading_noise is recorded since efdem 70b6021.
        if "leading_noise" in b and np.isfinite(tau):
            upper = np.log(mu + b["leading_residual"][:] + b["leading_noise"][:]) / tau
            ax_e.errorbar(lam, rate, yerr=[np.zeros_like(rate), upper - rate], fmt="none", ecolor=color, capsize=3,
                          label=r"upper end: $\log(|\mu|$ + residual + products' noise$)/\tau$" if k == 0 else None)
        reasons.append(f"{name}: " + run_files.text(b.attrs.get("end_reason", "")))
    ax_m.set(xlabel=f"{par} [scene unit]", ylabel=r"mean light-particle height [$d_p$]",
             title="steady segregation along the branch")
    ax_e.axhline(0, color="0.5", lw=0.8)
    ax_e.set(xlabel=f"{par} [scene unit]", ylabel=r"leading rate $\log|\mu|/\tau$ [$1/\sqrt{d_p/g}$]",
             title="coarse stability of each point")
    for ax in (ax_m, ax_e):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("\n".join(r[:140] for r in reasons), fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", nargs="+", help="a run file; several continuation runs share one diagram")
    ap.add_argument("-o", "--output", required=True)
    a = ap.parse_args()
    try:
        with contextlib.ExitStack() as stack:
            files = [stack.enter_context(run_files.open_run(r)) for r in a.run]
            modes = [run_files.text(f.attrs["mode"]) for f in files]
            f, mode = files[0], modes[0]
            if len(files) > 1 and any(m != "continuation" for m in modes):
                raise run_files.UsageError(f"{', '.join(a.run)}: several run files are drawn together only if all "
                                           f"are of mode = continuation (modes: {', '.join(modes)})")
            if mode == "continuation":
                plot_branch([(g, os.path.basename(r)) for g, r in zip(files, a.run)], a.output)
            elif mode == "steady":
                if "steady/iterate/residual" not in f or len(f["steady/iterate/residual"]) == 0:
                    raise run_files.UsageError(f"{a.run[0]}: the steady run recorded no iterate")
                plot_steady(f, os.path.basename(a.run[0]), a.output)
            else:
                raise run_files.UsageError(f"{a.run[0]}: a run of mode = {mode}; this script plots mode = steady or "
                                           "continuation (plot_icdf.py plots direct and cpi runs)")
    except run_files.UsageError as e:
        run_files.fail("plot_steady.py", e)
    print(f"plot_steady.py: wrote {a.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
