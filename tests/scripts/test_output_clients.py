#!/usr/bin/python3
"""The clients tier: efdem's output read by the programs a fluidized-bed user opens it with.

  test_output_clients.py vtk|csv|xarray|docs EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]

vtk: a tiny direct run writes VTK frames; VTK's own readers (vtkXMLDataParser for the .pvd,
     vtkXMLPolyDataReader for each .vtp, as ParaView uses them) must see one point and one vertex
     cell per particle, the arrays with values in their physical ranges, the species names, and
     frame times that increase.
csv: a tiny cpi run with thermo logs; plain pandas.read_csv(path) (no options) must give the
     documented columns, one row per sample or coarse step of the run file, and no NaN where
     there is always a value; the JSON sidecar must describe every column and the run's end.
xarray: run files of every kind (cpi adaptive with observe.bed, direct with a dropped realization,
     continuation): every group opened by xarray with its default engine (netCDF4) and with
     h5netcdf holds every dataset of the group with h5py's values, every dimension a coordinate
     with units and long_name, no variable named like a Dataset method; .sel(p = 0.5) and
     .sel(time = t) give h5py's value at that node and time.
docs: every ```python block of docs/output.md (the xarray, h5py, pandas, VTK and JSON examples)
     runs without error on the files of a real run, laid out under the names the doc uses.

Run by `ctest -L clients` (scripts/run_client_tests.sh installs python3-vtk9, python3-pandas,
python3-xarray, python3-netcdf4 and python3-h5netcdf).
A missing client module is a failure with a message, never a pass.
"""
import glob
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "tiny_scene.cfg")
# tiny_scene.cfg: 128 + 128 particles named light and heavy, box 4.28 x 4.28, lid at 60.
PARTICLES, SPECIES, LX, LY, LID = 256, ["light", "heavy"], 4.28, 4.28, 60.0


def need(module, package):
    try:
        return __import__(module)
    except ImportError as e:
        sys.exit(f"FAIL: cannot import {module} ({e}); install {package} "
                 "(scripts/run_client_tests.sh does) and run the clients tier again")


def run_efdem(argv, out, *keys):
    efdem, mpiexec, preflags = argv[0], argv[1], argv[2:]
    cmd = [mpiexec, "-n", "1", *preflags, efdem, SCENE, *keys, f"output.directory={out}"]
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=600)
    if r.returncode != 0:
        sys.exit(f"FAIL: efdem exited with {r.returncode}:\n{r.stdout}")
    return r.stdout


class Checks:
    def __init__(self):
        self.failures = 0

    def __call__(self, ok, what):
        print(("PASS: " if ok else "FAIL: ") + what)
        self.failures += not ok

    def done(self):
        sys.exit(1 if self.failures else 0)


def array_range(arr, component=-1):
    lo, hi = arr.GetRange(component)
    return lo, hi


