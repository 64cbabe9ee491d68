#!/usr/bin/python3
"""Assemblies whose interface QPs are ill-conditioned (thin plates, friction, bodies held by
friction), whole program (run by `make check`; doc/verification.md, "Assemblies"). Each
scene runs by Robin and monolithically with the inner solvers named below ('auto', the
default; 'active_set'; 'mprgp'), and every converged Robin run equals the monolithic solution
of the same inner solver (nodal normal and tangential forces, 1e-8 of the largest). MPRGP
alone takes 80-110 s a run on the lap joints (640,000 products): those runs are in
`make bench` (bench/bench_assemblies.py), not here.

(1) inputs/lap_joint.nml coarsened to 1 mm cells (a head and a nut clamp two 60 x 5 mm
    plates, Coulomb mu = 0.2 on three pairs; stage 1 the preload, stage 2 plate B pulled
    0.05 mm by its right end): every node of plate B's two interfaces slips, and the pull,
    the tangential force that the two interfaces put on plate B, equals
    mu x (the two clamp forces) to 1e-6 relative.
(2) the same joint with plate B held by nothing but its contacts and pulled by a traction of
    0.8 mu x the clamp forces of the displacement-controlled run: plate B's tangential forces
    balance the pull (1e-6 relative).
(3) a stack of 8 thin plates (aspect 20:1, alternating steel and aluminium), the bottom one
    clamped, the others held laterally by nothing but friction (mu = 0.3), pressed on the top
    and pushed sideways on the top plate by 0.1 mu of the press, with all three inner
    solvers at the default tol 1e-8 (the Robin residual of this stack does not go below
    1.4e-9): Robin = monolithic by the active-set method to 1e-7 (the monolithic run with
    MPRGP inside is 6.8e-7 away from it, at its relative tolerance on an ill-conditioned
    Hessian; the Robin run with MPRGP inside 3.3e-9), and each interface carries the press vertically
    (1e-7) and the push horizontally (1e-6). (Under the per-pair harmonic operator this
    stack stagnated near a residual of 0.2 with MPRGP inside; doc/method.md.)
(4) a block held only by friction on a long thin strip (40:1) clamped at both ends, pressed
    and pushed sideways by 0.5 mu of the press, with all three inner solvers: its tangential
    resultant is the push (1e-6).
(5) the lap joint's plates both held by nothing but their contacts (plate A pressed by the
    head, plate B by plate A against the nut: pressed through a neighbour), default solver:
    accepted, every pair carries the same vertical force (statics, 5e-8: the Robin run stops
    at tol 1e-8), Robin = monolithic (5e-8); with the head's displacement zero nothing presses them: exit 1 naming a plate.
(6) a stiff punch (E = 2.1e11) pressed by a force into a soft block (E = 2.1e3, contrast
    1e8): the Robin run is not stopped as diverging by the size of its obstacles (their scale
    counts what the forces do to the soft block), the load passes (1e-9) and the forces are
    within 1e-4 of the monolithic ones (cond(F1 + F2) ~ 1.5e9; measured 2.6e-5).
(7) a block held only by Coulomb friction (mu = 0.4), pushed sideways by exactly mu N: exit 0
    with a warning naming the body and the edge of sliding; by 0.99 mu N: no warning; by
    1.01 mu N: exit 1 (it would slide).
(8) a stack of 16 blocks, steel and a material 1e6 times softer in turn, the bottom one
    clamped, the others held sideways by a roller and vertically by nothing but their
    contacts, pressed on the top (the per-pair operator stagnated at a residual of 0.2):
    the default Robin run converges (its residual within tol or the scene's rounding
    level, which the run names), every pair carries the load (1e-9), and Robin = monolithic
    by the active-set method (1e-7 of the largest nodal force; measured 3.5e-8, the
    condition number of the monolithic Hessian is 3e7). At contrast 1e8 (cond 3e9) the run
    converges and its bound says nothing: the accuracy line says so and gives the forces'
    natural residual instead (below 1e-6; measured 5.2e-8).
(9) a ring of three bodies in three pairs (two blocks side by side under a plate that lies
    on both, the right block pushed against the left one): Robin = monolithic (1e-8) with
    the active-set method.
(10) a block pressed into the inner corner of an L-shaped bracket (tests/data/corner.msh),
    Coulomb mu = 0.3 on two pairs between the same two bodies (the block's bottom on the
    floor, its left side on the wall), loaded down and to the left: the default Robin run
    converges (it stagnated at a residual of 0.07 while the corner node carried a normal row
    in one pair and a tangential row in the other) and equals the monolithic solution by the
    active-set method (1e-8); no node sticks, and the resultants are those of the block's
    equilibrium at full slip, N_floor = (F_y - mu F_x)/(1 - mu^2), N_wall =
    (F_x - mu F_y)/(1 - mu^2), T = mu N on each (1e-6; F the load's magnitudes).
(11) the block of (7) with Tresca friction, slip_bound 1e5 over its 1 m width, pushed
    sideways by 0.95 and 1.05 times the bound: converged (its tangential resultant the push,
    1e-8, the run's tol) and refused (exit 1, "cannot be balanced ... the Tresca bound"); with slip_bound
    1e20 (the largest accepted) pushed by 0.95 times 1e5: converged, every node sticks (a
    bound far above every force left the stuck nodes "slipping" and the run at a residual
    of 0.16); with Coulomb mu = 1e4 (the largest accepted): converged, every node sticks,
    the tangential resultant the push (1e-8).

The inner work of each run is printed (INFO), not checked; the wall times likewise.
"""
import os
import re
import shutil
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import run_solver, solver_env  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
check = Checks()
ENV = solver_env()
SOLVERS = ("auto", "active_set", "mprgp")


