#!/usr/bin/env python3
"""Scene fuzzer for `efdem --check` (issue 8, item 5).

Mutates the seed scenes (and, for scenes that read a LAMMPS data file, sometimes that file) and
runs `efdem --check` on each mutant with a time limit. The promise under test: bad input gets a
clear error and nothing else happens. Every case must end with

  * exit 0 and "check passed" on stdout, or
  * exit 2 (input error) and a message on stderr,

never a signal, a hang, another exit code (3 = "runtime failure" is a finding too: set-up of a
scene must not fail at run time) or a silent exit 2.

Deterministic: case k of a run with --seed S is the same mutant whatever --cases, --jobs or the
order of execution. Failing cases are written to --failures DIR (scene, companion files, the
command, stdout and stderr) so that each can be replayed by hand.

Standard library only (runs with /usr/bin/python3 or any Python >= 3.8).

  python3 scripts/fuzz_scenes.py --efdem build/mpi_driver/efdem              # 1000 cases
  python3 scripts/fuzz_scenes.py --efdem build/mpi_driver/efdem --cases 50 --seed 1
  python3 scripts/fuzz_scenes.py --efdem build/mpi_driver/efdem --replay 17   # one case, verbose
"""

import argparse
import os
import random
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

HERE = Path(__file__).resolve().parent
DEFAULT_SEEDS = HERE.parent / "tests" / "data" / "fuzz"

NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")

# Values that probe the edges of number parsing and of every size derived from a number.
EXTREME_NUMBERS = [
    "0", "-0", "1e308", "1.7976931348623157e308", "1e309", "-1e308", "4.9e-324", "1e-320",
    "2.2250738585072014e-308", "1e-300", "1e300", "1e9", "1e12", "1e18", "1e19", "9.3e18",
    "2147483647", "2147483648", "-2147483649", "4294967296", "9223372036854775807",
    "9223372036854775808", "18446744073709551615", "18446744073709551616",
    "99999999999999999999999999", "1e6", "999999", "1000001", "268435456", "1.5", "0.5",
    "-1", "-1e9", "1e-9", "3.0000000000000001", "0x10", "1e", "1e+", ".", "-.", "+", "--1",
    "1..2", "1,5", "1_000", "0b101", "1e-", "0.1e-400",
]
NON_FINITE = ["nan", "NaN", "-nan", "inf", "-inf", "Inf", "infinity", "-Infinity", "1e999",
              "-1e999", "nan(123)", "NAN", "+inf"]
WORDS = ["abc", "true", "false", "light", "heavy", "lattice", "lammps_data", "hooke", "none",
         "gravity", '"quoted word"', '"', "#", "=", "===", "é", "\u00e9\u0301", "\u202e", "*",
         "../../etc/passwd", "/", "/dev/zero", "/dev/null", "tiny_bed.data", "%s%n%x", "\\"]
UNKNOWN_KEYS = ["foo", "foo.bar", "pair_contact.kk", "wall_contact.kn", "gas_drag.law",
                "bed.settle.maxtime", "domain.lz", "species.name", "Dt", "dt_", "effects.x",
                "viscous_damping.gamma", "gravity.g", "bed.file", "bed.source", "bed.read", "bed.write",
                "bed.read.shared", "bed.read.velocity_rms", "_", "a" * 300]
RANDOM_BYTES = [b"\x00", b"\xff", b"\xfe\xff", b"\xc3\x28", b"\xe2\x82", b"\x80", b"\r", b"\t",
                b"\x1b[31m", b"\x7f", b"\n", b"=", b"#", b'"', b"\xf0\x9f\x92\xa9", b"\x00\x00"]
REQUIRED_KEYS = ["dt", "effects", "domain.lx", "domain.ly", "species.names", "species.density",
                 "species.diameter", "bed.count", "pair_contact.kn", "pair_contact.mu",
                 "pair_contact.restitution", "bed.file", "viscous_damping.gamma"]


# ------------------------------------------------------------------------------------------
# Mutations. Each takes (rng, lines) where lines is a list of bytes (no newline) and returns
# the new list, plus a short description. They never fail: a mutation that finds nothing to
# act on falls back to appending an unknown key.

def value_positions(lines):
    """(line index, key, value) for every 'key = value' line."""
    out = []
    for i, raw in enumerate(lines):
        text = raw.decode("utf-8", "replace")
        if "=" in text and not text.lstrip().startswith("#"):
            key, value = text.split("=", 1)
            out.append((i, key.strip(), value.split("#", 1)[0].strip()))
    return out


