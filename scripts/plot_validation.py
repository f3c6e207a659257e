#!/usr/bin/python3
"""Plots the gas validation tier's output (tests/physics/test_gas_validation.cpp,
test_two_size_validation.cpp) for docs/validation.md.

usage: /usr/bin/python3 scripts/plot_validation.py DATA_DIR FIGURE_DIR

Reads the CSV files the [.validation] tests wrote to DATA_DIR ($EFDEM_VALIDATION_OUT) and writes
PNG figures to FIGURE_DIR. A figure whose CSV is missing is skipped with a line; no arguments,
a DATA_DIR that is not a folder, none of the CSVs there, or a CSV without the columns a figure
needs: a message and exit 2. Uses Debian's matplotlib (python3-matplotlib), not a virtualenv's.
"""
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import run_files  # noqa: E402  (scripts/run_files.py: exit 2 with a message)


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def header_value(path, key):
    """A number 'key = value' from the file's comment header."""
    for line in open(path):
        if line.startswith("#") and key in line:
            return float(line.split(key + " = ")[1].split(",")[0].split()[0])
    raise KeyError(key)


def dp_sweep(data, out):
    path = data / "dp_sweep_light.csv"
    r = rows(path)
    umf, wa = header_value(path, "U_mf,bed"), header_value(path, "W/A")
    u = [float(x["u_s"]) for x in r]
    dp = [float(x["pressure_drop"]) for x in r]
    sd = [float(x["pressure_drop_sd"]) for x in r]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.errorbar(u, dp, yerr=sd, fmt="o", label="simulation (time average, ±1 sd)")
    ax.plot([0, umf], [0, wa], "k--", lw=1, label="Darcy line through U_mf,bed")
    ax.axhline(wa, color="gray", lw=1, label=f"weight per area W/A = {wa:.3f}")
    ax.axhspan(0.98 * wa, 1.02 * wa, color="gray", alpha=0.15, label="±2 %")
    ax.axvline(umf, color="C3", lw=1, ls=":", label=f"U_mf,bed = {umf:.4f} (profile)")
    ax.set_xlabel("superficial gas velocity U_s  [sqrt(g d_p)]")
    ax.set_ylabel("pressure drop ΔP  [ρ_s g d_p]")
    ax.set_title("ΔP(U_s), light bed of 500 in 5 × 5 d_p, increasing U_s")
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(out / "dp_sweep.png", dpi=110)


