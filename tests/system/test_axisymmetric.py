#!/usr/bin/python3
"""Axisymmetric bodies, whole program (run by `make check`; decks written by the test in a
temporary folder, the sphere's mesh shipped). References are closed forms of elasticity.

(1) A thick cylinder under internal pressure (Lame): two tubes a = 0.1 < b = 0.15 < c = 0.2,
    height 0.05, in contact at r = b, pressure 1e8 inside, rollers uz = 0 top and bottom (the
    plane strain of a long cylinder): the pair is one cylinder a..c, ur = (1 + nu)/E ((1 - 2 nu)
    A r + A c^2/r), A = p a^2/(c^2 - a^2). Q1 on 2, 4, 8, 16 cells across each tube: the largest
    nodal error falls by about 4 per halving (observed order in [1.8, 2.2] on the last two),
    below 2e-4 of the largest ur on the finest; the contact force per radian is q b H (q the
    Lame pressure at b) within 1e-4; uz = 0 to rounding.
(2) A solid shaft shrink-fitted in a hub (overlap='interference', radial interference 1e-3 b,
    the shaft's nodes on the axis with ur = 0, rollers top and bottom): the contact force per
    radian over b H is Lame's pressure p = E' delta (c^2 - b^2)/(2 b c^2) within 0.5% (steel in
    steel) and, with an aluminium hub, delta = p b [((c^2 + b^2)/(c^2 - b^2) + nu_h')/E_h' +
    (1 - nu_s')/E_s'] (E' = E/(1 - nu^2), nu' = nu/(1 - nu)) within 0.5%; Robin = monolithic to
    1e-8.
(3) Hertz, a sphere on a flat (inputs/sphere_flat.nml, h = 0.01): with P = 2 pi x the force
    per radian, the contact radius a = (3 P R/(4 E*))^(1/3) and the peak pressure p0 = 3 P /
    (2 pi a^2), each within 1% of the Hertz shape fitted to the nodal pressures; the bodies
    balance along the axis (the `reaction:` lines) to 1e-9.
    With Coulomb friction (mu = 0.3) the harmonic Robin operator stalls (the tangential row at
    the axis, where ur = 0 on both bodies, is left free by the equations); the run says so,
    the Steklov operator goes on from its iterate, and the forces are the monolithic ones to
    1e-6.
(4) A hollow ring held only by contact: the only rigid motion a body of revolution has is a
    translation along its axis (y), and the run names it.
(5) Bad input, exit 1, one message, nothing written: a rectangle at x0 < 0, a mesh with a node
    at x < 0, an anisotropic material without c33 (the hoop strain needs it), a support that
    prescribes ux != 0 on the axis; the result file's forces are labelled per radian.
"""
import math
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

import h5py  # noqa: E402
import numpy as np  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
ENV = solver_env(1)
check = Checks()


def run(work, name, text, *over):
    return run_text(BIN, work, name, text, *over, env=ENV)


def nodal(f, b, name):
    v = f[f"/body{b}/{name}"][...]
    return v if v.shape[0] == 2 else v.T


