#!/usr/bin/env python3
"""Whole-program tests of general geometry (bodies from Gmsh files, conditions on named
groups, dual mortar on non-matching and curved contact surfaces), run by `make check`:

1. the Gmsh copy of the paper's scene (inputs/gmsh_paper.nml) gives the contact forces of the
   built-in 24x16 mesher (inputs/default.nml) to 1e-10, Robin and monolithic;
2. the contact patch test (inputs/patch.nml: triangles on quadrilaterals, non-matching): the
   pressure is uniform and equal to the uniaxial-strain value delta / (h1/M1 + h2/M2), an
   independent closed form, to 1e-8, monolithic and Robin (harmonic);
3. the non-matching paper scene (upper 24x16, lower 36x24): Robin = monolithic to 1e-6, and the
   total force within 0.5% of the matching 24x16 one (both discretise the same scene);
4. Hertz with real geometry (inputs/hertz.nml, h = 0.005 at the contact): half-width and peak
   pressure from a fit of the Hertz shape within 1% of Hertz's formulas for the computed force;
   on h = 0.01, Robin (harmonic) = monolithic to 1e-6;
5. a rectangle's sides are groups: the default scene with &boundary/&traction on 'left'/'top'
   and contact by groups gives the contact forces of the side-based deck to 1e-10;
6. bad input (exit 1, a message naming the file/group, no Fortran backtrace, no result file);
8. groups of nodes (inputs/gmsh/hertz_force_h0.04.msh): the disc held by ux = 0 on its axis (a
   curve inside it) and uy at its centre (a physical point) runs, and the result has those
   displacements; a point or an inside curve as a traction or contact group is bad input.
"""
import math
import os
import sys
import tempfile

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from rc_checks import Checks  # noqa: E402
from rc_results import read_lam  # noqa: E402
from rc_run import run_solver, solver_env  # noqa: E402
from hertz_study import hertz_fit  # noqa: E402

BIN = os.environ.get("BIN", "bin/robin_contact")
OUT = os.path.join(os.environ.get("BUILD", "build/release"), "test-out", "geometry")
os.makedirs(OUT, exist_ok=True)
check = Checks()


def run(deck, *over, name="run"):
    out = os.path.join(OUT, name + ".h5")
    if os.path.exists(out):
        os.remove(out)
    p, m = run_solver(BIN, deck, *over, f"&output file='{out}' /", env=solver_env("2"))
    return p, m, out


def rel(a, b):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(np.max(np.abs(b)), 1e-300))


MONO = "&solver method='monolithic' /"

# 1. Gmsh copy of the paper's scene = built-in mesher
for meth, over in (("robin", ()), ("monolithic", (MONO,))):
    pg, mg, og = run("inputs/gmsh_paper.nml", *over, name=f"gmsh_paper_{meth}")
    pd, md, od = run("inputs/default.nml", *over, name=f"default_{meth}")
    if check(pg.returncode == 0 and pd.returncode == 0, f"Gmsh paper scene and built-in ({meth}) exit 0",
             f"{pg.returncode} {pd.returncode} {pg.stderr[-200:]}"):
        lg, ld = read_lam(og), read_lam(od)
        e = rel(lg, ld) if lg.shape == ld.shape else float("inf")
        check(e <= 1e-10, f"Gmsh copy of the paper's scene = built-in 24x16 ({meth}) to 1e-10",
              f"{e:.2e}, m = {lg.size}")
        check(int(mg["outer"]) == int(md["outer"]), f"same outer count ({meth})", f"{mg['outer']} vs {md['outer']}")

# 2. contact patch test
E1, n1, E2, n2, delta, h1, h2 = 200.0, 0.3, 100.0, 0.25, 1e-3, 0.5, 1.0


def modulus(e, nu):
    return e * (1 - nu) / ((1 + nu) * (1 - 2 * nu))


