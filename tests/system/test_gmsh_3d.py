#!/usr/bin/python3
"""Gmsh volume meshes in a 3D deck, whole program (run by `make check`; decks written by the
test in a temporary folder, the mesh the shipped inputs/gmsh/blocks_3d.msh).

(1) Patch test: inputs/gmsh/blocks_3d.msh, an upper block of tetrahedra (0,1)x(1,2)x(0,1) on a
    lower block of hexahedra (0,1)^3, non-matching at y = 1, each body a physical volume
    (&body mesh=..., region=...); rollers through &boundary on physical surfaces (ux = 0 on
    x = 0 and uz = 0 on z = 0 of both, uy = 0 under the lower one), a uniform pressure p on
    the upper block's top (&traction group=..., pressure=p), the upper block held along y by
    contact only (&contact groups= on the two physical surfaces at y = 1). Exact: every contact
    node's pressure p, u = (nu p x / E, -p y / E, nu p z / E), syy = -p and every other stress 0,
    each to 1e-9 of its scale; the contact resultant p A; the bodies balance (`reaction:`) to
    1e-12; the monolithic method gives the same pressures (1e-9); the result's XDMF opens in
    meshio with tetrahedra and hexahedra.
(2) A body of mixed cells (a hexahedron and a tetrahedron on half of one of its faces, written
    here) pressed onto a box through a face group of a quadrangle and a triangle: converges, the
    bodies balance, and its XDMF ('Mixed' topology) opens in meshio with one hexahedron and one
    tetrahedron.
(3) Bad input, exit 1, one message naming the body and the file, nothing written: a region
    that is a physical surface, no region in a file of two volumes, a box's variable with a
    mesh file, a group the body does not have, a 2D mesh in a 3D deck, a 3D mesh in a 2D deck.
"""
import os
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import run_text, solver_env  # noqa: E402

import h5py  # noqa: E402
import numpy as np  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
MESH = os.path.join(ROOT, "inputs", "gmsh", "blocks_3d.msh")
MESH2D = os.path.join(ROOT, "inputs", "gmsh", "patch.msh")
ENV = solver_env(2)
check = Checks()


def run(work, name, text, *over):
    return run_text(BIN, work, name, text, *over, env=ENV)


def nodal(f, b, name):
    """A nodal field of body b as (nnode, components)."""
    return f[f"/body{b}/{name}"][...].T


def balances(out):
    """The balance of every `reaction:` line."""
    return [float(line.split("balance=")[1].split()[0]) for line in out.splitlines() if line.startswith("reaction:")]


def last_line(out):
    return out.strip().splitlines()[-1][:400] if out.strip() else ""


E, nu, p = 2.1e11, 0.3, 1.0e6
bodies = (f"&body id=1, mesh='{MESH}', region='upper', young={E}, poisson={nu} /\n"
          f"&body id=2, mesh='{MESH}', region='lower', young={E}, poisson={nu} /\n")
conditions = ("&contact bodies=1,2, groups='upper_bottom','lower_top' /\n"
              "&boundary body=1, group='upper_x0', ux=0.0 /\n"
              "&boundary body=1, group='upper_z0', uz=0.0 /\n"
              "&boundary body=2, group='lower_x0', ux=0.0 /\n"
              "&boundary body=2, group='lower_z0', uz=0.0 /\n"
              "&boundary body=2, group='lower_bottom', uy=0.0 /\n"
              f"&traction body=1, group='upper_top', pressure={p} /\n")
deck = "&scene title='gmsh 3D patch', dimension=3 /\n" + bodies + conditions

