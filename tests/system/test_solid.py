#!/usr/bin/python3
"""Solid (3D) bodies, whole program (run by `make check`; decks written by the test in a
temporary folder). References are exact solutions and the 2D program itself.

(1) Patch test: a box of hexahedra (3 x 2 x 4) on a box of tetrahedra (5 x 3 x 2 cells, six
    tetrahedra each), non-matching, the upper box held only by contact (one free rigid motion,
    along y: SMALBE), rollers on x = 0 and z = 0 of both and under the lower one, a uniform
    pressure p on top. Exact: u = (nu p x / E, -p y / E, nu p z / E), syy = -p, every other
    stress 0, every contact node's pressure p: each to 1e-9 of its scale; the contact resultant
    p A; the bodies balance (`reaction:` lines) to 1e-12; the result's XDMF opens in meshio with
    hexahedra, tetrahedra and six stress components.
(2) Consistency with 2D: the paper's two blocks (constant loads) in plane strain, and the same
    as boxes one hexahedron deep with rollers front and back: the 3D nodal contact forces,
    summed through the depth and divided by it, are the 2D ones to 1e-10; uz = 0; the same
    outer count.
(3) Robin = monolithic: two boxes pressed by a prescribed displacement, the forces to 1e-8;
    the bodies balance to 1e-12; the 'steklov' and 'constant' operators too (to 1e-8).
(4) Bad input, exit 1, one message, nothing written: a box's variable in a 2D deck, a body
    with no depth in a 3D deck, plane stress in a 3D deck, uz in a 2D deck, dimension = 4,
    a parabolic gap in a 3D deck, t1 in a 3D deck, an override that changes the
    dimension, a box resting on another held only by contact (nothing holds it along x).
(6) A cube held only by contact, its six rigid motions free, pressed into a corner of three
    clamped walls by a pressure on its other three faces: each wall's contact resultant is
    p A along its normal to 1e-9 (the cube's equilibrium), Robin = monolithic to 1e-8.
(8) The shipped boxes (inputs/boxes.nml): 1 and 2 threads bit for bit; 3 load steps, each
    carrying its third of p A, the last the one-step forces to 1e-10; a checkpoint after one
    outer iteration and a restart that ends as the uninterrupted run (forces to 1e-12, the
    same outer count).
(9) The shipped stack of three cubes on a plate (inputs/cube_stack.nml: four bodies, three
    pairs, no two surfaces matching, the cubes held along y only by contact): each interface's
    resultant p A to 1e-9, every contact node's pressure p and every body's stress the
    uniform syy = -p to 1e-9, Robin = monolithic to 1e-8.
(10) A long cylinder on a block against the plane program: the 2D Hertz mesh
    (inputs/gmsh/hertz_h0.02.msh) extruded one layer deep into tetrahedra (msh_extrude.py),
    uz = 0 on both end faces: the force per length within twice the 2D force's change from h
    to h/2 (the discretization error), the same contact zone, the pressure averaged through the
    depth within 1% of p0 of the 2D one.
(7) The memory check in 3D: a 40^3 box against a 200 MiB limit is refused before assembly,
    naming the estimate and what else fits a solid body's factor.
"""
import os
import shutil
import subprocess
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
ENV = solver_env(2)
check = Checks()


def run(work, name, text, *over):
    return run_text(BIN, work, name, text, *over, env=ENV)


def run_deck_file(work, name, deck, *over):
    """Run a shipped deck (its relative paths from its folder) into work/name.h5."""
    with open(deck) as f:
        text = f.read()
    return run(work, name, text, *over)


def nodal(f, b, name):
    """A nodal field of body b as (nnode, components)."""
    return f[f"/body{b}/{name}"][...].T


def balances(out):
    """The balance of every `reaction:` line."""
    return [float(line.split("balance=")[1].split()[0]) for line in out.splitlines() if line.startswith("reaction:")]