def info(what):
    print("INFO  " + what, flush=True)


def run(tmp, name, deck_text, *over):
    """Run a deck (text) with overrides; returns (ok, forces per pair, console text)."""
    deck = os.path.join(tmp, name + ".nml")
    h5 = os.path.join(tmp, name + ".h5")
    with open(deck, "w") as f:
        f.write(deck_text)
    p, res = run_solver(BIN, deck, *over, f"&output file='{h5}' /", cwd=tmp, env=ENV, timeout=900)
    ok = p.returncode == 0 and res is not None and res.get("status") == "converged" and os.path.exists(h5)
    pairs = []
    if ok:
        with h5py.File(h5, "r") as f:
            k = 1
            while f"contact/pair_{k}" in f:
                g = f[f"contact/pair_{k}"]
                t = g["tangential_force"][()] if "tangential_force" in g else np.zeros(0)
                pairs.append({"n": g["normal_force"][()], "t": t,
                              "state": g["state"][()] if "state" in g else np.zeros(0),
                              "res": g["resultant_on_first_body"][()]})
                k += 1
        os.remove(h5)
    if res:
        info(f"{name}: exit {p.returncode} status {res.get('status')} outer {res.get('outer')} "
             f"inner {res.get('inner')} wall {res.get('wall_s')} s")
    else:
        info(f"{name}: exit {p.returncode}: {(p.stdout + p.stderr)[-400:]}")
    return ok, pairs, p.stdout + p.stderr


def same_forces(a, b):
    """max |f_a - f_b| / max |f_b| over the normal and tangential forces of every pair."""
    fa = np.concatenate([np.concatenate([q["n"], q["t"]]) for q in a])
    fb = np.concatenate([np.concatenate([q["n"], q["t"]]) for q in b])
    return float(np.abs(fa - fb).max() / np.abs(fb).max())


