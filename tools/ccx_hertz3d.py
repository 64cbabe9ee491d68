#!/usr/bin/python3
"""Hertz in 3D side by side with CalculiX: the sphere on a block of inputs/sphere_block.nml
(quarter model, R = 1, E = 1000, nu = 0.3 for both, the sphere's top pushed down by 0.012,
rollers on x = 0 and z = 0, the block's bottom on rollers) solved by robin_contact and by
CalculiX's ccx on the SAME Gmsh tetrahedra (inputs/gmsh/sphere_block_h{0.02,0.01}.msh, and
meshes made here from sphere_block.geo by gmsh with --hc).

For CalculiX the mesh is written as an .inp: the same nodes, the tetrahedra as C3D4, the same
material and supports (node sets of the physical surfaces, *BOUNDARY), and one contact pair,
the sphere's arc (slave, element faces) on the block's top (master, element faces):
  --ccx-type s2s      TYPE=SURFACE TO SURFACE, CalculiX's face-to-face penalty contact, with
                      PRESSURE-OVERCLOSURE=LINEAR of slope K = --penalty x E (default 500 E)
  --ccx-type mortar   TYPE=MORTAR with PRESSURE-OVERCLOSURE=HARD (which 2.20 turns into linear,
                      K = 50 E). It fails on this model: SPOOLES finds the matrix singular in
                      the first iteration (the slave nodes on the symmetry planes carry SPCs);
                      kept to show it.
One *STATIC step, small deformations (no NLGEOM, as robin_contact), the displacement applied
in --inc increments of fixed size (DIRECT; default 1), ccx's convergence criteria left at their
defaults (--tol changes them). P = 4 x the reaction on the pushed face (*NODE PRINT ...
TOTALS=ONLY, RF), the nodal contact pressure CPRESS of the slave nodes from the .frd
(*CONTACT FILE: CSTR). How K, the increments and the criteria were chosen: doc/performance.md,
"Side by side with CalculiX 2.20: Hertz in 3D".

For each program and mesh: P, the contact radius a and the peak pressure p0 of the Hertz shape
p = p0 sqrt(1 - r^2/a^2) fitted to the nodal pressures (tools/hertz3d_study.py's fit, r the
distance from the y axis), against Hertz's a = (3 P R/(4 E*))^(1/3), p0 = 3 P/(2 pi a^2) for
the program's own P (E* = E/(2 (1 - nu^2))), and the wall time. Both programs run with
OMP_NUM_THREADS = --threads (default 2); ccx also gets CCX_NPROC_EQUATION_SOLVER,
CCX_NPROC_STIFFNESS and CCX_NPROC_RESULTS = --threads (its SPOOLES solver and its element
loops). Prints a Markdown table and the load average (uptime) before and after; exit 1 when a
run fails (its row says why).

CalculiX is not installed by tools/install-deps.sh (make check does not need it): install it
with `apt-get install -y calculix-ccx` (Debian 12: CalculiX 2.20).

usage: tools/ccx_hertz3d.py [--bin bin/robin_contact] [--ccx ccx] [--meshes 0.02,0.01]
           [--hc 0.005 [--rc 0.15]] [--ccx-type s2s|mortar] [--penalty 500] [--inc 1]
           [--tol 1e-4] [--threads 2] [--keep DIR] [--no-robin]
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
import meshio
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from hertz3d_study import E, NU, R, hertz_fit, measure  # noqa: E402
from rc_results import md_header, md_row  # noqa: E402
from rc_run import run_solver, solver_env, time_fields  # noqa: E402

DECK = os.path.join(ROOT, "inputs", "sphere_block.nml")
GEO = os.path.join(ROOT, "inputs", "gmsh", "sphere_block.geo")
PUSH = -0.012                       # uy of the sphere's top (inputs/sphere_block.nml)
# the supports of inputs/sphere_block.nml: group -> (dof, value); dof 1 = x, 2 = y, 3 = z
SUPPORTS = {"sphere_top": (2, PUSH), "sphere_x0": (1, 0.0), "sphere_z0": (3, 0.0),
            "block_bottom": (2, 0.0), "block_x0": (1, 0.0), "block_z0": (3, 0.0)}
SLAVE, MASTER = "sphere_arc", "block_top"
# CalculiX's C3D4 faces (manual, *SURFACE): S1 = 1-2-3, S2 = 1-4-2, S3 = 2-4-3, S4 = 3-4-1
C3D4_FACES = ((0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0))


def hertz(P):
    """Hertz's contact radius and peak pressure of the sphere on the block for the force P."""
    estar = E / (2 * (1 - NU * NU))
    a = (3 * P * R / (4 * estar)) ** (1 / 3)
    return a, 3 * P / (2 * math.pi * a * a)


