#!/usr/bin/env bash
# Every key has a physically sensible range, and `efdem --check` refuses what lies outside it
# with exit 2, naming the key and what is allowed (docs/reliability.md, "Value ranges"); keys are
# checked only in the mode that uses them; long values are quoted cut at 120 characters.
#   value_ranges.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
scene="$here/tiny_scene.cfg"
failures=0
long=$(printf 'a%.0s' $(seq 100000))

refused() {  # refused KEY ALLOWED_SUBSTRING OVERRIDE...
  local key=$1 allowed=$2; shift 2
  local out code
  out=$("$mpiexec" -n 1 "${launcher[@]}" "$@" 2>&1 > /dev/null)
  code=$?
  line=$(grep "^efdem: error:" <<< "$out")
  if [ $code -eq 2 ] && grep -q "key '$key'" <<< "$line" && grep -qF "$allowed" <<< "$line" && [ ${#line} -lt 400 ]; then
    echo "PASS: $key refused: $(grep -o "key '$key'.*" <<< "$out" | cut -c1-160)"
  else
    echo "FAIL: $key (exit $code, ${#out} characters): $out" | cut -c1-600; failures=$((failures + 1))
  fi
}
check() { refused "$1" "$2" "$efdem" --check "$scene" "${@:3}"; }

check run.duration "0 or a multiple of 0.25" run.duration=1e-300
check observe.interval "a multiple of 0.0001" observe.interval=1e-300
check pair_contact.mu "[0, 10]" pair_contact.mu=1e308
check pair_contact.restitution "[0.001, 1]" pair_contact.restitution=4.9e-324
check pair_contact.kn "[1, 1000000000000]" pair_contact.kn=1e300
check bed.settle.ke_threshold "[1e-12, 1]" bed.settle.ke_threshold=1e20
check gas_drag.superficial_velocity "[0, 1000]" gas_drag.superficial_velocity=1e9
check dt "[1e-09, 1)" dt=1e-12
check cpi.tolerance "(0, 1000000]" mode=cpi cpi.projection=adaptive cpi.tolerance=1e300
check output.prefix "1 to 200 characters" output.prefix=$long
check mode "direct, cpi" mode=$long
# A cpi run too short for one coarse step, and one of exactly cpi.warmup + one burst (0.5 + 1.5
# in tiny_scene.cfg): nothing left to jump.
check run.duration "or mode = direct" mode=cpi run.duration=1
check run.duration "run.duration > 2" mode=cpi run.duration=2
# LAMMPS' dt: a direct run does not check the (unused) cpi defaults against observe.interval...
out=$("$mpiexec" -n 1 "${launcher[@]}" "$efdem" --check "$scene" mode=direct dt=1.8e-4 observe.interval=0.09 run.duration=0.9 2>&1)
if [ $? -eq 0 ]; then echo "PASS: direct run with dt = 1.8e-4, observe.interval = 0.09 accepted"
else echo "FAIL: direct run with LAMMPS' dt refused: $out" | tail -1; failures=$((failures + 1)); fi
# ... a cpi run does, and names a key it reads.
check cpi.warmup "a multiple of 0.09" mode=cpi dt=1.8e-4 observe.interval=0.09 run.duration=90

# Bounds from physics (each was accepted once, then failed at run time or did nothing useful).
# The drag's relaxation time tau = rho (1 - phi_cap)^2.65 / A: A = 3000 blew up within 1,000 steps.
check dt "dt <= 1.372e-05, or gas_drag.A <= 411.5" gas_drag.A=3000 gas_drag.superficial_velocity=0
check gas_drag.superficial_velocity "[0, 17.4]" gas_drag.superficial_velocity=999
check gas_drag.slab_thickness "[0.1, 10]" gas_drag.slab_thickness=1e300
check bed.velocity_rms "[0, 10]" bed.velocity_rms=1e6
check bed.settle.ke_threshold "[1e-12, 1]" bed.settle.ke_threshold=4.9e-324
check watchdog.max_overlap "[0.0001, 1]" watchdog.max_overlap=1e-300

# A scene must be a regular text file: a FIFO blocked --check for 630 s, /dev/zero was read
# until memory ran out. Each is refused at once, saying what the path is.
mkfifo "$work/scene_fifo.cfg"
head -c 17000000 /dev/zero | tr '\0' '#' > "$work/huge.cfg"
for case in "$work/scene_fifo.cfg:is a FIFO (named pipe), not a file" "/dev/zero:is a device, not a file" \
            "$work:is a directory, not a file" "$work/huge.cfg:is 17000000 bytes long; a scene is a text file of at most 16777216 bytes"; do
  path=${case%%:*}; what=${case#*:}
  out=$(timeout 30 "$mpiexec" -n 1 "${launcher[@]}" "$efdem" --check "$path" 2>&1); code=$?
  if [ $code -eq 2 ] && grep -qF "efdem: error: $path: $what" <<< "$out"; then
    echo "PASS: scene $path refused: $what"
  else
    echo "FAIL: scene $path (exit $code): $out" | cut -c1-400; failures=$((failures + 1))
  fi
done

[ $failures -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
echo "PASS: value ranges"