work = tempfile.mkdtemp(prefix="rc_gmsh3d_")
try:
    # (1) the patch test
    code, out, h5 = run(work, "patch", deck)
    check(code == 0, "gmsh 3D patch test: converged", out[-400:])
    if code == 0:
        with h5py.File(h5, "r") as f:
            pres = f["/contact/pressure"][...]
            check(len(pres) > 0 and np.abs(pres - p).max() <= 1e-9 * p,
                  f"gmsh 3D patch test: every contact node's pressure is p ({len(pres)} nodes)",
                  f"max |p_j - p|/p = {np.abs(pres - p).max() / p:.2e}")
            res = f["/contact/resultant_body1"][...]
            check(np.abs(res - [0.0, p, 0.0]).max() <= 1e-9 * p, "gmsh 3D patch test: the contact resultant is p A",
                  f"{res}")
            area = f["/contact/tributary_area"][...].sum()
            check(abs(area - 1.0) <= 1e-12, "gmsh 3D patch test: the tributary areas sum to A", f"{area - 1:.1e}")
            for b in (1, 2):
                x, u, s = nodal(f, b, "coordinates"), nodal(f, b, "displacement"), nodal(f, b, "stress")
                exact = np.c_[nu * p / E * x[:, 0], -p / E * x[:, 1], nu * p / E * x[:, 2]]
                eu = np.abs(u - exact).max() / np.abs(exact).max()
                es = max(np.abs(s[:, 1] + p).max(), np.abs(s[:, [0, 2, 3, 4, 5]]).max()) / p
                kind = ["tetrahedra", "hexahedra"][b - 1]
                check(eu <= 1e-9, f"gmsh 3D patch test: body {b} ({kind}, {len(x)} nodes) displacement exact",
                      f"{eu:.2e}")
                check(es <= 1e-9, f"gmsh 3D patch test: body {b} stress exact (syy = -p, the others 0)", f"{es:.2e}")
        bal = balances(out)
        check(len(bal) == 2 and max(bal) <= 1e-12, "gmsh 3D patch test: both bodies balance", f"{bal}")
        check("rigid motion amplitudes" in out and "free: translation along y" in out,
              "gmsh 3D patch test: the upper block is held along y by contact only")
        try:
            import meshio
            m1 = meshio.read(os.path.join(work, "patch_body1.xdmf"))
            m2 = meshio.read(os.path.join(work, "patch_body2.xdmf"))
            ok = [c.type for c in m1.cells] == ["tetra"] and [c.type for c in m2.cells] == ["hexahedron"]
            check(ok, "gmsh 3D patch test: the XDMF files open in meshio (tetrahedra, hexahedra)",
                  f"{[c.type for c in m1.cells]}, {[c.type for c in m2.cells]}")
        except ImportError:
            check(False, "meshio is installed (python3-meshio)")
    cm, om, hm = run(work, "mono", deck, "&solver method='monolithic' /")
    check(cm == 0, "gmsh 3D patch test, monolithic: converged", om[-400:])
    if code == 0 and cm == 0:
        with h5py.File(h5, "r") as a, h5py.File(hm, "r") as b:
            d = np.abs(a["/contact/pressure"][...] - b["/contact/pressure"][...]).max() / p
        check(d <= 1e-9, "gmsh 3D patch test: Robin = monolithic", f"{d:.2e}")

    # (2) a body of mixed cells
    mixed = ("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
             "$PhysicalNames\n5\n3 1 \"solid\"\n2 2 \"y0\"\n2 3 \"z0\"\n2 4 \"x0\"\n2 5 \"y1\"\n$EndPhysicalNames\n"
             "$Entities\n0 0 4 1\n" + "".join(f"{t} 0 0 0 1 1 1 1 {t} 0\n" for t in (2, 3, 4, 5)) +
             "1 0 0 0 1 1 1 1 1 0\n$EndEntities\n"
             "$Nodes\n1 9 1 9\n3 1 0 9\n" + "".join(f"{k}\n" for k in range(1, 10)) +
             "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n2 0 0\n$EndNodes\n"
             "$Elements\n7 7 1 7\n2 2 3 1\n1 1 2 6 5\n2 2 2 1\n2 2 9 6\n2 3 3 1\n3 1 2 3 4\n2 4 3 1\n4 1 4 8 5\n"
             "2 5 3 1\n5 4 3 7 8\n3 1 5 1\n6 1 2 3 4 5 6 7 8\n3 1 4 1\n7 2 9 6 3\n$EndElements\n")
    with open(os.path.join(work, "mixed.msh"), "w") as f:
        f.write(mixed)
    mdeck = ("&scene dimension=3 /\n&body id=1, mesh='mixed.msh', region='solid' /\n"
             "&body id=2, x0=0.0, y0=-1.0, z0=0.0, width=2.0, height=1.0, depth=1.0, nx=2, ny=1, nz=1, "
             "bottom='clamped' /\n&contact bodies=1,2, groups='y0','top' /\n"
             "&boundary body=1, group='x0', ux=0.0, uz=0.0 /\n&traction body=1, group='y1', pressure=1.0e6 /\n")
    code, out, h5 = run(work, "mixed", mdeck)
    bal = balances(out)
    check(code == 0 and len(bal) == 2 and max(bal) <= 1e-12, "a body of a hexahedron and a tetrahedron: converged, "
          "both bodies balance", last_line(out) if code else f"{bal}")
    if code == 0:
        try:
            import meshio
            m = meshio.read(os.path.join(work, "mixed_body1.xdmf"))
            types = sorted((c.type, len(c.data)) for c in m.cells)
            check(types == [("hexahedron", 1), ("tetra", 1)] and len(m.points) == 9,
                  "a body of mixed cells: its XDMF opens in meshio (a hexahedron, a tetrahedron)", f"{types}")
        except ImportError:
            check(False, "meshio is installed (python3-meshio)")

    # (3) bad input
    mesh_of = f"mesh='{MESH}'"
    bad = [
        ("surface_region", deck.replace("region='upper'", "region='upper_top'"),
         ["body 1", "blocks_3d.msh", "'upper_top' is a physical surface"]),
        ("no_region", deck.replace(", region='upper'", ""),
         ["body 1", "blocks_3d.msh", "holds 2 physical volumes ('lower', 'upper')"]),
        ("box_var", deck.replace(f"{mesh_of}, region='upper',", f"{mesh_of}, region='upper', depth=1.0,"),
         ["body 1", "depth = 1.0", "a variable of a box, but this body comes from mesh="]),
        ("unknown_group", deck.replace("group='upper_top'", "group='top'"),
         ["body 1", "group 'top' has no face on the boundary", "physical surfaces of the file"]),
        ("mesh2d", deck.replace(f"{mesh_of}, region='lower'", f"mesh='{MESH2D}', region='bottom'"),
         ["body 2", "patch.msh", "has no physical volume 'bottom'", "'bottom' is a physical surface"]),
        ("deck2d", deck.replace(", dimension=3", "").replace(", uz=0.0", ", ux=0.0"),
         ["body 1", "blocks_3d.msh", "&scene dimension=3"]),
    ]
    for name, text, want in bad:
        code, out, h5 = run(work, name, text)
        named = all(w in out for w in want)
        check(code == 1 and named and "Backtrace" not in out and not os.path.exists(h5),
              f"bad input '{name}': exit 1, named, nothing written", last_line(out))
finally:
    shutil.rmtree(work, ignore_errors=True)

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
