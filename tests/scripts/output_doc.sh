#!/usr/bin/env bash
# docs/output.md lists every dataset a run file holds: a direct run with observe.bed and an
# adaptive cpi run with every optional record switched on (pooled slopes, evidence-sized healing
# and window, cpi.lift = own) are written, and each of their datasets must appear in the
# document by its full path (as `/group/name`). Fails naming the undocumented ones.
#   output_doc.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
src=$(cd "$here/../.." && pwd)
for spec in "direct mode=direct,observe.bed=true" \
            "cpi mode=cpi,observe.bed=true,cpi.projection=adaptive,cpi.slope=pooled,cpi.pool=3,cpi.healing_auto=true,cpi.window_auto=true,cpi.lift=own,cpi.tolerance=0.06,cpi.dt_min=0.5,run.duration=24"; do
  read -r name overrides <<< "$spec"
  IFS=, read -r -a extra <<< "$overrides"
  timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" "${extra[@]}" \
    ensemble.realizations_per_rank=2 output.directory="$work" output.prefix=$name > "$work/$name.log" 2>&1 \
    || { cat "$work/$name.log"; echo "FAIL: the $name run failed"; exit 1; }
done
/usr/bin/python3 - "$src/docs/output.md" "$work/direct.h5" "$work/cpi.h5" <<'PY'
import re, sys
import h5py
doc = open(sys.argv[1]).read()
documented = set(re.findall(r"`(/[A-Za-z0-9_/.-]+)`", doc))
missing = set()
for path in sys.argv[2:]:
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: missing.add("/" + name)
                     if isinstance(obj, h5py.Dataset) and "/" + name not in documented else None)
if missing:
    sys.exit("FAIL: datasets not in docs/output.md: " + ", ".join(sorted(missing)))
print("PASS: every dataset of a direct and an adaptive cpi run file (all optional records) is in docs/output.md")
PY
