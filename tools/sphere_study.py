#!/usr/bin/python3
"""Hertz's sphere on a flat, axisymmetric (inputs/sphere_flat.nml) on the shipped meshes
inputs/gmsh/sphere_flat_h{0.02,0.01,0.005}.msh: the force P = 2 pi x the force per radian, the
Hertz contact radius a = (3 P R/(4 E*))^(1/3) and peak pressure p0 = 3 P/(2 pi a^2) for that P
(E* = E/(2 (1 - nu^2)), R = 1), against the Hertz shape p^2 = p0^2 (1 - r^2/a^2) fitted to the
nodal pressures by linear least squares. Prints a Markdown table; --plot FILE draws the finest
mesh's nodal pressures over Hertz's (doc/sphere_flat.png).

usage: tools/sphere_study.py [--bin bin/robin_contact] [--plot doc/sphere_flat.png]
"""
import argparse
import math
import os
import shutil
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
E, NU, R = 1000.0, 0.3, 1.0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"))
    ap.add_argument("--plot", default="")
    a = ap.parse_args()
    estar = E / (2 * (1 - NU * NU))
    work = tempfile.mkdtemp(prefix="rc_sphere_")
    rows, last = [], None
    try:
        for h in ("0.02", "0.01", "0.005"):
            msh = os.path.join(ROOT, "inputs", "gmsh", f"sphere_flat_h{h}.msh")
            h5 = os.path.join(work, f"s{h}.h5")
            p = subprocess.run([a.bin, os.path.join(ROOT, "inputs", "sphere_flat.nml"), f"&body id=1, mesh='{msh}' /",
                                f"&body id=2, mesh='{msh}' /", f"&output file='{h5}' /"], capture_output=True, text=True)
            if p.returncode != 0:
                print(p.stdout[-2000:], p.stderr[-1000:])
                sys.exit(f"sphere_study: h = {h}: exit {p.returncode}")
            res = [ln for ln in p.stdout.splitlines() if ln.startswith("result:")][-1]
            with h5py.File(h5, "r") as f:
                x, pn = f["/contact/x"][...], f["/contact/pressure"][...]
                fy = f["/contact/resultant_body1"][...]
            P = 2 * math.pi * abs(fy[1])
            ah = (3 * P * R / (4 * estar)) ** (1 / 3)
            p0h = 3 * P / (2 * math.pi * ah * ah)
            on = pn > 0
            c, *_ = np.linalg.lstsq(np.vstack([np.ones(on.sum()), x[on] ** 2]).T, pn[on] ** 2, rcond=None)
            p0f, af = math.sqrt(c[0]), math.sqrt(-c[0] / c[1])
            outer = res.split(" outer=")[1].split()[0]
            wall = res.split(" wall_s=")[1].split()[0]
            dofs = res.split(" dofs=")[1].split()[0]
            rows.append((h, dofs, P, ah, af, p0h, p0f, outer, wall))
            last = (x, pn, ah, p0h)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print("| h at the contact | DOFs | P | a (Hertz) | a (fit) | p0 (Hertz) | p0 (fit) | Robin outer | wall [s] |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for h, dofs, P, ah, af, p0h, p0f, outer, wall in rows:
        print(f"| {h} | {dofs} | {P:.5f} | {ah:.5f} | {af:.5f} ({af / ah - 1:+.2%}) | {p0h:.3f} | "
              f"{p0f:.3f} ({p0f / p0h - 1:+.2%}) | {outer} | {wall} |")
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        x, pn, ah, p0h = last
        r = np.linspace(0, ah, 200)
        fig, ax = plt.subplots(figsize=(6, 3.6))
        ax.plot(r, p0h * np.sqrt(1 - (r / ah) ** 2), "k-", label="Hertz, for the computed force")
        sel = x <= 2 * ah
        ax.plot(x[sel], pn[sel], "o", ms=4, label="robin_contact, h = 0.005 (nodal pressure)")
        ax.set_xlabel("r")
        ax.set_ylabel("contact pressure")
        ax.set_title("A sphere on a flat, axisymmetric (inputs/sphere_flat.nml)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(a.plot, dpi=110)
        print(f"wrote {a.plot}")


if __name__ == "__main__":
    main()
