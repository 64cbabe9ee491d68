#!/usr/bin/python3
"""Contact pairs named by their groups (run by `make check`): decks and meshes written by the
test in a temporary folder.

(1) Two pairs of the same two bodies whose groups share edges: three blocks stacked (a Gmsh
    mesh written by tests/system/msh_blocks.py) whose contact curves carry a second physical
    name each; a pair on the second names beside the pair on the first (the same edges
    twice): exit 1, the message names both groups and one shared edge (its node tags), no
    Fortran runtime text, no result written. A pair of bodies 1 and 3 on body 1's second name
    (a surface may be in pairs with different bodies) is not refused for sharing edges, but
    for what it is: body 3's side does not face it (exit 1, "does not overlap"). The stack
    itself (every body's pairs on disjoint curves) runs (control).
(3) A lid bridging two blocks: the lid's bottom in a pair with each block (one group in two
    pairs with different bodies), pressed by a traction on its top, inner solver 'active_set':
    exit 0, the two pairs' vertical resultants add up to the load (1e-9), Robin = monolithic
    (1e-9 of the largest nodal force).
(2) A command-line override of a deck with two pairs of bodies 1 and 2 (rectangles: 'bottom' on
    'top', and 'left' on 'right'): `&contact bodies=1,2, slave=2 /` is refused (exit 1, naming
    both candidates by their groups, nothing written); with groups= it changes the pair with
    those groups, given in either order of the bodies, and only that one (the effective
    deck); groups= matching neither pair is refused naming both. On a deck with one pair of
    those bodies the override without groups still changes it (control).
"""
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, HERE)
from rc_checks import Checks  # noqa: E402
from rc_run import run_solver, solver_env  # noqa: E402
from msh_blocks import block, write_msh  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
ENV = solver_env(1)
RUNTIME = ("Fortran runtime error", "Error termination", "Backtrace")
check = Checks()


def run(tmp, name, deck_text, *over):
    """Write and run a deck into tmp/name.h5: (exit code, stdout+stderr, h5 path)."""
    deck = os.path.join(tmp, name + ".nml")
    h5 = os.path.join(tmp, name + ".h5")
    with open(deck, "w") as f:
        f.write(deck_text)
    p, _ = run_solver(BIN, deck, *over, f"&output file='{h5}' /", cwd=tmp, env=ENV, timeout=300)
    return p.returncode, p.stdout + p.stderr, h5


def refused(rc, text, h5, what, *needles):
    """Exit 1, each needle in the message, no runtime error text, no result file."""
    missing = [n for n in needles if n not in text]
    check(rc == 1 and not missing, f"{what}: exit 1 naming {', '.join(needles)}",
          f"exit {rc}, missing {missing}: {text.strip()[-400:]}")
    check(not any(r in text for r in RUNTIME), f"{what}: no Fortran runtime error")
    check(not os.path.exists(h5), f"{what}: no result written")


STACK = """&scene title='stack' /
&body id=1, mesh='stack.msh', region='top', young=1e3, poisson=0.3 /
&body id=2, mesh='stack.msh', region='middle', young=1e3, poisson=0.3 /
&body id=3, mesh='stack.msh', region='bottom', young=1e3, poisson=0.3 /
&boundary body=1, group='top_top', ux=0, uy=-1e-3 /
&boundary body=2, group='middle_left', ux=0 /
&boundary body=3, group='bottom_bottom', ux=0, uy=0 /
&contact bodies=1,2, groups='top_bottom','middle_top' /
&contact bodies=2,3, groups='middle_bottom','bottom_top' /
"""
SECOND = "&contact bodies=1,2, groups='top_alias','middle_alias' /\n"

with tempfile.TemporaryDirectory() as tmp:
    # three blocks 1 x 0.5 stacked; the bottom curve of the top block and the top curve of the
    # middle block have a second physical name each
    write_msh(os.path.join(tmp, "stack.msh"),
              [block("top", 0.0, 1.0, 1.0, 0.5, 4, 2, aliases={"bottom": ["top_alias"]}),
               block("middle", 0.0, 0.5, 1.0, 0.5, 4, 2, aliases={"top": ["middle_alias"]}),
               block("bottom", 0.0, 0.0, 1.0, 0.5, 4, 2)])
    rc, text, h5 = run(tmp, "shared", STACK + SECOND)
    refused(rc, text, h5, "a second pair of bodies 1, 2 on the other names of the same curves",
            "body 1: contact group 'top_bottom'", "'top_alias'", "share edges", "the edge of nodes")
    rc, text, h5 = run(tmp, "shared_one_side", STACK + "&contact bodies=1,3, groups='top_alias','bottom_left' /\n")
    refused(rc, text, h5, "a pair of bodies 1, 3 on the other name of body 1's contact curve (not facing)",
            "'top_alias'", "does not overlap")
    check("share edges" not in text, "a surface in pairs with different bodies is not refused for sharing edges",
          text.strip()[-300:])
    # control: the stack itself (each body's pairs on disjoint curves) runs
    rc, text, h5 = run(tmp, "stack", STACK)
    check(rc == 0 and os.path.exists(h5), "the stack, pairs on disjoint curves: exit 0, result written",
          f"exit {rc}: {text.strip()[-300:]}")