# ---- the .inp ------------------------------------------------------------------------------
def read_mesh(msh, groups=None):
    """Nodes (n x 3), the tetrahedra of each body {'sphere', 'block'} (0-based node indices,
    positive volume) and the triangles of each physical surface (groups: default this scene's
    supports and contact groups), from a Gmsh MSH 4.1 file."""
    m = meshio.read(msh)
    sets = m.cell_sets_dict
    tets = {}
    for body in ("sphere", "block"):
        t = m.cells_dict["tetra"][sets[body]["tetra"]].astype(np.int64)
        x = m.points[t]
        vol = np.einsum("ij,ij->i", np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), x[:, 3] - x[:, 0])
        t[vol < 0] = t[vol < 0][:, [0, 2, 1, 3]]
        tets[body] = t
    tris = {}
    for name in groups or list(SUPPORTS) + [SLAVE, MASTER]:
        tris[name] = m.cells_dict["triangle"][sets[name]["triangle"]].astype(np.int64)
    return m.points, tets, tris


def face_surface(tets, first_id, tris):
    """(element id, face number) of the C3D4 face of each triangle (tets numbered from first_id)."""
    where = {}
    for k, t in enumerate(tets):
        for f, loc in enumerate(C3D4_FACES):
            where[tuple(sorted(t[list(loc)]))] = (first_id + k, f + 1)
    return [where[tuple(sorted(tr))] for tr in tris]


def write_lines(f, values, per_line=8):
    for i in range(0, len(values), per_line):
        f.write(", ".join(str(v) for v in values[i:i + per_line]) + ",\n")


