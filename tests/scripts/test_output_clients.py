#!/usr/bin/python3
"""The clients tier: efdem's output read by the programs a fluidized-bed user opens it with.

  test_output_clients.py vtk|csv EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]

vtk: a tiny direct run writes VTK frames; VTK's own readers (vtkXMLDataParser for the .pvd,
     vtkXMLPolyDataReader for each .vtp, as ParaView uses them) must see one point and one vertex
     cell per particle, the arrays with values in their physical ranges, the species names, and
     frame times that increase.
csv: a tiny cpi run with thermo logs; plain pandas.read_csv(path) (no options) must give the
     documented columns, one row per sample or coarse step of the run file, and no NaN where
     there is always a value; the JSON sidecar must describe every column and the run's end.

Run by `ctest -L clients` (scripts/run_client_tests.sh installs python3-vtk9 and python3-pandas).
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


if __name__ == "__main__":
    if len(sys.argv) < 4 or sys.argv[1] not in ("vtk", "csv"):
        sys.exit(__doc__)
    {"vtk": test_vtk, "csv": test_csv}[sys.argv[1]](sys.argv[2:])