def set_value(lines, i, key, value):
    lines[i] = (key + " = " + value).encode("utf-8", "surrogateescape")
    return lines


def pick_token(rng, value, want_number):
    toks = value.split()
    idx = [k for k, t in enumerate(toks) if bool(NUMBER.match(t)) == want_number]
    if not idx:
        return None
    k = rng.choice(idx)
    return toks, k


def m_delete_line(rng, lines):
    if not lines:
        return lines, "delete (nothing)"
    i = rng.randrange(len(lines))
    return lines[:i] + lines[i + 1:], f"delete line {i + 1}"


def m_missing_required(rng, lines):
    pos = [p for p in value_positions(lines) if p[1] in REQUIRED_KEYS]
    if not pos:
        return m_delete_line(rng, lines)
    i, key, _ = rng.choice(pos)
    return lines[:i] + lines[i + 1:], f"remove required key {key}"


def m_duplicate_line(rng, lines):
    if not lines:
        return lines, "duplicate (nothing)"
    i = rng.randrange(len(lines))
    j = rng.randrange(len(lines) + 1)
    return lines[:j] + [lines[i]] + lines[j:], f"duplicate line {i + 1} at {j + 1}"


def m_random_bytes(rng, lines):
    if not lines:
        return [rng.choice(RANDOM_BYTES)], "random bytes into empty file"
    i = rng.randrange(len(lines))
    line = lines[i]
    at = rng.randrange(len(line) + 1)
    junk = b"".join(rng.choice(RANDOM_BYTES) if rng.random() < 0.6 else bytes([rng.randrange(256)])
                    for _ in range(rng.randint(1, 4)))
    lines = list(lines)
    lines[i] = line[:at] + junk + line[at:]
    return lines, f"bytes {junk!r} into line {i + 1} at column {at}"


def m_replace_number(rng, lines, pool, what):
    for pos in rng.sample(value_positions(lines), k=len(value_positions(lines))):
        i, key, value = pos
        picked = pick_token(rng, value, want_number=True)
        if picked:
            toks, k = picked
            toks[k] = rng.choice(pool)
            return set_value(list(lines), i, key, " ".join(toks)), f"{what} in {key}: {toks[k]}"
    return m_unknown_key(rng, lines)


def m_extreme_number(rng, lines):
    return m_replace_number(rng, lines, EXTREME_NUMBERS, "extreme number")


def m_non_finite(rng, lines):
    return m_replace_number(rng, lines, NON_FINITE, "non-finite")


def scaled(rng, token, factor):
    x = float(token)
    if factor is None:  # negate
        return repr(-x) if x != 0 else "-1"
    return "%.6g" % (x * factor) if x != 0 else "1e6"


def m_scale_number(rng, lines):
    """Realistic-looking but extreme: one number (or a whole vector) times 10^k, or negated."""
    for pos in rng.sample(value_positions(lines), k=len(value_positions(lines))):
        i, key, value = pos
        picked = pick_token(rng, value, want_number=True)
        if picked:
            toks, k = picked
            factor = None if rng.random() < 0.2 else 10.0 ** rng.randint(-12, 12)
            every = [j for j, t in enumerate(toks) if NUMBER.match(t)] if rng.random() < 0.5 else [k]
            for j in every:
                toks[j] = scaled(rng, toks[j], factor)
            return set_value(list(lines), i, key, " ".join(toks)), f"scaled {key} to {' '.join(toks)[:60]}"
    return m_unknown_key(rng, lines)


def m_unit_mistake(rng, lines):
    """Every number of 2 to 4 keys times the same 10^k (lengths in other units, say)."""
    pos = [p for p in value_positions(lines) if any(NUMBER.match(t) for t in p[2].split())]
    if len(pos) < 2:
        return m_scale_number(rng, lines)
    factor = 10.0 ** rng.choice([-9, -6, -4, -3, 3, 4, 6, 9])
    lines = list(lines)
    keys = []
    for i, key, value in rng.sample(pos, k=min(len(pos), rng.randint(2, 4))):
        toks = [scaled(rng, t, factor) if NUMBER.match(t) else t for t in value.split()]
        lines = set_value(lines, i, key, " ".join(toks))
        keys.append(key)
    return lines, f"{', '.join(keys)} times {factor:g}"