p_exact = delta / (h1 / modulus(E1, n1) + h2 / modulus(E2, n2))
for meth, over in (("monolithic", (MONO,)), ("robin", ())):
    p, m, out = run("inputs/patch.nml", *over, name=f"patch_{meth}")
    if check(p.returncode == 0, f"patch test ({meth}) converges", f"exit {p.returncode} {p.stdout[-200:]}"):
        with h5py.File(out, "r") as f:
            pr = np.array(f["/contact/pressure"])
            x = np.array(f["/contact/x"])
        e = float(np.max(np.abs(pr / p_exact - 1)))
        check(e <= 1e-8, f"patch test ({meth}): uniform pressure = {p_exact:.10g} to 1e-8 at all {pr.size} "
              "slave nodes", f"max rel err {e:.2e}")
        check(pr.size >= 6 and x.min() == 0.0 and x.max() == 1.0, "patch test: the slave rows cover the line",
              f"{pr.size} rows, x in [{x.min()}, {x.max()}]")

# 2b. the patch test with a mixed body (triangles and quadrilaterals in the top block); its XDMF
mixed = ("&body id=1, mesh='gmsh/patch_mixed.msh' /", "&body id=2, mesh='gmsh/patch_mixed.msh' /")
for meth, over in (("monolithic", (MONO,)), ("robin", ())):
    p, m, out = run("inputs/patch.nml", *mixed, *over, name=f"patch_mixed_{meth}")
    if check(p.returncode == 0, f"patch test, mixed top body ({meth}) converges", f"exit {p.returncode}"):
        with h5py.File(out, "r") as f:
            pr = np.array(f["/contact/pressure"])
            etype = f["/body1"].attrs["element"]
            ncell = f["/body1/cells"].shape[0]
        e = float(np.max(np.abs(pr / p_exact - 1)))
        check(e <= 1e-8, f"patch test, mixed top body ({meth}): pressure exact to 1e-8", f"{e:.2e}")
        check(etype == "mixed", "mixed body: element attribute 'mixed'", str(etype))
        if meth == "monolithic":
            xd = open(out[:-3] + "_body1.xdmf").read()
            check('TopologyType="Mixed"' in xd, "mixed body: XDMF Mixed topology")
            import meshio  # noqa: E402
            mm_ = meshio.read(out[:-3] + "_body1.xdmf")
            kinds = sorted((c.type, len(c.data)) for c in mm_.cells)
            check(sum(n for _, n in kinds) == ncell and {k for k, _ in kinds} == {"triangle", "quad"},
                  "mixed body: meshio reads its triangles and quadrilaterals", str(kinds))

# 3. non-matching paper scene
nm = ("&body id=1, mesh='gmsh/paper_nonmatching_24_36.msh' /",
      "&body id=2, mesh='gmsh/paper_nonmatching_24_36.msh' /")
pr_, mr, orr = run("inputs/gmsh_paper.nml", *nm, "&solver robin_operator='harmonic', delta=0.5 /", name="nm_robin")
pm, mm, om = run("inputs/gmsh_paper.nml", *nm, MONO, name="nm_mono")
pd, md, od = run("inputs/default.nml", MONO, name="nm_matching")
if check(pr_.returncode == 0 and pm.returncode == 0, "non-matching paper scene: Robin and monolithic converge",
         f"{pr_.returncode} {pm.returncode}"):
    lr, lm, ld = read_lam(orr), read_lam(om), read_lam(od)
    e = rel(lr, lm)
    check(e <= 1e-6, "non-matching paper scene: Robin = monolithic to 1e-6", f"{e:.2e}")
    e = abs(lm.sum() / ld.sum() - 1)
    check(e <= 5e-3, "non-matching 24/36 total force within 0.5% of the matching 24x16 one",
          f"{lm.sum():.6e} vs {ld.sum():.6e}: {e:.2e}")
    check(int(mm["m"]) == 36, "non-matching: the finer lower surface is the slave (36 rows)", f"m = {mm['m']}")

# 3b. the shipped non-matching deck (steklov, delta 0.95) converges to the same forces
p, m, out = run("inputs/nonmatching.nml", name="nm_deck")
if check(p.returncode == 0, "inputs/nonmatching.nml converges (steklov, delta 0.95)", f"exit {p.returncode}"):
    e = rel(read_lam(out), read_lam(om))
    check(e <= 1e-6, "inputs/nonmatching.nml: Robin (steklov) = monolithic to 1e-6", f"{e:.2e}")