def test_vtk(argv):
    vtk = need("vtk", "python3-vtk9")
    check = Checks()
    interval, duration = 0.5, 2.0
    with tempfile.TemporaryDirectory() as out:
        run_efdem(argv, out, "mode=direct", f"run.duration={duration}", f"output.vtk_interval={interval}")
        pvds = glob.glob(os.path.join(out, "*.pvd"))
        check(len(pvds) == 1, f"one .pvd for one realization ({[os.path.basename(p) for p in pvds]})")
        pvd = pvds[0]

        # The .pvd through VTK's XML parser (the one its XML readers use).
        parser = vtk.vtkXMLDataParser()
        parser.SetFileName(pvd)
        check(parser.Parse() == 1, "vtkXMLDataParser parses the .pvd")
        root = parser.GetRootElement()
        check(root.GetName() == "VTKFile" and root.GetAttribute("type") == "Collection",
              "the .pvd is a VTKFile of type Collection")
        collection = root.FindNestedElementWithName("Collection")
        datasets = [collection.GetNestedElement(i) for i in range(collection.GetNumberOfNestedElements())]
        times = [float(d.GetAttribute("timestep")) for d in datasets]
        files = [d.GetAttribute("file") for d in datasets]
        frames = int(round(duration / interval)) + 1  # the initial state and one per interval
        check(len(datasets) == frames, f"the .pvd lists {len(datasets)} frames (expected {frames})")
        check(all(b > a for a, b in zip(times, times[1:])), f"frame times increase: {times}")
        # Frame k is written at k * interval; times are printed with 10 significant digits.
        check(all(abs(t - k * interval) < 1e-9 for k, t in enumerate(times)),
              "frame times are the multiples of output.vtk_interval")

        for time, name in zip(times, files):
            path = os.path.join(out, name)
            with open(path, "rb") as f:
                head = f.read(400)
            check(b'header_type="UInt64"' in head and b'format="ascii"' not in head,
                  f"{name}: binary appended data with UInt64 block headers")
            reader = vtk.vtkXMLPolyDataReader()
            reader.SetFileName(path)
            reader.Update()
            poly = reader.GetOutput()
            check(reader.GetErrorCode() == 0, f"{name}: vtkXMLPolyDataReader reads it without error")
            check(poly.GetNumberOfPoints() == PARTICLES, f"{name}: {poly.GetNumberOfPoints()} points")
            verts = poly.GetVerts()
            check(poly.GetNumberOfVerts() == PARTICLES and poly.GetNumberOfCells() == PARTICLES,
                  f"{name}: {poly.GetNumberOfVerts()} vertex cells of {poly.GetNumberOfCells()} cells")
            check(verts.IsHomogeneous() == 1, f"{name}: every vertex cell has one point")
            ids = vtk.vtkIdList()
            points_in_cells = set()
            verts.InitTraversal()
            while verts.GetNextCell(ids):
                points_in_cells.add(ids.GetId(0))
            check(points_in_cells == set(range(PARTICLES)), f"{name}: each point is in its own vertex cell")

            pd = poly.GetPointData()
            wanted = {"velocity": 3, "angular_velocity": 3, "radius": 1, "diameter": 1, "mass": 1,
                      "species": 1, "tag": 1}
            for a, comps in wanted.items():
                arr = pd.GetArray(a)
                check(arr is not None and arr.GetNumberOfComponents() == comps
                      and arr.GetNumberOfTuples() == PARTICLES, f"{name}: point array {a} ({comps} components)")
            check(pd.GetArray("velocity").GetDataTypeAsString() == "double"
                  and poly.GetPoints().GetData().GetDataTypeAsString() == "double",
                  f"{name}: positions and velocities are float64")
            # Species diameters are 1 (tiny_scene.cfg): radius 0.5, diameter 1, exactly.
            check(array_range(pd.GetArray("radius")) == (0.5, 0.5)
                  and array_range(pd.GetArray("diameter")) == (1.0, 1.0), f"{name}: radius 0.5, diameter 1")
            check(array_range(pd.GetArray("species")) in ((0, 1), (0, 0), (1, 1)), f"{name}: species in 0..1")
            tags = {int(pd.GetArray("tag").GetTuple1(i)) for i in range(PARTICLES)}
            check(len(tags) == PARTICLES, f"{name}: {len(tags)} distinct tags")
            # Heights: the centres are above the floor and below the lid (a wall contact keeps
            # them at most a small overlap, much less than a radius, beyond the radius).
            zlo, zhi = poly.GetPoints().GetData().GetRange(2)
            check(0 < zlo and zhi < LID, f"{name}: heights in [{zlo:.3g}, {zhi:.3g}], inside the box (0, {LID})")
            # x, y are wrapped into [0, L) when the neighbour list is rebuilt; between rebuilds a
            # particle may be out by less than half the skin (0.1 by default): 0.05.
            xlo, xhi = poly.GetPoints().GetData().GetRange(0)
            ylo, yhi = poly.GetPoints().GetData().GetRange(1)
            check(-0.05 <= xlo and xhi < LX + 0.05 and -0.05 <= ylo and yhi < LY + 0.05,
                  f"{name}: x in [{xlo:.3g}, {xhi:.3g}], y in [{ylo:.3g}, {yhi:.3g}] inside the periodic box")

            fd = poly.GetFieldData()
            names = fd.GetAbstractArray("species_names")
            got = [names.GetValue(i) for i in range(names.GetNumberOfValues())] if names else None
            check(names is not None and names.GetClassName() == "vtkStringArray" and got == SPECIES,
                  f"{name}: field data species_names is a string array {got}")
            tv = fd.GetArray("TimeValue")
            check(tv is not None and abs(tv.GetTuple1(0) - time) < 1e-9,
                  f"{name}: field data TimeValue {tv.GetTuple1(0) if tv else None} = the .pvd's {time}")
    check.done()


