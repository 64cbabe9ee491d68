#!/usr/bin/python3
"""Mesh convergence of the coated punch (inputs/coated_punch.nml): the block meshed by gmsh
from inputs/gmsh/coated_punch.geo at element sizes h, h/2, h/4, h/8 (near the punch), the punch
rectangle refined alike, solved by Robin and monolithically. Reports per mesh the contact DOFs,
the punch's mean vertical displacement (monolithic; its compliance: a global quantity of the
energy norm's family), the Robin-monolithic difference of the nodal forces, and the observed order of the
displacement from three successive meshes, p = log2(|u_h - u_h/2| / |u_h/2 - u_h/4|). The punch's
corners make the pressure singular (a flat punch), which caps the order below 2.

usage: tools/coated_study.py [--bin bin/robin_contact] [--gmsh gmsh] [--h 0.001] [--levels 4]
Needs gmsh (apt-get install gmsh). Prints a Markdown table; exits 1 if a run fails (a Robin run
that does not converge, exit 2, is reported in the table).
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


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"))
    ap.add_argument("--gmsh", default="gmsh")
    ap.add_argument("--h", type=float, default=0.001)
    ap.add_argument("--levels", type=int, default=4)
    a = ap.parse_args()
    if shutil.which(a.gmsh) is None:
        sys.exit(f"coated_study: {a.gmsh} not found (apt-get install gmsh)")
    work = tempfile.mkdtemp(prefix="rc_coated_")
    rows, us = [], []
    try:
        for k in range(a.levels):
            h = a.h / 2 ** k
            msh = os.path.join(work, f"coated_{k}.msh")
            subprocess.run([a.gmsh, "-2", "-format", "msh41", "-setnumber", "h", repr(h),
                            os.path.join(ROOT, "inputs", "gmsh", "coated_punch.geo"), "-o", msh],
                           check=True, capture_output=True)
            n = max(3, round(0.003 / h))
            over = [f"&body id=1, mesh='{msh}' /", f"&body id=2, nx={n}, ny={n} /"]
            res = {}
            for method in ("robin", "monolithic"):
                h5 = os.path.join(work, f"{method}_{k}.h5")
                p = subprocess.run([a.bin, os.path.join(ROOT, "inputs", "coated_punch.nml"), *over,
                                    f"&solver method='{method}' /", f"&output file='{h5}' /"],
                                   capture_output=True, text=True)
                if p.returncode != 0 and not (method == "robin" and p.returncode == 2):
                    print(p.stdout[-2000:], p.stderr[-2000:])
                    sys.exit(f"coated_study: h = {h}: {method} exit {p.returncode}")
                line = [ln for ln in p.stdout.splitlines() if ln.startswith("result:")][-1]
                with h5py.File(h5, "r") as f:
                    u = f["/body2/displacement"][...]
                    res[method] = (f["/contact/normal_force"][...], np.mean(u[1] if u.shape[0] == 2 else u[:, 1]),
                                   line)
            fr, fm = res["robin"][0], res["monolithic"][0]
            m = int(res["robin"][2].split(" m=")[1].split()[0])
            dofs = int(res["robin"][2].split(" dofs=")[1].split()[0])
            outer = res["robin"][2].split(" outer=")[1].split()[0]
            if "status=converged" not in res["robin"][2]:
                outer += " (" + res["robin"][2].split("status=")[1].split()[0] + ", exit 2)"
            us.append(res["monolithic"][1])
            rows.append((h, dofs, m, outer, res["robin"][1], np.max(np.abs(fr - fm)) / np.max(np.abs(fm))))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print("| h near the punch [m] | DOFs | contact rows | Robin outer | punch mean uy [m] | |u_h - u_h/2| | "
          "observed order | Robin - monolithic (nodal forces) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for k, (h, dofs, m, outer, u, d) in enumerate(rows):
        diff = abs(us[k] - us[k + 1]) if k + 1 < len(us) else float("nan")
        order = ""
        if k + 2 < len(us):
            d1, d2 = abs(us[k] - us[k + 1]), abs(us[k + 1] - us[k + 2])
            order = f"{math.log2(d1 / d2):.2f}" if d2 > 0 else ""
        print(f"| {h:.6g} | {dofs} | {m} | {outer} | {u:.8e} | {diff:.3e} | {order} | {d:.1e} |")


if __name__ == "__main__":
    main()
