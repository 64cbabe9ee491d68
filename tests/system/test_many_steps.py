#!/usr/bin/python3
"""A long load history, whole program (run by `make check`; deck written by the test): a
block pressed on a clamped one in 1,000 load steps (&solver load_steps=1000). Every step
converges and prints its step: line in order; /steps holds step_1 .. step_1000 with
load_factor k/1000; step k's contact resultant is k/1000 of the load (1e-9, equilibrium);
the last step equals the one-step run (1e-10 relative). The run time of the contact
phase (`iterate=`) is printed (INFO), not checked: the steps are kept with geometric
growth of their array (each step used to copy every earlier one, 1,000 steps 7 s, now 0.3 s
on one thread; doc/performance.md).
"""
import os
import re
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import line_fields, run_solver, solver_env  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
ENV = solver_env(1)
N = 1000
P = 1.0e6   # pressure on the top of width 1: the load is P per unit thickness
DECK = f"""&body id=1, x0=0, y0=1, width=1, height=0.5, nx=2, ny=2, young=1e9, bottom='contact', left='roller' /
&body id=2, x0=0, y0=0, width=1, height=1, nx=2, ny=2, young=1e9, top='contact', bottom='clamped' /
&traction body=1, side='top', t0=0.0,-{P} /
"""
check = Checks()

with tempfile.TemporaryDirectory() as work:
    deck = os.path.join(work, "steps.nml")
    with open(deck, "w") as f:
        f.write(DECK)
    many, one = os.path.join(work, "many.h5"), os.path.join(work, "one.h5")
    p, res = run_solver(BIN, deck, f"&solver load_steps={N} /", f"&output file='{many}' /", cwd=work, env=ENV,
                        timeout=600)
    text = p.stdout + p.stderr
    check(p.returncode == 0 and res is not None and res.get("status") == "converged",
          f"{N} load steps: exit 0, converged", f"exit {p.returncode}: {text.strip()[-300:]}")
    steps = re.findall(r"^step: step=(\d+) of=(\d+) .*status=(\S+)", p.stdout, re.M)
    check([int(s[0]) for s in steps] == list(range(1, N + 1)) and all(s[1] == str(N) and s[2] == "converged"
                                                                      for s in steps),
          f"{N} step: lines in order, each converged", f"{len(steps)} lines")
    t = line_fields(p.stdout, "time")
    print(f"INFO  {N} steps: iterate={t.get('iterate') if t else '?'} s output={t.get('output') if t else '?'} s",
          flush=True)
    p1, _ = run_solver(BIN, deck, f"&output file='{one}' /", cwd=work, env=ENV, timeout=120)
    check(p1.returncode == 0, "the one-step run: exit 0")
    if os.path.isfile(many) and os.path.isfile(one):
        with h5py.File(many, "r") as f, h5py.File(one, "r") as g:
            names = sorted(f["steps"].keys(), key=lambda s: int(s.split("_")[1])) if "steps" in f else []
            check(names == [f"step_{k}" for k in range(1, N + 1)], f"/steps holds step_1 .. step_{N}",
                  f"{len(names)} groups")
            bad_f, bad_r = [], []
            for k in range(1, N + 1):
                s = f[f"steps/step_{k}"] if f"steps/step_{k}" in f else None
                if s is None:
                    bad_f.append(k)
                    continue
                lf = float(np.asarray(s.attrs["load_factor"]).reshape(-1)[0])
                if abs(lf - k / N) > 1e-12:
                    bad_f.append(k)
                fy = float(s["contact/resultant_body1"][1])
                if abs(fy - k / N * P) > 1e-9 * P:
                    bad_r.append((k, fy))
            check(not bad_f, f"every step's load_factor is k/{N}", str(bad_f[:5]))
            check(not bad_r, f"every step's contact resultant is k/{N} of the load (1e-9)", str(bad_r[:5]))
            a = np.array(f["contact/normal_force"], dtype=float)
            b = np.array(g["contact/normal_force"], dtype=float)
            err = np.max(np.abs(a - b)) / np.max(np.abs(b))
            check(err <= 1e-10, "the last step equals the one-step run (1e-10)", f"{err:.2e}")

sys.exit(1 if check.failed else 0)
