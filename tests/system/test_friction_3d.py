#!/usr/bin/python3
"""Friction between solid bodies (3D: a node's tangential force bounded by a disc), whole
program (run by `make check`; doc/verification.md, "Friction in space").

Two non-matching blocks (3 x 2 x 3 cells of six tetrahedra below, 4 x 2 x 4 hexahedra above,
poisson 0 so that a uniform state is exact with the lower block clamped below).

(1) mu = 0 and slip_bound = 0 are frictionless: the three-box stack gives bitwise the
    frictionless contact forces and outer counts.
(2) Frictional patch test, sticking: the upper block held only by contact (its six rigid
    motions free), loaded by (tau_x, -p, tau_z) on its top, |tau| = 0.2 p at 30 degrees from x,
    and by the shear its sides carry in the uniform state sigma_yy = -p, sigma_xy = tau_x,
    sigma_yz = tau_z (the lower block's sides too); Coulomb mu = 0.5: every node sticks, the
    pressure is p and the shear vector (tau_x, 0, tau_z) at every node to 1e-8, for the
    monolithic solve and the Robin iteration (harmonic; steklov; constant, alpha 2e-12 with
    Anderson), which equal each other to 1e-8.
(3) Sliding and isotropy: the upper block's top pressed down and moved along directions
    turned by 0, 15, 30 and 45 degrees about y (a prescribed displacement, on a lower block
    1000 times stiffer), Coulomb mu = 0.3: every node in contact slips (a corner may open:
    the shear's couple), |shear| = mu p at every node (1e-8), each node's force along its slip
    increment (1e-12), the contact's tangential resultant of length mu P in every direction
    (1e-8: the same sliding threshold; a box on the two tangential forces gives up to
    sqrt(2) mu P at 45 degrees) and along the push (1e-5 rad: the stiff block's surface moves
    a little across it); Robin (harmonic) = monolithic (1e-6) at 30 degrees. Tresca
    (slip_bound g): |shear| = g at every node, every node slips, Robin = monolithic (1e-8).
(4) Sliding threshold: the block of (2) pushed along 30 degrees by Q = 0.99 mu P sticks (held by
    friction alone, the tangential resultant Q to 1e-9); at Q = 1.01 mu P the run stops with
    exit 1, one message naming the body and the direction it would slide in, nothing written.
(6) Load history, steel pressed onto aluminium then moved sideways (Coulomb mu = 0.3, partial
    slip): in two stages against both at once the results differ (path dependence, > 1e-3), each
    equals the monolithic solution of its own history (1e-6); the slip increment of the second
    stage is not its slip; stopped at max_outer in the second stage and restarted from its
    checkpoint, bitwise the uninterrupted run.
(7) The same scene with one and two threads bitwise; mpirun -np 1, 2, 4 (MUMPS) = the serial
    run to 1e-10 (both to tol 1e-12; skipped without bin/robin_contact_mpi or mpirun).
(8) inputs/cattaneo_sphere.nml (a sphere pressed on a block then pulled sideways, a half model,
    on its shipped coarse mesh): Robin = monolithic (1e-6), the harmonic operator without a
    stall, no shear across the plane of symmetry, the pull held by the contact alone (1e-5),
    a stick zone inside a slipping ring (tools/cattaneo3d_study.py compares with Mindlin).
(5) The output of a frictional 3D pair: tangential force in the frame (2 components), as a
    vector, consistent with the tangents written beside it; shear magnitude; stick/slip counts
    and the vector resultant on the contact line; the contact surface's XDMF (read by meshio)
    with the shear's length, the force vector and the state (the stick zone).
"""
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from test_friction import (MONO, ROBIN as ROBIN_2D, ROOT, Run, check, converged, mpi_against_serial, refused,  # noqa: E402
                           rel, restart_in_second_stage)
from solid_decks import THREE_BOXES  # noqa: E402

ROBIN = "&solver robin_operator='harmonic', delta=0.5, stop='residual', tol=1e-11 /"
P = 1.0e6


def blocks(upper_extra, law, lower_young=2.1e11):
    """The two blocks: the lower one clamped below, the upper one on it."""
    return f"""&scene title='3D friction', dimension=3 /
&body id=1, x0=0.0, y0=0.0, z0=0.0, width=1.0, height=1.0, depth=1.0, nx=3, ny=2, nz=3, element='P1',
      young={lower_young}, poisson=0.0, bottom='clamped' /
&body id=2, x0=0.0, y0=1.0, z0=0.0, width=1.0, height=1.0, depth=1.0, nx=4, ny=2, nz=4, element='Q1',
      young=2.1e11, poisson=0.0 /
&contact bodies=1,2, groups='top','bottom', {law} /
{upper_extra}"""