work = tempfile.mkdtemp(prefix="rc_axisym_")
try:
    # (1) Lame
    a, b, c, H, p, E, nu = 0.1, 0.15, 0.2, 0.05, 1e8, 2.1e11, 0.3
    A = p * a * a / (c * c - a * a)
    errs = []
    for n in (2, 4, 8, 16):
        deck = (f"&scene plane='axisymmetric' /\n"
                f"&body id=1, x0={a}, y0=0.0, width={b - a}, height={H}, nx={n}, ny={max(1, n // 2)}, "
                "right='contact', bottom='roller', top='roller' /\n"
                f"&body id=2, x0={b}, y0=0.0, width={c - b}, height={H}, nx={n}, ny={max(1, n // 2)}, "
                "left='contact', bottom='roller', top='roller' /\n"
                f"&traction body=1, side='left', t0={p}, 0.0 /\n")
        code, out, h5 = run(work, f"lame{n}", deck)
        check(code == 0, f"Lame, {n} cells across: converged", "" if code == 0 else out[-400:])
        if code != 0:
            continue
        worst, uz = 0.0, 0.0
        with h5py.File(h5, "r") as f:
            for bd in (1, 2):
                xy, u = nodal(f, bd, "coordinates"), nodal(f, bd, "displacement")
                ur = (1 + nu) / E * ((1 - 2 * nu) * A * xy[0] + A * c * c / xy[0])
                worst = max(worst, np.max(np.abs(u[0] - ur)))
                uz = max(uz, np.max(np.abs(u[1])))
            fn = f["/contact/normal_force"][...]
        umax = (1 + nu) / E * ((1 - 2 * nu) * A * a + A * c * c / a)
        errs.append(worst / umax)
        check(uz <= 1e-12 * umax, f"Lame, {n} cells: uz = 0 (rollers, no axial load)", f"{uz / umax:.1e}")
        if n == 16:
            q = A * (c * c / (b * b) - 1)
            ferr = abs(np.sum(fn) / (q * b * H) - 1)
            check(ferr <= 1e-4, "Lame, 16 cells: the contact force per radian is q b H", f"{ferr:.2e}")
    if len(errs) == 4:
        orders = [math.log2(errs[k] / errs[k + 1]) for k in range(3)]
        check(all(1.8 <= o <= 2.2 for o in orders[1:]) and errs[-1] <= 2e-4,
              "Lame: ur's largest nodal error falls at order 2 (2, 4, 8, 16 cells), below 2e-4 on 16",
              "errors " + ", ".join(f"{e:.2e}" for e in errs) + "; orders " + ", ".join(f"{o:.2f}" for o in orders))

    # (2) shaft in hub
    b, c, H, d = 0.05, 0.1, 0.02, 5e-5
    for hub, Eh, nuh in (("steel", 2.1e11, 0.3), ("aluminium", 7.0e10, 0.33)):
        Es, nus = 2.1e11, 0.3
        Ep = lambda E_, n_: E_ / (1 - n_ * n_)  # noqa: E731
        np_ = lambda n_: n_ / (1 - n_)  # noqa: E731
        pex = d / (b * (((c * c + b * b) / (c * c - b * b) + np_(nuh)) / Ep(Eh, nuh) + (1 - np_(nus)) / Ep(Es, nus)))
        deck = ("&scene plane='axisymmetric' /\n"
                f"&body id=1, x0=0.0, y0=0.0, width={b + d}, height={H}, nx=32, ny=8, right='contact', "
                f"bottom='roller', top='roller', young={Es}, poisson={nus} /\n"
                f"&body id=2, x0={b}, y0=0.0, width={c - b}, height={H}, nx=32, ny=8, left='contact', "
                f"bottom='roller', top='roller', young={Eh}, poisson={nuh} /\n"
                "&contact overlap='interference' /\n")
        forces = {}
        for method in ("robin", "monolithic"):
            code, out, h5 = run(work, f"fit_{hub}_{method}", deck, f"&solver method='{method}' /")
            check(code == 0, f"shaft in a {hub} hub, {method}: converged", "" if code == 0 else out[-400:])
            if code == 0:
                with h5py.File(h5, "r") as f:
                    forces[method] = f["/contact/normal_force"][...]
        if len(forces) == 2:
            pr = np.sum(forces["robin"]) / (b * H)
            check(abs(pr / pex - 1) <= 5e-3, f"shaft in a {hub} hub: the contact pressure is Lame's {pex:.4e} Pa "
                  "within 0.5%", f"{pr:.4e} ({pr / pex - 1:+.3%})")
            dd = np.max(np.abs(forces["robin"] - forces["monolithic"])) / np.max(np.abs(forces["monolithic"]))
            check(dd <= 1e-8, f"shaft in a {hub} hub: Robin = monolithic", f"{dd:.1e}")

    # (3) Hertz: sphere on a flat
    E, nu, R = 1000.0, 0.3, 1.0
    Estar = E / (2 * (1 - nu * nu))
    h5 = os.path.join(work, "sphere.h5")
    p_, _ = run_solver(BIN, os.path.join(ROOT, "inputs", "sphere_flat.nml"), f"&output file='{h5}' /", cwd=work,
                       env=ENV, timeout=300)
    out = p_.stdout + p_.stderr
    check(p_.returncode == 0, "sphere on a flat: converged", "" if p_.returncode == 0 else out[-400:])
    if p_.returncode == 0:
        with h5py.File(h5, "r") as f:
            x, pn = f["/contact/x"][...], f["/contact/pressure"][...]
            res = f["/contact/resultant_body1"][...]
        P = 2 * math.pi * abs(res[1])
        a_h = (3 * P * R / (4 * Estar)) ** (1 / 3)
        p0_h = 3 * P / (2 * math.pi * a_h * a_h)
        on = pn > 0
        cf, *_ = np.linalg.lstsq(np.vstack([np.ones(on.sum()), x[on] ** 2]).T, pn[on] ** 2, rcond=None)
        p0_f, a_f = math.sqrt(cf[0]), math.sqrt(-cf[0] / cf[1])
        check(abs(a_f / a_h - 1) <= 0.01, "sphere on a flat: contact radius a = (3PR/(4E*))^(1/3) within 1%",
              f"fit {a_f:.5f}, Hertz {a_h:.5f} ({a_f / a_h - 1:+.2%})")
        check(abs(p0_f / p0_h - 1) <= 0.01, "sphere on a flat: peak pressure p0 = 3P/(2 pi a^2) within 1%",
              f"fit {p0_f:.4f}, Hertz {p0_h:.4f} ({p0_f / p0_h - 1:+.2%})")
        bal = [float(m) for m in re.findall(r"^reaction: .* balance=(\S+)", out, re.M)]
        check(len(bal) == 2 and max(bal) <= 1e-9, "sphere on a flat: both bodies balance along the axis",
              str(bal))

    # (3b) Coulomb friction on the sphere: the harmonic operator's stall, then Steklov
    fr = {}
    for method in ("robin", "monolithic"):
        h5 = os.path.join(work, f"coulomb_{method}.h5")
        p_, _ = run_solver(BIN, os.path.join(ROOT, "inputs", "sphere_flat.nml"),
                           "&contact friction='coulomb', mu=0.3 /", f"&solver method='{method}' /",
                           f"&output file='{h5}' /", cwd=work, env=ENV, timeout=300)
        if method == "robin":
            check(p_.returncode == 0 and "robin: the harmonic operator stalled" in p_.stdout
                  and "the steklov operator goes on" in p_.stdout,
                  "sphere with Coulomb friction: the harmonic stall is said, the Steklov operator converges",
                  (p_.stdout + p_.stderr)[-400:])
        if p_.returncode == 0:
            with h5py.File(h5, "r") as f:
                fr[method] = f["/contact/normal_force"][...]
    if len(fr) == 2:
        dd = np.max(np.abs(fr["robin"] - fr["monolithic"])) / np.max(np.abs(fr["monolithic"]))
        check(dd <= 1e-6, "sphere with Coulomb friction: Robin = monolithic", f"{dd:.1e}")

    # (4) a hollow ring held only by contact: its one rigid motion is along the axis
    deck = ("&scene plane='axisymmetric' /\n"
            "&body id=1, x0=0.5, y0=0.0, width=0.5, height=0.25, nx=4, ny=2, bottom='contact', left='roller' /\n"
            "&body id=2, x0=0.5, y0=-0.25, width=0.5, height=0.25, nx=4, ny=2, top='contact', bottom='clamped' /\n"
            "&traction body=1, side='top', t0=0.0, -1.0e6 /\n")
    code, out, h5 = run(work, "ring", deck)
    check(code == 0 and re.search(r"floating: body 1 .*\(free: translation along y\)", out) is not None,
          "a ring held only by contact (a roller on its bore): free along the axis only, named", out[-600:])
    deck2 = deck.replace(", left='roller'", "")
    code, out, h5 = run(work, "ring2", deck2)
    check(code == 0 and re.search(r"floating: body 1 .*\(free: translation along y\)", out) is not None,
          "a ring without any support: still free along the axis only (ur and a rotation strain the hoop)",
          out[-600:])

    # (5) bad input
    code, out, h5 = run(work, "neg", deck.replace("x0=0.5, y0=-0.25", "x0=-0.1, y0=-0.25"))
    check(code == 1 and "x0 = -0.1" in out and "below the axis" in out and not os.path.exists(h5),
          "a rectangle at x0 < 0: exit 1, named, nothing written", out[-300:])
    msh = os.path.join(work, "left.msh")
    with open(os.path.join(ROOT, "inputs", "gmsh", "sphere_flat_h0.02.msh")) as f:
        text = f.read()
    with open(msh, "w") as f:   # the whole file moved left by 0.5: the sphere crosses the axis
        lines = text.split("\n")
        i0, i1 = lines.index("$Nodes"), lines.index("$EndNodes")
        for i in range(i0 + 2, i1):
            parts = lines[i].split()
            if len(parts) == 3:
                lines[i] = f"{float(parts[0]) - 0.5!r} {parts[1]} {parts[2]}"
        f.write("\n".join(lines))
    code, out, h5 = run(work, "negmsh", open(os.path.join(ROOT, "inputs", "sphere_flat.nml")).read()
                        .replace("gmsh/sphere_flat_h0.01.msh", msh))
    check(code == 1 and "below the axis" in out and not os.path.exists(h5),
          "a mesh with nodes at x < 0: exit 1, named, nothing written", out[-300:])
    lame2 = ("&scene plane='axisymmetric' /\n"
             "&material name='a', c11=2.8e11, c12=1.2e11, c22=2.8e11, c66=8.1e10, c13=1.2e11, c23=1.2e11 /\n"
             "&body id=1, x0=0.1, y0=0.0, width=0.05, height=0.05, nx=4, ny=2, right='contact', bottom='roller', "
             "top='roller', material='a' /\n"
             "&body id=2, x0=0.15, y0=0.0, width=0.05, height=0.05, nx=4, ny=2, left='contact', bottom='roller', "
             "top='roller' /\n&traction body=1, side='left', t0=1e8, 0.0 /\n")
    code, out, h5 = run(work, "noc33", lame2)
    check(code == 1 and "c33" in out and "hoop" in out and not os.path.exists(h5),
          "an anisotropic material without c33 in an axisymmetric scene: exit 1, c33 named", out[-300:])
    code, out, h5 = run(work, "withc33", lame2.replace("c23=1.2e11 /", "c23=1.2e11, c33=2.8e11 /"))
    check(code == 0, "the same with c33: it runs", out[-300:])
    if code == 0:
        with h5py.File(h5, "r") as f:
            units = (f["/contact/normal_force"].attrs.get("units", b""), f["/contact/tributary_length"].attrs.get("units", b""))
            units = tuple(u.decode() if isinstance(u, bytes) else str(u) for u in units)
            per = f.attrs["forces_per"]
        check(units == ("N/rad", "m^2/rad") and per == "radian",
              "axisymmetric result file: forces in N/rad, tributary 'lengths' in m^2/rad, forces_per = radian",
              f"{units}, {per}")
    axis = ("&scene plane='axisymmetric' /\n"
            "&body id=1, x0=0.0, y0=0.0, width=0.5, height=0.25, nx=4, ny=2, bottom='contact' /\n"
            "&body id=2, x0=0.0, y0=-0.25, width=0.5, height=0.25, nx=4, ny=2, top='contact', bottom='clamped' /\n"
            "&boundary body=1, group='left', ux=0.001 /\n&traction body=1, side='top', t0=0.0, -1.0e6 /\n")
    code, out, h5 = run(work, "axisux", axis)
    check(code == 1 and "on the axis" in out and "ux = " in out and not os.path.exists(h5),
          "a support prescribing ux != 0 on the axis: exit 1, named", out[-300:])
finally:
    shutil.rmtree(work, ignore_errors=True)

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