def m_word_for_number(rng, lines):
    return m_replace_number(rng, lines, WORDS, "word for a number")


def m_number_for_word(rng, lines):
    for pos in rng.sample(value_positions(lines), k=len(value_positions(lines))):
        i, key, value = pos
        picked = pick_token(rng, value, want_number=False)
        if picked:
            toks, k = picked
            toks[k] = rng.choice(EXTREME_NUMBERS + ["1", "2", "0"])
            return set_value(list(lines), i, key, " ".join(toks)), f"number for a word in {key}"
    return m_unknown_key(rng, lines)


def m_unknown_key(rng, lines):
    key = rng.choice(UNKNOWN_KEYS)
    value = rng.choice(["1", "0.5", "abc", "1 2 3", "gravity"])
    j = rng.randrange(len(lines) + 1)
    return lines[:j] + [f"{key} = {value}".encode()] + lines[j:], f"unknown key {key[:40]}"


def m_truncate_line(rng, lines):
    if not lines:
        return lines, "truncate (nothing)"
    i = rng.randrange(len(lines))
    cut = rng.randrange(len(lines[i]) + 1)
    lines = list(lines)
    lines[i] = lines[i][:cut]
    return lines, f"truncate line {i + 1} at column {cut}"


def m_swap_values(rng, lines):
    pos = value_positions(lines)
    if len(pos) < 2:
        return m_unknown_key(rng, lines)
    a, b = rng.sample(pos, 2)
    lines = set_value(list(lines), a[0], a[1], b[2])
    lines = set_value(lines, b[0], b[1], a[2])
    return lines, f"swap values of {a[1]} and {b[1]}"


def m_empty_value(rng, lines):
    pos = value_positions(lines)
    if not pos:
        return m_unknown_key(rng, lines)
    i, key, _ = rng.choice(pos)
    lines = list(lines)
    lines[i] = (key + rng.choice([" =", " = ", "=", ' = ""', " = #comment"])).encode()
    return lines, f"empty value for {key}"


def m_long(rng, lines):
    pos = value_positions(lines)
    kind = rng.choice(["value", "token", "key", "line", "many_lines"])
    lines = list(lines)
    if kind == "many_lines":
        n = rng.choice([1000, 20000])
        return lines + [f"x{k} = 1".encode() for k in range(n)], f"{n} extra lines"
    if kind == "line" or not pos:
        return lines + [b"#" + b"x" * 2_000_000, b"y" * 500_000], "2 MB comment and 500 kB line"
    i, key, value = rng.choice(pos)
    if kind == "value":
        reps = rng.choice([1000, 100_000])
        return set_value(lines, i, key, " ".join([value or "1"] * reps)), f"{key} repeated {reps} times"
    if kind == "token":
        tok = rng.choice(["9", "1", "a", "e", "."]) * rng.choice([400, 100_000, 1_000_000])
        return set_value(lines, i, key, tok), f"{key} = one {len(tok)}-character token"
    long_key = key + "." + "k" * rng.choice([500, 200_000])
    return set_value(lines, i, long_key, value), f"{len(long_key)}-character key"


# Values at and beyond the bounds that physics sets (docs/scene_reference.md): each of the
# outside ones was once accepted by --check and then failed at run time or did nothing useful
# (the drag's relaxation time, the terminal velocity, a slab bigger than the box, settling that
# can never end, a watchdog that trips on a bed at rest).
PHYSICS_EDGES = {
    "gas_drag.A": ["3e3", "411", "412", "1500", "1e6"],
    "gas_drag.superficial_velocity": ["999", "17.4", "17.5", "8.7"],
    "gas_drag.slab_thickness": ["1e300", "10", "10.5", "0.1"],
    "bed.velocity_rms": ["1e6", "10", "10.1"],
    "bed.settle.ke_threshold": ["4.9e-324", "1e-12", "9e-13"],
    "watchdog.max_overlap": ["1e-300", "1e-4", "9e-5"],
}


def m_physics_edge(rng, lines):
    key = rng.choice(sorted(PHYSICS_EDGES))
    value = rng.choice(PHYSICS_EDGES[key])
    for i, k, _ in value_positions(lines):
        if k == key:
            return set_value(lines, i, key, value), f"physics edge {key} = {value}"
    return lines + [f"{key} = {value}".encode()], f"physics edge {key} = {value} (added)"


