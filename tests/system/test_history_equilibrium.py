#!/usr/bin/python3
"""Load histories whose loads the contact cannot hold at every step (run by `make check`;
doc/running.md, "Load steps and stages"). The holding checks run step by step:

(1) a pull-out test: a block held only by Coulomb friction (mu = 0.4) on a clamped base,
    pressed by N = 1e6 in stage 1, pulled sideways in stage 2 over 11 steps to 1.1 mu N
    (step k of stage 2 pulls k/11 of it): the steps up to mu N (stage 2's tenth, the 11th of
    the history) are solved and written, the 12th is not: exit 2, status `no_equilibrium` in
    the result line and the file, a message naming step 12, stage 2 and its load factor,
    `/steps` holding 11 steps, and each written step's tangential resultant on the base equal
    to its pull (1e-7: the runs stop at tol 1e-8).
(2) the same without the 11th step's excess (pulled to 0.9 mu N): every step solved, exit 0.
(3) stage 1 pulls a block off its support, stage 2 presses it back: refused before any work,
    exit 1, naming step 1 and stage 1; nothing written.
"""
import os
import shutil
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import run_solver, solver_env  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
check = Checks()

BLOCK = """&scene title = 'pull-out' /
&body id = 1, x0 = 0.0, y0 = 0.0, width = 4.0, height = 0.5, nx = 40, ny = 5, young = 2.1e11, poisson = 0.3, bottom = 'clamped' /
&body id = 2, x0 = 1.5, y0 = 0.5, width = 1.0, height = 0.5, nx = 10, ny = 5, young = 2.1e11, poisson = 0.3 /
&contact bodies = 2, 1, groups = 'bottom', 'top', friction = 'coulomb', mu = 0.4 /
&traction body = 2, side = 'top', t0 = 0.0, -1.0e6 /
&traction body = 2, side = 'left', t0 = {t}, 0.0, stage = 2 /
&solver load_steps = 1, 11 /
"""


def run(tmp, name, text):
    deck = os.path.join(tmp, name + ".nml")
    h5 = os.path.join(tmp, name + ".h5")
    with open(deck, "w") as f:
        f.write(text)
    p, res = run_solver(BIN, deck, f"&output file='{h5}' /", cwd=tmp, env=solver_env(), timeout=300)
    return p, res, h5


def main():
    tmp = tempfile.mkdtemp(prefix="test_history_equilibrium_")
    try:
        # (1) pulled to 1.1 mu N: Q = t x 0.5 (the left side's height), 1.1 x 0.4 x 1e6 = 4.4e5
        pull = 4.4e5
        p, res, h5 = run(tmp, "pullout", BLOCK.format(t=2.0 * pull))
        err = p.stderr
        check(p.returncode == 2 and res is not None and res.get("status") == "no_equilibrium",
              "pull-out beyond mu N: exit 2, status no_equilibrium", f"exit {p.returncode}, {res}")
        check("no static equilibrium from step 12 of 12 (stage 2, load factor 1.000E+00)" in err,
              "the message names step 12, stage 2 and its load factor", err[-300:])
        check("Traceback" not in err and "Backtrace" not in err, "no backtrace")
        if os.path.exists(h5):
            with h5py.File(h5, "r") as f:
                st = f.attrs["status"]
                st = st.decode() if isinstance(st, bytes) else str(st)
                steps = sorted(f["steps"].keys(), key=lambda s: int(s.split("_")[1])) if "steps" in f else []
                check(st == "no_equilibrium" and len(steps) == 11,
                      "the result file: status no_equilibrium, the 11 steps that hold", f"{st}, {len(steps)} steps")
                worst = 0.0
                for k, s in enumerate(steps[1:], start=1):
                    r = f[f"steps/{s}/contact/resultant_body1"][()]
                    q = pull * k / 11.0
                    worst = max(worst, abs(r[0] - q) / q)
                check(worst <= 1e-7, "each written step's tangential resultant on the base is its pull (1e-7)",
                      f"{worst:.1e}")
        else:
            check(False, "the result file of the steps that hold is written", h5)
        # (2) pulled to 0.9 mu N: every step
        p, res, h5 = run(tmp, "pull_below", BLOCK.format(t=2.0 * 0.9 * 0.4e6 * 11.0 / 11.0))
        check(p.returncode == 0 and res is not None and res.get("status") == "converged",
              "pulled to 0.9 mu N: every step solved, exit 0", f"exit {p.returncode}: {p.stderr[-200:]}")
        # (3) stage 1 pulls the block off its support
        deck = """&scene title = 'stage 1 pulls the block off, stage 2 presses it back' /
&body id = 1, x0 = 0.0, y0 = 0.0, width = 4.0, height = 0.5, nx = 40, ny = 5, young = 2.1e11, poisson = 0.3, bottom = 'clamped' /
&body id = 2, x0 = 1.5, y0 = 0.5, width = 1.0, height = 0.5, nx = 10, ny = 5, young = 2.1e11, poisson = 0.3, left = 'roller' /
&contact bodies = 2, 1, groups = 'bottom', 'top' /
&traction body = 2, side = 'top', t0 = 0.0, 1.0e6 /
&traction body = 2, side = 'right', t0 = 0.0, -3.0e6, stage = 2 /
&solver load_steps = 1, 2 /
"""
        p, res, h5 = run(tmp, "pulled_off", deck)
        check(p.returncode == 1 and "at step 1 of 3 (stage 1" in p.stderr and "pulls it away" in p.stderr
              and not os.path.exists(h5), "stage 1 pulls the block off: exit 1 naming step 1 and stage 1, nothing "
              "written", f"exit {p.returncode}: {p.stderr[-250:]}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"{len(check.failed)} failed checks")
    return 1 if check.failed else 0


if __name__ == "__main__":
    sys.exit(main())