# 4. Hertz with real geometry
p, m, out = run("inputs/hertz.nml", MONO, name="hertz_mono")
if check(p.returncode == 0, "Hertz (h = 0.005) converges", f"exit {p.returncode}"):
    with h5py.File(out, "r") as f:
        x = np.array(f["/contact/x"])
        pres = np.array(f["/contact/pressure"])
        lam = np.array(f["/contact/normal_force"])
        nrm = np.array(f["/contact/normal"])
        E = float(f["/body1"].attrs["young"])
        nu = float(f["/body1"].attrs["poisson"])
    P = float(-np.sum(lam * nrm[1, :]))
    es = E / (2 * (1 - nu ** 2))
    ah = math.sqrt(4 * P / (math.pi * es))
    p0h = 2 * P / (math.pi * ah)
    a, p0, xc = hertz_fit(x, pres)
    check(abs(a / ah - 1) < 0.01, "Hertz: fitted half-width within 1% of sqrt(4PR/(pi E*))",
          f"a = {a:.5f}, Hertz {ah:.5f}, {abs(a / ah - 1):.2%}")
    check(abs(p0 / p0h - 1) < 0.01, "Hertz: fitted peak pressure within 1% of 2P/(pi a)",
          f"p0 = {p0:.4f}, Hertz {p0h:.4f}, {abs(p0 / p0h - 1):.2%}")
    check(abs(xc) < 0.01 * ah, "Hertz: the pressure is centred on the first contact point", f"xc = {xc:.2e}")
    check(np.all(nrm[1, pres > 0] < -0.99), "Hertz: the slave normals in contact point down (disc is the slave)")
h01 = ("&body id=1, mesh='gmsh/hertz_h0.01.msh' /", "&body id=2, mesh='gmsh/hertz_h0.01.msh' /")
pr_, _, orr = run("inputs/hertz.nml", *h01, name="hertz01_robin")
pm, _, om = run("inputs/hertz.nml", *h01, MONO, name="hertz01_mono")
if check(pr_.returncode == 0 and pm.returncode == 0, "Hertz h = 0.01: Robin (harmonic) and monolithic converge"):
    e = rel(read_lam(orr), read_lam(om))
    check(e <= 1e-6, "Hertz h = 0.01: Robin = monolithic to 1e-6", f"{e:.2e}")

# 5. a rectangle's sides as groups
groups = ("&body id=1, left='free', bottom='free' /", "&body id=2, left='free', top='free' /",
          "&boundary body=1, group='left', ux=0.0, uy=0.0 /", "&boundary body=2, group='left', ux=0.0, uy=0.0 /",
          "&contact body1_group='bottom', body2_group='top' /")
for meth, over in (("robin", ()), ("monolithic", (MONO,))):
    pg, _, og = run("inputs/default.nml", *groups, *over, name=f"rect_groups_{meth}")
    pd, _, od = run("inputs/default.nml", *over, name=f"rect_sides_{meth}")
    if check(pg.returncode == 0, f"rectangles with groups ({meth}) exit 0", pg.stderr[-300:]):
        e = rel(read_lam(og), read_lam(od))
        check(e <= 1e-10, f"rectangles: contact by groups (mortar) = by sides ({meth}) to 1e-10", f"{e:.2e}")

# 6. bad input
tmp = tempfile.mkdtemp(prefix="rc_geom_")
with open("inputs/gmsh/patch.msh") as f:
    patch = f.read()


def write(name, text):
    path = os.path.join(tmp, name)
    with open(path, "w") as f:
        f.write(text)
    return path


PATCH_DECK = open("inputs/patch.nml").read()


def deck_with(meshfile, extra=""):
    text = PATCH_DECK.replace("gmsh/patch.msh", meshfile) + extra
    return write("deck_" + os.path.basename(meshfile) + ".nml", text)


