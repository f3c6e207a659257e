#!/usr/bin/python3
"""Read back an efdem run file and check its structure and basic physics:
shapes consistent, times increasing, every ICDF (mean and per realization) non-decreasing in p
and inside the bed, variances non-negative, provenance present, cpi records consistent.

    /usr/bin/python3 check_run_file.py RUN.h5 [--mode cpi|direct] [--realizations R] [--bed]

Every run file is also checked to be self-describing and readable group by group by netCDF-4
readers (format 3): every dataset has non-empty `units`, `long_name` and `description`
attributes, every dimension a label, and the axis of that name in the dataset's own group
(/samples/time, /samples/p, /bed/time, ...) is attached to it as a dimension scale of the
dimension's length.
--bed: the run recorded observe.bed = true; /bed is checked (shapes, ranges, and the solid-
fraction profile holds the particles' whole volume when the bed lies below its top).
"""
import argparse
import sys

import h5py
import numpy as np


def check_self_describing(f, check):
    check(int(f.attrs.get("format_version", 0)) == 3, f"format_version {f.attrs.get('format_version')} != 3")

    def visit(name, obj):
        if not isinstance(obj, h5py.Dataset):
            return
        for key in ("units", "long_name", "description"):
            value = obj.attrs.get(key)
            check(value is not None and len(str(value)) > 0, f"/{name} has no {key}")
        group = "/" + name.rpartition("/")[0]
        for k, dim in enumerate(obj.dims):
            check(len(dim.label) > 0, f"/{name} dimension {k} has no name")
            # The axis: the dataset of the dimension's name in the same group (netCDF-4 sees no
            # axis of a sibling group, xarray none of a parent group).
            axis = group.rstrip("/") + "/" + dim.label
            if axis == "/" + name:
                check(h5py.h5ds.is_scale(obj.id), f"/{name} is not a dimension scale")
                continue
            scales = [s.name for s in dim.values()]
            check(scales == [axis], f"/{name} dimension {k} ({dim.label}): attached {scales}, not [{axis}]")
            if axis.lstrip("/") in f:
                check(len(f[axis]) == obj.shape[k],
                      f"/{name} dimension {k} ({dim.label}) has {obj.shape[k]} entries, its axis {axis} {len(f[axis])}")
    f.visititems(visit)