def stick_deck(tx, tz, law="friction='coulomb', mu=0.5"):
    """(2): the uniform state's loads: (tx, -P, tz) on top, the sides' shear on both blocks."""
    loads = f"&traction body=2, side='top', t0={tx!r}, {-P}, {tz!r} /\n"
    for b in (1, 2):
        loads += (f"&traction body={b}, side='left', t0=0.0, {-tx!r}, 0.0 /\n"
                  f"&traction body={b}, side='right', t0=0.0, {tx!r}, 0.0 /\n"
                  f"&traction body={b}, side='front', t0=0.0, {-tz!r}, 0.0 /\n"
                  f"&traction body={b}, side='back', t0=0.0, {tz!r}, 0.0 /\n")
    return blocks(loads, law)


def slide_deck(deg, law):
    """(3): the upper block's top moved down by 1e-5 and by 1e-3 along deg degrees in the x-z
    plane (no tilt), on a lower block 1000 times stiffer (whose surface moves 1e-6 of the
    slip: every node slips along the push to that)."""
    d = 1.0e-3
    ux, uz = d * math.cos(math.radians(deg)), d * math.sin(math.radians(deg))
    return blocks(f"&boundary body=2, group='top', ux={ux!r}, uy=-1.0e-5, uz={uz!r} /\n", law, lower_young=2.1e14)


def pair(r):
    return r.pairs["pair_1"]


def shear_vectors(g):
    """(3, n) the shear of each node as a vector, from the tangential force and the area."""
    return g["tangential_force_xyz"].T / g["tributary_area"][None, :]


def zero_friction(tmp):
    base = Run(tmp, "zero_base", THREE_BOXES)
    for law in ("friction='coulomb', mu=0.0", "friction='tresca', slip_bound=0.0"):
        r = Run(tmp, "zero_" + law.split("'")[1], THREE_BOXES, f"&contact bodies=1,2, {law} /")
        what = f"three boxes, {law}"
        if not (converged(base, "three boxes, frictionless") and converged(r, what)):
            continue
        same = np.array_equal(base.c["normal_force"], r.c["normal_force"]) and base.res.get("outer") == r.res.get("outer")
        check(same, f"{what}: bitwise the frictionless forces and outer count",
              f"{rel(r.c['normal_force'], base.c['normal_force']):.2e}, outer {r.res.get('outer')} / {base.res.get('outer')}")


def patch_stick(tmp):
    tau = 0.2 * P
    tx, tz = tau * math.cos(math.radians(30.0)), tau * math.sin(math.radians(30.0))
    deck = stick_deck(tx, tz)
    mono = Run(tmp, "stick_mono", deck, MONO)
    runs = {"monolithic": mono, "harmonic": Run(tmp, "stick_harmonic", deck, ROBIN)}
    for op in ("steklov", "constant_anderson"):
        runs[op] = Run(tmp, f"stick_{op}", deck, ROBIN_2D[op])
    for name, r in runs.items():
        what = f"3D stick patch ({name})"
        if not converged(r, what):
            continue
        g = pair(r)
        e = rel(g["pressure"], np.full_like(g["pressure"], P))
        check(e <= 1e-8, f"{what}: pressure p at every node (1e-8)", f"{e:.2e}")
        want = np.repeat(np.array([[tx], [0.0], [tz]]), g["pressure"].size, axis=1)
        e = rel(shear_vectors(g), want)
        check(e <= 1e-8, f"{what}: shear (tau_x, 0, tau_z) at every node (1e-8)", f"{e:.2e}")
        check(np.all(g["state"] == 1), f"{what}: every node sticks", f"states {g['state'].tolist()}")
        if name != "monolithic" and mono.ok:
            e = max(rel(g["normal_force"], pair(mono)["normal_force"]),
                    rel(g["tangential_force"], pair(mono)["tangential_force"]))
            check(e <= 1e-8, f"{what}: = monolithic (1e-8)", f"{e:.2e}, outer {r.res.get('outer')}")
    if mono.ok:
        g = pair(mono)
        # the frame: the force's components along tangent1, tangent2 give its vector
        e = rel(g["tangent1"] * g["tangential_force"][0] + g["tangent2"] * g["tangential_force"][1],
                g["tangential_force_xyz"].T)
        check(e <= 1e-14, "3D output: tangential_force (frame) and tangential_force_xyz agree through the tangents",
              f"{e:.2e}")
        e = rel(g["shear_magnitude"], np.linalg.norm(shear_vectors(g), axis=0))
        check(e <= 1e-14, "3D output: shear_magnitude = |shear|", f"{e:.2e}")
        try:
            import meshio
            mesh = meshio.read(mono.h5[:-3] + "_contact.xdmf")
            pd = mesh.point_data
            ok = all(k in pd for k in ("shear_magnitude", "tangential_force", "state")) and \
                np.array_equal(np.asarray(pd["tangential_force"]), g["tangential_force_xyz"]) and \
                np.all(np.asarray(pd["state"]) == 1)
            check(ok, "3D output: the contact surface's XDMF (meshio) shows the shear's length, the tangential force "
                  "as a vector and the stick zone", f"{sorted(pd)}")
        except ImportError:
            print("SKIP  meshio absent: the XDMF fields are not read back")
        m = re.search(r"tangential_force_sum=(\S+) stick=(\d+) slip=(\d+)", mono.text)
        ok = m is not None and int(m.group(2)) == g["state"].size and int(m.group(3)) == 0
        if ok:
            t = np.array([float(v) for v in m.group(1).split(",")])
            ok = rel(t, [tx, 0.0, tz]) <= 1e-5
        check(ok, "3D contact line: the tangential resultant (x, y, z) and the stick and slip counts",
              m.group(0) if m else mono.text[-300:])