work = tempfile.mkdtemp(prefix="rc_solid_")
try:
    # (1) the patch test
    E, nu, p = 2.1e11, 0.3, 1.0e6
    patch = ("&scene title='patch' /\n"
             "&body id=1, x0=0.0, y0=1.0, z0=0.0, width=1.0, height=1.0, depth=1.0, nx=3, ny=2, nz=4, "
             f"young={E}, poisson={nu}, bottom='contact', left='roller', front='roller' /\n"
             "&body id=2, x0=0.0, y0=0.0, z0=0.0, width=1.0, height=1.0, depth=1.0, nx=5, ny=3, nz=2, "
             f"element='P1', young={E}, poisson={nu}, bottom='roller', left='roller', front='roller', "
             "top='contact' /\n"
             f"&traction body=1, side='top', t0=0.0, {-p}, 0.0 /\n")
    code, out, h5 = run(work, "patch", patch)
    check(code == 0, "patch test: converged", out[-400:])
    if code == 0:
        with h5py.File(h5, "r") as f:
            pres = f["/contact/pressure"][...]
            check(np.abs(pres - p).max() <= 1e-9 * p, "patch test: every contact node's pressure is p",
                  f"max |p_j - p|/p = {np.abs(pres - p).max() / p:.2e}")
            res = f["/contact/resultant_body1"][...]
            check(np.abs(res - [0.0, p, 0.0]).max() <= 1e-9 * p, "patch test: the contact resultant is p A",
                  f"{res}")
            check(abs(f["/contact/tributary_area"][...].sum() - 1.0) <= 1e-12, "patch test: the tributary areas sum to A")
            for b in (1, 2):
                x, u, s = nodal(f, b, "coordinates"), nodal(f, b, "displacement"), nodal(f, b, "stress")
                exact = np.c_[nu * p / E * x[:, 0], -p / E * x[:, 1], nu * p / E * x[:, 2]]
                eu = np.abs(u - exact).max() / np.abs(exact).max()
                es = max(np.abs(s[:, 1] + p).max(), np.abs(s[:, [0, 2, 3, 4, 5]]).max()) / p
                check(eu <= 1e-9, f"patch test: body {b} ({['hexahedra', 'tetrahedra'][b - 1]}) displacement exact",
                      f"{eu:.2e}")
                check(es <= 1e-9, f"patch test: body {b} stress exact (syy = -p, the others 0)", f"{es:.2e}")
        bal = balances(out)
        check(len(bal) == 2 and max(bal) <= 1e-12, "patch test: both bodies balance", f"{bal}")
        check("rigid motion amplitudes" in out, "patch test: the upper box is held only by contact (SMALBE)")
        try:
            import meshio
            m1 = meshio.read(os.path.join(work, "patch_body1.xdmf"))
            m2 = meshio.read(os.path.join(work, "patch_body2.xdmf"))
            ok = ([c.type for c in m1.cells] == ["hexahedron"] and [c.type for c in m2.cells] == ["tetra"]
                  and all(k in m1.point_data for k in ("sxx", "syy", "szz", "syz", "sxz", "sxy")))
            check(ok, "patch test: the XDMF files open in meshio (hexahedra, tetrahedra, six stresses)",
                  f"{[c.type for c in m1.cells]}, {[c.type for c in m2.cells]}")
        except ImportError:
            check(False, "meshio is installed (python3-meshio)")

    # (2) consistency with the plane program
    body = ("young=2.1e11, poisson=0.277, nx=12, ny=4, width=3.0, height=1.0, x0=0.0, left='clamped'")
    deck2 = (f"&body id=1, y0=1.0, {body}, bottom='contact' /\n&body id=2, y0=0.0, {body}, top='contact' /\n"
             "&traction body=1, side='top', t0=0.0, -3.0e6 /\n&traction body=1, side='right', t0=0.0, 2.0e6 /\n"
             "&solver tol=1e-12 /\n")
    box = "z0=0.0, depth=0.5, nz=1, front='roller', back='roller'"
    deck3 = (f"&body id=1, y0=1.0, {body}, {box}, bottom='contact' /\n"
             f"&body id=2, y0=0.0, {body}, {box}, top='contact' /\n"
             "&traction body=1, side='top', t0=0.0, -3.0e6, 0.0 /\n"
             "&traction body=1, side='right', t0=0.0, 2.0e6, 0.0 /\n&solver tol=1e-12 /\n")
    c2, o2, h2 = run(work, "plane", deck2)
    c3, o3, h3 = run(work, "solid", deck3)
    check(c2 == 0 and c3 == 0, "2D and one-cell-deep 3D blocks: both converge", (o2 + o3)[-400:])
    if c2 == 0 and c3 == 0:
        with h5py.File(h2, "r") as a, h5py.File(h3, "r") as b:
            f2, x2 = a["/contact/normal_force"][...], a["/contact/x"][...]
            f3, x3 = b["/contact/normal_force"][...], b["/contact/x"][...]
            per = np.array([f3[np.isclose(x3, x)].sum() for x in x2]) / 0.5
            err = np.abs(per - f2).max() / np.abs(f2).max()
            uz = np.abs(nodal(b, 1, "displacement")[:, 2]).max()
        check(len(f3) == 2 * len(f2) and err <= 1e-10, "3D forces through the depth / depth = the 2D forces",
              f"{err:.2e}")
        check(uz == 0.0, "3D with rollers front and back: uz = 0", f"{uz:.1e}")
        n2 = [w for w in o2.split() if w.startswith("outer=")]
        n3 = [w for w in o3.split() if w.startswith("outer=")]
        check(n2 == n3, "2D and 3D: the same outer count", f"{n2} {n3}")

    # (3) Robin = monolithic
    boxes = ("&body id=1, x0=0.0, y0=1.0, z0=0.0, width=1.0, height=1.0, depth=1.0, nx=4, ny=3, nz=4, "
             "bottom='contact', top='displacement' /\n"
             "&body id=2, x0=0.0, y0=0.0, z0=0.0, width=1.0, height=1.0, depth=1.0, nx=3, ny=3, nz=3, "
             "element='P1', bottom='clamped', top='contact' /\n"
             "&displacement body=1, side='top', u=2.0e-5, -1.0e-4, 0.0 /\n")
    cr, orb, hr = run(work, "robin", boxes)
    cm, om, hm = run(work, "mono", boxes, "&solver method='monolithic' /")
    check(cr == 0 and cm == 0, "boxes pressed and sheared by a displacement: Robin and monolithic converge",
          (orb + om)[-400:])
    if cr == 0 and cm == 0:
        with h5py.File(hr, "r") as a, h5py.File(hm, "r") as b:
            fr, fm = a["/contact/normal_force"][...], b["/contact/normal_force"][...]
        d = np.abs(fr - fm).max() / np.abs(fm).max()
        check(d <= 1e-8, "boxes: Robin = monolithic", f"{d:.2e}")
        bal = balances(orb)
        check(len(bal) == 2 and max(bal) <= 1e-12, "boxes: both bodies balance", f"{bal}")
        # the paper's operator (the other body's flexibility) and the constant one (alpha of
        # the flexibilities' scale, 1/(E h)) on the same scene
        for op, over in (("steklov", "&solver robin_operator='steklov', tol=1e-10 /"),
                         ("constant", "&solver robin_operator='constant', alpha=1e-12, tol=1e-10 /")):
            co, oo, ho = run(work, op, boxes, over)
            if check(co == 0, f"boxes: the {op} operator converges", oo[-300:]):
                with h5py.File(ho, "r") as a:
                    d = np.abs(a["/contact/normal_force"][...] - fm).max() / np.abs(fm).max()
                check(d <= 1e-8, f"boxes: the {op} operator = monolithic", f"{d:.2e}")

    # (4) bad input
    bad = [
        ("dim2depth", "&scene dimension=2 /\n" + boxes, "a variable of a box, in a 2D deck"),
        ("nodepth", boxes.replace("depth=1.0, nx=3, ny=3, nz=3,", "nx=3, ny=3,"), "gives no depth"),
        ("stress", "&scene plane='stress' /\n" + boxes, "plane strain, plane stress and axisymmetric bodies"),
        ("uz2d", deck2 + "&boundary body=2, group='bottom', uz=0.0 /\n", "uz = 0.0 in a 2D deck"),
        ("dim4", "&scene dimension=4 /\n" + boxes, "must be 2 (plane or axisymmetric bodies) or 3"),
        ("gap", boxes + "&contact gap_radius=2.0 /\n", "the parabolic gap is a 2D profile"),
        ("t1", boxes + "&traction body=1, side='right', t0=0.0, 0.0, 0.0, t1=1.0, 0.0 /\n", "t1 (a traction varying"),
        ("floating6", boxes.replace("top='displacement'", "top='free'").replace(
            "&displacement body=1, side='top', u=2.0e-5, -1.0e-4, 0.0 /\n", "&traction body=1, side='top', t0=0.0, -1e6, 0.0 /\n"),
         "the contact cannot hold its translation along x"),
    ]
    for name, text, want in bad:
        code, out, h5 = run(work, name, text)
        check(code == 1 and want in out and "Backtrace" not in out and not os.path.exists(h5),
              f"bad input '{name}': exit 1, named, nothing written", out.strip().splitlines()[-1][:300] if out.strip() else "")
    code, out, h5 = run(work, "override", boxes, "&scene dimension=2 /")
    check(code == 1 and "cannot be changed by a command-line override" in out and not os.path.exists(h5),
          "an override changing the dimension: exit 1, named", out[-300:])

    # (6) a cube held only by contact, all six rigid motions free, pressed into a corner of three
    # walls (each clamped on its far side) by a pressure on its three other faces: by the cube's
    # equilibrium each wall's contact carries p A along its normal, exactly
    wall = "young=2.1e11, poisson=0.3, nx=3, ny=3, nz=3"
    corner = ("&body id=1, x0=0.0, y0=0.0, z0=0.0, width=1.0, height=1.0, depth=1.0, " + wall + " /\n"
              "&body id=2, x0=-0.5, y0=0.0, z0=0.0, width=0.5, height=1.0, depth=1.0, nx=2, ny=4, nz=4, left='clamped' /\n"
              "&body id=3, x0=0.0, y0=-0.5, z0=0.0, width=1.0, height=0.5, depth=1.0, nx=4, ny=2, nz=4, bottom='clamped' /\n"
              "&body id=4, x0=0.0, y0=0.0, z0=-0.5, width=1.0, height=1.0, depth=0.5, nx=4, ny=4, nz=2, front='clamped' /\n"
              "&contact bodies=1,2, groups='left','right' /\n&contact bodies=1,3, groups='bottom','top' /\n"
              "&contact bodies=1,4, groups='front','back' /\n"
              f"&traction body=1, side='right', t0={-p}, 0.0, 0.0 /\n&traction body=1, side='top', t0=0.0, {-p}, 0.0 /\n"
              f"&traction body=1, side='back', t0=0.0, 0.0, {-p} /\n&solver tol=1e-10 /\n")
    cc, oc, hc = run(work, "corner", corner)
    cm, om, hm = run(work, "corner_mono", corner, "&solver method='monolithic' /")
    check(cc == 0 and cm == 0, "a cube held only by contact (six free motions) pressed into a corner: Robin and "
          "monolithic converge", (oc + om)[-400:])
    if cc == 0 and cm == 0:
        with h5py.File(hc, "r") as a, h5py.File(hm, "r") as b:
            res = [a[f"/contact/pair_{q}/resultant_on_first_body"][...] for q in (1, 2, 3)]
            d = np.abs(a["/contact/normal_force"][...] - b["/contact/normal_force"][...]).max() / \
                np.abs(b["/contact/normal_force"][...]).max()
        want = [np.array([p, 0, 0]), np.array([0, p, 0]), np.array([0, 0, p])]
        err = max(np.abs(r - w).max() for r, w in zip(res, want)) / p
        check(err <= 1e-9, "corner: each wall's contact carries p A along its normal", f"{err:.2e}")
        check(d <= 1e-8, "corner: Robin = monolithic", f"{d:.2e}")
        check("free: 6" in oc or "6 free" in oc or "rigid motion amplitudes" in oc,
              "corner: the cube's six rigid motions are handled (SMALBE)")

    # (9) the shipped stack of three cubes on a plate (four bodies, three pairs, non-matching;
    # the cubes held along y by their contacts alone): every interface carries p A, every
    # contact node's pressure and every body's stress are the uniform exact ones
    stack = os.path.join(ROOT, "inputs", "cube_stack.nml")
    cs, os_, hs = run_deck_file(work, "stack", stack)
    cm, om, hm = run_deck_file(work, "stack_mono", stack, "&solver method='monolithic' /")
    check(cs == 0 and cm == 0, "cube stack: Robin and monolithic converge", (os_ + om)[-400:])
    if cs == 0 and cm == 0:
        with h5py.File(hs, "r") as a, h5py.File(hm, "r") as b:
            res = [a[f"/contact/pair_{q}/resultant_on_first_body"][...] for q in (1, 2, 3)]
            pres = a["/contact/pressure"][...]
            es = max(max(np.abs(nodal(a, k, "stress")[:, 1] + p).max(),
                         np.abs(nodal(a, k, "stress")[:, [0, 2, 3, 4, 5]]).max()) for k in (1, 2, 3, 4)) / p
            d = np.abs(a["/contact/normal_force"][...] - b["/contact/normal_force"][...]).max() / \
                np.abs(b["/contact/normal_force"][...]).max()
        err = max(np.abs(r - [0.0, -p, 0.0]).max() for r in res) / p
        check(err <= 1e-9, "cube stack: each of the three interfaces carries p A", f"{err:.2e}")
        check(len(pres) == 25 + 16 + 25 and np.abs(pres - p).max() <= 1e-9 * p,
              "cube stack: every contact node's pressure is p", f"{len(pres)} nodes, {np.abs(pres - p).max() / p:.2e}")
        check(es <= 1e-9, "cube stack: every body's stress is uniform (syy = -p, the others 0)", f"{es:.2e}")
        check(d <= 1e-8, "cube stack: Robin = monolithic", f"{d:.2e}")
        check(os_.count("is held only by contact (free: translation along y)") == 3,
              "cube stack: the three cubes are held only by contact")

    # (10) a long cylinder on a block in plane strain against the plane program: the 2D Hertz
    # mesh (half-disc on a block) extruded one prism layer deep into tetrahedra, uz = 0 on
    # both end faces of both bodies
    sys.path.insert(0, HERE)
    from msh_extrude import extrude
    gm = os.path.join(ROOT, "inputs", "gmsh")
    dz = 0.02
    extrude(os.path.join(gm, "hertz_h0.02.msh"), os.path.join(work, "cyl3d.msh"), dz)
    mat = "young=1000.0, poisson=0.3"
    plane = ("&scene plane='strain' /\n"
             f"&body id=1, mesh='{gm}/hertz_h0.02.msh', region='disc', {mat} /\n"
             f"&body id=2, mesh='{gm}/hertz_h0.02.msh', region='block', {mat} /\n"
             "&boundary body=1, group='disc_top', ux=0.0, uy=-0.01 /\n"
             "&boundary body=2, group='block_bottom', ux=0.0, uy=0.0 /\n"
             "&contact body1_group='disc_arc', body2_group='block_top' /\n&solver tol=1e-10 /\n")
    solid = ("&scene dimension=3 /\n"
             f"&body id=1, mesh='cyl3d.msh', region='disc', {mat} /\n"
             f"&body id=2, mesh='cyl3d.msh', region='block', {mat} /\n"
             "&boundary body=1, group='disc_top', ux=0.0, uy=-0.01, uz=0.0 /\n"
             "&boundary body=2, group='block_bottom', ux=0.0, uy=0.0, uz=0.0 /\n"
             + "".join(f"&boundary body={b}, group='{g}_{e}', uz=0.0 /\n"
                       for b, g in ((1, "disc"), (2, "block")) for e in ("front", "back"))
             + "&contact body1_group='disc_arc', body2_group='block_top' /\n&solver tol=1e-10 /\n")
    c2, o2, h2 = run(work, "cyl2d", plane)
    cf, of, hf = run(work, "cyl2d_fine", plane.replace("hertz_h0.02", "hertz_h0.01"))
    c3, o3, h3 = run(work, "cyl3d", solid)
    check(c2 == 0 and cf == 0 and c3 == 0, "cylinder: the 2D (h, h/2) and 3D runs converge", (o2 + of + o3)[-400:])
    if c2 == 0 and cf == 0 and c3 == 0:
        with h5py.File(h2, "r") as a, h5py.File(hf, "r") as f_, h5py.File(h3, "r") as b:
            P2, Pf = a["/contact/resultant_body1"][1], f_["/contact/resultant_body1"][1]
            P3 = b["/contact/resultant_body1"][1] / dz
            x2, p2 = a["/contact/x"][...], a["/contact/pressure"][...]
            x3, p3 = b["/contact/x"][...], b["/contact/pressure"][...]
        # the 3D pressure averaged over the two end faces' nodes at each x of the 2D slave nodes
        # (the slave nodes of both runs along the arc: the 3D slave has them on both end faces)
        near = [np.isclose(x3, x, atol=1e-12) for x in x2]
        both = np.array([k.sum() == 2 for k in near])
        check(both[p2 > 0].all() and both.sum() >= 2 * (p2 > 0).sum(), "cylinder: each 2D slave node in contact, "
              "and as many again around them, is a 3D slave node on both end faces", f"{both.sum()} of {len(x2)}")
        p3x = np.array([p3[k].mean() if k.any() else 0.0 for k in near])
        check(abs(P3 - P2) <= 2.0 * abs(P2 - Pf), "cylinder: the 3D force per length is the 2D one within the 2D "
              "discretization error (twice its change from h to h/2)",
              f"3D {P3:.6f}, 2D {P2:.6f} (h/2: {Pf:.6f}): {abs(P3 - P2) / P2:.2e} vs {abs(P2 - Pf) / P2:.2e}")
        check(np.array_equal(p3x > 0, p2 > 0), "cylinder: the same contact zone in 2D and 3D",
              f"{np.sort(x2[p2 > 0])} / {np.sort(x2[p3x > 0])}")
        check(np.abs(p3x - p2).max() <= 0.01 * p2.max(), "cylinder: the 3D pressure (averaged through the depth) "
              "is the 2D one within 1% of p0", f"{np.abs(p3x - p2).max() / p2.max():.2e}")

    # (8) threads, load steps and a restart on the shipped boxes
    deck = os.path.join(ROOT, "inputs", "boxes.nml")
    runs = {}
    for name, threads, over in (("t1", 1, ()), ("t2", 2, ()), ("steps", 2, ("&solver load_steps=3 /",)),
                                ("ckpt", 2, ("&solver max_outer=1 /",))):
        out = os.path.join(work, name + ".h5")
        extra = [f"&output file='{out}'" + (", checkpoint_every=1 /" if name == "ckpt" else " /")]
        p_ = subprocess.run([BIN, deck, *over, *extra], capture_output=True, text=True, env=solver_env(threads))
        runs[name] = (p_.returncode, out, p_.stdout)
    ck = os.path.join(work, "ckpt.h5.ckpt.h5")
    ck_written = os.path.exists(ck)          # (a converged restart removes it)
    p_ = subprocess.run([BIN, deck, "&solver max_outer=1 /", f"&output file='{os.path.join(work, 'ckpt.h5')}', "
                         "checkpoint_every=1 /", "&solver max_outer=800 /", "--restart", ck],
                        capture_output=True, text=True, env=solver_env(2))
    check(runs["t1"][0] == 0 and runs["t2"][0] == 0, "boxes: 1 and 2 threads converge")
    if runs["t1"][0] == 0 and runs["t2"][0] == 0:
        with h5py.File(runs["t1"][1], "r") as a, h5py.File(runs["t2"][1], "r") as b:
            diff = []
            a.visititems(lambda n, o: diff.append(n) if isinstance(o, h5py.Dataset) and n not in
                         ("history/wall_s", "input_deck") and not np.array_equal(o[...], b[n][...]) else None)
        check(not diff, "boxes: 1 and 2 threads give the same result file bit for bit", f"{diff[:4]}")
        with h5py.File(runs["t1"][1], "r") as a:
            ref = a["/contact/normal_force"][...]
        if check(runs["steps"][0] == 0, "boxes in 3 load steps: converged"):
            with h5py.File(runs["steps"][1], "r") as a:
                sums = [a[f"/steps/step_{k}/contact/normal_force"][...].sum() for k in (1, 2, 3)]
                last = a["/contact/normal_force"][...]
            e = max(abs(sums[k] - (k + 1) * p / 3) for k in range(3)) / p
            d = np.abs(last - ref).max() / np.abs(ref).max()
            check(e <= 1e-9 and d <= 1e-10, "boxes in 3 load steps: each step carries its third of p A, the last "
                  "the one-step forces", f"{e:.1e}, {d:.1e}")
        if check(runs["ckpt"][0] == 2 and ck_written and p_.returncode == 0,
                 "boxes: a checkpoint after one outer iteration (exit 2: max_outer), and the restart converges", p_.stderr[-300:]):
            with h5py.File(os.path.join(work, "ckpt.h5"), "r") as a:
                d = np.abs(a["/contact/normal_force"][...] - ref).max() / np.abs(ref).max()
                outer = int(a.attrs["outer_iterations"])
            with h5py.File(runs["t1"][1], "r") as a:
                outer_ref = int(a.attrs["outer_iterations"])
            check(d <= 1e-12 and outer == outer_ref, "boxes: the restart = the uninterrupted run (forces, outer count)",
                  f"{d:.1e}, outer {outer} / {outer_ref}")

    # (7) the memory check, before assembly: a 40^3 box against a 200 MiB limit
    big = boxes.replace("nx=4, ny=3, nz=4", "nx=40, ny=40, nz=40")
    env = dict(ENV)
    env["ROBIN_MEMORY_LIMIT_MB"] = "200"
    code, out, h5 = run_text(BIN, work, "budget", big, env=env)
    check(code == 1 and "needs about" in out and "(its DOFs)^1.4" in out and "phase: assembly" not in out
          and not os.path.exists(h5), "a 40^3 box beyond a 200 MiB limit: exit 1 before assembly, the estimate and "
          "the remedies named", out.strip().splitlines()[-1][:300] if out.strip() else "")
finally:
    shutil.rmtree(work, ignore_errors=True)

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
