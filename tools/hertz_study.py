#!/usr/bin/python3
"""Hertz line contact with real geometry (inputs/hertz.nml): run the half-disc on the block on
the shipped meshes (inputs/gmsh/hertz_h*.msh), fit the Hertz shape to the contact pressure and
compare half-width and peak pressure with Hertz's formulas for the computed force.
--deck hertz_force.nml: the force-controlled scene (the disc held only by contact, pressed by
P = 2 per unit thickness; meshes inputs/gmsh/hertz_force_h*.msh): the table adds the
equilibrium error |P_contact / P - 1|.

Fit: on the nodes with a positive pressure, p(x)^2 = p0^2 (1 - (x - xc)^2 / a^2) is a quadratic
in x, A + B x + C x^2, fitted by linear least squares (weights 1), which gives a, p0 and xc
without taking the last node in contact (that only brackets a within one element).
Hertz (two identical half-planes): E* = E / (2 (1 - nu^2)), a = sqrt(4 P R / (pi E*)),
p0 = 2 P / (pi a).

usage: tools/hertz_study.py [--bin bin/robin_contact] [--meshes 0.04,0.02,0.01] [--method monolithic]
                           [--deck hertz.nml | hertz_force.nml]
Prints one line per mesh and the observed orders; exits 1 if a run fails.
"""
import argparse
import math
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
R = 1.0


def hertz_fit(x, p):
    on = p > 0.0
    if np.count_nonzero(on) < 3:
        raise ValueError("fewer than 3 nodes in contact: refine the mesh or press harder")
    xs, ps = x[on], p[on]
    A = np.vstack([np.ones_like(xs), xs, xs ** 2]).T
    c, *_ = np.linalg.lstsq(A, ps ** 2, rcond=None)
    if not c[2] < 0.0:
        raise ValueError("the pressure is not Hertz-shaped (p^2 is not concave)")
    xc = -c[1] / (2.0 * c[2])
    p0sq = c[0] - c[1] ** 2 / (4.0 * c[2])
    a = math.sqrt(p0sq / -c[2])
    return a, math.sqrt(p0sq), xc


def run(binary, h, method, out, deck="hertz.nml"):
    mesh = f"gmsh/{deck[:-4]}_h{h}.msh"
    cmd = [binary, os.path.join(ROOT, "inputs", deck),
           f"&body id=1, mesh='{mesh}' /", f"&body id=2, mesh='{mesh}' /",
           f"&output file='{out}' /", f"&solver method='{method}' /"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"h={h}: exit {r.returncode}: {r.stderr.strip()[-300:]}")
    return read_contact(out)


def read_contact(out):
    """x, pressure, the total vertical force P on the disc, E, nu and the outer count of a
    Hertz result file."""
    with h5py.File(out, "r") as f:
        x = np.array(f["/contact/x"], dtype=float)
        p = np.array(f["/contact/pressure"], dtype=float)
        lam = np.array(f["/contact/normal_force"], dtype=float)
        nrm = np.array(f["/contact/normal"], dtype=float)
        E = float(f["/body1"].attrs["young"])
        nu = float(f["/body1"].attrs["poisson"])
        outer = int(f.attrs["outer_iterations"])
    # total vertical force on the disc (the normals are not vertical away from x = 0)
    P = float(-np.sum(lam * nrm[1, :]))
    return x, p, P, E, nu, outer


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"))
    ap.add_argument("--meshes", default="0.04,0.02,0.01")
    ap.add_argument("--method", default="monolithic")
    ap.add_argument("--deck", default="hertz.nml", help="hertz.nml (displacement) or hertz_force.nml (force, P = 2)")
    args = ap.parse_args()
    p_applied = 2.0 if "force" in args.deck else None
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for h in args.meshes.split(","):
            x, p, P, E, nu, outer = run(args.bin, h, args.method, os.path.join(tmp, f"h{h}.h5"), args.deck)
            es = E / (2.0 * (1.0 - nu ** 2))
            ah = math.sqrt(4.0 * P * R / (math.pi * es))
            p0h = 2.0 * P / (math.pi * ah)
            a, p0, xc = hertz_fit(x, p)
            rows.append((float(h), P, a, ah, p0, p0h, xc, int(np.count_nonzero(p > 0)), outer))
    print(f"Hertz study ({args.deck}, {args.method}): R = {R}, E*, a and p0 for the computed force P")
    print(f"{'h':>7} {'P':>10} {'a fit':>9} {'a Hertz':>9} {'err a':>8} {'p0 fit':>9} {'p0 Hertz':>9} "
          f"{'err p0':>8} {'xc':>9} {'nodes':>5} {'outer':>5}" + ("  |P/2 - 1|" if p_applied else ""))
    for h, P, a, ah, p0, p0h, xc, n, outer in rows:
        print(f"{h:7.4f} {P:10.5f} {a:9.5f} {ah:9.5f} {abs(a / ah - 1):8.2%} {p0:9.4f} {p0h:9.4f} "
              f"{abs(p0 / p0h - 1):8.2%} {xc:9.2e} {n:5d} {outer:5d}"
              + (f"  {abs(P / p_applied - 1):9.2e}" if p_applied else ""))
    for k in range(1, len(rows)):
        (h1, *_r1), (h2, *_r2) = rows[k - 1], rows[k]
        ea1, ea2 = abs(rows[k - 1][2] / rows[k - 1][3] - 1), abs(rows[k][2] / rows[k][3] - 1)
        ep1, ep2 = abs(rows[k - 1][4] / rows[k - 1][5] - 1), abs(rows[k][4] / rows[k][5] - 1)
        r = math.log(h1 / h2)
        print(f"observed order h={h1:g} -> {h2:g}: a {math.log(ea1 / ea2) / r:5.2f}, "
              f"p0 {math.log(ep1 / ep2) / r:5.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
