#!/usr/bin/python3
"""The module graph of src/, from the `use` statements of the Fortran sources.

Every module (and the program) of src/**/*.f90 is a node, grouped by its source folder; an
edge a --> b means that a uses b. Only modules defined in src/ appear: intrinsic and library
modules (iso_c_binding, iso_fortran_env, omp_lib, hdf5, mpi, ...) are left out. A module
with two sources (a serial and an MPI variant) gets the union of their uses. The output is a
Mermaid `graph` block, which GitHub renders.

  tools/module_graph.py            print the block
  tools/module_graph.py --write    put it into doc/developing.md between the marker lines
  tools/module_graph.py --check    exit 1 (and print the diff) when that file differs

--src DIR and --doc FILE choose other sources and another document (for tests).
Exit codes: 0 done or up to date, 1 out of date, missing markers or unreadable files.
"""
import argparse
import difflib
import glob
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BEGIN = "<!-- module-graph:begin -->"
END = "<!-- module-graph:end -->"

UNIT_RE = re.compile(r"^\s*(module|program)\s+(\w+)\s*$", re.I)
SUBMODULE_RE = re.compile(r"^\s*submodule\s*\(\s*(\w+)", re.I)
# use name | use :: name | use, non_intrinsic :: name (use, intrinsic :: name is skipped)
USE_RE = re.compile(r"^\s*use\b\s*(?:,\s*(\w+)\s*)?(?:::)?\s*(\w+)", re.I)


def scan(src):
    """{unit name: (folder relative to src, set of used names)} for every source file."""
    units = {}
    files = sorted(glob.glob(os.path.join(src, "**", "*.f90"), recursive=True)
                   + glob.glob(os.path.join(src, "**", "*.F90"), recursive=True))
    for path in files:
        with open(path, encoding="utf-8", errors="replace") as f:
            lines = [line.split("!", 1)[0] for line in f]
        name = None
        uses = set()
        for line in lines:
            m = UNIT_RE.match(line)
            if m and name is None and m.group(2).lower() not in ("procedure", "subroutine", "function"):
                name = m.group(2).lower()
                continue
            m = SUBMODULE_RE.match(line)
            if m and name is None:
                name = m.group(1).lower()
                continue
            m = USE_RE.match(line)
            if m and (m.group(1) or "").lower() != "intrinsic":
                uses.add(m.group(2).lower())
        if name is None:
            continue
        folder = os.path.relpath(os.path.dirname(path), src).replace(os.sep, "/")
        if name in units:
            units[name][1].update(uses)
        else:
            units[name] = (folder, uses)
    return units


def node(name):
    """A Mermaid node id that no keyword (end, graph, ...) can collide with."""
    return "m_" + name


def mermaid(src):
    units = scan(src)
    folders = {}
    for name, (folder, _) in units.items():
        folders.setdefault(folder, []).append(name)
    out = ["```mermaid", "graph TD"]
    for folder in sorted(folders, key=lambda f: (f != ".", f)):
        label = "src" if folder == "." else "src/" + folder
        out.append(f'  subgraph g_{re.sub(r"[^A-Za-z0-9_]", "_", label)} ["{label}"]')
        for name in sorted(folders[folder]):
            out.append(f'    {node(name)}["{name}"]')
        out.append("  end")
    for name in sorted(units):
        for used in sorted(units[name][1] & set(units) - {name}):
            out.append(f"  {node(name)} --> {node(used)}")
    out.append("```")
    return "\n".join(out) + "\n"


def replaced(text, block, doc):
    """text with the part between the markers replaced by block; ValueError without markers."""
    i, j = text.find(BEGIN), text.find(END)
    if i < 0 or j < 0 or j < i:
        raise ValueError(f"{doc}: the marker lines {BEGIN} and {END} are missing or out of order")
    head = text[:i + len(BEGIN)]
    return head + "\n" + block + text[j:]


def main():
    ap = argparse.ArgumentParser(description="Mermaid module graph of src/ from the use statements.")
    ap.add_argument("--src", default=os.path.join(ROOT, "src"), help="source folder (default: src/)")
    ap.add_argument("--doc", default=os.path.join(ROOT, "doc", "developing.md"),
                    help="document with the marker lines (default: doc/developing.md)")
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--write", action="store_true", help="write the graph into the document")
    mode.add_argument("--check", action="store_true", help="exit 1 if the document is out of date")
    a = ap.parse_args()

    if not os.path.isdir(a.src):
        print(f"module_graph: no source folder {a.src}", file=sys.stderr)
        return 1
    block = mermaid(a.src)
    if not (a.write or a.check):
        sys.stdout.write(block)
        return 0
    try:
        with open(a.doc, encoding="utf-8") as f:
            text = f.read()
        new = replaced(text, block, a.doc)
    except (OSError, ValueError) as e:
        print(f"module_graph: {e}", file=sys.stderr)
        return 1
    if a.check:
        if new == text:
            print(f"module_graph: {a.doc} is up to date")
            return 0
        sys.stdout.writelines(difflib.unified_diff(text.splitlines(True), new.splitlines(True),
                                                   a.doc, a.doc + " (generated)"))
        print(f"module_graph: {a.doc} is out of date: run tools/module_graph.py --write")
        return 1
    if new != text:
        tmp = a.doc + ".tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(new)
        os.replace(tmp, a.doc)
    print(f"module_graph: wrote {a.doc}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