def robin_vs_monolithic(tmp, name, deck, *over, solvers=SOLVERS, tol=1e-8, reference=None):
    """Each inner solver of `solvers`, Robin and monolithic (with the same inner solver, or
    with `reference` for all); returns the first Robin run's pairs."""
    first = None
    ref = None
    for s in solvers:
        rob = run(tmp, f"{name}_{s}_robin", deck, *over, f"&solver inner_solver='{s}' /")
        if reference is None or ref is None:
            ref = run(tmp, f"{name}_{reference or s}_mono", deck, *over,
                      f"&solver inner_solver='{reference or s}', method='monolithic' /")
        mono = ref
        check(rob[0], f"{name}, inner_solver '{s}', Robin: exit 0, converged", rob[2][-300:] if not rob[0] else "")
        check(mono[0], f"{name}, inner_solver '{s}', monolithic: exit 0, converged",
              mono[2][-300:] if not mono[0] else "")
        if rob[0] and mono[0]:
            d = same_forces(rob[1], mono[1])
            check(d <= tol, f"{name}, inner_solver '{s}': Robin = monolithic ({tol:.0e} of the largest force)", f"{d:.2e}")
        if first is None and rob[0]:
            first = rob[1]
    return first


def lap_deck(pull_side):
    """inputs/lap_joint.nml at 1 mm cells; pull_side: the group text of plate B's pull."""
    text = open(os.path.join(ROOT, "inputs", "lap_joint.nml")).read()
    text = re.sub(r"nx = 32, ny = 16", "nx = 16, ny = 8", text)
    text = re.sub(r"nx = 120, ny = 10", "nx = 60, ny = 5", text)
    text = text.replace("&solver load_steps = 1, 20 /", "&solver load_steps = 1, 4 /")
    return text.replace("young = 2.1e5, poisson = 0.3, right = 'displacement' /",
                        "young = 2.1e5, poisson = 0.3" + pull_side[0] + " /").replace(
        "&displacement body = 3, side = 'right', u = 0.05, 0.0, stage = 2 /", pull_side[1])


def b_tangential(pairs):
    """The x force the two interfaces put on plate B (body 3): -R(pair 2) + R(pair 3), and the
    clamp forces |R_y| of those pairs."""
    fx = -pairs[1]["res"][0] + pairs[2]["res"][0]
    return fx, abs(pairs[1]["res"][1]) + abs(pairs[2]["res"][1])


