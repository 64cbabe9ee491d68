#!/usr/bin/python3
"""Hertz in 3D, whole program (run by `make check`): a sphere (R = 1) on a block, a quarter model
on the shipped Gmsh tetrahedra (inputs/sphere_block.nml; inputs/gmsh/sphere_block_h0.02.msh and
_h0.01.msh). With P = 4 x the quarter's force, Hertz gives a = (3 P R/(4 E*))^(1/3) and
p0 = 3 P/(2 pi a^2); the Hertz shape fitted to the nodal pressures (tools/hertz3d_study.py's
fit) has a within 2% and p0 within 3% on the finer mesh, both closer than on the coarser one
(a finer mesh, hc = 0.005, reaches 0.95% and 1.8%: doc/verification.md); both bodies balance
(`reaction:` lines) to 1e-9; Robin = monolithic to 1e-8 on the coarser mesh. Force control on
the finer mesh: the sphere's top under a uniform pressure q, the sphere held along y by the
contact alone (SMALBE): the contact force is 4 q A to 1e-9 (A the area of the top's
triangles, summed by meshio), a and p0 within 2% and 3% of Hertz for that force. Different
materials (the sphere's E three times the block's, P half as large again on the same approach):
a and p0 within 2% and 3.5% of Hertz with both materials' E* on the finer mesh (-1.71%,
+3.00%), Robin = monolithic to 1e-8 on the coarser. A run stopped at outer iteration 12
with a checkpoint that notes a kept active-set factor, resumed: bitwise the uninterrupted run
(forces, history, product count).
"""
import os
import re
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import run_solver, solver_env  # noqa: E402
from hertz3d_study import hertz_fit, measure  # noqa: E402

import h5py  # noqa: E402
import numpy as np  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
DECK = os.path.join(ROOT, "inputs", "sphere_block.nml")
check = Checks()


def face_area(msh, name):
    """The area of the triangles of a physical surface of a Gmsh file (read by meshio)."""
    import meshio
    m = meshio.read(msh)
    tag = m.field_data[name][0]
    area = 0.0
    for cells, phys in zip(m.cells, m.cell_data["gmsh:physical"]):
        if cells.type == "triangle":
            x = m.points[cells.data[phys == tag]]
            area += 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1).sum()
    return area


RUNS = (("0.02", ()), ("0.01", ()), ("0.02m", ("&solver method='monolithic' /",)))


def solve(h, over, name, sphere=""):
    """The deck on the shipped mesh of size h[:4] with the overrides; (process, result path)."""
    msh = os.path.join(ROOT, "inputs", "gmsh", f"sphere_block_h{h[:4]}.msh")
    h5 = os.path.join(work, f"{name}{h}.h5")
    p, _ = run_solver(BIN, DECK, f"&body id=1, mesh='{msh}'{sphere} /", f"&body id=2, mesh='{msh}' /", *over,
                      f"&output file='{h5}' /", env=solver_env(2), timeout=300)
    return p, h5


