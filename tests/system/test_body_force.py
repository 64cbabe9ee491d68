#!/usr/bin/python3
"""Body forces, whole program (run by `make check`; decks written by the test in a
temporary folder). The reference is statics: a block's weight is density x g x its area
(per unit thickness), and each contact of a stack carries the weight of the blocks above it.

(1) three 1 x 1 blocks stacked on their own weight (`&body_force gravity=0,-9.81`, density
    7850 kg/m^3): the upper two on rollers, held only by contact, the lowest clamped; the
    middle one of P1 triangles on a 5 x 3 grid, so its faces do not match the others'. Pair 1
    carries W = 7850 x 9.81 = 77008.5 N/m, pair 2 2W, each to 1e-9 (result file); the same in
    mm-N-MPa (density 7.85e-9 t/mm^3, g = 9810 mm/s^2, blocks of 1000 mm): the same forces in
    N/mm, W = 77.0085;
(2) stages: the weight in stage 1, a pressure of 1e5 on the top block in stage 2, load_steps
    = 1,2: the steps carry W, 2W; W + 5e4, 2W + 5e4; W + 1e5, 2W + 1e5 (each to 1e-9);
    The supports' reactions: the clamped block's sum to 3W (its weight and the two above) in
    the result file, to 1e-9, and every body's `reaction:` line balances (supports + loads +
    contact forces, the last from the mortar forces, independent of the displacement) to
    1e-10;
    A history whose stage 2 pulls the top block up beyond its weight (1e5 on its top face
    over two steps: 5e4 < W still presses it, 1e5 > W does not) ends with exit 2 after step
    2: the result is step 2's, and so are its reactions (3W - 5e4 on the clamped block, the
    same as /steps/step_2, not the loads of the step that failed) and its `reaction:` lines
    (balanced);
(3) `force=` on one body only (density 0 everywhere): 2e5 N/m^3 down on the top block, of
    area 0.5 (1 x 0.5): both pairs carry 1e5;
(4) bad input, exit 1, one message, nothing written: gravity on a body whose density is 0
    (naming the body and the &body_force's line), a &body_force on a body the deck lacks, a
    negative density, an unknown variable of &body_force, and a gravity of 1e300 (its
    stresses would overflow: refused before any work, not a non-finite solve, exit 3);
(5) the effective deck printed by the run holds the &body_force and every body's density,
    and reads back to the same run (its result equal to the first to the last bit);
(6) per support group: the clamped block also on a roller on its left side: its 'bottom'
    carries the 3W in y (the printed 6 digits), its 'left' nothing in y (a roller holds x
    only: the clamped corner's uy is the clamp's), and their x reactions cancel (each DOF
    counts once, in the first support that prescribes it).
Every shipped deck's equilibrium body by body is tools/regression.py's (test_regression).
"""
import re
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
ENV = solver_env(1)
check = Checks()


def stack(scale=1.0, density=7850.0, g=9.81, extra=(), heights=(1.0, 1.0, 1.0), gravity=True):
    """Three blocks of width `scale`, heights `heights` x scale, body 3 clamped below."""
    y = [scale * (heights[1] + heights[2]), scale * heights[2], 0.0]
    cells = [(4, 4, "Q1"), (5, 3, "P1"), (4, 4, "Q1")]
    lines = []
    for k in range(3):
        nx, ny, el = cells[k]
        bc = ", bottom='clamped'" if k == 2 else ", left='roller'"
        lines.append(f"&body id={k + 1}, x0=0.0, y0={y[k]}, width={scale}, height={scale * heights[k]}, "
                     f"nx={nx}, ny={ny}, element='{el}', density={density}{bc} /")
    if gravity:
        lines.append(f"&body_force gravity=0.0, {-g} /")
    lines += list(extra)
    lines += ["&contact bodies=1,2, groups='bottom','top' /", "&contact bodies=2,3, groups='bottom','top' /"]
    return "\n".join(lines) + "\n"


def run(work, name, text, *over):
    return run_text(BIN, work, name, text, *over, env=ENV)