def slide(tmp):
    mu = 0.3
    for deg in (0.0, 15.0, 30.0, 45.0):
        law = f"friction='coulomb', mu={mu}"
        mono = Run(tmp, f"slide{deg:.0f}_mono", slide_deck(deg, law), MONO)
        runs = {"monolithic": mono}
        if deg == 30.0:
            runs["harmonic"] = Run(tmp, f"slide{deg:.0f}_harmonic", slide_deck(deg, law), ROBIN)
        push = np.array([math.cos(math.radians(deg)), 0.0, math.sin(math.radians(deg))])
        for name, r in runs.items():
            what = f"3D Coulomb slide at {deg:.0f} degrees ({name})"
            if not converged(r, what):
                continue
            g = pair(r)
            sv = shear_vectors(g)
            e = rel(np.linalg.norm(sv, axis=0), mu * g["pressure"])
            check(e <= 1e-8, f"{what}: |shear| = mu p at every node (1e-8)", f"{e:.2e}")
            on = g["normal_force"] > 0.0
            check(np.all(g["state"][on] == 2) and np.count_nonzero(on) >= g["state"].size - 1,
                  f"{what}: every node in contact slips (at most a corner open)", f"states {g['state'].tolist()}")
            f, s = g["tangential_force"][:, on], g["slip_increment"][:, on]
            cos = np.sum(f * s, axis=0) / (np.linalg.norm(f, axis=0) * np.linalg.norm(s, axis=0))
            check(np.all(1.0 - cos <= 1e-12), f"{what}: each node's force along its slip (1e-12)",
                  f"1 - cos up to {np.max(1.0 - cos):.2e}")
            res = np.sum(g["tangential_force_xyz"], axis=0)
            ptot = np.sum(g["normal_force"])
            e = abs(np.linalg.norm(res) / (mu * ptot) - 1.0)
            check(e <= 1e-8, f"{what}: |tangential resultant| = mu P (1e-8)", f"{e:.2e}")
            e = np.linalg.norm(np.cross(res / np.linalg.norm(res), push))
            check(e <= 1e-5, f"{what}: the resultant along the push (1e-5 rad)", f"{e:.2e}")
            if name != "monolithic" and mono.ok:
                e = max(rel(g["normal_force"], pair(mono)["normal_force"]),
                        rel(g["tangential_force"], pair(mono)["tangential_force"]))
                check(e <= 1e-6, f"{what}: = monolithic (1e-6)", f"{e:.2e}, outer {r.res.get('outer')}")
    gb = 1.0e5
    runs = {}
    for name, over in (("monolithic", MONO), ("harmonic", ROBIN)):
        r = runs[name] = Run(tmp, f"tresca_{name}", slide_deck(30.0, f"friction='tresca', slip_bound={gb}"), over)
        what = f"3D Tresca slide at 30 degrees ({name})"
        if converged(r, what):
            g = pair(r)
            e = rel(np.linalg.norm(shear_vectors(g), axis=0), np.full(g["pressure"].size, gb))
            check(e <= 1e-8, f"{what}: |shear| = slip_bound at every node (1e-8)", f"{e:.2e}")
            check(np.all(g["state"] == 2), f"{what}: every node slips", f"states {g['state'].tolist()}")
    if runs["monolithic"].ok and runs["harmonic"].ok:
        g, gm = pair(runs["harmonic"]), pair(runs["monolithic"])
        e = max(rel(g["normal_force"], gm["normal_force"]), rel(g["tangential_force"], gm["tangential_force"]))
        check(e <= 1e-8, "3D Tresca slide at 30 degrees: Robin = monolithic (1e-8)", f"{e:.2e}")