def main():
    tmp = tempfile.mkdtemp(prefix="test_assemblies_")
    try:
        return scenes(tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def scenes(tmp):
    mu = 0.2
    # (1) displacement-controlled pull to full slip
    deck = lap_deck((", right = 'displacement'", "&displacement body = 3, side = 'right', u = 0.05, 0.0, stage = 2 /"))
    pairs = robin_vs_monolithic(tmp, "lap joint, pulled by a displacement", deck, solvers=("auto", "active_set"))
    clamp = None
    if pairs:
        slip = all(np.all(q["state"] == 2) for q in pairs[1:]) if pairs else False
        states = [sorted(set(int(v) for v in q["state"])) for q in pairs[1:]]
        fx, clamp = b_tangential(pairs)
        err = abs(abs(fx) - mu * clamp) / (mu * clamp)
        check(slip or err <= 1e-6, "lap joint: every node of plate B's interfaces slips", f"states {states}")
        check(err <= 1e-6, "lap joint, full slip: the pull = mu x (the two clamp forces) (1e-6 relative)",
              f"pull {abs(fx):.6e}, mu x clamp {mu * clamp:.6e}, {err:.1e}")
    # (2) force-controlled pull below the threshold, plate B held by its contacts alone
    if clamp:
        t = 0.8 * mu * clamp / 5.0
        deck = lap_deck(("", f"&traction body = 3, side = 'right', t0 = {t:.10e}, 0.0, stage = 2 /"))
        pairs = robin_vs_monolithic(tmp, "lap joint, pulled by a force", deck, solvers=("auto", "active_set"))
        if pairs:
            fx, _ = b_tangential(pairs)
            err = abs(fx + t * 5.0) / (t * 5.0)
            check(err <= 1e-6, "lap joint, force-controlled: plate B's tangential forces balance the pull (1e-6)",
                  f"{fx:.6e} against {-t * 5.0:.6e}, {err:.1e}")
    # (3) a stack of 8 thin plates with friction
    lines = ["&scene title = 'stack of 8 thin plates', plane = 'strain' /"]
    p, push = 1.0e6, 0.1 * 0.3 * 1.0e6
    for k in range(8):
        e = 2.1e11 if k % 2 == 0 else 7.0e10
        bc = "bottom = 'clamped'" if k == 0 else "left = 'free'"
        lines.append(f"&body id = {k + 1}, x0 = 0.0, y0 = {0.05 * k:.2f}, width = 1.0, height = 0.05, nx = 40, "
                     f"ny = 2, young = {e}, poisson = 0.3, {bc} /")
    for k in range(7):
        lines.append(f"&contact bodies = {k + 1}, {k + 2}, groups = 'top', 'bottom', friction = 'coulomb', mu = 0.3 /")
    lines.append(f"&traction body = 8, side = 'top', t0 = {push}, {-p} /")
    lines.append("&solver tol = 1.0e-8 /")
    pairs = robin_vs_monolithic(tmp, "stack of 8 thin plates", "\n".join(lines) + "\n", tol=1e-7,
                                reference="active_set")
    if pairs:
        ey = max(abs(abs(q["res"][1]) - p) for q in pairs) / p
        ex = max(abs(abs(q["res"][0]) - push) for q in pairs) / push
        check(ey <= 1e-7, "stack of 8: every interface carries the press (1e-7)", f"{ey:.1e}")
        check(ex <= 1e-6, "stack of 8: every interface carries the push (1e-6)", f"{ex:.1e}")
    # (4) a block held only by friction on a long thin strip
    deck = """&scene title = 'block held by friction on a thin strip', plane = 'strain' /
&body id = 1, x0 = 0.0, y0 = 0.0, width = 4.0, height = 0.1, nx = 80, ny = 2, young = 2.1e11, poisson = 0.3,
      left = 'clamped', right = 'clamped' /
&body id = 2, x0 = 1.5, y0 = 0.1, width = 1.0, height = 0.5, nx = 20, ny = 10, young = 2.1e11, poisson = 0.3 /
&contact bodies = 2, 1, groups = 'bottom', 'top', friction = 'coulomb', mu = 0.4 /
&traction body = 2, side = 'top', t0 = 0.0, -1.0e6 /
&traction body = 2, side = 'left', t0 = 4.0e5, 0.0 /
&solver tol = 1.0e-10 /
"""
    pairs = robin_vs_monolithic(tmp, "block on a thin strip", deck)
    if pairs:
        push = 4.0e5 * 0.5
        err = abs(abs(pairs[0]["res"][0]) - push) / push
        check(err <= 1e-6, "block on a strip: its tangential resultant is the push 0.5 mu P (1e-6)",
              f"{pairs[0]['res'][0]:.6e}, {err:.1e}")
    # (5) plates pressed through a neighbour
    deck = lap_deck(("", "")).replace("young = 2.1e5, poisson = 0.3, left = 'clamped' /", "young = 2.1e5, poisson = 0.3 /")
    deck = deck.replace("&solver load_steps = 1, 4 /", "")
    rob = run(tmp, "clamped plates", deck)
    mono = run(tmp, "clamped plates mono", deck, "&solver method='monolithic' /")
    check(rob[0] and mono[0], "plates pressed through a neighbour: accepted, Robin and monolithic converge",
          rob[2][-300:] if not rob[0] else "")
    if rob[0] and mono[0]:
        fy = [abs(q["res"][1]) for q in rob[1]]
        e = (max(fy) - min(fy)) / max(fy)
        check(e <= 5e-8, "plates pressed through a neighbour: every pair carries the same vertical force (5e-8)",
              f"{fy}, {e:.1e}")
        d = same_forces(rob[1], mono[1])
        check(d <= 5e-8, "plates pressed through a neighbour: Robin = monolithic (5e-8)", f"{d:.2e}")
    zero = deck.replace("&displacement body = 1, side = 'top', u = 0.0, -0.01 /",
                        "&displacement body = 1, side = 'top', u = 0.0, 0.0 /")
    bad = run(tmp, "clamped plates unpressed", zero)
    check(not bad[0] and re.search(r"exit|error", bad[2]) and re.search(r"body [23] is held only by contact", bad[2])
          and "no load presses it" in bad[2], "plates nothing presses: exit 1 naming a plate", bad[2][-200:])
    # (6) a stiff punch on a soft block
    punch = """&scene title = 'stiff punch on a soft block' /
&body id = 1, x0 = 0.4, y0 = 1.0, width = 0.2, height = 0.2, nx = 8, ny = 8, young = 2.1e11, poisson = 0.3, left = 'roller' /
&body id = 2, x0 = 0.0, y0 = 0.0, width = 1.0, height = 1.0, nx = 20, ny = 20, young = 2.1e3, poisson = 0.3, bottom = 'clamped' /
&traction body = 1, side = 'top', t0 = 0.0, -10.0 /
&contact bodies = 1, 2, groups = 'bottom', 'top' /
"""
    deck_path = os.path.join(tmp, "punch.nml")
    with open(deck_path, "w") as f:
        f.write(punch)
    h5 = os.path.join(tmp, "punch.h5")
    p, res = run_solver(BIN, deck_path, f"&output file='{h5}' /", cwd=tmp, env=ENV, timeout=300)
    text = p.stdout + p.stderr
    check("obstacles grew" not in text and os.path.exists(h5) and res is not None,
          "punch at contrast 1e8: not stopped by the size of its obstacles", text[-300:])
    mono = run(tmp, "punch mono", punch, "&solver method='monolithic' /")
    if os.path.exists(h5) and mono[0]:
        with h5py.File(h5, "r") as f:
            lam = f["contact/normal_force"][()]
        lm = np.concatenate([q["n"] for q in mono[1]])
        e = float(np.abs(lam - lm).max() / np.abs(lm).max())
        check(abs(lam.sum() - 2.0) <= 2e-9, "punch: the load passes (1e-9)", f"{lam.sum():.12f}")
        check(e <= 1e-4, "punch: forces within 1e-4 of monolithic", f"{e:.1e}; {res.get('status') if res else ''}")
    # (7) a block pushed by exactly mu N
    for q, want in ((8.0e5, "warn"), (7.92e5, "quiet"), (8.08e5, "refused")):
        deck = f"""&scene title = 'block pushed by mu N' /
&body id = 1, x0 = 0.0, y0 = 0.0, width = 4.0, height = 0.5, nx = 40, ny = 5, young = 2.1e11, poisson = 0.3, bottom = 'clamped' /
&body id = 2, x0 = 1.5, y0 = 0.5, width = 1.0, height = 0.5, nx = 10, ny = 5, young = 2.1e11, poisson = 0.3 /
&contact bodies = 2, 1, groups = 'bottom', 'top', friction = 'coulomb', mu = 0.4 /
&traction body = 2, side = 'top', t0 = 0.0, -1.0e6 /
&traction body = 2, side = 'left', t0 = {q}, 0.0 /
"""
        ok, _, text = run(tmp, f"edge {q:.3g}", deck)
        warned = re.search(r"warning: .*body 2 .*edge of sliding", text) is not None
        if want == "warn":
            check(ok and warned, "pushed by exactly mu N: converged, a warning names body 2 at the edge of sliding",
                  text[-300:])
        elif want == "quiet":
            check(ok and not warned, "pushed by 0.99 mu N: converged, no warning", text[-300:])
        else:
            check(not ok and "would slide" in text, "pushed by 1.01 mu N: refused (it would slide)", text[-200:])
    # (8) 16 blocks, contrast 1e6 between neighbours
    lines = ["&scene title = '16 blocks, contrast 1e6' /"]
    for k in range(1, 17):
        e = 2.1e11 if k % 2 else 2.1e5
        bc = "bottom = 'clamped'" if k == 16 else "left = 'roller'"
        lines.append(f"&body id = {k}, x0 = 0.0, y0 = {16 - k}.0, width = 1.0, height = 1.0, nx = {8 + k % 3}, ny = 6, "
                     f"young = {e}, poisson = 0.3, {bc} /")
    lines += [f"&contact bodies = {k}, {k + 1}, groups = 'bottom', 'top' /" for k in range(1, 16)]
    lines.append("&traction body = 1, side = 'top', t0 = 0.0, -1.0e5 /")
    deck = "\n".join(lines) + "\n"
    rob = run(tmp, "stack16", deck)
    mono = run(tmp, "stack16 mono", deck, "&solver method = 'monolithic', inner_solver = 'active_set' /")
    check(rob[0], "16 blocks at contrast 1e6: the default Robin run converges", rob[2][-300:])
    if rob[0]:
        ey = max(abs(abs(q["res"][1]) - 1.0e5) for q in rob[1]) / 1.0e5
        check(ey <= 1e-9, "16 blocks: every pair carries the load (1e-9)", f"{ey:.1e}")
    if rob[0] and mono[0]:
        d = same_forces(rob[1], mono[1])
        check(d <= 1e-7, "16 blocks: Robin = monolithic by the active-set method (1e-7)", f"{d:.2e}")
    # (8b) the same stack at contrast 1e8: converged, its bound says nothing (cond(H) 3e9),
    # and the accuracy line says what is known: the natural residual
    rob = run(tmp, "stack16 1e8", deck.replace("young = 210000.0,", "young = 2100.0,"))
    acc = next((ln for ln in rob[2].splitlines() if ln.startswith("accuracy:")), "")
    m = re.search(r"natural residual \|lam - P\(lam - grad/L\)\|/\|lam\| = (\S+)", acc)
    check(rob[0] and acc.startswith("accuracy: no bound (") and m is not None and float(m.group(1)) < 1e-6,
          "16 blocks at contrast 1e8: converged, no bound, the accuracy line gives the natural residual (< 1e-6)", acc)
    # (9) a ring of three bodies
    deck = """&scene title = 'ring of three' /
&body id = 1, x0 = 0.0, y0 = 0.0, width = 1.0, height = 1.0, nx = 10, ny = 10, young = 2.1e11, poisson = 0.3,
      bottom = 'clamped' /
&body id = 2, x0 = 1.0, y0 = 0.0, width = 1.0, height = 1.0, nx = 12, ny = 10, young = 7.0e10, poisson = 0.33,
      bottom = 'roller' /
&body id = 3, x0 = 0.2, y0 = 1.0, width = 1.6, height = 0.4, nx = 24, ny = 6, young = 2.1e11, poisson = 0.3,
      left = 'roller' /
&traction body = 3, side = 'top', t0 = 0.0, -1.0e6 /
&traction body = 2, side = 'right', t0 = -1.0e6, 0.0 /
&contact bodies = 3, 1, groups = 'bottom', 'top' /
&contact bodies = 3, 2, groups = 'bottom', 'top' /
&contact bodies = 1, 2, groups = 'right', 'left' /
"""
    robin_vs_monolithic(tmp, "ring of three", deck, solvers=("active_set",))
    # (10) a block in a corner, friction on two pairs of the same two bodies
    shutil.copy(os.path.join(ROOT, "tests", "data", "corner.msh"), tmp)
    mu, fx, fy = 0.3, 0.8e6 + 0.8*0.3e6, 0.8*1.0e6
    deck = """&scene title = 'block in a corner' /
&body id = 1, mesh = 'corner.msh', region = 'block', young = 7.0e10, poisson = 0.33 /
&body id = 2, mesh = 'corner.msh', region = 'bracket', young = 2.1e11, poisson = 0.3 /
&boundary body = 2, group = 'base', ux = 0.0, uy = 0.0 /
&traction body = 1, group = 'block_top', t0 = -3.0e5, -1.0e6 /
&traction body = 1, group = 'block_right', t0 = -1.0e6, 0.0 /
&contact bodies = 1, 2, groups = 'block_bottom', 'floor', friction = 'coulomb', mu = 0.3 /
&contact bodies = 1, 2, groups = 'block_left', 'wall', friction = 'coulomb', mu = 0.3 /
"""
    # the outer tolerance ten times below the check's 1e-8: a Robin run stopped at an increment
    # of tol lands about tol from the monolithic forces (1.0e-8 at tol = 1e-8, 3e-11 at 1e-10)
    pairs = robin_vs_monolithic(tmp, "block in a corner", deck, "&solver tol = 1e-9 /", solvers=("auto",),
                                reference="active_set")
    if pairs:
        slip = all(np.all((q["state"] == 2) | (q["state"] == 0)) for q in pairs)
        check(slip, "corner: no node sticks (each slips or is open)",
              str([sorted(set(int(v) for v in q["state"])) for q in pairs]))
        n_floor = (fy - mu*fx)/(1.0 - mu*mu)
        n_wall = (fx - mu*fy)/(1.0 - mu*mu)
        want = [(mu*n_floor, n_floor), (n_wall, mu*n_wall)]
        got = [tuple(q["res"]) for q in pairs]
        err = max(abs(g - w)/w for gw, ww in zip(got, want) for g, w in zip(gw, ww))
        check(err <= 1e-6, "corner: the resultants of the full-slip equilibrium (1e-6)", f"{got} against {want}, {err:.1e}")
    # (11) Tresca's bound and the largest bounds accepted
    block = """&scene title = 'block pushed sideways' /
&body id = 1, x0 = 0.0, y0 = 0.0, width = 4.0, height = 0.5, nx = 40, ny = 5, young = 2.1e11, poisson = 0.3, bottom = 'clamped' /
&body id = 2, x0 = 1.5, y0 = 0.5, width = 1.0, height = 0.5, nx = 10, ny = 5, young = 2.1e11, poisson = 0.3 /
&contact bodies = 2, 1, groups = 'bottom', 'top', LAW /
&traction body = 2, side = 'top', t0 = 0.0, -1.0e6 /
&traction body = 2, side = 'left', t0 = PUSH, 0.0 /
"""
    for k, (law, push, want) in enumerate((("friction = 'tresca', slip_bound = 1.0e5", 1.9e5, "held"),
                            ("friction = 'tresca', slip_bound = 1.0e5", 2.1e5, "refused"),
                            ("friction = 'tresca', slip_bound = 1.0e20", 1.9e5, "stuck"),
                            ("friction = 'coulomb', mu = 1.0e4", 1.9e5, "stuck"))):
        deck = block.replace("LAW", law).replace("PUSH", repr(push))
        ok, pairs, text = run(tmp, f"bound {k + 1}", deck)
        what = f"{law}, pushed by {0.5 * push:.3g} N/m"
        if want == "refused":
            check(not ok and "cannot be balanced by contact forces within the friction limits" in text
                  and "Tresca bound" in text, f"{what}: refused (beyond the Tresca bound)", text[-300:])
            continue
        check(ok, f"{what}: converged", text[-300:])
        if ok:
            e = abs(abs(pairs[0]["res"][0]) - 0.5 * push) / (0.5 * push)
            check(e <= 1e-8, f"{what}: the tangential resultant is the push (1e-8, the run's tol)",
                  f"{pairs[0]['res'][0]:.9e}, {e:.1e}")
            if want == "stuck":
                check(bool(np.all(pairs[0]["state"] == 1)), f"{what}: every node sticks",
                      str(sorted(set(int(v) for v in pairs[0]["state"]))))
    print(f"{len(check.failed)} failed checks")
    return 1 if check.failed else 0


if __name__ == "__main__":
    sys.exit(main())
