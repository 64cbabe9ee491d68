#!/usr/bin/python3
"""The modules of src/ that use neither MPI nor MUMPS, not even through another module: their
objects are the same in the serial and the MPI build, so `make check` copies them from the
serial build into the MPI one instead of compiling them twice. Prints their names, one line,
blank-separated.

usage: tools/mpi_free_modules.py [--src src]
"""
import argparse
import glob
import os
import re
import sys

MPI_MODULES = {"mpi_env", "mumps_iface"}   # the modules with a serial and an MPI source


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--src", default=os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "src"))
    a = ap.parse_args()
    uses = {}
    for path in glob.glob(os.path.join(a.src, "**", "*.f90"), recursive=True):
        with open(path) as f:
            text = f.read()
        m = re.search(r"^\s*module\s+(\w+)\s*$", text, re.M | re.I)
        if not m:
            continue
        name = m.group(1).lower()
        uses.setdefault(name, set()).update(u.lower() for u in re.findall(r"^\s*use\s+(\w+)", text, re.M | re.I))
    tainted = set(MPI_MODULES)
    grown = True
    while grown:
        grown = False
        for name, used in uses.items():
            if name not in tainted and used & tainted:
                tainted.add(name)
                grown = True
    print(" ".join(sorted(n for n in uses if n not in tainted)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
