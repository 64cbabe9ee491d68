#!/usr/bin/python3
"""Cattaneo-Mindlin (tools/cattaneo_study.py has the scene and the theory; doc/verification.md,
"Friction"): two equal blocks in Hertz contact (a parabolic gap of radius 1), pressed by P, then
sheared by Q = mu P / 2 (Coulomb, mu = 0.3) with the upper block held along x by friction alone.
On three meshes (h = 0.02, 0.01, 0.005) the stick-zone half-width c (fitted to the shear) and
the shear traction (L2 away from the zone edges) against theory; on the finest one both within
2%, and Hertz's a and p0 within 1%; the observed orders are printed. The same with Q given by a
prescribed displacement of the upper block's top (the finest mesh), the same with P and Q in two
load stages (Coulomb on the slip increment; for equal materials P alone makes no slip, so it
equals the one-step result), and the Robin iteration = monolithic to 1e-6: harmonic on the
middle mesh, steklov and constant on the coarse one.
Then the same on a half-disc of radius 1 on a block 8 x 4 (`--scene disc`, the shipped meshes
inputs/gmsh/cattaneo_disc_a8/16/32.msh, a/R = 0.005), P in a first load stage and Q = mu P / 2 in
a second: Q as a traction on the disc's flat side, the disc held along x by friction alone, on
three meshes (a/h = 8, 16, 32), c and the shear within 2% on the finest; Q as a prescribed
displacement of the flat side, the finest mesh; Robin = monolithic (1e-6) on the middle one;
tools/plot_contact.py --mindlin --radius 1 draws the finest run with its Cattaneo-Mindlin curve.
"""
import os
import re
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
import cattaneo_study as cs  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
check = Checks()


def attempt(what, *args, run=cs.run, **kw):
    try:
        return run(BIN, *args, **kw)
    except Exception as e:  # a failed run fails its checks, the others still run
        check(False, f"{what}: the run ends converged", str(e)[-300:])
        return None


def plot(h5, png):
    """plot_contact --mindlin on a run whose gap is the disc's geometry (Hertz's radius given)."""
    p = subprocess.run([sys.executable, os.path.join(ROOT, "tools", "plot_contact.py"), h5, "--mindlin",
                        "--radius", "1", "-o", png], capture_output=True, text=True, timeout=300)
    m = re.search(r"Mindlin for \S+: .* err_c=(\S+) err_q=(\S+)", p.stdout)
    check(p.returncode == 0 and m is not None and os.path.isfile(png) and os.path.getsize(png) > 10000
          and float(m.group(1)) <= 0.02 and float(m.group(2)) <= 0.03,
          "plot_contact --mindlin --radius 1 draws the disc run with its Cattaneo-Mindlin curve "
          "(its err_c <= 0.02, err_q <= 0.03 over the whole zone)",
          (m.group(0) if m else (p.stdout + p.stderr).strip()[-300:]))


def force_study(prefix, ns, h_of, out, held, run=cs.run):
    """Q as a force on three meshes: the rows (h, run) and the checks on the finest mesh (c and
    the shear within 2% of theory, Hertz's a and p0 within 1%, the error falling with the mesh,
    the contact's tangential force = the applied Q)."""
    rows = []
    for n in ns:
        r = attempt(f"{prefix}force, n = {n}", n, "force", "monolithic", out, run=run)
        if r is not None:
            rows.append((h_of(n), r))
            print(f"INFO  {prefix}force, n = {n}: a/R {r['a'] / cs.R:.4f}, a {r['a_err']:+.2%}, p0 {r['p0_err']:+.2%}, "
                  f"c {r['c_err']:+.2%}, shear L2 {r['l2']:.2%}", flush=True)
    if len(rows) != len(ns):
        return rows
    hs = [h for h, _ in rows]
    print(f"INFO  {prefix}observed orders: c", [round(v, 2) for v in cs.orders(hs, [r["c_err"] for _, r in rows])],
          "shear", [round(v, 2) for v in cs.orders(hs, [r["l2"] for _, r in rows])], flush=True)
    fine = rows[-1][1]
    check(abs(fine["c_err"]) <= 0.02, f"{prefix}force, finest mesh: stick-zone half-width c within 2% of theory",
          f"{fine['c_err']:+.2%}")
    check(fine["l2"] <= 0.02, f"{prefix}force, finest mesh: shear traction within 2% (L2, away from the zone edges)",
          f"{fine['l2']:.2%}")
    check(abs(fine["a_err"]) <= 0.01 and abs(fine["p0_err"]) <= 0.01,
          f"{prefix}force, finest mesh: Hertz's a and p0 within 1%", f"{fine['a_err']:+.2%}, {fine['p0_err']:+.2%}")
    check(fine["l2"] < rows[0][1]["l2"], f"{prefix}force: the shear error falls with the mesh",
          f"{rows[0][1]['l2']:.2%} -> {fine['l2']:.2%}")
    check(abs(fine["Q"] - fine["Q_applied"]) <= 1e-9 * fine["Q_applied"],
          f"{prefix}force: the contact's tangential force is the applied Q (1e-9): friction alone holds the {held}",
          f"{fine['Q']!r} against {fine['Q_applied']!r}")
    return rows


