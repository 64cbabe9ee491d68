#!/usr/bin/python3
"""The Makefile's module dependencies are exactly the real ones (run by `make check`).

For every Fortran module under src/, the line `$(BUILD)/<module>.o: ...` must list exactly
the project modules that its source `use`s: a missing one breaks parallel and incremental
builds, an extra one is a dependency that is not real. Every module must also be in MODS.
"""
import glob
import os
import re
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from rc_checks import Checks  # noqa: E402

check = Checks()
uses, path = {}, {}
for f in glob.glob("src/**/*.f90", recursive=True):
    text = open(f).read()
    m = re.search(r"^\s*module\s+(\w+)\s*$", text, re.M | re.I)
    name = m.group(1).lower() if m else os.path.basename(f)[:-4]
    path[name] = f
    # a module with a serial and an MPI source (mpi_env, mumps_iface): the union of their uses
    uses.setdefault(name, set()).update(u.lower() for u in re.findall(r"^\s*use\s+(\w+)", text, re.M | re.I))
own = set(path)

mk = re.sub(r"\\\n", " ", open("Makefile").read())
rules = {}
for m in re.finditer(r"^\$\(BUILD\)/(\w+)\.o:([^\n]*)$", mk, re.M):
    rules.setdefault(m.group(1), set()).update(re.findall(r"\$\(BUILD\)/(\w+)\.o", m.group(2)))
mods = set(re.search(r"^MODS := (.*)$", mk, re.M).group(1).split())

for name in sorted(own - {"robin_contact"}):
    real = (uses[name] & own) - {name}
    listed = rules.get(name)
    check(listed is not None and listed == real, f"{path[name]}: Makefile dependencies = its uses",
          "" if listed == real else f"missing {sorted(real - (listed or set()))}, not real {sorted((listed or set()) - real)}")
    check(name in mods, f"{name} is in MODS")
print(f"{'FAILED: ' + str(len(check.failed)) if check.failed else 'all checks passed'}")
sys.exit(1 if check.failed else 0)