def write_inp(path, points, tets, tris, ctype, penalty, inc, tol=None):
    """The CalculiX deck of the sphere on the block (ids: node = mesh index + 1)."""
    used = np.unique(np.concatenate([tets["sphere"].ravel(), tets["block"].ravel()]))
    with open(path, "w") as f:
        f.write("** Hertz in 3D, quarter model: inputs/sphere_block.nml's scene, written by tools/ccx_hertz3d.py\n")
        f.write("*NODE, NSET=NALL\n")
        for i in used:     # 13 digits: ccx reads each number from at most 20 characters
            f.write(f"{i + 1}, {points[i, 0]:.13g}, {points[i, 1]:.13g}, {points[i, 2]:.13g}\n")
        first = {"sphere": 1, "block": 1 + len(tets["sphere"])}
        for body in ("sphere", "block"):
            f.write(f"*ELEMENT, TYPE=C3D4, ELSET={body.upper()}\n")
            for k, t in enumerate(tets[body]):
                f.write(f"{first[body] + k}, {t[0] + 1}, {t[1] + 1}, {t[2] + 1}, {t[3] + 1}\n")
        for name in SUPPORTS:
            f.write(f"*NSET, NSET=N_{name.upper()}\n")
            write_lines(f, [int(i) + 1 for i in np.unique(tris[name])])
        for name, body in ((SLAVE, "sphere"), (MASTER, "block")):
            f.write(f"*SURFACE, NAME=S_{name.upper()}, TYPE=ELEMENT\n")
            for e, s in face_surface(tets[body], first[body], tris[name]):
                f.write(f"{e}, S{s}\n")
        f.write("*MATERIAL, NAME=MAT\n*ELASTIC\n"
                f"{E:g}, {NU:g}\n"
                "*SOLID SECTION, ELSET=SPHERE, MATERIAL=MAT\n*SOLID SECTION, ELSET=BLOCK, MATERIAL=MAT\n")
        kind = {"mortar": "MORTAR", "s2s": "SURFACE TO SURFACE"}[ctype]
        f.write(f"*CONTACT PAIR, INTERACTION=SI1, TYPE={kind}\nS_{SLAVE.upper()}, S_{MASTER.upper()}\n"
                "*SURFACE INTERACTION, NAME=SI1\n")
        if ctype == "mortar":
            f.write("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=HARD\n")
        else:
            f.write(f"*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{penalty * E:g}\n")
        f.write("*STEP\n")
        if tol:     # ccx's residual (R_n, R_p) and correction (C_n) criteria, defaults 0.005, 0.02, 0.01
            f.write(f"*CONTROLS, PARAMETERS=FIELD\n{tol:g}, {tol:g}, 0.01, , {tol:g}, 1.e-5, 1.e-3, 1.e-8\n")
        f.write(f"*STATIC, DIRECT\n{1.0 / inc:.10g}, 1.0\n*BOUNDARY\n")
        for name, (dof, val) in SUPPORTS.items():
            f.write(f"N_{name.upper()}, {dof}, {dof}, {val:g}\n")
        f.write("*NODE PRINT, NSET=N_SPHERE_TOP, TOTALS=ONLY\nRF\n"
                "*NODE PRINT, NSET=N_BLOCK_BOTTOM, TOTALS=ONLY\nRF\n"
                "*CONTACT FILE\nCSTR\n*END STEP\n")


# ---- reading ccx's output --------------------------------------------------------------------
def dat_totals(dat):
    """{node set: (Fx, Fy, Fz)} of the last 'total force' blocks of a .dat file."""
    out, name = {}, None
    with open(dat) as f:
        for line in f:
            m = re.search(r"total force \(fx,fy,fz\) for set (\S+)", line)
            if m:
                name = m.group(1)
                continue
            if name and line.strip():
                out[name] = tuple(float(v) for v in line.split()[:3])
                name = None
    return out


def frd_contact(frd):
    """{node id: CPRESS} of the last CONTACT block of an ASCII .frd file (slave nodes)."""
    return {n: v["CPRESS"] for n, v in frd_fields(frd).items()}


def frd_fields(frd):
    """{node id: {name: value}} of the last CONTACT block of an ASCII .frd file (slave nodes:
    CPRESS, CSHEAR1, CSHEAR2 with CSTR)."""
    last, cur, names = {}, None, []
    with open(frd) as f:
        for line in f:
            if line.startswith(" -4"):
                cur = {} if line.split()[1] == "CONTACT" else None
                names = []
            elif cur is not None and line.startswith(" -5"):
                names.append(line.split()[1])
            elif cur is not None and line.startswith(" -1"):
                vals = [float(line[13 + 12 * k:25 + 12 * k]) for k in range(len(names))]
                cur[int(line[3:13])] = dict(zip(names, vals))
            elif cur is not None and line.startswith(" -3"):
                last, cur = cur, None
    return last


def sta_counts(sta):
    """(increments, iterations) of a converged ccx run, from its .sta file."""
    inc = it = 0
    with open(sta) as f:
        for line in f:
            w = line.split()
            if len(w) >= 7 and w[0].isdigit() and w[1].isdigit():
                inc, it = inc + 1, it + int(w[3])
    return inc, it