def test_csv(argv):
    pandas = need("pandas", "python3-pandas")
    h5py = need("h5py", "python3-h5py")
    check = Checks()
    with tempfile.TemporaryDirectory() as out:
        run_efdem(argv, out, "mode=cpi", "output.thermo_interval=0.25")
        run = h5py.File(os.path.join(out, "efdem.h5"), "r")
        sample_times = run["samples/time"][:]
        steps = len(run["cpi/t_start"])
        p_grid = run["p"][:]

        icdf = pandas.read_csv(os.path.join(out, "efdem_mean_icdf.csv"))
        columns = ["time"] + [f"Q({p:.4g})" for p in p_grid]
        check(list(icdf.columns) == columns, f"mean ICDF columns: {list(icdf.columns)[:4]}...")
        check(len(icdf) == len(sample_times), f"mean ICDF: {len(icdf)} rows, {len(sample_times)} samples in the run file")
        check(not icdf.isna().any().any(), "mean ICDF: no NaN")
        check(all(icdf.dtypes == "float64"), "mean ICDF: every column is numeric")
        # Printed with 10 significant digits: the times agree with the run file's to 1e-9.
        check(len(icdf) == len(sample_times) and abs(icdf["time"].to_numpy() - sample_times).max() < 1e-9,
              "mean ICDF: the times are the run file's sample times")
        # Each row is an ICDF: non-decreasing in p (the run file's own means are).
        q = icdf[columns[1:]].to_numpy()
        check((q[:, 1:] >= q[:, :-1]).all(), "mean ICDF: every row non-decreasing in p")

        cpi = pandas.read_csv(os.path.join(out, "efdem_cpi_steps.csv"))
        check(len(cpi) == steps and steps > 0, f"cpi steps: {len(cpi)} rows, {steps} coarse steps in the run file")
        check(len(cpi.columns) == 18 and cpi.columns[0] == "t_start", f"cpi steps: {len(cpi.columns)} columns")
        always = ["t_start", "burst_length", "healing", "window", "dt_requested", "dt", "status", "labels_changed"]
        check(not cpi[always].isna().any().any(), f"cpi steps: no NaN in {always}")

        with open(os.path.join(out, "efdem_csv_meta.json")) as f:
            meta = json.load(f)
        check(meta["end_status"] == "completed" and meta["mode"] == "cpi", f"sidecar: end_status {meta['end_status']}")
        documented = meta["files"]["efdem_cpi_steps.csv"]["columns"]
        check(list(documented) == list(cpi.columns), "sidecar: documents every cpi-step column, in order")
        check(set(meta["files"]["efdem_mean_icdf.csv"]["columns"]) == {"time", "Q(p)"}, "sidecar: mean ICDF columns")

        thermo_files = glob.glob(os.path.join(out, "*_thermo.csv"))
        check(len(thermo_files) == 1, f"one thermo log for one realization ({len(thermo_files)})")
        thermo = pandas.read_csv(thermo_files[0])
        check(list(thermo.columns) == ["step", "time", "ke_trans_per_particle", "ke_rot_per_particle",
                                       "contacts_per_particle", "wall_contacts", "max_overlap", "neighbor_builds"],
              f"thermo columns: {list(thermo.columns)}")
        check(not thermo.isna().any().any(), "thermo: no NaN")
        check(thermo["step"].dtype == "int64" and thermo["step"].is_monotonic_increasing, "thermo: steps increase")
        # thermo_interval = observe.interval: the initial state at t = 0, then one row per
        # sample of the realization, which are the run file's samples (those start one
        # interval in; a projective jump moves the clock without a sample).
        times = [0.0, *sample_times]
        check(len(thermo) == len(times), f"thermo: {len(thermo)} rows = the initial state + {len(sample_times)} samples")
        check(len(thermo) == len(times) and max(abs(a - b) for a, b in zip(thermo["time"], times)) < 1e-9,
              "thermo: the rows are at t = 0 and the run file's sample times")
    check.done()


