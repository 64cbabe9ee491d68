#!/usr/bin/python3
"""Scenes a user brings, solved with the default solver settings (run by `make check`):

(a) the paper's scene with body 1 on a roller (inputs/paper_roller.nml, contact by the
    rectangles' sides): converges; Robin = monolithic to 1e-8; the vertical resultant of the
    contact forces on body 1 equals the vertical load, 11.5e6 (from the deck's tractions:
    3e6 x 3 + 1e6 x 9/2 down on the top, 2e6 x 1 up on the right side), to 1e-9;
(b) the same scene with the contact named by groups ('bottom', 'top'): the same forces,
    bitwise: the way a deck names the contact line does not change the problem;
(c) rectangles whose contact sides do not match node for node, or overlap in part
    (decks rect_nonmatching, rect_partial_overlap): Robin = monolithic to 1e-7;
(d) a steel pin in the closed bore of an aluminium plate (inputs/pin_hole.nml: both contact
    groups whole circles): converges; the resultant on the pin is the shaft's load,
    (0, 1000) from 100 MPa on the lower half of a bore of radius 5, to 1e-9 vertically
    (the sideways part goes into the axis support: below 1e-3 of it); Robin = monolithic to
    1e-6; every contact node is on the pin's rim, and the active ones on its lower half;
(e) a steel cylinder on an aluminium one (inputs/cylinders.nml): converges; resultant 400
    to 1e-9; half-width and peak pressure within 3% of Hertz's a = sqrt(4 P R / (pi E*)),
    p0 = 2 P / (pi a) with 1/R = 1/R1 + 1/R2, 1/E* = sum (1 - nu^2)/E.
"""
import math
import os
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_results import rel_err  # noqa: E402
from rc_run import line_fields, run_solver  # noqa: E402
from hertz_study import hertz_fit  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
MONO = "&solver method='monolithic' /"
check = Checks()


def run(tmp, name, deck, *over):
    """Run deck with overrides; returns (exit code, contact forces, resultant on body 1, h5 path)."""
    out = os.path.join(tmp, name + ".h5")
    p, res = run_solver(BIN, deck, *over, f"&output file='{out}' /", cwd=ROOT, timeout=600)
    if p.returncode != 0:
        print(p.stdout[-1500:] + p.stderr[-1500:])
        return p.returncode, None, None, out
    c = line_fields(p.stdout, "contact")
    fx, fy = (float(v) for v in c["resultant_on_body1"].split(","))
    with h5py.File(out, "r") as f:
        lam = np.array(f["/contact/normal_force"], dtype=float)
    return 0, lam, np.array([fx, fy]), out