bad = [
    ("binary MSH", deck_with(write("bin.msh", patch.replace("4.1 0 8", "4.1 1 8", 1))), ["bin.msh", "binary"]),
    ("MSH 2.2", deck_with(write("v22.msh", patch.replace("4.1 0 8", "2.2 0 8", 1))), ["v22.msh", "2.2"]),
    ("unknown region", write("d1.nml", PATCH_DECK.replace("region = 'top'", "region = 'lid'")
                             .replace("gmsh/patch.msh", os.path.abspath("inputs/gmsh/patch.msh"))), ["lid"]),
    ("unknown &boundary group", write("d2.nml", PATCH_DECK.replace("group = 'top_top'", "group = 'roof'")
                                      .replace("gmsh/patch.msh", os.path.abspath("inputs/gmsh/patch.msh"))),
     ["roof", "top_top"]),
    ("group of the other body", write("d3.nml", PATCH_DECK.replace("group = 'top_left'", "group = 'bottom_left'", 1)
                                      .replace("gmsh/patch.msh", os.path.abspath("inputs/gmsh/patch.msh"))),
     ["bottom_left"]),
    ("unknown contact group", write("d4.nml", PATCH_DECK.replace("body2_group = 'bottom_top'",
                                                                 "body2_group = 'bottom_lid'")
                                    .replace("gmsh/patch.msh", os.path.abspath("inputs/gmsh/patch.msh"))),
     ["bottom_lid", "bottom_top"]),
    ("contact group facing nothing", write("d5.nml", PATCH_DECK.replace("body2_group = 'bottom_top'",
                                                                        "body2_group = 'bottom_bottom'")
                                           .replace("gmsh/patch.msh", os.path.abspath("inputs/gmsh/patch.msh"))),
     ["bottom_bottom"]),
    ("rectangle variable on a mesh body", write("d6.nml", PATCH_DECK.replace("region = 'top',", "region = 'top', nx = 4,")
                                                .replace("gmsh/patch.msh", os.path.abspath("inputs/gmsh/patch.msh"))),
     ["nx", "mesh"]),
    ("no support against rigid motion", write("d7.nml", PATCH_DECK.replace(
        "&boundary body = 2, group = 'bottom_bottom', uy = 0.0 /", "")
        .replace("gmsh/patch.msh", os.path.abspath("inputs/gmsh/patch.msh"))), ["body 2", "rigid motion"]),
    ("missing mesh file", deck_with("/nonexistent/part.msh"), ["part.msh"]),
]
# an initial overlap: the paper's rectangles with contact by groups, body 1 moved 0.05 into body 2
bad.append(("initial overlap", write("overlap.nml", open("inputs/default.nml").read()),
            ["overlap", "-5.000E-02"]))
OVERLAP = groups + ("&body id=1, y0=0.95 /",)
for k, (what, deck, words) in enumerate(bad):
    out = os.path.join(tmp, f"never{k}.h5")
    extra = OVERLAP if what == "initial overlap" else ()
    p, _ = run_solver(BIN, deck, *extra, f"&output file='{out}' /")
    text = p.stdout + p.stderr
    ok = p.returncode == 1 and all(w in text for w in words) and "Backtrace" not in text \
        and not os.path.exists(out)
    check(ok, f"bad input: {what}: exit 1, message names {words}, nothing written",
          f"exit {p.returncode}: {p.stderr.strip()[-260:]}")

# 7. the paper's operator on a singular master flexibility: the slave (the finer surface) has
# more rows than the coarser master has normal DOFs, F_master is singular, and the master's
# subproblem carries a proximal term (robin_operators `proximal_term`)
E2e, n2e = 200.0, 0.3
p_eq = delta / (h1 / modulus(E1, n1) + h2 / modulus(E2e, n2e))
EQ = (f"&body id=2, young={E2e}, poisson={n2e} /",)
STEK = "&solver robin_operator='steklov', delta=0.5, tol=1e-10 /"
pr_, mr, orr = run("inputs/patch.nml", *EQ, STEK, name="patch_eq_steklov")
pm, _, om_eq = run("inputs/patch.nml", *EQ, MONO, name="patch_eq_mono")
if check(pr_.returncode == 0 and pm.returncode == 0, "patch test, equal materials: Robin (steklov) and monolithic converge",
         f"exit {pr_.returncode} {pm.returncode}: {(pr_.stdout.strip().splitlines() or [''])[-1][-200:]}"):
    e = rel(read_lam(orr), read_lam(om_eq))
    check(e <= 1e-6, "patch test, equal materials: Robin (steklov) = monolithic to 1e-6", f"{e:.2e}")
    with h5py.File(orr, "r") as f:
        pr = np.array(f["/contact/pressure"])
    e = float(np.max(np.abs(pr / p_eq - 1)))
    check(e <= 1e-8, f"patch test (steklov): uniform pressure = {p_eq:.10g} to 1e-8 at all {pr.size} slave nodes",
          f"max rel err {e:.2e}")
