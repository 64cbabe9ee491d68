#!/usr/bin/env python3
"""A body read from a Gmsh file is numbered for locality inside the program; its results are
written in the file's order all the same (a user maps them onto their own mesh), checked
against the .msh file read here by a parser of its own:

1. /body<a>/coordinates and geometry_xyz are the body's nodes (those of its physical surface's
   elements) in increasing tag order, with the file's coordinates;
2. /body<a>/cells (and the mixed 'topology') are the body's elements in file order, each with
   the file's nodes (their place in that node order; a cell may be turned counter-clockwise);
3. the displacement in that order: the nodes of a group with a prescribed component have it;
4. the nodal stresses in that order: on a triangle body, the mean over the cells around each
   node of sigma = D B u, recomputed here from the written coordinates, cells and displacement;
5. the contact pressure is zero off the nodes of the contact groups.
"""
import os
import sys
import tempfile

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import run_solver, solver_env  # noqa: E402

BIN = os.environ.get("BIN", "bin/robin_contact")
ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
check = Checks()


def read_msh(path):
    """(physical names {(dim, tag): name}, surface entity -> physical tags, curve entity ->
    physical tags, node tag -> (x, y), elements [(entity dim, entity tag, type, [node tags])]
    in file order) of a Gmsh MSH 4.1 ASCII file."""
    with open(path) as f:
        lines = [ln.split() for ln in f]
    names, ents, nodes, elems = {}, {1: {}, 2: {}}, {}, []
    i = 0
    while i < len(lines):
        sec = lines[i][0] if lines[i] else ""
        i += 1
        if sec == "$PhysicalNames":
            for k in range(int(lines[i][0])):
                d, t, name = lines[i + 1 + k][0], lines[i + 1 + k][1], " ".join(lines[i + 1 + k][2:])
                names[(int(d), int(t))] = name.strip('"')
        elif sec == "$Entities":
            counts = [int(x) for x in lines[i][:4]]
            row = i + 1 + counts[0]
            for dim in (1, 2):
                for k in range(counts[dim]):
                    w = lines[row]
                    nphys = int(w[7])
                    ents[dim][int(w[0])] = [int(x) for x in w[8:8 + nphys]]
                    row += 1
        elif sec == "$Nodes":
            nblock = int(lines[i][0])
            row = i + 1
            for _ in range(nblock):
                n = int(lines[row][3])
                tags = [int(lines[row + 1 + k][0]) for k in range(n)]
                for k in range(n):
                    x, y = float(lines[row + 1 + n + k][0]), float(lines[row + 1 + n + k][1])
                    nodes[tags[k]] = (x, y)
                row += 1 + 2 * n
        elif sec == "$Elements":
            nblock = int(lines[i][0])
            row = i + 1
            for _ in range(nblock):
                dim, etag, etype, n = (int(x) for x in lines[row][:4])
                for k in range(n):
                    elems.append((dim, etag, etype, [int(x) for x in lines[row + 1 + k][1:]]))
                row += 1 + n
    return names, ents, nodes, elems


def body_of(msh, region):
    """(node tags in increasing order, coordinates (n, 2), elements [(type, node tags)] in file
    order) of the physical surface `region`."""
    names, ents, nodes, elems = msh
    tag = [t for (d, t), nm in names.items() if d == 2 and nm == region][0]
    surf = {e for e, ph in ents[2].items() if tag in ph}
    cells = [(ty, nt) for d, e, ty, nt in elems if d == 2 and e in surf and ty in (2, 3)]
    tags = sorted({t for _, nt in cells for t in nt})
    return tags, np.array([nodes[t] for t in tags]), cells


def group_tags(msh, group):
    """The node tags of the line elements of physical curve `group`."""
    names, ents, _, elems = msh
    tag = [t for (d, t), nm in names.items() if d == 1 and nm == group][0]
    curves = {e for e, ph in ents[1].items() if tag in ph}
    return {t for d, e, ty, nt in elems if d == 1 and e in curves and ty == 1 for t in nt}


def run(deck, *over):
    out = os.path.join(tempfile.mkdtemp(prefix="gmsh_order_"), "run.h5")
    p, _ = run_solver(BIN, deck, *over, f"&output file='{out}' /", env=solver_env("2"), cwd=ROOT)
    check(p.returncode == 0 and os.path.exists(out), f"{deck} runs", p.stdout[-500:] + p.stderr[-500:])
    return out


