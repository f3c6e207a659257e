#!/usr/bin/python3
"""Keeps docs/scene_reference.md true to the code.

    /usr/bin/python3 scripts/scene_reference.py --efdem build/mpi_driver/efdem            # check
    /usr/bin/python3 scripts/scene_reference.py --efdem build/mpi_driver/efdem --keys     # the keys, TSV
    /usr/bin/python3 scripts/scene_reference.py --write-meanings   # after editing a meaning

The page's meanings also reach `efdem --list-keys` (its fourth column): the first sentence of
each, without markdown, is compiled in from mpi_driver/run/key_meanings.inc, which
--write-meanings writes from the page; the check fails while that file is not what it would write.

The keys: `efdem --list-keys` (every key a scene's set-up reads, with what it accepts and its
default, from the code's own declarations: core/param_table.hpp KeyDeclaration) on a matrix of
scenes and overrides that switches on every mode and option (SCENES below). The check fails when
  * a key the code reads is not a row of the page,
  * a row's `allowed` cell is not what the code accepts (its text, verbatim; where that depends
    on the scene, e.g. bounds from the box, a cell `depends on ...`),
  * a row's `default` cell is not the code's default (verbatim; `required` for a required key;
    a default the code derives from other keys is written `derived: ...`),
  * a row's meaning is empty, or a row names a key no scene reads and the source never names,
  * a key name written as a string literal in a get/get_or/get_choice/... call in the source
    is not the last part of some documented key (keys in branches the matrix does not reach).
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, ".."))
PAGE = os.path.join(ROOT, "docs", "scene_reference.md")
TINY = "tests/scripts/tiny_scene.cfg"
# (scene, overrides): together they reach every branch that reads keys.
SCENES = [
    ("examples/demo_small/scene.cfg", []),
    ("examples/fluidized_binary_bed/scene.cfg", ["run.duration=10"]),
    ("examples/paper_fig2a/scene.cfg", []),
    ("examples/paper_fig2b/scene.cfg", []),
    ("examples/paper_fig4/scene.cfg", []),
    ("examples/steady_demo/scene.cfg", []),
    ("examples/size_segregation/scene.cfg", ["mode=cpi"]),
    ("examples/tall_bed/scene_u019.cfg", ["ensemble.realizations_per_rank=2"]),
    ("examples/tall_bed/scene_u041.cfg", ["ensemble.realizations_per_rank=2"]),
    ("bench/scenes/demo_bed.cfg", []),
    ("bench/scenes/reference_bed.cfg", []),
    ("tests/scripts/single_species_bed.cfg", []),
    (TINY, []),
    (TINY, ["mode=cpi"]),
    (TINY, ["mode=cpi", "cpi.projection=periods"]),
    (TINY, ["mode=cpi", "cpi.projection=adaptive", "cpi.integrator=adams_bashforth2", "cpi.tolerance=0.1", "cpi.dt_min=1", "cpi.dt_max=2",
            "ensemble.realizations_per_rank=2"]),
    (TINY, ["mode=cpi", "cpi.projection=adaptive", "cpi.accuracy=1.5", "ensemble.realizations_per_rank=2"]),
    (TINY, ["mode=cpi", "cpi.observable=compact"]),
    (TINY, ["observe.bed=true", "observe.compact=true"]),
    (TINY, ["checkpoint.interval=2", "ensemble.on_failure=drop"]),
    (TINY, ["pair_contact.normal=hertz", "wall_contact.normal=hertz"]),
    # "-key": the key's line is taken out of a copy of the scene (an override cannot unset it).
    (TINY, ["pair_contact.damping=gamma", "wall_contact.damping=gamma", "pair_contact.gamma_n=100",
            "wall_contact.gamma_n=100", "pair_contact.tangential=none", "-pair_contact.restitution",
            "-pair_contact.mu"]),
    (TINY, ["effects=gravity pair_contact wall_contact gas_drag viscous_damping", "viscous_damping.gamma=0.1"]),
    (TINY, ["bed.settle=true", "gas_drag.A=0.114939"]),
    (TINY, ["mode=steady", "ensemble.realizations_per_rank=2"]),
    (TINY, ["mode=steady", "steady.coordinates=gaps", "ensemble.realizations_per_rank=2"]),
    (TINY, ["mode=steady", "steady.solver=anderson", "steady.eigenvalues=0", "ensemble.realizations_per_rank=2"]),
    (TINY, ["mode=cpi", "cpi.hand_off=steady", "ensemble.realizations_per_rank=2"]),
    (TINY, ["mode=continuation", "continuation.parameter=gas_drag.superficial_velocity", "continuation.end=0.5",
            "ensemble.realizations_per_rank=2"]),
]
# A key read in the source: get<T>("kn"), get_or(...), get_choice(...), contains("x"), and the
# contact laws' real_or_fallback(p, fb, "kn", ...) (wall_contact falls back to pair_contact).
CALL = re.compile(r"\b(?:get\w*|contains|\w+_or_fallback)\s*(?:<[^>]*>)?\s*\((?:\s*\w+\s*,)*\s*\"([A-Za-z_0-9.]+)\"")


def list_keys(efdem):
    keys = {}
    with tempfile.TemporaryDirectory() as out:
        for k, (scene, overrides) in enumerate(SCENES):
            path = os.path.join(ROOT, scene)
            drop = tuple(o[1:] for o in overrides if o.startswith("-"))
            if drop:
                with open(path, encoding="utf-8") as f:
                    lines = [x for x in f if not x.split("=")[0].strip() in drop]
                path = os.path.join(out, f"scene_{k}.cfg")
                with open(path, "w", encoding="utf-8") as f:
                    f.writelines(lines)
            overrides = [o for o in overrides if not o.startswith("-")]
            cmd = [efdem, "--list-keys", path, f"output.directory={out}", *overrides]
            r = subprocess.run(cmd, capture_output=True, text=True)
            if r.returncode != 0:
                sys.exit(f"scene_reference.py: {' '.join(cmd)} failed ({r.returncode}):\n{r.stderr}{r.stdout}")
            for line in r.stdout.splitlines()[1:]:  # under the header line
                key, expected, default, _meaning = line.split("\t")
                entry = keys.setdefault(key, {"expected": set(), "defaults": set()})
                entry["expected"].add(expected)
                entry["defaults"].add(default)
    return keys


def page_rows(path):
    rows = {}
    with open(path, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            m = re.match(r"^\|\s*`([A-Za-z_0-9.]+)`\s*\|(.*)\|\s*$", line)
            if not m:
                continue
            cells = [c.strip() for c in m.group(2).split("|")]
            if len(cells) != 5:
                sys.exit(f"{path}:{n}: a key row has key | meaning | unit | default | allowed | read when: {line.strip()}")
            rows[m.group(1)] = {"line": n, "meaning": cells[0], "unit": cells[1], "default": cells[2].strip("`"),
                                "allowed": cells[3], "when": cells[4]}
    return rows


MEANINGS = os.path.join(ROOT, "mpi_driver", "run", "key_meanings.inc")


def short_meaning(text):
    """The first sentence of a page meaning, without markdown: what --list-keys shows."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text).replace("`", "").replace("**", "")
    ends = [m.start() for m in re.finditer(r"\.(\s|$)", text) if not re.search(r"(i\.e|e\.g|cf)$", text[:m.start()])]
    first = (text[:ends[0]] if ends else text).strip()
    if len(first) > 150:  # a line a terminal shows: cut at a word
        first = first[:147].rsplit(" ", 1)[0] + "..."
    return first


def meanings_file(rows):
    lines = ["// Written by scripts/scene_reference.py --write-meanings from docs/scene_reference.md (the",
             "// first sentence of each key's meaning): edit the page, then run it. Read by listings.cpp."]
    for key in sorted(rows):
        text = short_meaning(rows[key]["meaning"]).replace("\\", "\\\\").replace('"', '\\"')
        lines.append(f'{{"{key}", "{text}"}},')
    return "\n".join(lines) + "\n"


def source_literals():
    names = {}
    for folder in ("core", "dem", "coarse", "mpi_driver"):
        for dirpath, _, files in os.walk(os.path.join(ROOT, folder)):
            for name in files:
                if name.endswith((".cpp", ".hpp")):
                    path = os.path.join(dirpath, name)
                    with open(path, encoding="utf-8") as f:
                        for m in CALL.finditer(f.read()):
                            names.setdefault(m.group(1), os.path.relpath(path, ROOT))
    return names


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--efdem", default=os.path.join(ROOT, "build", "mpi_driver", "efdem"))
    ap.add_argument("--page", default=PAGE)
    ap.add_argument("--keys", action="store_true", help="print the keys the code reads (TSV) and stop")
    ap.add_argument("--write-meanings", action="store_true",
                    help=f"write {os.path.relpath(MEANINGS, ROOT)} from the page and stop")
    a = ap.parse_args()
    if a.write_meanings:
        with open(MEANINGS, "w", encoding="utf-8") as f:
            f.write(meanings_file(page_rows(a.page)))
        print(f"scene_reference.py: wrote {os.path.relpath(MEANINGS, ROOT)}")
        return 0
    keys = list_keys(a.efdem)
    if a.keys:
        for k, v in keys.items():
            print(f"{k}\t{' | '.join(sorted(v['expected']))}\t{' | '.join(sorted(v['defaults']))}")
        return 0
    rows = page_rows(a.page)
    errors = []
    for k, v in keys.items():
        row = rows.get(k)
        if row is None:
            errors.append(f"`{k}` is read by the code ({' | '.join(sorted(v['expected']))}; default {' | '.join(sorted(v['defaults']))}) "
                          f"but has no row in {os.path.relpath(a.page, ROOT)}")
            continue
        where = f"{os.path.relpath(a.page, ROOT)}:{row['line']}: `{k}`"
        if not row["meaning"]:
            errors.append(f"{where}: no meaning")
        expected = v["expected"]
        if len(expected) > 1:
            if not row["allowed"].startswith("depends on"):
                errors.append(f"{where}: what the code accepts depends on the scene ({' | '.join(sorted(expected))}): "
                              "write it as 'depends on ...'")
        elif row["allowed"] != next(iter(expected)):
            errors.append(f"{where}: allowed '{row['allowed']}', the code accepts '{next(iter(expected))}'")
        defaults = v["defaults"]
        if row["default"].startswith("derived:"):
            pass
        elif len(defaults) > 1:
            errors.append(f"{where}: the default depends on the scene ({' | '.join(sorted(defaults))}): write it as 'derived: ...'")
        elif row["default"] != next(iter(defaults)):
            errors.append(f"{where}: default '{row['default']}', the code's is '{next(iter(defaults))}'")
    literals = source_literals()
    leaves = {k.split(".")[-1] for k in rows} | {k for k in rows}
    for name, path in sorted(literals.items()):
        if name not in leaves and not any(k.endswith("." + name) for k in rows):
            errors.append(f"{path} reads a key '{name}' that no row of the page names (a branch no scene of "
                          f"scripts/scene_reference.py reaches? add a scene there and a row to the page)")
    for k, row in rows.items():
        if k not in keys and k.split(".")[-1] not in literals:
            errors.append(f"{os.path.relpath(a.page, ROOT)}:{row['line']}: `{k}` is documented but nothing reads it")
    with open(MEANINGS, encoding="utf-8") as f:
        if f.read() != meanings_file(rows):
            errors.append(f"{os.path.relpath(MEANINGS, ROOT)} is not the page's meanings: run "
                          "/usr/bin/python3 scripts/scene_reference.py --write-meanings and rebuild")
    if errors:
        print("scene_reference.py: docs/scene_reference.md does not match the code:\n  " + "\n  ".join(errors))
        return 1
    print(f"scene_reference.py: all {len(keys)} keys the code reads are documented and match ({len(rows)} rows)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
