#!/usr/bin/python3
"""When does each realization stop demixing (issue 34, items 2-4)? At U_s = 0.19 the heavy spheres
alone are not fluidized: as they gather at the bottom a realization's bed defluidizes and its
light-particle ICDF freezes — exactly: once stopped, no light quantile moves by more than ~1e-12 d_p
(floating-point drift of a bed at rest), while a moving bed's quantiles change by 1e-2 d_p or more
within a few time units. So "stopped at t" is judged without a threshold to tune: a realization
is stopped from the first sample after which none of its quantiles ever moves by more than
FROZEN = 1e-6 d_p again (until the end of the run, or the next lift in a CPI run).

    /usr/bin/python3 bench/stop_times.py                                   # the 600-unit study
    /usr/bin/python3 bench/stop_times.py bench/results/slope_study_r4_u0.19_t600 other/folder ...

For every run file (direct or CPI) of the given study folders: each realization's stop time (or
"moving" at the end), how many have stopped by each quarter of the run, and the ensemble mean's
end state. Writes <folder>/stop_times.md. In a CPI run a lift changes the members' ICDFs: a
realization counts as stopped only if its ICDF also stays through every later lift (cpi.lift = own
keeps a member whose slope is 0 where it is; mean and members move it).
"""
import argparse
import glob
import os
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import study_runs as sr  # noqa: E402

FROZEN = 1e-6  # d_p: largest change of any quantile of a bed at rest (measured: 1e-13 to 7e-13)


def stop_times(t, icdf):
    """Per realization: the time from which its ICDF (samples x R x m) stays within FROZEN of its
    last value for good, or NaN if it still moves at the end."""
    out = []
    for r in range(icdf.shape[1]):
        moved = np.abs(icdf[:, r, :] - icdf[-1, r, :]).max(axis=1) > FROZEN
        idx = np.nonzero(moved)[0]
        if len(idx) == 0:
            out.append(float(t[0]))
        elif idx[-1] >= len(t) - 2:  # moved at (or next to) the last sample
            out.append(float("nan"))
        else:
            out.append(float(t[idx[-1] + 1]))
    return out


def frozen_at_end(t, icdf, span=10.0):
    """How many realizations did not move at all over the run's last `span` time units (for a CPI
    run: within its last burst, after its last lift)."""
    sel = t >= t[-1] - span - 1e-9
    return int(sum(np.abs(icdf[sel, r, :] - icdf[-1, r, :]).max() <= FROZEN for r in range(icdf.shape[1])))


def analyse(folder):
    rows = []
    for path in sorted(glob.glob(os.path.join(folder, "*.h5"))):
        with h5py.File(path, "r") as f:
            if "samples/icdf" not in f:
                continue
            t = f["samples/time"][:]
            icdf = f["samples/icdf"][:]
            mode = sr.text(f.attrs.get("mode", "?"))
            overrides = sr.text(f.attrs.get("overrides", ""))
        lift = next((w.split("=")[1] for w in overrides.split() if w.startswith("cpi.lift=")), "mean")
        stops = stop_times(t, icdf)
        span = t[-1] - t[0]
        quarters = [sum(1 for s in stops if np.isfinite(s) and s <= t[0] + span * k / 4) for k in (1, 2, 3, 4)]
        rows.append((os.path.basename(path)[:-3], mode if mode == "direct" else f"cpi, lift {lift}", stops,
                     quarters, icdf[-1, :, 9], frozen_at_end(t, icdf)))
    if not rows:
        return ""
    name = os.path.basename(os.path.normpath(folder))
    lines = [f"## {name}\n",
             "Made by `/usr/bin/python3 bench/stop_times.py " + os.path.relpath(folder, os.path.join(HERE, "..")) + "`. "
             f"A realization is stopped from the first sample after which no quantile of its light ICDF moves by more "
             f"than {FROZEN:g} d_p again.\n",
             "| run | kind | stop time per realization (moving: still moving at the end) | stopped by each quarter "
             "| at rest over the last 10 units | median light height at the end, per realization [d_p] |",
             "|---" * 6 + "|"]
    total = {"direct": [0, 0, 0], "cpi": [0, 0, 0]}
    for run, kind, stops, quarters, med, frozen in rows:
        key = "direct" if kind == "direct" else "cpi"
        total[key][0] += sum(1 for s in stops if np.isfinite(s))
        total[key][1] += len(stops)
        total[key][2] += frozen
        lines.append(f"| {run} | {kind} | " + ", ".join("moving" if not np.isfinite(s) else f"{s:g}" for s in stops)
                     + " | " + " / ".join(str(q) for q in quarters) + f" | {frozen} | " + ", ".join(f"{m:.2f}" for m in med) + " |")
    lines.append("")
    lines.append(f"Stopped for good by the end: direct {total['direct'][0]} of {total['direct'][1]} realizations, "
                 f"CPI {total['cpi'][0]} of {total['cpi'][1]} (a lift to the mean or by the common increment moves a "
                 f"stopped realization, so with those lifts only the next column can show a stop); at rest over the "
                 f"last 10 units: direct {total['direct'][2]}, CPI {total['cpi'][2]}.\n")
    with open(os.path.join(folder, "stop_times.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    return "\n".join(lines)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("folders", nargs="*", default=[os.path.join(HERE, "results", "slope_study_r4_u0.19_t600")])
    args = p.parse_args()
    for folder in args.folders:
        print(analyse(folder))


if __name__ == "__main__":
    main()