# ---- the runs ------------------------------------------------------------------------------------
def run_ccx(ccx, msh, work, ctype, penalty, inc, threads, tol=None):
    """Write the .inp, run ccx; a dict of P, a, p0 (fit), the Hertz values, wall time, counts."""
    points, tets, tris = read_mesh(msh)
    job = os.path.join(work, "hertz3d")
    write_inp(job + ".inp", points, tets, tris, ctype, penalty, inc, tol)
    env = solver_env(threads)
    for k in ("CCX_NPROC_EQUATION_SOLVER", "CCX_NPROC_STIFFNESS", "CCX_NPROC_RESULTS"):
        env[k] = str(threads)
    t0 = time.time()
    p = subprocess.run([ccx, "-i", "hertz3d"], cwd=work, env=env, capture_output=True, text=True)
    wall = time.time() - t0
    log = p.stdout + p.stderr
    with open(job + ".log", "w") as f:
        f.write(log)
    err = re.search(r"\*ERROR.*", log)
    frd = open(job + ".frd").read() if os.path.exists(job + ".frd") else ""
    if p.returncode != 0 or err or " -4  CONTACT" not in frd:
        why = err.group(0).strip() if err else f"exit {p.returncode}"
        spooles = os.path.join(work, "spooles.out")
        if os.path.exists(spooles) and "singular" in open(spooles).read():
            why += ", SPOOLES: matrix found to be singular"
        return {"status": f"failed: {why}", "wall": wall}
    tot = dat_totals(job + ".dat")
    P = -4.0 * tot["N_SPHERE_TOP"][1]
    cp = frd_contact(job + ".frd")
    ids = np.unique(tris[SLAVE]) + 1          # the block lists every node, the master's at 0
    pr = np.array([cp[i] for i in ids])
    xs = points[ids - 1]
    a_h, p0_h = hertz(P)
    af, p0f = hertz_fit(np.hypot(xs[:, 0], xs[:, 2]), pr)
    incs, its = sta_counts(job + ".sta")
    neq = re.search(r"number of equations\s+(\d+)", log)
    return {"status": "ok", "P": P, "a": af, "p0": p0f, "a_h": a_h,
            "p0_h": p0_h, "wall": wall, "nodes": int((pr > 0).sum()), "dofs": int(neq.group(1)) if neq else "?",
            "note": f"{incs} increment{'s' if incs != 1 else ''}, {its} iterations"}


def run_robin(binary, msh, work, threads):
    """robin_contact on the deck inputs/sphere_block.nml with the mesh msh."""
    h5 = os.path.join(work, "robin.h5")
    t0 = time.time()
    p, res = run_solver(binary, DECK, f"&body id=1, mesh='{msh}' /", f"&body id=2, mesh='{msh}' /",
                        f"&output file='{h5}' /", env=solver_env(threads))
    wall = time.time() - t0
    if p.returncode != 0 or res is None or res["status"] != "converged":
        return {"status": f"failed: exit {p.returncode}, status {res['status'] if res else '?'}", "wall": wall}
    P, a_h, p0_h, af, p0f = measure(h5)
    with h5py.File(h5, "r") as f:
        nodes = int((f["/contact/pressure"][...] > 0).sum())
    tf = time_fields(p.stdout) or {}
    return {"status": res["status"], "P": P, "a": af, "p0": p0f, "a_h": a_h, "p0_h": p0_h, "wall": wall,
            "nodes": nodes, "dofs": int(res["dofs"]),
            "note": f"{res['method']}, {res['outer']} outer, peak {tf.get('peak_mb', '?')} MiB"}


