#!/usr/bin/python3
"""Cattaneo-Mindlin in 3D side by side with CalculiX 2.20: the sphere on a block of
tools/cattaneo3d_study.py (R = 1, E = 1000, nu = 0.3 for both, Coulomb mu = 0.3, a half model
with the plane z = 0 of symmetry, a/R ~ 0.02) on the SAME Gmsh tetrahedra (meshed here from
inputs/gmsh/cattaneo_sphere.geo with --hc, rc = 0.06), loaded by displacements in two steps:
the sphere's top moved down by --push (its x held), then along x by --shift. robin_contact runs
the study's deck (its 'displacement' pull, method --method); CalculiX's ccx the same nodes, the
tetrahedra as C3D4, one SURFACE TO SURFACE contact pair (the sphere's arc on the block's top)
with PRESSURE-OVERCLOSURE=LINEAR of slope --penalty x E and *FRICTION mu with the stick slope
--stick x E, two *STATIC steps, *CONTACT FILE CSTR (CPRESS, CSHEAR1, CSHEAR2 of the slave nodes).

Measured from each program's slave nodes (the same nodes, the same estimators for both): P and
Q (2 x the reactions on the sphere's top), Hertz's a for P, the stick radius c from the area of
the stick nodes (|shear| < 0.99 mu p, with p > 0: each node's share of its slave triangles'
areas projected on y = 0, two halves of a disc: sqrt(2 A / pi)), Mindlin's c = a (1 -
Q/(mu P))^(1/3), and the ring-averaged shear's length against Mindlin's shear (tools/cattaneo3d_study.py's
rings, a/8 wide; the length, since ccx gives the shear in its faces' own tangents: it counts
the small radial shear that P alone leaves too), and the wall time. Prints a
Markdown table; exit 1 when a run fails.

CalculiX is not installed by tools/install-deps.sh: `apt-get install -y calculix-ccx`.

usage: tools/ccx_cattaneo3d.py [--bin bin/robin_contact] [--ccx ccx] [--hc 0.0033] [--push -4e-4]
           [--shift 5e-5] [--penalty 500] [--stick 50] [--inc 1] [--threads 2] [--keep DIR]
"""
import argparse
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from cattaneo3d_study import DECK, E, MU, NU, R, mindlin_shear, ring_error  # noqa: E402
from ccx_hertz3d import dat_totals, face_surface, frd_fields, read_mesh, sta_counts, write_lines  # noqa: E402
from rc_run import solver_env  # noqa: E402

GROUPS = ("sphere_top", "sphere_z0", "block_bottom", "block_z0", "sphere_arc", "block_top")


def node_areas(points, tris):
    """Each node's share (a third) of its triangles' areas projected on the plane y = 0."""
    x = points[:, [0, 2]]
    a = np.abs(np.cross(x[tris[:, 1]] - x[tris[:, 0]], x[tris[:, 2]] - x[tris[:, 0]])) / 2.0
    out = np.zeros(len(points))
    for k in range(3):
        np.add.at(out, tris[:, k], a / 3.0)
    return out


def measure(xz, area, p, sx, sabs, P, Q):
    """a, c, Mindlin's c, the ring-averaged shear error of nodes at xz with pressure p, shear
    along x sx, shear length sabs, tributary areas area."""
    estar = E / (2.0 * (1.0 - NU * NU))
    a = (3.0 * P * R / (4.0 * estar)) ** (1.0 / 3.0)
    p0 = 3.0 * P / (2.0 * math.pi * a * a)
    ct = a * (1.0 - Q / (MU * P)) ** (1.0 / 3.0)
    stick = (p > 0) & (sabs < 0.99 * MU * p)
    c = math.sqrt(2.0 * np.sum(area[stick]) / math.pi)
    r = np.hypot(xz[:, 0], xz[:, 1])
    sx = sx * np.sign(np.sum(sx * area))
    shear = ring_error(r, sx * area, area, a, ct, mindlin_shear(r, a, p0, ct))
    return dict(a=a, c=c, ct=ct, shear=shear, active=int(np.count_nonzero(p > 0)), QmuP=Q / (MU * P))