def threshold(tmp):
    mu = 0.5
    c, s = math.cos(math.radians(30.0)), math.sin(math.radians(30.0))
    for q in (0.99, 1.01):
        tau = q * mu * P
        r = Run(tmp, f"threshold{q}", stick_deck(tau * c, tau * s, f"friction='coulomb', mu={mu}"))
        what = f"3D: Q = {q} mu P along 30 degrees"
        if q < 1.0:
            if converged(r, what):
                res = np.sum(pair(r)["tangential_force_xyz"], axis=0)
                e = rel(res, [tau * c, 0.0, tau * s])
                check(e <= 1e-9, f"{what}: sticks, the tangential resultant is Q (1e-9)", f"{e:.2e}")
        else:
            refused(r, what, ["body 2", "it would slide along (", "no static equilibrium"])
            m = re.search(r"slide along \((\S+), (\S+), (\S+)\)", r.text)
            d = [float(m.group(k)) for k in (1, 2, 3)] if m else [float("nan")] * 3
            check(rel(d, [c, 0.0, s]) <= 1e-3, f"{what}: the direction it would slide in is the pull's, "
                  "(0.866, 0, 0.5) (1e-3: the message's four digits)", f"{d}")


# steel pressed onto aluminium (a Poisson mismatch), then moved sideways a little: partial slip
PATH_DECK = """&scene title='3D load history', dimension=3 /
&body id=1, x0=0.0, y0=0.0, z0=0.0, width=1.0, height=0.5, depth=1.0, nx=4, ny=2, nz=4, element='P1',
      young=7.0e10, poisson=0.33, bottom='clamped' /
&body id=2, x0=0.0, y0=0.5, z0=0.0, width=1.0, height=0.5, depth=1.0, nx=5, ny=2, nz=5, element='Q1',
      young=2.1e11, poisson=0.3 /
&contact bodies=1,2, groups='top','bottom', friction='coulomb', mu=0.3 /
"""
PRESS = "&boundary body=2, group='top', uy=-2.0e-6{} /"
SHIFT = "&boundary body=2, group='top', ux=2.0e-7, uz=1.0e-7{} /"
TIGHT = "&solver stop='residual', tol=1e-10 /"


def both(r):
    g = pair(r)
    return np.concatenate([g["normal_force"], g["tangential_force"].ravel()])


def load_history(tmp):
    runs = {}
    for hist, st in (("two stages", (", stage=1", ", stage=2")), ("at once", ("", ""))):
        for meth in ("monolithic", "robin"):
            r = Run(tmp, f"path_{hist[:3]}_{meth}", PATH_DECK, PRESS.format(st[0]), SHIFT.format(st[1]), TIGHT,
                    f"&solver method='{meth}' /")
            runs[hist, meth] = r
            converged(r, f"3D load history {hist} ({meth})")
    if not all(r.ok for r in runs.values()):
        return runs
    d = rel(both(runs["two stages", "monolithic"]), both(runs["at once", "monolithic"]))
    check(d > 1e-3, "3D load history: P then Q differs from P and Q at once (path dependence)", f"{d:.2e}")
    for hist in ("two stages", "at once"):
        e = rel(both(runs[hist, "robin"]), both(runs[hist, "monolithic"]))
        check(e <= 1e-6, f"3D load history {hist}: Robin = monolithic of the same history (1e-6)", f"{e:.2e}")
    g = pair(runs["two stages", "monolithic"])
    check(not np.allclose(g["slip"], g["slip_increment"]), "3D load history: the second stage's slip increment is not "
          "its slip")
    restart_in_second_stage(tmp, "3D load history", [PRESS.format(", stage=1"), SHIFT.format(", stage=2"), TIGHT], 40,
                            "contact/pair_1", pair(runs["two stages", "robin"]), runs["two stages", "robin"].h5)
    return runs