def same_values(a, b):
    """Equal arrays (NaN equal to NaN; text as str)."""
    import numpy as np

    a, b = np.asarray(a), np.asarray(b)
    if a.dtype.kind in "OSU" or b.dtype.kind in "OSU":
        text = np.vectorize(lambda v: v.decode() if isinstance(v, bytes) else str(v), otypes=[str])
        return a.shape == b.shape and (a.size == 0 or np.array_equal(text(a), text(b)))
    return a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind == "f")


def check_group(check, xr, h5py, path, group, engine):
    """One group of run file `path` through xarray (`engine`, None: the default) against h5py."""
    import numpy as np

    where = f"{os.path.basename(path)} {group} ({engine or 'default engine'})"
    try:
        ds = xr.open_dataset(path, group=group, engine=engine)
    except Exception as e:  # noqa: BLE001  (any failure to open is the finding)
        check(False, f"{where}: xarray cannot open it: {type(e).__name__}: {e}")
        return
    with ds, h5py.File(path, "r") as f:
        g = f[group]
        names = [k for k, v in g.items() if isinstance(v, h5py.Dataset)]
        missing = [k for k in names if k not in ds.variables]
        check(not missing, f"{where}: every dataset is a variable ({len(names)}; missing {missing})")
        differ = [k for k in names if k in ds.variables and not same_values(ds[k].values, g[k][()])]
        check(not differ, f"{where}: every variable has h5py's values (differ: {differ})")
        not_coords = [d for d in ds.dims if d not in ds.coords]
        check(not not_coords, f"{where}: every dimension {list(ds.dims)} is a coordinate (not: {not_coords})")
        bare = [k for k in ds.variables if not ds[k].attrs.get("units") or not ds[k].attrs.get("long_name")]
        check(not bare, f"{where}: every variable has units and long_name (not: {bare})")
        methods = [k for k in ds.variables if hasattr(xr.Dataset, k)]
        check(not methods, f"{where}: no variable named like a Dataset method ({methods})")
        if "p" in ds.dims:
            j = int(np.flatnonzero(g["p"][:] == 0.5)[0])
            arrays = [k for k in ds.data_vars if "p" in ds[k].dims]
            bad = [k for k in arrays if not same_values(ds[k].sel(p=0.5).values, np.take(g[k][()], j, axis=ds[k].dims.index("p")))]
            if arrays or group != "/":  # the root holds the axis /p only
                check(arrays and not bad, f"{where}: .sel(p=0.5) of {arrays} is h5py's node {j} (differ: {bad})")
        if "time" in ds.dims and ds.sizes["time"] > 0:
            k = ds.sizes["time"] // 2
            t = float(g["time"][k])
            arrays = [a for a in ds.data_vars if "time" in ds[a].dims]
            bad = [a for a in arrays if not same_values(ds[a].sel(time=t).values, np.take(g[a][()], k, axis=ds[a].dims.index("time")))]
            check(arrays and not bad, f"{where}: .sel(time={t:g}) of {len(arrays)} arrays is h5py's row {k} (differ: {bad})")
        if group == "samples":
            j = int(np.flatnonzero(g["p"][:] == 0.5)[0])
            k = len(g["time"]) - 1
            value = ds["mean_icdf"].sel(p=0.5, time=float(g["time"][k])).item()
            check(value == g["mean_icdf"][k, j] and 0 < value < LID,
                  f"{where}: mean_icdf.sel(p=0.5, time=last) = {value:.6g} d_p, h5py's [{k}, {j}], inside the box")
            label = xr.plot.utils.label_from_attrs(ds["mean_icdf"])
            check(label.replace("\n", " ") == "ensemble-mean ICDF [d_p]", f"{where}: plot label {label!r}")


