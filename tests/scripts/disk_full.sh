#!/usr/bin/env bash
# A disk that fills during each kind of output ends the run cleanly (docs/reliability.md, "Full
# disks"): exit 3 with "no space left" in the message, no rank hangs (`timeout` is the hang
# detector), the run file stays readable and says end_status "failed: ... no space left ...",
# no partial VTK frame is left under a frame's name, every VTK frame and complete checkpoint
# left behind is readable. The file systems are small tmpfs mounts (needs root and mount; skipped
# with a message, exit 77, where it cannot mount).
#   disk_full.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
mounted=()
cleanup() { for m in "${mounted[@]}"; do umount "$m" 2>/dev/null; done; rm -rf "$work"; }
trap cleanup EXIT
mount_small() {  # mount_small DIR SIZE
  mkdir -p "$1"
  mount -t tmpfs -o size="$2" tmpfs "$1" 2>/dev/null || return 1
  mounted+=("$1")
}
mount_small "$work/probe" 64k || { echo "SKIP: cannot mount a tmpfs here (not root, or no mount permission)"; exit 77; }
failures=0

# kind, size of the output file system, size of a separate checkpoint file system (- : none), overrides
for spec in "vtk 1500k - output.vtk_interval=0.25" \
            "thermo 1150k - output.thermo_interval=0.25" \
            "run-file 1100k - observe.interval=0.25" \
            "checkpoint 4000k 1600k checkpoint.interval=2 checkpoint.keep=1"; do
  read -r kind size cksize extra <<< "$spec"
  read -r -a overrides <<< "$extra"
  out="$work/$kind"; mount_small "$out" "$size" || { echo "FAIL: mount"; exit 1; }
  ck=()
  if [ "$cksize" != "-" ]; then mount_small "$work/$kind-ck" "$cksize"; ck=(checkpoint.directory="$work/$kind-ck"); fi
  timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=direct run.duration=1000 \
    output.directory="$out" "${ck[@]}" "${overrides[@]}" > "$work/$kind.log" 2>&1
  code=$?
  msg=$(grep -i "error:.*no space left" "$work/$kind.log" | head -1 | cut -c1-220)
  if [ $code -ne 3 ] || [ -z "$msg" ]; then
    grep -v "^t = " "$work/$kind.log" | head -20; echo "FAIL: $kind: exit $code"; failures=$((failures + 1)); continue
  fi
  if /usr/bin/python3 - "$out" "$work/$kind-ck" <<'PY'
import glob, os, sys, xml.etree.ElementTree as ET, h5py
out, ck = sys.argv[1], sys.argv[2]
status = h5py.File(os.path.join(out, "efdem.h5"), "r").attrs["end_status"]
status = status.decode() if isinstance(status, bytes) else str(status)
assert status.startswith("failed:") and "no space left" in status.lower(), status
assert not glob.glob(os.path.join(out, "*.vtp.tmp")), "a partial VTK frame was left"
def vtp_is_whole(path):
    """The XML part parses and every appended block (UInt64 byte count + bytes) lies inside the
    file, which ends right after the last block with the closing tags."""
    data = open(path, "rb").read()
    start = data.index(b'<AppendedData encoding="raw">')
    head = ET.fromstring(data[:start] + b"</VTKFile>")
    base = data.index(b"_", start) + 1
    end = base
    for a in head.iter("DataArray"):
        at = base + int(a.get("offset"))
        end = max(end, at + 8 + int.from_bytes(data[at:at + 8], sys.byteorder))
    return data[end:] == b"\n  </AppendedData>\n</VTKFile>\n"
for f in glob.glob(os.path.join(out, "*.vtp")):
    assert vtp_is_whole(f), f"{f} is cut short"  # every frame left is whole
for f in glob.glob(os.path.join(out, "*.pvd")):
    ET.parse(f)  # and every series file
for f in glob.glob(os.path.join(ck, "*_ckpt_????????.h5")):
    with h5py.File(f, "r") as c:
        assert c.attrs["complete"] == 1, f
print(f"  run file: {status[:110]}...; {len(glob.glob(os.path.join(out, '*.vtp')))} VTK frames, "
      f"{len(glob.glob(os.path.join(ck, '*_ckpt_????????.h5')))} complete checkpoints, all readable")
PY
  then echo "PASS: $kind: exit 3: $msg"
  else echo "FAIL: $kind: files left behind"; failures=$((failures + 1)); fi
