#!/usr/bin/python3
"""Interference fits, whole program (run by `make check`): the shipped deck
inputs/shrink_fit.nml (a quarter of a solid shaft in a quarter ring, the shaft's radius
larger than the bore by delta = 1e-3 b, plane strain, symmetry supports) against Lame's
solution of a shaft shrink-fitted in a thick ring:

    delta = p b [ ((c^2 + b^2)/(c^2 - b^2) + nu_r') / E_r' + (1 - nu_s') / E_s' ]

with E' = E/(1 - nu^2), nu' = nu/(1 - nu) (plane strain); the same material gives
p = E' delta (c^2 - b^2)/(2 b c^2) = 8.654e7 Pa.

(1) steel in steel: the pressure at every slave node within 0.5% of Lame, the resultant on
    the quarter shaft (-p b, -p b) within 0.05% (it averages the nodes' scatter);
(2) the ring of aluminium (E = 7e10, nu = 0.33): the same against the two-material formula;
(3) Robin = monolithic: the contact forces to 1e-8 of the largest;
(4) without overlap='interference' the overlap is bad input (exit 1, the message names the
    node and the word that makes it a fit, nothing written); two blocks overlapping by 3% of
    the slave group's extent, declared a fit, are bad input too (a strain beyond small strain);
(5) ramped: `interference_stage=1` with `load_steps=4` presses the fit step by step, each
    step's normal force k/4 of the one-step run's to 1e-9 (linear elasticity, the whole bore in
    contact at every step), the last step the one-step result to 1e-9; interference_stage
    without overlap='interference' is bad input.
"""
import os
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import run_solver, solver_env  # noqa: E402

import h5py  # noqa: E402
import numpy as np  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
ENV = solver_env(1)
DECK = os.path.join(ROOT, "inputs", "shrink_fit.nml")
check = Checks()
B, C, DELTA = 0.05, 0.1, 5e-5


def lame(es, nus, er, nur):
    """Contact pressure of a solid shaft (es, nus) in a ring (er, nur), plane strain."""
    def prime(e, nu):
        return e / (1 - nu * nu), nu / (1 - nu)
    es_, nus_ = prime(es, nus)
    er_, nur_ = prime(er, nur)
    return DELTA / (B * (((C * C + B * B) / (C * C - B * B) + nur_) / er_ + (1 - nus_) / es_))


def run(work, name, *over, deck=DECK):
    h5 = os.path.join(work, name + ".h5")
    p, _ = run_solver(BIN, deck, *over, f"&output file='{h5}' /", cwd=work, env=ENV, timeout=300)
    return p.returncode, p.stdout + p.stderr, h5


def contact(h5):
    with h5py.File(h5, "r") as f:
        return (f["contact/pressure"][()], f["contact/normal_force"][()],
                f["contact/pair_1/resultant_on_first_body"][()] if "pair_1" in f["contact"]
                else f["contact/resultant_body1"][()])


work = tempfile.mkdtemp(prefix="rc_interference_")
try:
    # (1) and (2): the pressure against Lame, one material and two
    for tag, over, p_ref in [("steel in steel", [], lame(2.1e11, 0.3, 2.1e11, 0.3)),
                             ("steel in aluminium", ["&body id=2, young=7.0e10, poisson=0.33 /"],
                              lame(2.1e11, 0.3, 7.0e10, 0.33))]:
        code, out, h5 = run(work, tag.replace(" ", "_"), *over)
        if code != 0:
            check(False, f"{tag}: the fit runs (exit 0)", out.strip()[-300:])
            continue
        p, _, res = contact(h5)
        dev = np.abs(p / p_ref - 1.0)
        check(dev.max() <= 5e-3, f"{tag}: every node's pressure within 0.5% of Lame's {p_ref:.5e} Pa "
              f"({len(p)} nodes, worst {dev.max():.2%})")
        rdev = np.abs(-res / (p_ref * B) - 1.0).max()
        check(rdev <= 5e-4, f"{tag}: the resultant on the quarter shaft is -p b in x and y to 0.05% ({rdev:.3%})",
              str(res))

    # (3) Robin = monolithic
    code1, out1, h1 = run(work, "robin")
    code2, out2, h2 = run(work, "mono", "&solver method='monolithic' /")
    if code1 == 0 and code2 == 0:
        _, l1, _ = contact(h1)
        _, l2, _ = contact(h2)
        err = np.abs(l1 - l2).max() / np.abs(l2).max()
        check(err <= 1e-8, f"Robin = monolithic to 1e-8 ({err:.1e})")
    else:
        check(False, "Robin and monolithic both run", (out1 + out2).strip()[-300:])

    # (4) bad input: an overlap without the word, and one beyond small strain
    before = set(os.listdir(work))
    code, out, _ = run(work, "refused", "&contact bodies=1,2, overlap='refuse' /")
    made = set(os.listdir(work)) - before
    check(code == 1 and "overlap in the initial configuration" in out and "overlap='interference'" in out
          and "Traceback" not in out and not made,
          "overlap='refuse': the initial overlap is bad input naming the fit's word, nothing written",
          out.strip()[-300:])
    # two rectangles overlapping by 3% of the slave's extent (the upper block's bottom 0.03
    # below the lower block's top): beyond small strain even as a fit
    deck = os.path.join(work, "big.nml")
    with open(deck, "w") as f:
        f.write("&body id=1, x0=0.0, y0=0.97, width=1.0, height=1.0, nx=8, ny=8, top='clamped' /\n"
                "&body id=2, x0=0.0, y0=0.0, width=1.0, height=1.0, nx=8, ny=8, bottom='clamped' /\n"
                "&contact bodies=1,2, groups='bottom','top', overlap='interference' /\n")
    before = set(os.listdir(work))
    code, out, _ = run(work, "big", deck=deck)
    made = set(os.listdir(work)) - before - {"big.nml"}
    check(code == 1 and "beyond 1% of the slave group's extent" in out and not made,
          "an overlap of 3% of the slave group's extent is refused as beyond small strain, nothing written",
          out.strip()[-300:])

    # (5) the interference ramped over stage 1's four steps
    code0, out0, h0 = run(work, "once")
    code, out, h = run(work, "ramped", "&contact bodies=1,2, interference_stage=1 /", "&solver load_steps=4 /")
    steps = []
    if code == 0:
        with h5py.File(h, "r") as f:
            steps = [float(np.sum(f[f"steps/step_{k}/contact/normal_force"][()])) for k in range(1, 5)]
    if code0 == 0 and code == 0 and len(steps) == 4:
        _, f0, _ = contact(h0)
        _, f4, _ = contact(h)
        full = f0.sum()
        dev = max(abs(steps[k] / ((k + 1) / 4 * full) - 1) for k in range(4))
        check(dev <= 1e-9, "ramped interference: step k carries k/4 of the fit's normal force", f"{dev:.1e}, {steps}")
        d4 = np.abs(f4 - f0).max() / np.abs(f0).max()
        check(d4 <= 1e-9, "ramped interference: the last step is the one-step fit", f"{d4:.1e}")
    else:
        check(False, "the ramped fit runs its four steps", out.strip()[-300:])
    before = set(os.listdir(work))
    code, out, _ = run(work, "stage_no_fit", "&contact bodies=1,2, overlap='refuse', interference_stage=1 /")
    made = set(os.listdir(work)) - before
    check(code == 1 and "interference_stage" in out and "overlap='interference'" in out and not made,
          "interference_stage without overlap='interference': bad input, nothing written", out.strip()[-300:])
finally:
    shutil.rmtree(work, ignore_errors=True)

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
