#!/usr/bin/python3
"""Checks the output of scripts/accuracy_cost.py (issue 9): every plot and table exists, every
number is finite, and the accounting is consistent: DT = 0 (bursts only, no lift) reproduces
the direct run (error at the sampling-noise level: here exactly 0, the same seeds), the ideal
speed-up grows with DT, and errors stay within a few standard errors of the ensemble mean.

    /usr/bin/python3 check_accuracy_study.py OUT_DIR
"""
import csv
import math
import os
import sys


def main(out):
    errors = []
    for f in ("error_vs_wall_time.png", "speedup_vs_dt.png", "error_vs_realizations.png", "predicted_vs_measured.png",
              "icdf_cpi_vs_direct.png", "table.md", "accuracy_cost.csv"):
        if not os.path.getsize(os.path.join(out, f)) > 0:
            errors.append(f"{f} missing or empty")
    rows = list(csv.DictReader(open(os.path.join(out, "accuracy_cost.csv"))))
    for r in rows:
        for k in ("wall", "particle_steps", "error", "normalized", "speedup", "ideal", "noise_floor"):
            if not math.isfinite(float(r[k])):
                errors.append(f"{r['name']}: {k} = {r[k]} is not finite")
    by = {r["name"]: r for r in rows}
    dt0 = by.get("DT0")
    if dt0 is None:
        errors.append("no DT = 0 run")
    elif float(dt0["normalized"]) > 1.0:
        errors.append(f"DT = 0 differs from the direct run by {dt0['normalized']} standard errors")
    dts = sorted((float(r["dt"]), float(r["ideal"])) for r in rows if r["name"].startswith("DT"))
    if any(b[1] < a[1] for a, b in zip(dts, dts[1:])):
        errors.append(f"ideal speed-up does not grow with DT: {dts}")
    for r in rows:
        # 5 standard errors: a CPI run that is wrong by more than that is a failure of the method
        # (or of the code), not noise (p < 1e-6 for Gaussian noise).
        if float(r["normalized"]) > 5:
            errors.append(f"{r['name']}: error {r['normalized']} standard errors")
    if errors:
        print("check_accuracy_study: " + "; ".join(errors))
        return 1
    print(f"check_accuracy_study: {len(rows)} runs, all numbers finite and consistent")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