done
# A disk with room for the 1 MiB reserve and a few pages more (1 MiB + k x 4 KiB free): the run
# fails while it creates its outputs (the run file's metadata, the CSV sidecar, the first CSV
# header) or at its first sample. Whatever fails, the run ends with exit 3 and "no space left",
# its run file is absent or readable and says "failed: ...", and the reserve is gone. (Before:
# the run file was left "running" after a CSV header failed, or unreadable, and the reserve
# stayed.) tmpfs allocates whole pages, so these k cover each of those places on this scene.
nearly="$work/nearly"; mount_small "$nearly" 2000k || { echo "FAIL: mount"; exit 1; }
places=""
for k in 1 2 3 4 5 6 7 8; do
  rm -rf "${nearly:?}"/*
  avail=$(df -B1 --output=avail "$nearly" | tail -1)
  fallocate -l $((avail - 1048576 - k * 4096)) "$nearly/filler"
  timeout 120 "$mpiexec" -n 1 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=direct run.duration=1 \
    output.directory="$nearly/out" > "$work/nearly-$k.log" 2>&1
  code=$?
  if [ $code -eq 3 ] && grep -qi "error:.*no space left" "$work/nearly-$k.log" && [ ! -e "$nearly/out/efdem.h5.reserve" ] \
     && { [ ! -e "$nearly/out/efdem.h5" ] || /usr/bin/python3 -c "
import h5py, sys
s = h5py.File(sys.argv[1], 'r').attrs['end_status']
assert s.startswith('failed:') and 'no space left' in s.lower(), s" "$nearly/out/efdem.h5"; }; then
    places="$places $(grep -o -m1 "cannot write the CSV [a-z]*\|cannot create the HDF5 file\|HDF5 error in [^:]*: [a-z]*\|reserve" "$work/nearly-$k.log" | sed 's|/[^ ]*/||; s/ /_/g')"
  else
    grep -v "^t = " "$work/nearly-$k.log" | head -5; ls "$nearly/out"
    echo "FAIL: 1 MiB + $k pages free: exit $code"; failures=$((failures + 1))
  fi
done
echo "PASS: nearly full disks (1 MiB + 1..8 pages): exit 3, run file absent or marked failed, no reserve left; failed at:$places"

# A disk filled by another process during a checkpoint write (after the space check passed; the
# write is held open by debug.checkpoint_delay after the root's own realizations; what fails
# next is the other rank's rows, the header or the close, whichever HDF5 puts on the disk
# first): the run used to abort with the run file still
# "running", its 1 MiB reserve left behind and, in cpi mode, no reason given; a write failing on
# a rank other than the root aborted from that rank (a collective MPI-IO write). The root now
# writes every row and tells every rank: all end together with exit 3, no MPI_Abort.
for mode in direct cpi; do
  out="$work/filled-$mode"; mount_small "$out" 3000k || { echo "FAIL: mount"; exit 1; }
  timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=$mode run.duration=6 \
    output.directory="$out" checkpoint.interval=1 debug.checkpoint_delay=3 > "$work/filled-$mode.log" 2>&1 &
  job=$!
  for _ in $(seq 1200); do compgen -G "$out/*.tmp" > /dev/null && break; sleep 0.05; done
  sleep 0.5; fallocate -l 100M "$out/filler" 2>/dev/null || dd if=/dev/zero of="$out/filler" bs=64k 2>/dev/null
  wait $job; code=$?
  status=$(/usr/bin/python3 -c "import h5py, sys; print(h5py.File(sys.argv[1], 'r').attrs['end_status'])" "$out/efdem.h5")
  if [ $code -eq 3 ] && [[ $status == "failed: writing checkpoint 1: "*"no space left"* ]] \
     && [ ! -e "$out/efdem.h5.reserve" ] && ! compgen -G "$out/*.tmp" > /dev/null \
     && grep -q "error: writing checkpoint 1: .*no space left" "$work/filled-$mode.log" \
     && ! grep -q "MPI_ABORT" "$work/filled-$mode.log"; then
    echo "PASS: $mode, disk filled during a checkpoint: exit 3, run file '$(cut -c1-90 <<< "$status")...', reserve and partial checkpoint gone, no abort"
  else
    grep -v "^t = " "$work/filled-$mode.log" | head; ls "$out"; echo "FAIL: $mode, disk filled during a checkpoint: exit $code, status $status"
    failures=$((failures + 1))
  fi
done

[ $failures -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
echo "PASS: full disks end the run cleanly"
