#!/usr/bin/python3
"""Every `physics.md §N[.M]` the code, scenes, scripts and docs cite names a section of
docs/physics.md (a heading `## N.` / `### N.M`, or item `M.` of the list in section N), and every
`docs/<page>.md` they name exists: a reader who follows a citation finds it in the repository.

    /usr/bin/python3 tests/scripts/check_doc_citations.py [ROOT]
"""
import os
import re
import sys

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
FOLDERS = ("core", "dem", "coarse", "mpi_driver", "tests", "bench", "scripts", "examples", "docs")
SUFFIXES = (".cpp", ".hpp", ".md", ".cfg", ".py", ".sh", ".txt", ".slurm")
CITE = re.compile(r"physics\.md,? ?§ ?([0-9]+(?:\.[0-9]+)?)")
PAGE = re.compile(r"\bdocs/([A-Za-z0-9_/]+\.md)\b")


def sections(path):
    """{"4": set of list items and subsections in section 4, ...}"""
    out, current = {}, None
    with open(path, encoding="utf-8") as f:
        for line in f:
            h = re.match(r"^#{2,3} ([0-9]+)\.([0-9]+)?", line)
            if h:
                if h.group(2):
                    out.setdefault(h.group(1), set()).add(h.group(2))
                else:
                    current = h.group(1)
                    out.setdefault(current, set())
                continue
            item = re.match(r"^([0-9]+)\. ", line)
            if item and current:
                out[current].add(item.group(1))
    return out


def main():
    known = sections(os.path.join(ROOT, "docs", "physics.md"))
    errors, cites = [], 0
    for folder in FOLDERS:
        for dirpath, _, files in os.walk(os.path.join(ROOT, folder)):
            for name in files:
                if not name.endswith(SUFFIXES):
                    continue
                path = os.path.join(dirpath, name)
                rel = os.path.relpath(path, ROOT)
                with open(path, encoding="utf-8", errors="replace") as f:
                    for n, line in enumerate(f, 1):
                        for m in CITE.finditer(line):
                            cites += 1
                            top, _, sub = m.group(1).partition(".")
                            if top not in known or (sub and sub not in known[top]):
                                errors.append(f"{rel}:{n}: cites physics.md §{m.group(1)}, which docs/physics.md does not have")
                        for m in PAGE.finditer(line):
                            if not os.path.exists(os.path.join(ROOT, "docs", m.group(1))):
                                errors.append(f"{rel}:{n}: names docs/{m.group(1)}, which does not exist")
    if errors:
        print("check_doc_citations:\n  " + "\n  ".join(errors))
        return 1
    print(f"check_doc_citations: {cites} citations of physics.md resolve; every docs/ page named exists")
    return 0


if __name__ == "__main__":
    sys.exit(main())
