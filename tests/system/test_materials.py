#!/usr/bin/python3
"""Materials, whole program (run by `make check`; meshes and decks written by the test in a
temporary folder, no gmsh needed). References are closed forms of statics.

(1) A bimaterial bar pressed end-on, plane stress: body 1 is the bar [0, 2] x [0, 0.5] of a
    mesh file, its left half steel (`&body material='steel'`, E = 2e11, nu = 0.3), its right
    half the region 'soft' (`&region`) of an orthotropic material with its axis 1 along x
    (E1 = 1e11, nu12 = 0.15: the same nu/E across, so the stress stays uniform); body 2 a
    rectangle (young = 1e11) pressing on its right end with a pressure t = 1e6 on its far side,
    both on rollers below, the bar on a roller at x = 0. The exact solution is piecewise
    linear: sxx = -t everywhere, ux = -t x/2e11 in the steel, -t (1/2e11 + (x - 1)/1e11) in the
    soft half; every node of the bar within 1e-10 of the largest ux, every nodal sxx within
    1e-9 t, the contact force t H = 5e5 N/m to 1e-10;
    the same with the soft half's material turned by 90 degrees (`angle=90` on the &region,
    E1 = 5e10, E2 = 1e11, nu12 = 0.075: along x it is E2 = 1e11 with nu21 = 0.15): the same
    displacements to 1e-10;
    the same with an anisotropic soft half given by its plane-stress stiffness (c11 .. c66,
    the inverse of that orthotropic compliance): the same displacements to 1e-10;
(2) the effective deck printed by the run reads back to the same result, bit for bit;
(3) bad input, exit 1, one message naming the deck and the group's line, nothing written:
    a material named twice, a &region named twice, a &region on a rectangle, a &region whose
    name is no physical surface of the body's cells (its surfaces listed), a material= naming
    no &material, constants of two kinds, Poisson's ratios beyond positive definiteness (its
    eigenvalue named), plane strain without e3, material= with young on one &body, a cell in
    two regions of different materials, an override of density on a body of a material (it
    would silently replace the material), a material's modulus beyond double precision's range
    (the budget's check of the stiffness, on the materials' moduli);
(4) the shipped inputs/coated_punch.nml (a flat punch on an aluminium block with a titanium
    nitride coating, the coating a region of the block's mesh): Robin = monolithic to 1e-8 of
    the largest nodal force, both carry the 3e5 N/m applied; the coating matters: without its
    &region (all aluminium) the punch sinks deeper, its mean displacement larger by more than 1%.
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
from rc_run import run_solver, run_text, solver_env  # noqa: E402
from msh_bar import write_bar  # noqa: E402

import h5py  # noqa: E402
import numpy as np  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
ENV = solver_env(1)
check = Checks()

L, H, NX, NY = 1.0, 0.5, 8, 3      # each half L x H, NX x NY cells
T = 1.0e6



def bar_deck(soft, region_extra="", body1_extra="material='steel'", materials_extra=""):
    return "\n".join([
        "&scene plane='stress' /",
        "&material name='steel', young=2.0e11, poisson=0.3 /",
        soft,
        materials_extra,
        f"&body id=1, mesh='bar.msh', region='bar', {body1_extra} /",
        f"&region body=1, name='soft', material='soft'{region_extra} /",
        f"&body id=2, x0={2 * L}, y0=0.0, width=0.5, height={H}, nx=2, ny={NY}, young=1.0e11, poisson=0.15, "
        "bottom='roller' /",
        f"&traction body=2, side='right', t0={-T}, 0.0 /",
        "&boundary body=1, group='bar_left', ux=0.0 /",
        "&boundary body=1, group='bar_bottom', uy=0.0 /",
        "&contact bodies=1,2, groups='bar_right','left' /",
    ]) + "\n"


def run(work, name, text, *over):
    return run_text(BIN, work, name, text, *over, env=ENV)


def exact_ux(x):
    return np.where(x <= L, -T * x / 2e11, -T * (L / 2e11 + (x - L) / 1e11))


work = tempfile.mkdtemp(prefix="rc_materials_")
try:
    write_bar(os.path.join(work, "bar.msh"), NX, NY)
    ortho0 = "&material name='soft', e1=1.0e11, e2=4.0e10, nu12=0.15, g12=3.0e10 /"
    ortho90 = "&material name='soft', e1=5.0e10, e2=1.0e11, nu12=0.075, g12=3.0e10 /"
    # the anisotropic form of ortho0: the inverse of its plane-stress compliance
    S = np.array([[1 / 1e11, -0.15 / 1e11, 0], [-0.15 / 1e11, 1 / 4e10, 0], [0, 0, 1 / 3e10]])
    C = np.linalg.inv(S)
    aniso = (f"&material name='soft', c11={C[0, 0]!r}, c12={C[0, 1]!r}, c22={C[1, 1]!r}, "
             f"c66={C[2, 2]!r} /")
    first = None
    for label, soft, extra in [("orthotropic, axis 1 along x", ortho0, ""),
                               ("orthotropic turned by 90 degrees", ortho90, ", angle=90.0"),
                               ("anisotropic (plane-stress stiffness)", aniso, "")]:
        code, out, h5 = run(work, "bar", bar_deck(soft, extra))
        check(code == 0, f"bimaterial bar, {label}: converged", "" if code == 0 else out[-400:])
        if code != 0:
            continue
        with h5py.File(h5, "r") as f:
            xy = f["/body1/coordinates"][...]
            u = f["/body1/displacement"][...]
            s = f["/body1/stress"][...]
            fn = f["/contact/normal_force"][...]
        if xy.shape[0] != 2:
            xy, u, s = xy.T, u.T, s.T
        ux = exact_ux(xy[0])
        err = np.max(np.abs(u[0] - ux)) / np.max(np.abs(ux))
        check(err <= 1e-10, f"bimaterial bar, {label}: ux piecewise linear, exact (rel)", f"{err:.2e}")
        serr = np.max(np.abs(s[0] + T)) / T
        check(serr <= 1e-9, f"bimaterial bar, {label}: sxx = -t at every node (rel)", f"{serr:.2e}")
        ferr = abs(np.sum(fn) - T * H) / (T * H)
        check(ferr <= 1e-10, f"bimaterial bar, {label}: the contact carries t H = 5e5 N/m (rel)", f"{ferr:.2e}")
        if first is None:
            first = (out, h5)

    # (2) the effective deck reads back to the same result, bit for bit
    code, out, h5 = run(work, "eff1", bar_deck(ortho90, ", angle=90.0"))
    m = re.search(r"effective input\n(.*?)\nphase:", out, re.S)
    eff = m.group(1) if m else ""
    check("&material name='soft'" in eff and "angle=90.0" in eff and "material='steel'" in eff
          and "young=2.0e11" not in eff.split("&body id=1")[1].split("/")[0],
          "the effective deck holds the materials, the region's angle and body 1's material (not its young)")
    eff = re.sub(r"file='[^']*'", "file='eff2.h5'", eff)
    code2, out2, h52 = run(work, "eff2", eff)
    same = code == 0 and code2 == 0
    if same:
        with h5py.File(h5, "r") as f1, h5py.File(h52, "r") as f2:
            same = np.array_equal(f1["/body1/displacement"][...], f2["/body1/displacement"][...])
    check(same, "the effective deck read back gives the same displacements, bit for bit", out2[-300:])

    # (3) bad input
    def bad(name, text, *expect, over=()):
        outfile = os.path.join(work, name + ".h5")
        if os.path.exists(outfile):
            os.remove(outfile)
        code, out, h5 = run(work, name, text, *over)
        nlines = len([ln for ln in out.strip().splitlines() if "error" in ln])
        ok = code == 1 and all(e in out for e in expect) and not os.path.exists(h5) and "Backtrace" not in out
        check(ok, f"bad input ({name}): exit 1, the message names {', '.join(expect)}, nothing written",
              f"exit {code}: {out.strip()[-400:]}")
        check(nlines == 1, f"bad input ({name}): one message", out.strip()[-400:])

    good = bar_deck(ortho0)
    bad("twice", good.replace("&body id=1", ortho0 + "\n&body id=1"), "name = 'soft'", "used twice", "line 3")
    bad("region_twice", good + "&region body=1, name='soft', material='steel' /\n", "region of body 1 twice",
        "line 6")
    bad("region_rect", good + "&region body=2, name='soft', material='steel' /\n", "a rectangle", "line 12")
    bad("region_unknown", good.replace("name='soft', material='soft'", "name='coat', material='soft'"),
        "no physical surface 'coat'", "'soft'", "line 6")
    bad("no_material", good.replace("material='steel'", "material='iron'"), "'iron'", "names no &material",
        "the materials are 'steel', 'soft'")
    bad("two_kinds", good.replace("g12=3.0e10", "g12=3.0e10, young=1e9"), "two kinds", "isotropic (young)",
        "orthotropic (e1)", "two_kinds.nml:3:")
    bad("not_pd", good.replace("nu12=0.15", "nu12=2.0"), "not positive definite", "eigenvalue", "line 3")
    bad("strain_no_e3", good.replace("plane='stress'", "plane='strain'"), "plane strain", "e3", "line 3")
    bad("material_and_young", good.replace("material='steel'", "material='steel', young=1e9"),
        "young = 1e9", "material = 'steel'", "material_and_young.nml:5:")
    bad("override_density", good, "density", "material = 'steel'", "change the material",
        over=("&body id=1, density=2700.0 /",))
    bad("huge_modulus", good.replace("young=2.0e11, poisson=0.3 /", "young=1.0e300, poisson=0.3 /"),
        "huge_modulus.nml:2: in group &material: young = 1.0e300 is outside", "rescale the units")
    # young within its range, the plane-stress stiffness E/(1 - nu^2) beyond it
    bad("huge_stiffness", good.replace("young=2.0e11, poisson=0.3 /", "young=1.3e148, poisson=0.3 /"),
        "its materials' moduli", "outside", "rescale the units")
    write_bar(os.path.join(work, "bar2.msh"), NX, NY, extra_region=True)
    bad("two_regions", good.replace("bar.msh", "bar2.msh") + "&region body=1, name='strip', material='steel' /\n",
        "in region 'soft' and in region 'strip'", "of different materials")

    # (4) the shipped coated punch: Robin = monolithic, and the coating matters
    deck = os.path.join(ROOT, "inputs", "coated_punch.nml")
    runs = {}
    for label, over in [("robin", ()), ("monolithic", ("&solver method='monolithic' /",)),
                        ("uncoated", ("&region body=1, name='coating', material='aluminium' /",))]:
        h5 = os.path.join(work, f"cp_{label}.h5")
        p, _ = run_solver(BIN, deck, *over, f"&output file='{h5}' /", cwd=work, env=ENV, timeout=300)
        check(p.returncode == 0, f"coated punch, {label}: converged", "" if p.returncode == 0 else
              (p.stdout + p.stderr)[-400:])
        if p.returncode == 0:
            with h5py.File(h5, "r") as f:
                runs[label] = (f["/contact/normal_force"][...], f["/body2/displacement"][...])
    if len(runs) == 3:
        fr, fm = runs["robin"][0], runs["monolithic"][0]
        d = np.max(np.abs(fr - fm)) / np.max(np.abs(fm))
        check(d <= 1e-8, "coated punch: Robin = monolithic (max nodal force difference / max force)", f"{d:.2e}")
        check(abs(np.sum(fr) - 3e5) <= 1e-9 * 3e5 and abs(np.sum(fm) - 3e5) <= 1e-9 * 3e5,
              "coated punch: both carry the applied 1e8 Pa x 3 mm = 3e5 N/m", f"{np.sum(fr):.6e}")
        u_c, u_a = runs["robin"][1], runs["uncoated"][1]
        uy = lambda u: np.mean(u[1] if u.shape[0] == 2 else u[:, 1])  # noqa: E731
        rel = (uy(u_a) - uy(u_c)) / abs(uy(u_c))
        check(rel < -0.01, "coated punch: without the coating the punch sinks deeper (mean uy lower by > 1%)",
              f"{rel:+.3%}")
finally:
    shutil.rmtree(work, ignore_errors=True)

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