pnm, _, onm = run("inputs/gmsh_paper.nml", *nm, MONO, name="nm_mono_7")
for op, over in (("steklov", "&solver robin_operator='steklov', delta=0.95 /"),
                 ("constant", "&solver robin_operator='constant', alpha=1e-13, delta=0.5 /")):
    pr_, mr, orr = run("inputs/gmsh_paper.nml", *nm, over, name=f"nm_{op}")
    if check(pr_.returncode == 0 and pnm.returncode == 0, f"non-matching paper scene: Robin ({op}) converges",
             f"exit {pr_.returncode} {pnm.returncode}: {(pr_.stdout.strip().splitlines() or [''])[-1][-200:]}"):
        e = rel(read_lam(orr), read_lam(onm))
        check(e <= 1e-6, f"non-matching paper scene: Robin ({op}) = monolithic to 1e-6",
              f"{e:.2e} ({mr['outer']} outer iterations)")

# 8. groups of nodes: a physical point and a curve inside the body hold the disc
HF_MESH = os.path.abspath("inputs/gmsh/hertz_force_h0.04.msh")
HF_DECK = write("hertz_force.nml", f"""&scene plane='strain' /
&body id=1, mesh='{HF_MESH}', region='disc', young=1000.0, poisson=0.3 /
&body id=2, mesh='{HF_MESH}', region='block', young=1000.0, poisson=0.3 /
&boundary body=1, group='disc_axis', ux=0.0 /
&boundary body=1, group='disc_centre', uy=-0.01 /
&traction body=1, group='disc_top', pressure=1.0 /
&boundary body=2, group='block_bottom', ux=0.0, uy=0.0 /
&contact body1_group='disc_arc', body2_group='block_top' /
&solver robin_operator='harmonic', delta=0.5, tol=1e-10 /
""")
p, _, ohf = run(HF_DECK, name="hertz_force_points")
if check(p.returncode == 0, "point groups: disc held by ux on its axis and uy at its centre runs", p.stderr[-300:]):
    with h5py.File(ohf, "r") as f:
        x = np.array(f["/body1/coordinates"])
        u = np.array(f["/body1/displacement"])
    axis = x[0] == 0
    centre = axis & (x[1] == 2)
    check(centre.sum() == 1 and abs(u[1, centre][0] + 0.01) < 1e-14 and np.all(u[0, axis] == 0)
          and axis.sum() > 10, "point groups: uy = -0.01 at disc_centre, ux = 0 on every disc_axis node",
          f"centre nodes {centre.sum()}, axis nodes {axis.sum()}")
for k, (what, over, words) in enumerate([
        ("traction on a physical point", "&traction body=1, group='disc_centre', pressure=1.0 /",
         ["'disc_centre' is a physical point", "traction"]),
        ("contact on a physical point", "&contact body1_group='disc_centre' /",
         ["'disc_centre' is a physical point", "contact"]),
        ("traction on a curve inside the body", "&traction body=1, group='disc_axis', pressure=1.0 /",
         ["'disc_axis' is a curve inside the body"]),
        ("a point of the other body", "&boundary body=2, group='disc_centre', uy=0.0 /",
         ["disc_centre", "physical points: disc_centre"])]):
    out = os.path.join(tmp, f"never_pt{k}.h5")
    p, _ = run_solver(BIN, HF_DECK, over, f"&output file='{out}' /")
    text = p.stdout + p.stderr
    check(p.returncode == 1 and all(w in text for w in words) and "Backtrace" not in text
          and not os.path.exists(out), f"bad input: {what}: exit 1, message names {words}, nothing written",
          f"exit {p.returncode}: {p.stderr.strip()[-260:]}")

if check.failed:
    print(f"test_geometry: {len(check.failed)} failed check(s)")
    sys.exit(1)
print("test_geometry: 0 failed check(s)")
