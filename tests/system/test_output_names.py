#!/usr/bin/python3
"""Output names the file system cannot hold are bad input, found before any work (run by
`make check`; decks written by the test in a temporary folder).

(1) a 238-byte result name (its temporary name `<name>.<host>.<pid>.<n>.tmp` and its XDMF
    companions `<stem>_body1.xdmf` are over NAME_MAX, 255 bytes): exit 1 naming NAME_MAX, before the
    assembly phase, nothing written;
(2) a result path of 4085 bytes (short folder names, PATH_MAX 4096): its temporary names would
    be over PATH_MAX: exit 1 naming PATH_MAX, before the assembly, nothing written, no folder made;
(3) a result under a "folder" that is a regular file (`afile/sub/r.h5`): exit 1 saying it is not a folder,
    before the assembly;
(4) control: a 200-byte result name runs (exit 0, its files written).
"""
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import run_solver, solver_env  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
ENV = solver_env(1)
RUNTIME = ("Fortran runtime error", "Error termination", "Backtrace")
DECK = """&body id=1, x0=0.0, y0=1.0, width=1.0, height=1.0, nx=4, ny=4, left='clamped', bottom='contact' /
&body id=2, x0=0.0, y0=0.0, width=1.0, height=1.0, nx=4, ny=4, bottom='clamped', top='contact' /
&traction body=1, side='top', t0=0.0, -1.0e6 /
"""
check = Checks()


def files_under(d):
    return sorted(os.path.relpath(os.path.join(r, f), d) for r, _, fs in os.walk(d) for f in fs)


def run(work, h5):
    deck = os.path.join(work, "deck.nml")
    with open(deck, "w") as f:   # in the deck: a command-line override holds at most 4096 characters
        f.write(DECK + f"&output file='{h5}' /\n")
    p, _ = run_solver(BIN, deck, cwd=work, env=ENV, timeout=120)
    return p.returncode, p.stdout + p.stderr


def refused(work, h5, what, *needles):
    before = files_under(work)
    rc, text = run(work, h5)
    missing = [n for n in needles if n not in text]
    check(rc == 1 and not missing, f"{what}: exit 1 naming {', '.join(needles)}",
          f"exit {rc}, missing {missing}: {text.strip()[-500:]}")
    check("phase: assembly" not in text, f"{what}: refused before the assembly")
    check(not any(r in text for r in RUNTIME), f"{what}: no Fortran runtime error")
    after = [f for f in files_under(work) if f != "deck.nml"]
    check(after == [f for f in before if f != "deck.nml"], f"{what}: nothing written", str(after[:5]))


with tempfile.TemporaryDirectory() as work:
    refused(work, os.path.join(work, "x" * 235 + ".h5"), "a 238-byte result name (its companions longer)",
            "NAME_MAX", "255 bytes")
    sub = os.path.join(work, "deep")
    path = sub
    while len(path) < 4000:
        path = os.path.join(path, "d" * 60)
    path = os.path.join(path, "r" * (4081 - len(path)) + ".h5")
    check(4000 < len(path) < 4096, "the deep path is under the deck's limit of 4096", str(len(path)))
    refused(work, path, f"a {len(path)}-byte result path", "PATH_MAX", "4095 bytes")
    check(not os.path.exists(sub), "a path over PATH_MAX: no folder made")
    with open(os.path.join(work, "afile"), "w") as f:
        f.write("not a folder\n")
    refused(work, os.path.join(work, "afile", "sub", "r.h5"), "a result under a regular file",
            "afile is not a folder")
    ok = os.path.join(work, "y" * 197 + ".h5")
    rc, text = run(work, ok)
    check(rc == 0 and os.path.isfile(ok) and os.path.isfile(ok[:-3] + "_body2.xdmf"),
          "control: a 200-byte result name runs and writes its files", f"exit {rc}: {text.strip()[-300:]}")

sys.exit(1 if check.failed else 0)