def threads_and_mpi(tmp):
    over = [PRESS.format(""), SHIFT.format(""), TIGHT]
    one = Run(tmp, "threads1", PATH_DECK, *over, threads=1)
    two = Run(tmp, "threads2", PATH_DECK, *over, threads=2)
    if converged(one, "3D friction, one thread") and converged(two, "3D friction, two threads"):
        same = all(np.array_equal(pair(one)[k], pair(two)[k]) for k in ("normal_force", "tangential_force"))
        check(same and one.res.get("outer") == two.res.get("outer"), "3D friction: one and two threads bitwise")
    mpi_bin = os.path.abspath(os.environ.get("MPI_BIN", os.path.join(ROOT, "bin/robin_contact_mpi")))
    if not (os.path.exists(mpi_bin) and shutil.which("mpirun")):
        print(f"SKIP  {mpi_bin} or mpirun absent: no MPI check")
        return
    serial = Run(tmp, "mpi_serial", PATH_DECK, *over, "&solver tol=1e-12 /")
    if not converged(serial, "3D friction, serial, tol 1e-12"):
        return
    mpi_against_serial(tmp, mpi_bin, os.path.join(tmp, "mpi_serial.nml"), [*over, "&solver tol=1e-12 /"],
                       "3D friction", "contact/pair_1", pair(serial))


def cattaneo(tmp):
    """(8) inputs/cattaneo_sphere.nml on its shipped mesh."""
    deck = os.path.join(ROOT, "inputs", "cattaneo_sphere.nml")
    robin = Run(tmp, "cm_robin", deck)
    mono = Run(tmp, "cm_mono", deck, MONO)
    if not (converged(robin, "Cattaneo-Mindlin sphere (Robin)") and converged(mono, "Cattaneo-Mindlin sphere (monolithic)")):
        return
    check("stalled" not in robin.text, "Cattaneo-Mindlin sphere: the harmonic operator does not stall (the plane of "
          "symmetry's rows dropped)", robin.text[-300:] if "stalled" in robin.text else "")
    g, gm = pair(robin), pair(mono)
    e = max(rel(g["normal_force"], gm["normal_force"]), rel(g["tangential_force"], gm["tangential_force"]))
    check(e <= 1e-6, "Cattaneo-Mindlin sphere: Robin = monolithic (1e-6)", f"{e:.2e}, outer {robin.res.get('outer')}")
    # the plane z = 0: no shear across it, and those nodes' tangent along z has no row
    on_plane = np.abs(g["z"]) < 1e-12
    tz = np.abs(g["tangential_force_xyz"][on_plane, 2])
    check(np.count_nonzero(on_plane) >= 5 and np.all(tz <= 1e-14 * np.max(np.abs(g["tangential_force_xyz"]))),
          "Cattaneo-Mindlin sphere: no shear across the plane of symmetry", f"{np.count_nonzero(on_plane)} nodes, "
          f"largest z shear {np.max(tz) if tz.size else 0:.2e}")
    # Q (the traction on the top) is held by the contact alone: the contact's resultant on the
    # sphere along x balances the sphere's load (its reaction line's loads=)
    qx = g["resultant_on_first_body"][0]
    m = re.search(r"reaction: body=1 .*?loads=(\S+?),", robin.text)
    load = float(m.group(1)) if m else float("nan")
    check(load > 0 and abs(qx + load) <= 1e-5 * load,
          "Cattaneo-Mindlin sphere: the contact alone holds the pull Q (1e-5, the line's six digits)",
          f"contact {qx:.9e}, load {load:.9e}")
    # a stick zone in the middle, ringed by slip
    r = np.hypot(g["x"], g["z"])
    stick, slip = g["state"] == 1, g["state"] == 2
    check(stick.any() and slip.any() and np.median(r[stick]) < np.median(r[slip]),
          "Cattaneo-Mindlin sphere: a stick zone inside a slipping ring", f"stick {stick.sum()}, slip {slip.sum()}")


def main():
    with tempfile.TemporaryDirectory(prefix="rc_friction3d_") as tmp:
        zero_friction(tmp)
        patch_stick(tmp)
        slide(tmp)
        threshold(tmp)
        load_history(tmp)
        threads_and_mpi(tmp)
        cattaneo(tmp)
    print(f"{len(check.failed)} failed")
    return 1 if check.failed else 0


if __name__ == "__main__":
    sys.exit(main())