work = tempfile.mkdtemp(prefix="rc_hertz3d_")
try:
    errs = {}
    for h, over in RUNS:
        p, h5 = solve(h, over, "r")
        if not check(p.returncode == 0, f"Hertz 3D, hc = {h}: converged", (p.stdout + p.stderr)[-300:]):
            continue
        bal = [float(l.split("balance=")[1].split()[0]) for l in p.stdout.splitlines() if l.startswith("reaction:")]
        check(len(bal) == 2 and max(bal) <= 1e-9, f"Hertz 3D, hc = {h}: both bodies balance", f"{bal}")
        if h.endswith("m"):
            with h5py.File(h5, "r") as a, h5py.File(os.path.join(work, "r0.02.h5"), "r") as b:
                fm, fr = a["/contact/normal_force"][...], b["/contact/normal_force"][...]
            d = np.abs(fm - fr).max() / np.abs(fm).max()
            check(d <= 1e-8, "Hertz 3D: Robin = monolithic", f"{d:.2e}")
            continue
        P, a_h, p0_h, a_f, p0_f = measure(h5)
        errs[h] = (a_f / a_h - 1, p0_f / p0_h - 1)
        print(f"INFO  hc = {h}: P = {P:.5f}, a {a_f:.5f} / Hertz {a_h:.5f} ({100 * errs[h][0]:+.2f}%), "
              f"p0 {p0_f:.3f} / Hertz {p0_h:.3f} ({100 * errs[h][1]:+.2f}%)")
    # a restart in the middle: stopped at outer iteration 12 with a checkpoint (the bodies'
    # active-set factors kept then, which the checkpoint notes and the resumed run makes
    # again), resumed: the forces, the history and the product count of the uninterrupted run
    full = os.path.join(work, "r0.01.h5")
    p, part = solve("0.01", ("&solver max_outer=12 /", "&output checkpoint_every=6 /"), "stop")
    ck = part + ".ckpt.h5"
    if check(p.returncode == 2 and os.path.exists(ck), "Hertz 3D: stopped at max_outer = 12, checkpoint written",
             (p.stdout + p.stderr)[-300:]):
        with h5py.File(ck, "r") as f:
            kept = f["/state/kept"][...]
        check(kept.max() == 1, "Hertz 3D: at the checkpoint a body's active-set factor is kept", f"{kept}")
        msh = os.path.join(ROOT, "inputs", "gmsh", "sphere_block_h0.01.msh")
        resumed = os.path.join(work, "resumed.h5")
        p, _ = run_solver(BIN, DECK, f"&body id=1, mesh='{msh}' /", f"&body id=2, mesh='{msh}' /",
                          f"&output file='{resumed}' /", "--restart", ck, env=solver_env(2), timeout=300)
        same = p.returncode == 0 and os.path.exists(resumed) and os.path.exists(full)
        if same:
            with h5py.File(full, "r") as a, h5py.File(resumed, "r") as b:
                diff = [k for k in ("/contact/normal_force", "/history/inner", "/history/residual",
                                    "/history/criterion") if not np.array_equal(a[k][...], b[k][...])]
            same = not diff
        check(same, "Hertz 3D: the resumed run = the uninterrupted one, bitwise (forces, history, products)",
              (p.stdout + p.stderr)[-300:])
    # force control: the sphere's top loaded by a uniform pressure q instead of pushed down,
    # held along y by the contact alone (the symmetry planes hold the rest: SMALBE); its force
    # is known before the run, P = 4 q pi R^2 / 4, and it is about the pushed run's
    with open(DECK) as f:
        text = f.read()
    q = 0.328
    lines = [l for l in text.splitlines() if "group = 'sphere_top'" not in l]
    lines.append(f"&traction body = 1, group = 'sphere_top', t0 = 0.0, {-q}, 0.0 /")
    deck = os.path.join(work, "force.nml")
    with open(deck, "w") as f:
        f.write("\n".join(lines).replace("'gmsh/", "'" + os.path.join(ROOT, "inputs", "gmsh") + "/") + "\n")
    h5 = os.path.join(work, "force.h5")
    p, _ = run_solver(BIN, deck, f"&output file='{h5}' /", env=solver_env(2), timeout=300)
    if check(p.returncode == 0, "Hertz 3D, force control: converged", (p.stdout + p.stderr)[-300:]):
        check("is held only by contact (free: translation along y)" in p.stdout,
              "Hertz 3D, force control: the sphere is held only by contact (SMALBE)")
        # its fixing DOF, named by node tag and component: a y component (the free motion's),
        # of a node of the mesh (three components per node, not two)
        fx = re.search(r"fixing DOFs for its generalized inverse: node (\d+) u([xyz]);", p.stdout)
        import meshio
        npts = len(meshio.read(os.path.join(ROOT, "inputs", "gmsh", "sphere_block_h0.01.msh")).points)
        check(fx is not None and fx.group(2) == "y" and 1 <= int(fx.group(1)) <= npts,
              "Hertz 3D, force control: the fixing DOF named as a y component of a mesh node",
              fx.group(0) if fx else p.stdout[-300:])
        P, a_h, p0_h, a_f, p0_f = measure(h5)
        want = 4.0 * q * face_area(os.path.join(ROOT, "inputs", "gmsh", "sphere_block_h0.01.msh"), "sphere_top")
        check(abs(P - want) <= 1e-9 * want, "Hertz 3D, force control: the contact force is the load, 4 q A "
              "(A the area of the top's triangles, by meshio)", f"{P:.12f} / {want:.12f}")
        ea, ep = a_f / a_h - 1, p0_f / p0_h - 1
        print(f"INFO  force control, hc = 0.01: P = {P:.5f}, a {100 * ea:+.2f}%, p0 {100 * ep:+.2f}%")
        check(abs(ea) <= 0.02 and abs(ep) <= 0.03, "Hertz 3D, force control, hc = 0.01: a within 2%, p0 within 3%",
              f"{100 * ea:+.2f}%, {100 * ep:+.2f}%")
    # different materials: the sphere three times as stiff as the block (E* from both), the
    # finer mesh; and Robin = monolithic on the coarser one
    E1, E2, nu = 3000.0, 1000.0, 0.3
    estar = 1.0 / ((1 - nu * nu) / E1 + (1 - nu * nu) / E2)
    mats = {}
    for h, over in RUNS:
        p, h5 = solve(h, over, "mat", sphere=f", young={E1}")
        if check(p.returncode == 0, f"Hertz 3D, E1 = 3 E2, hc = {h}: converged", (p.stdout + p.stderr)[-300:]):
            with h5py.File(h5, "r") as f:
                mats[h] = (f["/contact/x"][...], f["/contact/z"][...], f["/contact/pressure"][...],
                           4.0 * f["/contact/resultant_body1"][1], f["/contact/normal_force"][...])
    if "0.01" in mats:
        x, z, pr, P, _ = mats["0.01"]
        a_h = (3 * P * 1.0 / (4 * estar)) ** (1 / 3)
        p0_h = 3 * P / (2 * np.pi * a_h ** 2)
        a_f, p0_f = hertz_fit(np.hypot(x, z), pr)
        ea, ep = a_f / a_h - 1, p0_f / p0_h - 1
        print(f"INFO  E1 = 3 E2, hc = 0.01: P = {P:.5f}, a {100 * ea:+.2f}%, p0 {100 * ep:+.2f}%")
        check(abs(ea) <= 0.02 and abs(ep) <= 0.035, "Hertz 3D, E1 = 3 E2, hc = 0.01: a within 2%, p0 within 3.5% "
              "(E* of both materials)", f"{100 * ea:+.2f}%, {100 * ep:+.2f}%")
    if "0.02" in mats and "0.02m" in mats:
        fr, fm = mats["0.02"][4], mats["0.02m"][4]
        d = np.abs(fr - fm).max() / np.abs(fm).max()
        check(d <= 1e-8, "Hertz 3D, E1 = 3 E2: Robin = monolithic", f"{d:.2e}")
    if len(errs) == 2:
        (ea1, ep1), (ea2, ep2) = errs["0.02"], errs["0.01"]
        check(abs(ea2) <= 0.02 and abs(ep2) <= 0.03, "Hertz 3D, hc = 0.01: a within 2%, p0 within 3%",
              f"{100 * ea2:+.2f}%, {100 * ep2:+.2f}%")
        check(abs(ea2) < abs(ea1) and abs(ep2) < abs(ep1), "Hertz 3D: both errors fall with the mesh",
              f"a {100 * ea1:+.2f}% -> {100 * ea2:+.2f}%, p0 {100 * ep1:+.2f}% -> {100 * ep2:+.2f}%")
finally:
    shutil.rmtree(work, ignore_errors=True)

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