def nodes_and_cells(f, a, name, msh, region):
    """Checks 1 and 2 for body a; returns (tags, written coordinates (n, 2), cells as lists of
    0-based node places, element types)."""
    tags, xy, cells = body_of(msh, region)
    g = f[f"body{a}"]
    w = g["coordinates"][()].T
    scale = np.abs(xy).max()
    check(w.shape == xy.shape and np.abs(w - xy).max() <= 1e-14 * scale,
          f"{name} body {a}: coordinates are the file's nodes in tag order", f"{w.shape} vs {xy.shape}")
    gx = g["geometry_xyz"][()]
    check(gx.shape == (len(tags), 3) and np.abs(gx[:, :2] - xy).max() <= 1e-14 * scale,
          f"{name} body {a}: geometry_xyz in the file's order")
    place = {t: k for k, t in enumerate(tags)}
    wc = g["cells"][()]
    want = [sorted(place[t] for t in nt) for _, nt in cells]
    got = [sorted(int(v) for v in row if v >= 0) for row in wc]
    check(got == want, f"{name} body {a}: cells are the file's elements in file order, with its nodes",
          f"first difference at cell {next((k for k in range(min(len(got), len(want))) if got[k] != want[k]), -1)}")
    if "topology" in g:
        t, k, rows = g["topology"][()], 0, []
        while k < len(t):
            nv = 4 if t[k] == 5 else 3
            rows.append(sorted(int(v) for v in t[k + 1:k + 1 + nv]))
            k += 1 + nv
        check(rows == want, f"{name} body {a}: the mixed topology in file order")
    return tags, w, [[place[t] for t in nt] for _, nt in cells], [ty for ty, _ in cells]


def test_patch_mixed():
    """Triangles on a mixed mesh: every check but the stresses (uniform in a patch test)."""
    deck = "inputs/patch.nml"
    path = os.path.join(ROOT, "inputs", "gmsh", "patch_mixed.msh")
    over = ("&body id=1, mesh='gmsh/patch_mixed.msh' /", "&body id=2, mesh='gmsh/patch_mixed.msh' /")
    out = run(deck, *over)
    msh = read_msh(path)
    with h5py.File(out, "r") as f:
        for a, region, held in ((1, "top", [("top_top", 1, -1.0e-3), ("top_left", 0, 0.0)]),
                                (2, "bottom", [("bottom_bottom", 1, 0.0), ("bottom_right", 0, 0.0)])):
            tags, _, _, _ = nodes_and_cells(f, a, "patch_mixed", msh, region)
            u = f[f"body{a}/displacement"][()].T
            for group, comp, value in held:
                on = [k for k, t in enumerate(tags) if t in group_tags(msh, group)]
                check(len(on) > 1 and np.all(u[on, comp] == value),
                      f"patch_mixed body {a}: the nodes of '{group}' have u{'xy'[comp]} = {value}",
                      f"{u[on, comp][:5]}")
            free = [k for k, t in enumerate(tags) if t not in group_tags(msh, held[0][0])]
            if a == 1:
                check(np.abs(u[free, 1] + 1.0e-3).max() > 1e-6, "patch_mixed body 1: the other nodes move otherwise")


def test_pin_hole():
    """Triangles, two bodies of one file, a curved contact: the stresses in file order."""
    out = run("inputs/pin_hole.nml")
    msh = read_msh(os.path.join(ROOT, "inputs", "gmsh", "pin_hole.msh"))
    young, poisson = {1: 210000.0, 2: 70000.0}, {1: 0.3, 2: 0.33}
    with h5py.File(out, "r") as f:
        for a, region, contact in ((1, "pin", "pin_rim"), (2, "plate", "bore")):
            tags, xy, cells, types = nodes_and_cells(f, a, "pin_hole", msh, region)
            u = f[f"body{a}/displacement"][()].T
            sig = f[f"body{a}/stress"][()].T
            if all(ty == 2 for ty in types):
                e, nu = young[a], poisson[a]
                lam, mu = e * nu / ((1 + nu) * (1 - 2 * nu)), e / (2 * (1 + nu))
                acc, cnt = np.zeros((len(tags), 4)), np.zeros(len(tags))
                for c in cells:
                    p = xy[c]
                    area2 = (p[1, 0] - p[0, 0]) * (p[2, 1] - p[0, 1]) - (p[2, 0] - p[0, 0]) * (p[1, 1] - p[0, 1])
                    b = np.array([p[1, 1] - p[2, 1], p[2, 1] - p[0, 1], p[0, 1] - p[1, 1]]) / area2
                    d = np.array([p[2, 0] - p[1, 0], p[0, 0] - p[2, 0], p[1, 0] - p[0, 0]]) / area2
                    exx, eyy = b @ u[c, 0], d @ u[c, 1]
                    gxy = d @ u[c, 0] + b @ u[c, 1]
                    s = [(lam + 2 * mu) * exx + lam * eyy, lam * exx + (lam + 2 * mu) * eyy, mu * gxy,
                         lam * (exx + eyy)]
                    acc[c] += s
                    cnt[c] += 1
                mine = acc / cnt[:, None]
                err = np.abs(mine - sig).max() / np.abs(mine).max()
                check(err < 1e-9, f"pin_hole body {a}: nodal stresses in file order (recomputed from the "
                      f"written displacement: {err:.1e})")
            p = f[f"body{a}/contact_pressure"][()]
            on = {k for k, t in enumerate(tags) if t in group_tags(msh, contact)}
            off = [k for k in range(len(tags)) if k not in on]
            check(np.abs(p).max() > 0 and np.all(p[off] == 0.0),
                  f"pin_hole body {a}: the contact pressure is zero off '{contact}'")


if __name__ == "__main__":
    test_patch_mixed()
    test_pin_hole()
    sys.exit(1 if check.failed else 0)