def disc(tmp):
    """The half-disc on a block (see the docstring)."""
    rows = force_study("disc, ", (8, 16, 32), lambda n: cs.AC / n, os.path.join(tmp, "d"), "disc", run=cs.run_disc)
    if len(rows) == 3:
        fine = rows[-1][1]
        check(abs(fine["a"] / cs.R - 0.005) <= 0.0005, "disc: a/R = 0.005 (10%), the scene's size against the disc",
              f"{fine['a'] / cs.R:.5f}")
        plot(os.path.join(tmp, "d", "cmd_force_monolithic_32.h5"), os.path.join(tmp, "disc_contact.png"))
    d = attempt("disc, displacement, a/h = 32", 32, "displacement", "monolithic", os.path.join(tmp, "dd"),
                run=cs.run_disc)
    if d is not None:
        check(abs(d["c_err"]) <= 0.02 and d["l2"] <= 0.02,
              "disc, displacement, finest mesh: c and the shear within 2% of theory (with the measured P and Q)",
              f"c {d['c_err']:+.2%}, shear {d['l2']:.2%}, Q/(mu P) = {d['Q'] / (cs.MU * d['P']):.4f}")
    r = attempt("disc, robin, a/h = 16", 16, "force", "robin", os.path.join(tmp, "dr"), run=cs.run_disc)
    if r is not None and len(rows) == 3:
        m = rows[1][1]
        e = max(np.linalg.norm(r["lam"] - m["lam"]) / np.linalg.norm(m["lam"]),
                np.linalg.norm(r["lt"] - m["lt"]) / np.linalg.norm(m["lt"]))
        check(e <= 1e-6, "disc: Robin (harmonic) = monolithic (1e-6), a/h = 16", f"{e:.2e}")


def main():
    with tempfile.TemporaryDirectory(prefix="rc_cattaneo_") as tmp:
        rows = force_study("", (100, 200, 400), lambda n: cs.W / n, tmp, "block")
        g = attempt("stages, 400 cells", 400, "stages", "monolithic", os.path.join(tmp, "s"))
        if g is not None:
            check(abs(g["c_err"]) <= 0.02 and g["l2"] <= 0.02,
                  "stages (P in a first load stage, Q in a second), finest mesh: c and the shear within 2%",
                  f"c {g['c_err']:+.2%}, shear {g['l2']:.2%}")
            if len(rows) == 3:
                e = np.linalg.norm(g["lt"] - rows[-1][1]["lt"]) / np.linalg.norm(rows[-1][1]["lt"])
                check(e <= 1e-6, "stages = P and Q at once for equal materials (P alone makes no slip; 1e-6)",
                      f"{e:.2e}")
        # the top moved by the force run's mean displacement: the finest force run's, not run again
        fine = os.path.join(tmp, "cm_force_monolithic_400.h5") if len(rows) == 3 else None
        d = attempt("displacement, 400 cells", 400, "displacement", "monolithic", tmp, force_h5=fine)
        if d is not None:
            check(abs(d["c_err"]) <= 0.02 and d["l2"] <= 0.02,
                  "displacement, finest mesh: c and the shear within 2% of theory (with the measured P and Q)",
                  f"c {d['c_err']:+.2%}, shear {d['l2']:.2%}, Q/(mu P) = {d['Q'] / (cs.MU * d['P']):.4f}")
        # monolithic: the force study's run on the middle mesh
        m = next((res for h, res in rows if abs(h - cs.W / 200) < 1e-12), None)
        r = attempt("robin, 200 cells", 200, "force", "robin", os.path.join(tmp, "r"))
        if m is not None and r is not None:
            e = max(np.linalg.norm(r["lam"] - m["lam"]) / np.linalg.norm(m["lam"]),
                    np.linalg.norm(r["lt"] - m["lt"]) / np.linalg.norm(m["lt"]))
            check(e <= 1e-6, "Robin (harmonic) = monolithic (1e-6), 200 cells", f"{e:.2e}")
        # the other operators on the coarse mesh (constant: alpha about h / E = 2e-5, Anderson)
        if rows and abs(rows[0][0] - cs.W / 100) < 1e-12:
            m = rows[0][1]
            for op, line in (("steklov", "&solver robin_operator='steklov', delta=0.5, acceleration='none' /"),
                             ("constant", "&solver robin_operator='constant', alpha=3e-5, delta=0.5, "
                                          "acceleration='anderson' /")):
                r = attempt(f"robin ({op}), 100 cells", 100, "force", "robin", os.path.join(tmp, op), extra=[line])
                if r is not None:
                    e = max(np.linalg.norm(r["lam"] - m["lam"]) / np.linalg.norm(m["lam"]),
                            np.linalg.norm(r["lt"] - m["lt"]) / np.linalg.norm(m["lt"]))
                    check(e <= 1e-6, f"Robin ({op}) = monolithic (1e-6), 100 cells", f"{e:.2e}")
        disc(tmp)
    print(f"{len(check.failed)} failed")
    return 1 if check.failed else 0


if __name__ == "__main__":
    sys.exit(main())