MUTATIONS = [
    m_delete_line, m_missing_required, m_duplicate_line, m_random_bytes, m_extreme_number,
    m_non_finite, m_scale_number, m_scale_number, m_unit_mistake, m_unit_mistake,
    m_word_for_number, m_number_for_word,
    m_unknown_key, m_truncate_line, m_swap_values, m_empty_value, m_long, m_physics_edge,
]


def mutate_data_file(rng, data):
    """A line-level mutation of a LAMMPS data file (numbers, deletions, duplications, bytes)."""
    lines = data.split(b"\n")
    kind = rng.randrange(6)
    i = rng.randrange(len(lines))
    toks = lines[i].split()
    if kind == 0 and toks:
        k = rng.randrange(len(toks))
        toks[k] = rng.choice(EXTREME_NUMBERS + NON_FINITE + WORDS).encode("utf-8")
        lines[i] = b" ".join(toks)
        what = f"data line {i + 1} token {k + 1}"
    elif kind == 1:
        del lines[i]
        what = f"data line {i + 1} deleted"
    elif kind == 2:
        lines.insert(rng.randrange(len(lines) + 1), lines[i])
        what = f"data line {i + 1} duplicated"
    elif kind == 3:
        lines[i] = lines[i][: rng.randrange(len(lines[i]) + 1)]
        what = f"data line {i + 1} truncated"
    elif kind == 4:
        lines = lines[: rng.randrange(len(lines) + 1)]
        what = "data file truncated"
    else:
        lines[i] = lines[i] + rng.choice(RANDOM_BYTES)
        what = f"bytes into data line {i + 1}"
    return b"\n".join(lines), what


# ------------------------------------------------------------------------------------------

class Case:
    def __init__(self, index, seed_scene, scene, companions, overrides, description):
        self.index = index
        self.seed_scene = seed_scene
        self.scene = scene              # bytes
        self.companions = companions    # {name: bytes}
        self.overrides = overrides      # [str]
        self.description = description  # [str]


def make_case(master_seed, index, seeds, companions):
    rng = random.Random(master_seed * 1_000_003 + index)
    name = rng.choice(sorted(seeds))
    lines = seeds[name].split(b"\n")
    description = []
    for _ in range(rng.choice([1, 1, 1, 2, 2, 3])):
        lines, what = rng.choice(MUTATIONS)(rng, lines)
        description.append(what)
    files = dict(companions)
    if b"bed.file" in seeds[name] and rng.random() < 0.3:
        for cname in list(files):
            if cname.endswith(".data"):
                files[cname], what = mutate_data_file(rng, files[cname])
                description.append(what)
    overrides = []
    if rng.random() < 0.1:
        pos = value_positions(seeds[name].split(b"\n"))
        if pos:
            _, key, _ = rng.choice(pos)
            value = rng.choice(EXTREME_NUMBERS + NON_FINITE + WORDS + [""])
            overrides.append(f"{key}={value}")
            description.append(f"override {key}={value}")
    return Case(index, name, b"\n".join(lines), files, overrides, description)


def write_case(case, directory):
    directory.mkdir(parents=True, exist_ok=True)
    for cname, data in case.companions.items():
        (directory / cname).write_bytes(data)
    scene = directory / "scene.cfg"
    scene.write_bytes(case.scene)
    return scene


def limit_memory(megabytes):
    if megabytes <= 0:
        return None

    def apply():
        limit = megabytes * 1024 * 1024
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    return apply


def classify(code, stdout, stderr, timed_out):
    """Returns None if the outcome keeps the promise, else what is wrong."""
    if timed_out:
        return "timeout"
    if code < 0:
        return f"signal {-code}"
    if code == 0:
        return None if b"check passed" in stdout else "exit 0 without 'check passed'"
    if code == 2:
        return None if stderr.strip() else "exit 2 without a message on stderr"
    return f"exit code {code}"


def run_case(case, efdem, workdir, timeout, memory_mb):
    scene = write_case(case, workdir / f"case_{case.index:05d}")
    cmd = [efdem, "--check", str(scene)] + case.overrides
    env = dict(os.environ)
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    env.setdefault("OMPI_MCA_rmaps_base_oversubscribe", "1")
    start = time.monotonic()
    timed_out = False
    try:
        proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=timeout,
                              env=env, preexec_fn=limit_memory(memory_mb))
        code, out, err = proc.returncode, proc.stdout, proc.stderr
    except subprocess.TimeoutExpired as e:
        timed_out, code, out, err = True, None, e.stdout or b"", e.stderr or b""
    seconds = time.monotonic() - start
    problem = classify(code, out, err, timed_out)
    outcome = "timeout" if timed_out else ("ok" if code == 0 else "input error" if code == 2 and not problem
                                           else f"exit {code}")
    shutil.rmtree(scene.parent, ignore_errors=True)
    return dict(case=case, cmd=cmd, code=code, stdout=out, stderr=err, seconds=seconds,
                problem=problem, outcome=outcome)