def uptime():
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"), help="the robin_contact binary")
    ap.add_argument("--ccx", default="ccx", help="the CalculiX solver (default: ccx on the PATH)")
    ap.add_argument("--meshes", default="0.02,0.01", help="shipped meshes inputs/gmsh/sphere_block_h<hc>.msh")
    ap.add_argument("--hc", default="", help="more meshes made here by gmsh from sphere_block.geo (comma list of hc)")
    ap.add_argument("--rc", type=float, default=0.2, help="the fine zone's radius of the --hc meshes (default 0.2)")
    ap.add_argument("--ccx-type", choices=("s2s", "mortar"), default="s2s")
    ap.add_argument("--penalty", type=float, default=500.0, help="s2s: the penalty slope in units of E (default 500)")
    ap.add_argument("--inc", type=int, default=1, help="ccx: fixed increments of the step (default 1)")
    ap.add_argument("--tol", type=float, default=0.0,
                    help="ccx: residual and correction criteria of *CONTROLS,PARAMETERS=FIELD (default: ccx's own)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--keep", default="", help="keep the work files (.inp, .dat, .frd, .h5) in this folder")
    ap.add_argument("--no-robin", action="store_true", help="run CalculiX only")
    a = ap.parse_args()
    ccx = shutil.which(a.ccx)
    if ccx is None:
        print(f"ccx_hertz3d: CalculiX's solver '{a.ccx}' is not installed; on Debian 12: "
              "apt-get install -y calculix-ccx (CalculiX 2.20; not part of tools/install-deps.sh, "
              "only this study needs it)", file=sys.stderr)
        return 1
    if not a.no_robin and not os.access(a.bin, os.X_OK):
        print(f"ccx_hertz3d: no robin_contact binary at {a.bin} (make, or --bin)", file=sys.stderr)
        return 1
    work = os.path.abspath(a.keep) if a.keep else tempfile.mkdtemp(prefix="rc_ccx_hertz3d_")
    os.makedirs(work, exist_ok=True)
    meshes = [(h, os.path.join(ROOT, "inputs", "gmsh", f"sphere_block_h{h}.msh")) for h in a.meshes.split(",") if h]
    setting = ("mortar, PRESSURE-OVERCLOSURE=HARD (2.20: linear, K = 50 E)" if a.ccx_type == "mortar"
               else f"surface to surface, linear penalty K = {a.penalty:g} E")
    print(f"load before: {uptime()}")
    print(f"CalculiX: {setting}, {a.inc} fixed increments; threads {a.threads}")
    head = ["hc", "program", "DOFs", "P", "a (fit)", "a (Hertz)", "error a", "p0 (fit)", "p0 (Hertz)", "error p0",
            "nodes p > 0", "wall s", "load", "notes"]
    rows = []
    failed = False
    try:
        for h in [h for h in a.hc.split(",") if h]:
            msh = os.path.join(work, f"sphere_block_h{h}.msh")
            subprocess.run(["gmsh", "-3", "-format", "msh41", "-setnumber", "hc", h, "-setnumber", "rc", str(a.rc),
                            GEO, "-o", msh], capture_output=True, check=True)
            meshes.append((h, msh))
        for h, msh in meshes:
            for prog in (("robin_contact",) if not a.no_robin else ()) + ("CalculiX 2.20",):
                d = os.path.join(work, f"{prog.split()[0].split('_')[0]}_h{h}")
                os.makedirs(d, exist_ok=True)
                load = f"{os.getloadavg()[0]:.1f}"     # the 1-minute load average as the run starts
                if prog == "robin_contact":
                    r = run_robin(a.bin, msh, d, a.threads)
                else:
                    r = run_ccx(ccx, msh, d, a.ccx_type, a.penalty, a.inc, a.threads, a.tol)
                if "P" not in r:
                    rows.append([h, prog] + [""] * 9 + [f"{r['wall']:.1f}", load, r["status"]])
                    failed = True
                else:
                    rows.append([h, prog, r["dofs"], f"{r['P']:.5f}", f"{r['a']:.5f}", f"{r['a_h']:.5f}",
                                 f"{100 * (r['a'] / r['a_h'] - 1):+.2f}%", f"{r['p0']:.3f}", f"{r['p0_h']:.3f}",
                                 f"{100 * (r['p0'] / r['p0_h'] - 1):+.2f}%", r["nodes"], f"{r['wall']:.1f}", load,
                                 r["note"]])
                print(md_row(rows[-1]), file=sys.stderr, flush=True)
    finally:
        if not a.keep:
            shutil.rmtree(work, ignore_errors=True)
    print("\n".join(md_header(head)))
    for r in rows:
        print(md_row(r))
    print(f"load after: {uptime()}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
