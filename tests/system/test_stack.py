#!/usr/bin/python3
"""The programs run with a non-executable stack (run by `make check`).

An internal procedure passed as an actual argument makes gfortran build a trampoline on the
stack, and the linker then marks the whole program's stack executable (with a warning in the
build, easy to miss): a hardening loss for a program that reads files from users. The
program (BIN) and, when built, the MPI program must carry a GNU_STACK header without the
execute flag; so must an object file of src/ (its .note.GNU-stack section, which the linker
combines).
"""
import glob
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from rc_checks import Checks  # noqa: E402

check = Checks()
build = os.environ.get("BUILD", "build/release")
programs = [os.environ.get("BIN", "bin/robin_contact")]
if os.path.exists("bin/robin_contact_mpi") and build == "build/release":
    programs.append("bin/robin_contact_mpi")
for prog in programs:
    out = subprocess.run(["readelf", "-lW", prog], capture_output=True, text=True)
    stack = [line.split() for line in out.stdout.splitlines() if line.split()[:1] == ["GNU_STACK"]]
    check(out.returncode == 0 and len(stack) == 1, f"{prog}: one GNU_STACK program header", out.stderr)
    if stack:
        check("E" not in stack[0][6], f"{prog}: stack not executable (flags {stack[0][6]})")
for obj in sorted(glob.glob(os.path.join(build, "*.o"))):
    out = subprocess.run(["readelf", "-SW", obj], capture_output=True, text=True)
    lines = [line for line in out.stdout.splitlines() if ".note.GNU-stack" in line]
    fields = lines[0].split("]", 1)[1].split() if lines else []
    flags = fields[6] if len(fields) == 10 else ""   # Name Type Address Off Size ES [Flg] Lk Inf Al
    check(lines != [] and "X" not in flags, f"{obj}: .note.GNU-stack present and not executable (flags {flags or 'none'})")
print(f"{'FAILED: ' + str(len(check.failed)) if check.failed else 'all checks passed'}")
sys.exit(1 if check.failed else 0)