def save_failure(result, failures):
    case = result["case"]
    d = failures / f"case_{case.index:05d}"
    shutil.rmtree(d, ignore_errors=True)
    write_case(case, d)
    (d / "stdout.txt").write_bytes(result["stdout"])
    (d / "stderr.txt").write_bytes(result["stderr"])
    args = " ".join(repr(o) for o in case.overrides)
    (d / "README.txt").write_text(
        f"problem: {result['problem']}\nseed scene: {case.seed_scene}\n"
        f"mutations: {'; '.join(case.description)}\n"
        f"replay: efdem --check scene.cfg {args}\n", encoding="utf-8")
    return d


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--efdem", required=True, help="the efdem executable")
    ap.add_argument("--seeds", default=str(DEFAULT_SEEDS),
                    help="folder of seed scenes (*.cfg) and their companion files")
    ap.add_argument("--cases", type=int, default=1000, help="number of mutants (default 1000)")
    ap.add_argument("--seed", type=int, default=1, help="master seed (default 1)")
    ap.add_argument("--timeout", type=float, default=20.0,
                    help="seconds per case before it counts as a hang (default 20)")
    ap.add_argument("--memory-mb", type=int, default=8192,
                    help="address-space limit per case in MiB, 0 for none (default 8192; use 0 "
                         "for sanitizer builds)")
    ap.add_argument("--jobs", type=int, default=1, help="cases run at once (default 1)")
    ap.add_argument("--failures", default="fuzz-failures",
                    help="folder for failing cases (default ./fuzz-failures)")
    ap.add_argument("--replay", type=int, default=None,
                    help="run only this case index and print its command and output")
    args = ap.parse_args()

    efdem = str(Path(args.efdem).resolve())
    seeds_dir = Path(args.seeds)
    seeds = {p.name: p.read_bytes() for p in sorted(seeds_dir.glob("*.cfg"))}
    companions = {p.name: p.read_bytes() for p in sorted(seeds_dir.iterdir())
                  if p.is_file() and p.suffix != ".cfg"}
    if not seeds:
        sys.exit(f"fuzz_scenes: no seed scenes (*.cfg) in {seeds_dir}")

    indices = [args.replay] if args.replay is not None else range(args.cases)
    cases = [make_case(args.seed, k, seeds, companions) for k in indices]
    failures = Path(args.failures)
    with tempfile.TemporaryDirectory(prefix="efdem-fuzz-") as tmp:
        work = Path(tmp)
        with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
            results = list(pool.map(
                lambda c: run_case(c, efdem, work, args.timeout, args.memory_mb), cases))

    if args.replay is not None:
        r = results[0]
        print("mutations:", "; ".join(r["case"].description))
        print("command:", " ".join(r["cmd"]))
        print("exit:", r["code"], "problem:", r["problem"])
        sys.stdout.write(r["stderr"].decode("utf-8", "replace")[-4000:])
        return 0 if r["problem"] is None else 1

    counts = {}
    for r in results:
        counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
    failed = [r for r in results if r["problem"]]
    slowest = sorted(results, key=lambda r: -r["seconds"])[:5]
    print(f"fuzz_scenes: {len(results)} cases from {len(seeds)} seed scenes, --seed {args.seed}")
    for outcome in sorted(counts):
        print(f"  {outcome:12s} {counts[outcome]}")
    print("slowest cases:")
    for r in slowest:
        print(f"  case {r['case'].index}: {r['seconds']:.2f} s ({r['outcome']}; "
              f"{r['case'].seed_scene}: {'; '.join(r['case'].description)[:100]})")
    for r in failed:
        d = save_failure(r, failures)
        first = r["stderr"].decode("utf-8", "replace").strip().splitlines()[-1:] or [""]
        print(f"FAILED case {r['case'].index}: {r['problem']} -> {d}\n    {first[0][:300]}")
    print(f"{len(results) - len(failed)} passed, {len(failed)} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