with tempfile.TemporaryDirectory() as tmp:
    # (a), (b)
    rc, lam, fr, _ = run(tmp, "roller", "inputs/paper_roller.nml")
    rcm, lamm, frm, _ = run(tmp, "roller_mono", "inputs/paper_roller.nml", MONO)
    load = 3.0e6 * 3.0 + 1.0e6 * 9.0 / 2.0 - 2.0e6
    if check(rc == 0 and rcm == 0, "roller by sides: Robin and monolithic converge", f"exit {rc}, {rcm}"):
        check(rel_err(lam, lamm) <= 1e-8, "roller by sides: Robin = monolithic", f"{rel_err(lam, lamm):.2e}")
        check(abs(fr[1] - load) <= 1e-9 * load, "roller by sides: vertical resultant = vertical load 11.5e6",
              f"{fr[1]:.10e}, error {abs(fr[1] - load) / load:.1e}")
        check(abs(frm[1] - load) <= 1e-9 * load, "roller by sides, monolithic: vertical resultant = load",
              f"error {abs(frm[1] - load) / load:.1e}")
    rcg, lamg, _, _ = run(tmp, "roller_groups", "inputs/paper_roller.nml", "&body id=1, bottom='free' /",
                          "&body id=2, top='free' /", "&contact body1_group='bottom', body2_group='top' /")
    check(rcg == 0 and lam is not None and lamg is not None and np.array_equal(lam, lamg),
          "roller: contact by groups 'bottom'/'top' = contact by sides, bitwise")

    # (c)
    for deck in ("rect_nonmatching", "rect_partial_overlap"):
        path = os.path.join("tests", "data", "decks", deck + ".nml")
        rc, lam, _, _ = run(tmp, deck, path)
        rcm, lamm, _, _ = run(tmp, deck + "_mono", path, MONO)
        if check(rc == 0 and rcm == 0, f"{deck}: Robin and monolithic converge", f"exit {rc}, {rcm}"):
            check(np.max(lamm) > 0 and rel_err(lam, lamm) <= 1e-7, f"{deck}: Robin = monolithic, in contact",
                  f"{rel_err(lam, lamm):.2e}")

    # (d)
    rc, lam, fr, out = run(tmp, "pin", "inputs/pin_hole.nml")
    rcm, lamm, _, _ = run(tmp, "pin_mono", "inputs/pin_hole.nml", MONO)
    if check(rc == 0 and rcm == 0, "pin in a closed bore: converges with the default settings, and monolithic",
             f"exit {rc}, {rcm}"):
        P = 100.0 * 2 * 5.0
        check(abs(fr[1] - P) <= 1e-9 * P, "pin: vertical resultant on the pin = the shaft's load 1000",
              f"{fr[1]:.10e}")
        check(abs(fr[0]) <= 1e-3 * P, "pin: sideways resultant small (the axis support takes it)", f"{fr[0]:.2e}")
        check(rel_err(lam, lamm) <= 1e-6, "pin: Robin = monolithic", f"{rel_err(lam, lamm):.2e}")
        with h5py.File(out, "r") as f:
            x, y = np.array(f["/contact/x"]), np.array(f["/contact/y"])
        r = np.hypot(x, y)
        check(np.allclose(r, 10.0, rtol=1e-9) and np.ptp(np.arctan2(y, x)) > 6.0,
              "pin: the contact nodes go all round the pin's rim (a closed loop)", f"{lam.size} nodes")
        on = lam > 1e-9 * np.max(lam)
        check(np.all(y[on] < 0), "pin: the active nodes are on the lower half", f"{np.count_nonzero(on)} active")

    # (e)
    rc, lam, fr, out = run(tmp, "cyl", "inputs/cylinders.nml")
    if check(rc == 0, "cylinders: converge with the default settings", f"exit {rc}"):
        P = 10.0 * 40.0
        check(abs(fr[1] - P) <= 1e-9 * P, "cylinders: vertical resultant = 400", f"{fr[1]:.10e}")
        with h5py.File(out, "r") as f:
            x = np.array(f["/contact/x"], dtype=float)
            p = np.array(f["/contact/pressure"], dtype=float)
        a, p0, xc = hertz_fit(x, p)
        R = 1.0 / (1.0 / 20.0 + 1.0 / 30.0)
        Es = 1.0 / ((1 - 0.3 ** 2) / 210000.0 + (1 - 0.33 ** 2) / 70000.0)
        aH = math.sqrt(4 * P * R / (math.pi * Es))
        p0H = 2 * P / (math.pi * aH)
        check(abs(a - aH) <= 0.03 * aH, "cylinders: half-width within 3% of Hertz",
              f"a = {a:.4f}, Hertz {aH:.4f}: {100 * (a - aH) / aH:+.2f}%")
        check(abs(p0 - p0H) <= 0.03 * p0H, "cylinders: peak pressure within 3% of Hertz",
              f"p0 = {p0:.1f}, Hertz {p0H:.1f}: {100 * (p0 - p0H) / p0H:+.2f}%")

print(f"{len(check.failed)} failed" if check.failed else "all passed")
sys.exit(1 if check.failed else 0)