def check_bed(f, check, n, R, particles, area):
    if "bed" not in f:
        check(False, "no /bed group")
        return
    b = f["bed"]
    for name in ("pressure_drop", "pressure_drop_ratio", "height", "expansion", "mixing_index"):
        check(b[name].shape == (n, R), f"/bed/{name} shape {b[name].shape} != {(n, R)}")
        check(b["ensemble_mean/" + name].shape == (n,), f"/bed/ensemble_mean/{name} shape {b['ensemble_mean/' + name].shape}")
    S, J = len(b["species"]), len(b["z"])
    check(b["species_height"].shape == (n, R, S), f"/bed/species_height shape {b['species_height'].shape}")
    check(b["solid_fraction"].shape == (n, R, J), f"/bed/solid_fraction shape {b['solid_fraction'].shape}")
    phi = b["solid_fraction"][:]
    # A sphere fills at most pi/6 of the cube around it; random packings reach 0.64, and a slab
    # cutting through a layer of touching spheres can read up to about 0.9 of its volume.
    check(np.all(phi >= 0) and np.all(phi < 0.95), f"solid fraction outside [0, 0.95): {phi.min()}..{phi.max()}")
    check(np.all(b["height"][:] > 0), "a bed height <= 0")
    ratio = b["pressure_drop_ratio"][:]
    check(np.all(ratio >= 0) and np.all(ratio < 2), f"pressure_drop_ratio outside [0, 2): {ratio.min()}..{ratio.max()}")
    check(np.allclose(b["ensemble_mean/height"][:], b["height"][:].mean(axis=1), rtol=1e-12),
          "/bed/ensemble_mean/height is not the mean")
    check(np.array_equal(b["time"][:], f["samples/time"][:]) and np.array_equal(b["ensemble_mean/time"][:], f["samples/time"][:]),
          "/bed/time or /bed/ensemble_mean/time is not /samples/time")
    check(np.allclose(b["expansion"][0], 1.0), "expansion at the first sample is not 1")
    if particles and area:
        # The exact partial volumes put every sphere's whole volume into the slabs (the floor
        # overlap in slab 0): sum_j phi_j dz A = N pi/6 to round-off while the bed lies below
        # the profile's top (its last slab empty: no particle reaches it).
        dz = float(b.attrs["profile_dz"])
        below = phi[:, :, -1] == 0
        held = phi.sum(axis=2) * dz * area / (particles * np.pi / 6)
        check(np.allclose(held[below], 1.0, rtol=1e-9), f"phi(z) holds {held[below].min()}..{held[below].max()} of the particle volume")


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("run")
    ap.add_argument("--mode")
    ap.add_argument("--realizations", type=int)
    ap.add_argument("--min-samples", type=int, default=2)
    ap.add_argument("--bed", action="store_true")
    ap.add_argument("--particles", type=int, help="particles per realization (the --bed volume check)")
    ap.add_argument("--area", type=float, help="lx * ly (the --bed volume check)")
    a = ap.parse_args(argv)
    errors = []

    def check(cond, msg):
        if not cond:
            errors.append(msg)

    with h5py.File(a.run, "r") as f:
        R = int(f.attrs["realizations"])
        p = f["p"][:]
        m = len(p)
        t = f["samples/time"][:]
        mean = f["samples/mean_icdf"][:]
        var = f["samples/variance"][:]
        icdf = f["samples/icdf"][:]
        n = len(t)
        for key in ("efdem_version", "git_hash", "date", "mode", "seed", "end_status"):
            check(key in f.attrs, f"attribute {key} missing")
        check(len(f["scene"][()]) > 0, "scene text missing")
        if a.mode:
            check(f.attrs["mode"] == a.mode, f"mode {f.attrs['mode']} != {a.mode}")
        if a.realizations:
            check(R == a.realizations, f"realizations {R} != {a.realizations}")
        check(n >= a.min_samples, f"only {n} samples")
        check(np.all(np.diff(p) > 0) and p[0] > 0 and p[-1] < 1, "p-grid not increasing inside (0, 1)")
        check(mean.shape == (n, m) and var.shape == (n, m), f"mean/variance shapes {mean.shape}, {var.shape}")
        check(icdf.shape == (n, R, m), f"icdf shape {icdf.shape} != {(n, R, m)}")
        check(np.all(np.diff(t) > 0), "sample times not strictly increasing")
        check(np.all(np.isfinite(icdf)), "non-finite ICDF values")
        check(np.all(np.diff(icdf, axis=2) >= 0), "a realization's ICDF decreases in p")
        check(np.all(np.diff(mean, axis=1) >= 0), "a mean ICDF decreases in p")
        check(np.all(var >= 0), "negative variance")
        check(np.all(icdf > 0), "a particle centre below the floor")
        check(np.allclose(mean, icdf.mean(axis=1), rtol=1e-12, atol=1e-12), "mean is not the mean of the realizations")
        if f.attrs["mode"] == "cpi":
            c = f["cpi"]
            k = len(c["t_start"])
            check(k >= 1, "no coarse steps recorded")
            check(int(f.attrs["coarse_steps"]) == k, "coarse_steps attribute does not match the records")
            for name in ("burst_length", "dt", "t_end", "slope", "x_projected", "lift_changed"):
                check(len(c[name]) == k, f"/cpi/{name} has {len(c[name])} rows, expected {k}")
            se = c["slope_standard_error"]
            check(se.shape == c["slope"].shape, f"/cpi/slope_standard_error shape {se.shape} != /cpi/slope {c['slope'].shape}")
            check(not np.any(se[:] < 0), "negative slope standard error")
            check(np.all(c["lift_changed"][:] >= 0), "negative label counts")
            status = [x.decode() if isinstance(x, bytes) else str(x) for x in c["status"][:]]
            if "rejected" in status:
                # Adaptive: a rejected jump is redone from where it started; the jump origins
                # (t_end) never go back, and a redone burst starts earlier than the rejected one.
                check(np.all(np.diff(c["t_end"][:]) >= 0), "coarse steps' jump origins go back in time")
            else:
                check(np.all(np.diff(c["t_start"][:]) > 0), "coarse steps not in time order")
            if "controller" in c:
                for name in ("accepted", "error_statistical", "error_truncation", "dt_tolerance", "limited_by"):
                    check(len(c["controller"][name]) == k, f"/cpi/controller/{name} has {len(c['controller'][name])} rows, expected {k}")
                acc = c["controller/accepted"][:]
                check(all(acc[i] == 0 for i, x in enumerate(status) if x == "rejected"), "a rejected step marked accepted")
        check_self_describing(f, check)
        if a.bed:
            check_bed(f, check, n, R, a.particles, a.area)
    if errors:
        print(f"check_run_file: {a.run}: " + "; ".join(errors))
        return 1
    print(f"check_run_file: {a.run}: ok ({n} samples, R = {R}, m = {m})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