def pair_forces(path, step=None):
    """The y resultant on the upper body of pairs 1 and 2 (of a step, or the final result)."""
    with h5py.File(path, "r") as f:
        root = f if step is None else f["steps"][f"step_{step}"]
        return [float(root["contact"][f"pair_{k}"]["resultant_on_first_body"][1]) for k in (1, 2)]


def reaction_sum(path, body, step=None):
    """The y sum of a body's nodal reactions (of a step, or the final result)."""
    with h5py.File(path, "r") as f:
        root = f if step is None else f["steps"][f"step_{step}"]
        return float(np.sum(root[f"body{body}"]["reaction"][()][1]))


def balances(out):
    """The balance of every `reaction:` line."""
    return [float(ln.split("balance=", 1)[1].split()[0]) for ln in out.splitlines() if ln.startswith("reaction: body=")]


def close(a, b, tol=1e-9):
    return abs(a - b) <= tol * abs(b)


work = tempfile.mkdtemp(prefix="rc_body_force_")
try:
    W = 7850.0 * 9.81
    # (1) the stack on its own weight, SI and mm-N-MPa
    code, out, h5 = run(work, "si", stack())
    f = pair_forces(h5) if code == 0 else [0.0, 0.0]
    check(code == 0 and close(f[0], W) and close(f[1], 2 * W),
          f"stack on its own weight (SI): pairs carry W and 2W to 1e-9 ({f[0]!r}, {f[1]!r}; W = {W})",
          out.strip()[-300:])
    rs = reaction_sum(h5, 3) if code == 0 else 0.0
    b = balances(out)
    check(code == 0 and close(rs, 3 * W) and len(b) == 3 and max(b) <= 1e-10,
          f"the clamped block's reactions sum to 3W ({rs!r}), every body's reaction: line balances ({b})",
          out.strip()[-300:])
    code, out, h5 = run(work, "mm", stack(scale=1000.0, density=7.85e-9, g=9810.0),
                        "&scene units='mm-N-MPa' /", "&body id=1, young=2.1e5 /", "&body id=2, young=2.1e5 /",
                        "&body id=3, young=2.1e5 /")
    f = pair_forces(h5) if code == 0 else [0.0, 0.0]
    check(code == 0 and close(f[0], W / 1000.0) and close(f[1], 2 * W / 1000.0),
          f"stack on its own weight (mm-N-MPa): pairs carry W and 2W in N/mm ({f[0]!r}, {f[1]!r})",
          out.strip()[-300:])

    # (2) stages: weight first, then a pressure on the top block
    code, out, h5 = run(work, "staged", stack(extra=["&traction body=1, side='top', t0=0.0, -1.0e5, stage=2 /",
                                                     "&solver load_steps=1,2 /"]))
    want = [(W, 2 * W), (W + 5e4, 2 * W + 5e4), (W + 1e5, 2 * W + 1e5)]
    got = [pair_forces(h5, s) for s in (1, 2, 3)] if code == 0 else []
    rsteps = [reaction_sum(h5, 3, s) for s in (1, 2, 3)] if code == 0 else []
    check(code == 0 and all(close(r, w) for r, w in zip(rsteps, (3 * W, 3 * W + 5e4, 3 * W + 1e5))),
          f"each step's reactions of the clamped block: 3W, 3W + 5e4, 3W + 1e5 ({rsteps})", out.strip()[-200:])
    check(code == 0 and len(got) == 3 and all(close(g[0], w[0]) and close(g[1], w[1]) for g, w in zip(got, want)),
          "weight in stage 1, a pressure in stage 2 over two steps: each step's pairs to 1e-9",
          f"{got} against {want}; " + out.strip()[-200:])

    code, out, h5 = run(work, "pulled", stack(extra=["&traction body=1, side='top', t0=0.0, 1.0e5, stage=2 /",
                                                     "&solver load_steps=1,2 /"]))
    rs = [reaction_sum(h5, 3), reaction_sum(h5, 3, 2)] if code == 2 and os.path.exists(h5) else []
    b = balances(out)
    check(code == 2 and "no static equilibrium from step 3" in out and len(rs) == 2 and close(rs[0], 3 * W - 5e4)
          and rs[0] == rs[1] and len(b) == 3 and max(b) <= 1e-10,
          f"no equilibrium from step 3: the result's reactions are step 2's, 3W - 5e4 ({rs}), its lines balance ({b})",
          out.strip()[-300:])

    # (3) a force per volume on one body only
    code, out, h5 = run(work, "force", stack(density=0.0, gravity=False, heights=(0.5, 1.0, 1.0),
                                             extra=["&body_force body=1, force=0.0, -2.0e5 /"]))
    f = pair_forces(h5) if code == 0 else [0.0, 0.0]
    check(code == 0 and close(f[0], 1e5) and close(f[1], 1e5),
          f"force= on body 1 (area 0.5): both pairs carry 1e5 ({f[0]!r}, {f[1]!r})", out.strip()[-300:])

    # (4) bad input
    bad = [("nodensity", stack().replace("density=7850.0,", "density=0.0,", 1), [],
            ["body 1", "density = 0", "&body_force at line 4", "gravity = 0"]),
           ("nobody", stack(extra=["&body_force body=4, force=0.0, -1.0 /"]), [],
            ["body = 4", "does not exist", "0 means every body"]),
           ("negdensity", stack(), ["&body id=2, density=-1.0 /"], ["density = -1", "must be >= 0"]),
           ("unknownvar", stack(extra=["&body_force gravty=0.0, -9.81 /"]), [], ["gravty"]),
           ("overflow", stack(g=1e300), [], ["&body_force at line 4 on body 1 (density 7.850E+03, gravity up to "
                                               "1.000E+300", "beyond double precision"])]
    for name, text, over, words in bad:
        before = set(os.listdir(work))
        code, out, _ = run(work, name, text, *over)
        made = sorted(set(os.listdir(work)) - before - {name + ".nml"})
        check(code == 1 and all(w in out for w in words) and "Traceback" not in out and not made,
              f"bad input '{name}': exit 1 naming {words}, nothing written", out.strip()[-300:] + " " + " ".join(made))

    # (5) the effective deck reads back to the same run
    code, out, h5 = run(work, "eff1", stack())
    lines = out.splitlines()
    start = next((i for i, ln in enumerate(lines) if ln.startswith("&scene")), None)
    end = next((i for i, ln in enumerate(lines) if ln.startswith("&output")), None)
    deck = "\n".join(lines[start:end]) + "\n" if start is not None and end is not None else ""
    check("&body_force body=0, gravity=0.0, -9.81, force=0.0, 0.0, stage=1 /" in deck
          and deck.count("density=7850.0") == 3, "the effective deck holds the &body_force and the densities",
          deck[:400])
    code2, out2, h52 = run(work, "eff2", deck)
    same = False
    if code == 0 and code2 == 0:
        with h5py.File(h5, "r") as a, h5py.File(h52, "r") as b:
            same = all(np.array_equal(a[f"body{k}/displacement"][()], b[f"body{k}/displacement"][()]) for k in (1, 2, 3))
    check(same, "the effective deck gives the same displacements to the last bit", out2.strip()[-300:])

    # (6) two support groups on one body
    code, out, h5 = run(work, "groups", stack().replace("bottom='clamped' /", "bottom='clamped', left='roller' /"))
    line = next((ln for ln in out.splitlines() if ln.startswith("reaction: body=3 ")), "")
    grp = {k: (float(x), float(y)) for k, x, y in re.findall(r"'(\w+)'=(\S+?),(\S+)", line)}
    check(code == 0 and set(grp) == {"bottom", "left"} and close(grp["bottom"][1], 3 * W, 1e-5)
          and grp["left"][1] == 0.0 and abs(grp["left"][0] + grp["bottom"][0]) <= 1e-5 * W,
          f"per group: 'bottom' carries 3W in y, 'left' (a roller) nothing in y, their x parts cancel ({grp})",
          out.strip()[-400:])

finally:
    shutil.rmtree(work, ignore_errors=True)

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