TWO = """&body id=1, x0=0.0, y0=1.0, width=1.0, height=1.0, nx=2, ny=2, left='clamped' /
&body id=2, x0=0.0, y0=0.0, width=1.0, height=1.0, nx=2, ny=2, bottom='clamped' /
&contact bodies=1,2, groups='bottom','top' /
&contact bodies=2,1, groups='right','left' /
&traction body=1, side='top', t0=0.0, -1.0e6 /
"""


def contact_lines(text):
    """The &contact groups of the effective deck, one string each (continuation lines joined)."""
    out, cur = [], None
    for ln in text.splitlines():
        if ln.startswith("&contact"):
            cur = ln
            out.append(cur)
        elif cur is not None and ln.startswith("      "):
            out[-1] += " " + ln.strip()
        else:
            cur = None
    return out


with tempfile.TemporaryDirectory() as tmp:
    rc, text, h5 = run(tmp, "two", TWO, "&contact bodies=1,2, slave=2 /")
    refused(rc, text, h5, "an override naming two pairs by their bodies", "bodies = 1,2 names 2 pairs",
            "groups='bottom','top' (&contact at line 3)", "groups='left','right' (&contact at line 4)")
    for over, want, other in (("&contact bodies=1,2, groups='left','right', slave=2 /",
                               "&contact bodies=1, 2, groups='left', 'right', slave=2", "groups='bottom', 'top', slave=0"),
                              ("&contact bodies=2,1, groups='top','bottom', slave=1 /",
                               "&contact bodies=2, 1, groups='top', 'bottom', slave=1", "groups='right', 'left', slave=0")):
        rc, text, h5 = run(tmp, "pick", TWO, over)
        lines = contact_lines(text)
        check(len(lines) == 2 and sum(want in ln for ln in lines) == 1 and sum(other in ln for ln in lines) == 1,
              f"override {over}: changes the pair with those groups and not the other", " | ".join(lines))
    rc, text, h5 = run(tmp, "none", TWO, "&contact bodies=1,2, groups='top','left', slave=2 /")
    refused(rc, text, h5, "an override whose groups match neither pair", "is none of the 2 pairs of bodies 1 and 2",
            "groups='bottom','top'", "groups='left','right'")
    one = TWO.replace("&contact bodies=2,1, groups='right','left' /\n", "")
    rc, text, h5 = run(tmp, "one", one, "&contact bodies=1,2, slave=2 /")
    lines = contact_lines(text)
    check(rc == 0 and len(lines) == 1 and "groups='bottom', 'top', slave=2" in lines[0],
          "one pair of bodies 1, 2: the override without groups changes it, the run converges",
          f"exit {rc}: " + " | ".join(lines))

LID = """&scene title='a lid on two blocks', plane='strain', units='SI' /
&body id=1, x0=0.0, y0=0.0, width=1.0, height=1.0, nx=10, ny=10, young=2.1e11, poisson=0.3, bottom='clamped' /
&body id=2, x0=1.5, y0=0.0, width=1.0, height=1.0, nx=10, ny=10, young=2.1e11, poisson=0.3, bottom='clamped' /
&body id=3, x0=0.2, y0=1.0, width=2.1, height=0.3, nx=42, ny=6, young=7e10, poisson=0.33, left='roller' /
&traction body=3, side='top', t0=0.0, -1.0e6 /
&contact bodies=3,1, groups='bottom','top' /
&contact bodies=3,2, groups='bottom','top' /
"""


def lid_forces(h5):
    """(vertical resultants on the lid of both pairs, nodal normal forces of both) from h5."""
    import h5py
    import numpy as np
    with h5py.File(h5, "r") as f:
        res = [f[f"contact/pair_{k}/resultant_on_first_body"][()][1] for k in (1, 2)]
        lam = np.concatenate([f[f"contact/pair_{k}/normal_force"][()] for k in (1, 2)])
    return res, lam


with tempfile.TemporaryDirectory() as tmp:
    load = 1.0e6*2.1
    out = {}
    for method in ("robin", "monolithic"):
        # the monolithic reference by the active-set method: exact face solves (MPRGP's
        # relative tolerance leaves it 9e-9 away on this scene)
        rc, text, h5 = run(tmp, "lid_" + method, LID, f"&solver method='{method}', inner_solver='active_set' /")
        check(rc == 0 and os.path.exists(h5), f"lid on two blocks ({method}): exit 0, result written",
              f"exit {rc}: {text.strip()[-300:]}")
        if rc == 0:
            out[method] = lid_forces(h5)
    if "robin" in out:
        res = out["robin"][0]
        # the blocks push the lid up: each resultant on the lid (the pairs' first body) is negative
        err = abs(-sum(res) - load)/load
        check(err <= 1e-9 and max(res) < 0.0, "lid: the two pairs' vertical resultants on the lid add up to the load (1e-9)",
              f"{res}, {err:.1e}")
    if len(out) == 2:
        lr, lm = out["robin"][1], out["monolithic"][1]
        d = float(abs(lr - lm).max()/abs(lm).max())
        check(d <= 1e-9, "lid: Robin = monolithic (1e-9 of the largest nodal force)", f"{d:.1e}")

sys.exit(1 if check.failed else 0)