def write_inp(path, points, tets, tris, a):
    used = np.unique(np.concatenate([tets["sphere"].ravel(), tets["block"].ravel()]))
    first = {"sphere": 1, "block": 1 + len(tets["sphere"])}
    with open(path, "w") as f:
        f.write("** Cattaneo-Mindlin in 3D, half model: tools/cattaneo3d_study.py's scene, by tools/ccx_cattaneo3d.py\n")
        f.write("*NODE, NSET=NALL\n")
        for i in used:
            f.write(f"{i + 1}, {points[i, 0]:.13g}, {points[i, 1]:.13g}, {points[i, 2]:.13g}\n")
        for body in ("sphere", "block"):
            f.write(f"*ELEMENT, TYPE=C3D4, ELSET={body.upper()}\n")
            for k, t in enumerate(tets[body]):
                f.write(f"{first[body] + k}, {t[0] + 1}, {t[1] + 1}, {t[2] + 1}, {t[3] + 1}\n")
        for name in ("sphere_top", "sphere_z0", "block_bottom", "block_z0"):
            f.write(f"*NSET, NSET=N_{name.upper()}\n")
            write_lines(f, [int(i) + 1 for i in np.unique(tris[name])])
        for name, body in (("sphere_arc", "sphere"), ("block_top", "block")):
            f.write(f"*SURFACE, NAME=S_{name.upper()}, TYPE=ELEMENT\n")
            for e, s in face_surface(tets[body], first[body], tris[name]):
                f.write(f"{e}, S{s}\n")
        f.write(f"*MATERIAL, NAME=MAT\n*ELASTIC\n{E:g}, {NU:g}\n"
                "*SOLID SECTION, ELSET=SPHERE, MATERIAL=MAT\n*SOLID SECTION, ELSET=BLOCK, MATERIAL=MAT\n")
        f.write("*CONTACT PAIR, INTERACTION=SI1, TYPE=SURFACE TO SURFACE\nS_SPHERE_ARC, S_BLOCK_TOP\n"
                f"*SURFACE INTERACTION, NAME=SI1\n*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{a.penalty * E:g}\n"
                f"*FRICTION\n{MU:g}, {a.stick * E:g}\n")
        f.write("*BOUNDARY\nN_SPHERE_Z0, 3, 3, 0.0\nN_BLOCK_BOTTOM, 1, 3, 0.0\nN_BLOCK_Z0, 3, 3, 0.0\n")
        for k, (ux, uy) in enumerate(((0.0, a.push), (a.shift, a.push))):
            f.write(f"*STEP\n*STATIC, DIRECT\n{1.0 / a.inc:.10g}, 1.0\n*BOUNDARY\n"
                    f"N_SPHERE_TOP, 1, 1, {ux!r}\nN_SPHERE_TOP, 2, 2, {uy!r}\n"
                    "*NODE PRINT, NSET=N_SPHERE_TOP, TOTALS=ONLY\nRF\n*CONTACT FILE\nCSTR\n*END STEP\n")


def run_ccx(a, msh, work, mesh):
    points, tets, tris = mesh
    job = os.path.join(work, "cm3d")
    write_inp(job + ".inp", points, tets, tris, a)
    env = solver_env(a.threads)
    for k in ("CCX_NPROC_EQUATION_SOLVER", "CCX_NPROC_STIFFNESS", "CCX_NPROC_RESULTS"):
        env[k] = str(a.threads)
    t0 = time.time()
    p = subprocess.run([a.ccx, "-i", "cm3d"], cwd=work, env=env, capture_output=True, text=True)
    wall = time.time() - t0
    log = p.stdout + p.stderr
    err = re.search(r"\*ERROR.*", log)
    if p.returncode != 0 or err or not os.path.exists(job + ".frd"):
        return {"status": "failed: " + (err.group(0).strip() if err else f"exit {p.returncode}"), "wall": wall}
    cs = frd_fields(job + ".frd")
    tot = dat_totals(job + ".dat")["N_SPHERE_TOP"]
    ids = np.unique(tris["sphere_arc"])
    area = node_areas(points, tris["sphere_arc"])[ids]
    v = np.array([[cs.get(i + 1, {}).get(k, 0.0) for k in ("CPRESS", "CSHEAR1", "CSHEAR2")] for i in ids])
    # CalculiX gives the shear in its faces' own tangents: its length is what both programs'
    # rings compare (tools/cattaneo3d_study.py compares the x part of robin_contact's)
    sabs = np.hypot(v[:, 1], v[:, 2])
    m = measure(points[ids][:, [0, 2]], area, v[:, 0], sabs, sabs, 2.0 * abs(tot[1]), 2.0 * abs(tot[0]))
    incs, its = sta_counts(job + ".sta")
    neq = re.search(r"number of equations\s+(\d+)", log)
    m.update(status="ok", wall=wall, dofs=int(neq.group(1)) if neq else "?", note=f"{incs} increments, {its} iterations")
    return m


