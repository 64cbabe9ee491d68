#!/usr/bin/python3
"""Messages print computed numbers as the summary does and suggest what fits the run
(run by `make check`; decks written by the test in a temporary folder).

(1) a body held only by contact pulled away by a traction (0.1, 200.2) on its top of width 3:
    exit 1, the load resultant and the unbalanced part in the summary's format
    ("(3.000E-01, 6.006E+02)", "unbalanced part 6.006E+02"), no number with 8 or more
    digits (binary noise such as 600.5999999999999);
(2) a monolithic solve stopped by inner_max_it: exit 2, the next: line suggests
    monolithic_rtol and inner_max_it and the equilibrium, never method='monolithic';
(3) a Robin run that does not converge (delta = 1, max_outer = 40): exit 2, the next: line
    still suggests method='monolithic';
(4) Tresca on two blocks 0.1 apart, pushed sideways: converged (given friction allows it),
    and a warning names the pair, the nodes that carry a shear across the open gap and
    friction='coulomb'; the same blocks in contact (no gap) print no such warning.
"""
import os
import re
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import run_solver, solver_env  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
ENV = solver_env(1)
DEFAULT = os.path.join(ROOT, "inputs", "default.nml")
PULLED = """&body id=1, x0=0.0, y0=1.0, width=3.0, height=1.0, nx=3, ny=1, left='roller', right='roller', bottom='contact' /
&body id=2, x0=0.0, y0=0.0, width=3.0, height=1.0, nx=3, ny=1, left='roller', bottom='clamped', top='contact' /
&traction body=1, side='top', t0=0.1, 200.2 /
"""
NOISE = re.compile(r"\d\.\d{7,}|\d{8,}")
check = Checks()

with tempfile.TemporaryDirectory() as work:
    deck = os.path.join(work, "pulled.nml")
    with open(deck, "w") as f:
        f.write(PULLED)
    p, _ = run_solver(BIN, deck, cwd=work, env=ENV, timeout=60)
    err = p.stderr
    check(p.returncode == 1 and "(resultant (3.000E-01, 6.006E+02))" in err and "unbalanced part 6.006E+02" in err,
          "a floating body pulled away: exit 1, the resultant and the unbalanced part as 3.000E-01, 6.006E+02",
          f"exit {p.returncode}: {err.strip()[-300:]}")
    check(not NOISE.search(err), "a floating body pulled away: no number of 8 or more digits in the message",
          str(NOISE.findall(err)))

    h5 = os.path.join(work, "m.h5")
    p, _ = run_solver(BIN, DEFAULT, "&solver method='monolithic', inner_max_it=1 /", f"&output file='{h5}' /",
                      cwd=work, env=ENV, timeout=120)
    nxt = [ln for ln in p.stderr.splitlines() if "next:" in ln]
    check(p.returncode == 2 and len(nxt) == 1 and "monolithic_rtol" in nxt[0] and "inner_max_it" in nxt[0]
          and "equilibrium" in nxt[0] and "method='monolithic'" not in nxt[0],
          "a monolithic run that stops short: exit 2, next: suggests monolithic_rtol, inner_max_it, equilibrium",
          f"exit {p.returncode}: {nxt}")

    p, _ = run_solver(BIN, DEFAULT, "&solver delta=1.0, max_outer=40 /", f"&output file='{h5}' /",
                      cwd=work, env=ENV, timeout=120)
    nxt = [ln for ln in p.stderr.splitlines() if "next:" in ln]
    check(p.returncode == 2 and len(nxt) == 1 and "method='monolithic'" in nxt[0],
          "a Robin run that does not converge: exit 2, next: suggests method='monolithic'",
          f"exit {p.returncode}: {nxt}")

    for gap, want in ((0.1, True), (0.0, False)):
        deck = os.path.join(work, f"tresca_gap{gap}.nml")
        with open(deck, "w") as f:
            f.write(f"""&body id = 1, x0 = 0.0, y0 = {1.0 + gap}, width = 1.0, height = 1.0, nx = 10, ny = 10, left = 'clamped' /
&body id = 2, x0 = 0.0, y0 = 0.0, width = 1.0, height = 1.0, nx = 10, ny = 10, bottom = 'clamped' /
&contact bodies = 1, 2, groups = 'bottom', 'top', friction = 'tresca', slip_bound = 2.5e4 /
&traction body = 1, side = 'top', t0 = 1.0e6, {-1.0e6 if gap == 0.0 else 0.0} /
""")
        p, res = run_solver(BIN, deck, f"&output file='{h5}' /", cwd=work, env=ENV, timeout=120)
        warned = re.search(r"warning: pair 1 \(Tresca.*nodes carry a shear force across an open gap.*coulomb", p.stderr)
        if want:
            check(p.returncode == 0 and warned is not None, "Tresca across an open gap: converged, a warning names the "
                  "pair and friction='coulomb'", f"exit {p.returncode}: {p.stderr[-300:]}")
        else:
            check(p.returncode == 0 and warned is None, "Tresca on blocks in contact: no open-gap warning",
                  f"exit {p.returncode}: {p.stderr[-300:]}")

sys.exit(1 if check.failed else 0)