def rz_profiles(data, out):
    r = rows(data / "rz_profiles.csv")
    fig, ax = plt.subplots(figsize=(6, 4))
    cases = sorted({(x["species"], x["u_s"]) for x in r}, key=lambda c: (c[0], float(c[1])))
    for k, (sp, u) in enumerate(cases):
        sel = [x for x in r if x["species"] == sp and x["u_s"] == u]
        z = [int(x["slab"]) + 0.5 for x in sel]
        phi = [float(x["phi"]) for x in sel]
        ax.plot(z, phi, "-o", ms=3, color=f"C{k}", label=f"{sp}, U_s = {float(u):.2f}")
        ax.axhline(float(sel[0]["phi_hom"]), color=f"C{k}", ls="--", lw=1)
    ax.set_xlabel("height z  [d_p]")
    ax.set_ylabel("time-averaged solid fraction φ")
    ax.set_title("Short fluidized beds vs Richardson-Zaki φ_hom (dashed)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "richardson_zaki.png", dpi=110)


def waves(data, out):
    fig, axes = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    for ax, u in zip(axes, ("0.19", "0.41")):
        r = rows(data / f"waves_u{u}.csv")
        t = [float(x["time"]) for x in r]
        ax.plot(t, [float(x["z_com"]) for x in r], label="all")
        ax.plot(t, [float(x["z_com_light"]) for x in r], label="light")
        ax.plot(t, [float(x["z_com_heavy"]) for x in r], label="heavy")
        ax.set_ylabel("z_com  [d_p]")
        ax.set_title(f"U_s = {u}", fontsize=9)
    axes[0].legend(fontsize=8, ncol=3)
    axes[1].set_xlabel("time  [sqrt(d_p/g)]")
    fig.suptitle("Centre-of-mass heights, binary bed of 1,250 in 5 × 5 d_p")
    fig.tight_layout()
    fig.savefig(out / "waves.png", dpi=110)


def spacetime(data, out):
    import numpy as np

    fig, axes = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
    for ax, u in zip(axes, ("0.19", "0.41")):
        d = np.loadtxt(data / f"spacetime_u{u}.csv", delimiter=",", comments="#")
        t, phi = d[:, 0], d[:, 1:]
        im = ax.imshow(phi.T, origin="lower", aspect="auto", extent=[t[0], t[-1], 0, phi.shape[1]],
                       vmin=0, vmax=0.65, cmap="viridis")
        ax.set_ylabel("height z  [d_p]")
        ax.set_title(f"U_s = {u}", fontsize=9)
    axes[1].set_xlabel("time  [sqrt(d_p/g)]")
    fig.colorbar(im, ax=axes, label="solid fraction φ of the 1 d_p slab")
    fig.suptitle("φ(z, t), binary bed of 1,250 in 5 × 5 d_p, from the packed state")
    fig.savefig(out / "spacetime.png", dpi=110)


def randomization(data, out):
    r = rows(data / "randomization_icdf.csv")
    ps = [k for k in r[0] if k.startswith("p")]
    fig, ax = plt.subplots(figsize=(6, 4))
    for k, p in enumerate(("p0.25", "p0.50", "p0.75")):
        for arm, style in (("control", "-"), ("randomized", "--")):
            sel = [x for x in r if x["arm"] == arm]
            ax.plot([float(x["t"]) for x in sel], [float(x[p]) for x in sel], style, color=f"C{k}",
                    label=f"Q_L({p[1:]}) {arm}")
    ax.set_xlabel("time after the fork  [sqrt(d_p/g)]")
    ax.set_ylabel("light-particle height quantile  [d_p]")
    ax.set_title(f"Velocity randomization at t = 0 (ensemble means; {len(ps)}-point grid)")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(out / "randomization.png", dpi=110)


def dp_sweep_sizes(data, out):
    r = rows(data / "dp_sweep_sizes.csv")
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for k, d in enumerate(sorted({x["diameter"] for x in r}, key=float)):
        sel = [x for x in r if x["diameter"] == d]
        wa = float(sel[0]["weight_per_area"])
        umf = float(sel[-1]["u_mf_darcy"])
        u = [float(x["u_s"]) for x in sel]
        ratio = [float(x["pressure_drop"]) / wa for x in sel]
        sd = [float(x["pressure_drop_sd"]) / wa for x in sel]
        axes[0].errorbar(u, ratio, yerr=sd, fmt="o-", color=f"C{k}", label=f"d = {d}")
        axes[0].axvline(umf, color=f"C{k}", ls=":", lw=1, label=f"U_mf (Darcy) = {umf:.3f}")
        axes[1].errorbar([x / umf for x in u], ratio, yerr=sd, fmt="o-", color=f"C{k}", label=f"d = {d}")
    axes[0].set_xlabel("superficial gas velocity U_s  [sqrt(g d_p)]")
    axes[1].set_xlabel("U_s / U_mf of the bed (its Darcy slope)")
    for ax in axes:
        ax.axhline(1, color="gray", lw=1)
        ax.axhspan(0.97, 1.03, color="gray", alpha=0.15)
        ax.set_ylabel("ΔP / (W/A)")
        ax.legend(fontsize=8, loc="lower right")
    fig.suptitle("One-size beds of 500 spheres with gas_drag.polydisperse = van_der_hoef: U_mf ∝ d²")
    fig.tight_layout()
    fig.savefig(out / "two_sizes_dp_sweep.png", dpi=110)


def two_sizes_bed(data, out):
    r = rows(data / "two_sizes_bed.csv")
    fig, axes = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
    for k, real in enumerate(sorted({x["realization"] for x in r})):
        sel = [x for x in r if x["realization"] == real]
        t = [float(x["time"]) for x in sel]
        axes[0].plot(t, [float(x["pressure_drop_ratio"]) for x in sel], color=f"C{k}", lw=1,
                     label=f"seed {real}")
        axes[1].plot(t, [float(x["z_com_small"]) for x in sel], color=f"C{k}", label=f"small, seed {real}")
        axes[1].plot(t, [float(x["z_com_large"]) for x in sel], color=f"C{k}", ls="--",
                     label=f"large, seed {real}")
    axes[0].axhline(1, color="gray", lw=1)
    axes[0].set_ylabel("ΔP / (W/A)")
    axes[0].legend(fontsize=8)
    axes[1].set_ylabel("centre-of-mass height  [d_p]")
    axes[1].set_xlabel("time  [sqrt(d_p/g)]")
    axes[1].legend(fontsize=7, ncol=2)
    fig.suptitle("800 spheres d = 1 and 100 of d = 2, one density, U_s = 0.6: the small rise")
    fig.tight_layout()
    fig.savefig(out / "two_sizes_bed.png", dpi=110)


USAGE = "usage: /usr/bin/python3 scripts/plot_validation.py DATA_DIR FIGURE_DIR"


def main(argv):
    if len(argv) != 2:
        run_files.fail("plot_validation", f"expected 2 arguments, got {len(argv)}\n{USAGE}")
    data, out = Path(argv[0]), Path(argv[1])
    if not data.is_dir():
        run_files.fail("plot_validation", f"DATA_DIR {data}: not a folder (the [.validation] tests write their "
                                          f"CSV files to $EFDEM_VALIDATION_OUT)\n{USAGE}")
    out.mkdir(parents=True, exist_ok=True)
    written = 0
    for plot in (dp_sweep, rz_profiles, waves, spacetime, randomization, dp_sweep_sizes, two_sizes_bed):
        try:
            plot(data, out)
            print(f"plot_validation: {plot.__name__} written")
            written += 1
        except FileNotFoundError as e:
            print(f"plot_validation: {plot.__name__} skipped ({e.filename} missing)")
        except (KeyError, IndexError, ValueError) as e:
            run_files.fail("plot_validation", f"{plot.__name__}: a CSV in {data} lacks what the figure needs "
                                              f"({type(e).__name__}: {e}); was it written by the [.validation] tier?")
    if written == 0:
        run_files.fail("plot_validation", f"no validation CSV files in {data} (dp_sweep_light.csv, rz_profiles.csv, "
                                          "waves_u*.csv, spacetime_u*.csv, randomization_icdf.csv, dp_sweep_sizes.csv, "
                                          "two_sizes_bed.csv)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