def run_robin(a, msh, work, mesh):
    h5 = os.path.join(work, "robin.h5")
    deck = os.path.join(work, "robin.nml")
    with open(deck, "w") as f:
        f.write(DECK.format(msh=msh, push=a.push, method=a.method, h5=h5))
        f.write(f"&boundary body=1, group='sphere_top', ux={a.shift!r}, stage=2 /\n")
    t0 = time.time()
    p = subprocess.run([a.bin, deck], capture_output=True, text=True, env=solver_env(a.threads))
    wall = time.time() - t0
    if p.returncode != 0:
        return {"status": f"failed: exit {p.returncode}", "wall": wall}
    points, _, tris = mesh
    with h5py.File(h5, "r") as f:
        g = f["/contact/pair_1"]
        xyz = np.stack([g["x"][()], g["y"][()], g["z"][()]], axis=1)
        ta = g["tributary_area"][()]
        fx = g["tangential_force_xyz"][()]
        pres = g["pressure"][()]
        res = g["resultant_on_first_body"][()]
    # the same nodes as CalculiX's: the shear from the force over the mortar's area, the areas
    # for the estimators from the slave triangles as for CalculiX
    ids = np.unique(tris["sphere_arc"])
    area = node_areas(points, tris["sphere_arc"])
    order = {tuple(np.round(points[i], 12)): i for i in ids}
    node = np.array([order[tuple(np.round(q, 12))] for q in xyz])
    shear = np.where(ta[:, None] > 0, fx / np.where(ta > 0, ta, 1.0)[:, None], 0.0)
    sabs = np.linalg.norm(shear, axis=1)
    m = measure(xyz[:, [0, 2]], area[node], pres, sabs, sabs, 2.0 * abs(res[1]), 2.0 * abs(res[0]))
    out = dict(re.findall(r"(\w+)=(\S+)", next((ln for ln in p.stdout.splitlines() if ln.startswith("result:")), "")))
    m.update(status="ok", wall=wall, dofs=out.get("dofs", "?"), note=f"{out.get('method', '?')}, {out.get('outer', '?')} outer")
    return m


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"))
    ap.add_argument("--ccx", default="ccx")
    ap.add_argument("--hc", default="0.0033")
    ap.add_argument("--push", type=float, default=-4.0e-4)
    ap.add_argument("--shift", type=float, default=5.0e-5)
    ap.add_argument("--method", default="robin")
    ap.add_argument("--penalty", type=float, default=500.0, help="ccx's normal penalty slope / E")
    ap.add_argument("--stick", type=float, default=50.0, help="ccx's stick slope / E")
    ap.add_argument("--inc", type=int, default=1)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--keep", default=None)
    a = ap.parse_args()
    if not (shutil.which(a.ccx) and shutil.which("gmsh")):
        print("ccx_cattaneo3d: needs ccx (apt-get install calculix-ccx) and gmsh")
        return 1
    work = os.path.abspath(a.keep) if a.keep else tempfile.mkdtemp(prefix="rc_ccx_cm3d_")
    os.makedirs(work, exist_ok=True)
    bad = 0
    try:
        msh = os.path.join(work, f"cattaneo_sphere_h{a.hc}.msh")
        subprocess.run(["gmsh", "-3", "-format", "msh41", "-v", "2", "-setnumber", "hc", a.hc, "-setnumber", "rc", "0.06",
                        os.path.join(ROOT, "inputs", "gmsh", "cattaneo_sphere.geo"), "-o", msh],
                       capture_output=True, check=True)
        mesh = read_mesh(msh, GROUPS)
        print(f"mesh hc = {a.hc}; push {a.push}, shift {a.shift}; ccx: penalty {a.penalty} E, stick slope {a.stick} E, "
              f"{a.inc} increment(s) a step\n")
        print("| program | DOFs | contact nodes | Q / (mu P) | a | c | c (Mindlin) | c error | shear error (rings) "
              "| wall s | notes |")
        print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
        for name, fn in (("robin_contact", run_robin), ("CalculiX 2.20", run_ccx)):
            sub = os.path.join(work, name.split()[0].lower())
            os.makedirs(sub, exist_ok=True)
            r = fn(a, msh, sub, mesh)
            if r["status"] != "ok":
                bad += 1
                print(f"| {name} | {r['status']} | | | | | | | | {r['wall']:.1f} | |")
                continue
            print(f"| {name} | {r['dofs']} | {r['active']} | {r['QmuP']:.4f} | {r['a']:.5f} | {r['c']:.5f} | {r['ct']:.5f} "
                  f"| {100 * (r['c'] / r['ct'] - 1):+.2f}% | {100 * r['shear']:.2f}% | {r['wall']:.1f} | {r['note']} |",
                  flush=True)
    finally:
        if not a.keep:
            shutil.rmtree(work, ignore_errors=True)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