def test_xarray(argv):
    xr = need("xarray", "python3-xarray")
    need("netCDF4", "python3-netcdf4")
    need("h5netcdf", "python3-h5netcdf")
    h5py = need("h5py", "python3-h5py")
    check = Checks()
    runs = {
        "cpi": ["mode=cpi", "observe.bed=true", "cpi.projection=adaptive", "cpi.tolerance=0.06", "cpi.dt_min=0.5",
                "run.duration=12", "ensemble.realizations_per_rank=4"],
        "drop": ["mode=direct", "observe.bed=true", "run.duration=2", "ensemble.realizations_per_rank=4",
                 "ensemble.on_failure=drop", "debug.fail_realization=1", "debug.fail_time=1"],
        "branch": ["mode=continuation", "continuation.parameter=gas_drag.superficial_velocity", "continuation.end=0.5",
                   "continuation.step=0.05", "continuation.max_points=2", "run.duration=0", "steady.warmup=1",
                   "steady.tau=1", "steady.max_iterations=1", "steady.max_krylov=2", "steady.eigenvalues=1",
                   "steady.eigenvalue_products=2", "steady.noise_factor=50", "ensemble.realizations_per_rank=2"],
    }
    with tempfile.TemporaryDirectory() as out:
        groups_seen = set()
        for prefix, keys in runs.items():
            run_efdem(argv, out, *keys, f"output.prefix={prefix}")
            path = os.path.join(out, f"{prefix}.h5")
            groups = ["/"]
            with h5py.File(path, "r") as f:
                f.visititems(lambda name, obj: groups.append(name) if isinstance(obj, h5py.Group) else None)
            groups_seen |= set(groups)
            for group in groups:
                for engine in (None, "h5netcdf"):
                    check_group(check, xr, h5py, path, group, engine)
        expected = {"/", "samples", "bed", "bed/ensemble_mean", "cpi", "cpi/controller", "failures", "steady",
                    "steady/iterate", "branch"}
        check(expected <= groups_seen, f"the runs made every group ({sorted(expected - groups_seen)} missing)")
        # The default engine is netCDF-4's own library: a file it cannot read is not netCDF-4.
        check(xr.backends.plugins.guess_engine(os.path.join(out, "cpi.h5")) == "netcdf4",
              "xarray's default engine for a run file is netcdf4")
    check.done()


def doc_blocks(path):
    """The ```python blocks of a markdown file, in order."""
    blocks, block = [], None
    with open(path) as f:
        for line in f:
            if block is None and line.strip() == "```python":
                block = []
            elif block is not None and line.strip() == "```":
                blocks.append("".join(block))
                block = None
            elif block is not None:
                block.append(line)
    return blocks


def test_docs(argv):
    for module, package in (("xarray", "python3-xarray"), ("pandas", "python3-pandas"), ("vtk", "python3-vtk9")):
        need(module, package)
    check = Checks()
    doc = os.path.join(HERE, "..", "..", "docs", "output.md")
    blocks = doc_blocks(doc)
    kinds = [k for k in ("xarray", "h5py", "pandas", "vtk", "json") if not any(f"import {k}" in b for b in blocks)]
    check(not kinds, f"docs/output.md has {len(blocks)} python examples, one for each reader (none for {kinds})")
    with tempfile.TemporaryDirectory() as out:
        run_efdem(argv, os.path.join(out, "out"), "mode=direct", "observe.bed=true", "run.duration=2",
                  "output.vtk_interval=0.5", "ensemble.realizations_per_rank=2")
        # The names the doc uses: runs/demo_small/quick_direct.h5 (the README's quick start) and
        # out/efdem_* (output.directory = out), and a frame in the working folder.
        os.makedirs(os.path.join(out, "runs", "demo_small"))
        os.symlink(os.path.join(out, "out", "efdem.h5"), os.path.join(out, "runs", "demo_small", "quick_direct.h5"))
        os.symlink(os.path.join(out, "out", "efdem_r0000_000004.vtp"), os.path.join(out, "efdem_r0000_000004.vtp"))
        env = dict(os.environ, MPLBACKEND="Agg")
        for k, code in enumerate(blocks):
            r = subprocess.run(["/usr/bin/python3", "-c", code], cwd=out, env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, timeout=300)
            first = code.strip().splitlines()[0]
            check(r.returncode == 0, f"docs/output.md example {k + 1} ({first}) runs" +
                  ("" if r.returncode == 0 else f":\n{r.stdout}"))
    check.done()


if __name__ == "__main__":
    tests = {"vtk": test_vtk, "csv": test_csv, "xarray": test_xarray, "docs": test_docs}
    if len(sys.argv) < 4 or sys.argv[1] not in tests:
        sys.exit(__doc__)
    tests[sys.argv[1]](sys.argv[2:])
