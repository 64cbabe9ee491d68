#!/usr/bin/python3
"""What a run prints on decks of more than two bodies (run by `make check`; doc/running.md,
"What a run prints"):

(a) `--help` names any number of bodies and pairs, not two bodies;
(b) a stack of 4 blocks, 3 pairs, 2 load steps: the `assembled:` line keeps n1 and n2 and
    adds bodies=, pairs= and dofs= (the sum over the bodies); one `bodies:` line follows it
    with each body's DOFs and contact rows (rows of the pairs it takes part in); the
    `result:` line has the documented shape with dofs=; each `step:` line has
    pair_normal_force_sum= with one sum per pair, which add up to its normal_force_sum and
    are, on the last step, the pairs' sums of /contact/pair_K/normal_force in the file;
(c) a two-body deck prints no `bodies:` line and no per-pair sums, and dofs = n1 + n2;
(d) a stack of 23 blocks lists 20 bodies on its `bodies:` line, then "... 3 more", and 20
    pair sums on its `step:` lines, then more_pairs=2.
The decks are written in a temporary folder.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import RESULT_LINE, line_fields, run_solver, solver_env  # noqa: E402

check = Checks()
BIN = os.path.abspath(os.path.join(ROOT, os.environ.get("BIN", "bin/robin_contact")))


def stack(n, steps=2):
    """Deck text of n unit blocks stacked downwards (body 1 on top, pressed; body n clamped
    below, the others clamped on their left sides), pairs (k, k+1), `steps` load steps."""
    lines = [f"&body id={k}, x0=0.0, y0={float(n - k)}, width=1.0, height=1.0, nx=2, ny={2 + k % 2}"
             + (", bottom='clamped'" if k == n else ", left='clamped'") + " /" for k in range(1, n + 1)]
    lines.append("&traction body=1, side='top', t0=0.0, -1.0e6 /")
    lines += [f"&contact bodies={k},{k + 1}, groups='bottom','top' /" for k in range(1, n)]
    lines.append(f"&solver method='monolithic', load_steps={steps} /")
    return "\n".join(lines) + "\n"


def run(work, name, text):
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write(text)
    h5 = os.path.join(work, name + ".h5")
    p, res = run_solver(BIN, deck, f"&output file='{h5}' /", env=solver_env(1), cwd=work, timeout=300)
    return p, res, h5


def tagged(text, tag):
    return [ln for ln in text.splitlines() if ln.startswith(tag + ": ")]


def step_fields(line):
    return dict(kv.split("=", 1) for kv in line.split()[1:] if "=" in kv)


work = tempfile.mkdtemp(prefix="rc_run_lines_")
try:
    # (a) --help
    p = subprocess.run([BIN, "--help"], capture_output=True, text=True, timeout=60)
    check(p.returncode == 0 and "two &body (id=1, id=2)" not in p.stdout and "two or more &body" in p.stdout
          and "one\n            per contact pair" in p.stdout,
          "--help: two or more &body groups, one &contact per pair", "" if "two or more" in p.stdout else p.stdout[:400])

    # (b) four bodies, three pairs
    p, res, h5 = run(work, "stack4", stack(4))
    check(p.returncode == 0, "stack of 4: exit 0", f"exit {p.returncode} {p.stderr.strip()[-300:]}")
    lines = p.stdout.splitlines()
    asm = line_fields(p.stdout, "assembled") or {}
    at = [i for i, ln in enumerate(lines) if ln.startswith("assembled: ")]
    bl = [i for i, ln in enumerate(lines) if ln.startswith("bodies: ")]
    # dofs per body: 2 dofs per node, the clamped side's nodes left out
    nodes = [3 * (3 + k % 2) for k in range(1, 5)]
    clamped = [3 + k % 2 for k in range(1, 4)] + [3]
    want = [2 * (n - c) for n, c in zip(nodes, clamped)]
    check(all(k in asm for k in ("n1", "n2", "m", "threads", "bodies", "pairs", "dofs")),
          "stack of 4: assembled: keeps n1, n2, m, threads and adds bodies, pairs, dofs", str(asm))
    if asm:
        check((asm.get("n1"), asm.get("n2"), asm.get("bodies"), asm.get("pairs"), asm.get("dofs"))
              == (str(want[0]), str(want[1]), "4", "3", str(sum(want))),
              f"stack of 4: n1={want[0]} n2={want[1]} bodies=4 pairs=3 dofs={sum(want)}", str(asm))
    check(len(bl) == 1 and len(at) == 1 and bl[0] == at[0] + 1, "stack of 4: one bodies: line, just after assembled:",
          f"assembled at {at}, bodies at {bl}")
    if bl:
        per = dict(kv.split("=", 1) for kv in lines[bl[0]].split() if "=" in kv)
        got = {int(k): tuple(int(x) for x in v.split(",")) for k, v in per.items()}
        m = int(asm.get("m", -1))
        check(sorted(got) == [1, 2, 3, 4] and [got[a][0] for a in range(1, 5)] == want,
              "stack of 4: bodies: lists each body's DOFs", lines[bl[0]])
        rows = [got.get(a, (0, 0))[1] for a in range(1, 5)]
        check(sum(rows) == 2 * m and rows[0] > 0 and rows[3] > 0 and rows[1] > rows[0] and rows[2] > rows[3],
              "stack of 4: bodies: lists each body's contact rows (each row counted on both its bodies)",
              f"rows {rows}, m={m}")
    check(RESULT_LINE.search(p.stdout) is not None and res and res.get("dofs") == str(sum(want)),
          "stack of 4: result: line has the documented shape, dofs = the sum over the bodies",
          (tagged(p.stdout, "result") or ["no result: line"])[-1])
    steps = [step_fields(ln) for ln in tagged(p.stdout, "step")]
    check(len(steps) == 2, "stack of 4: two step: lines", f"{len(steps)}")
    for s in steps:
        sums = [float(x) for x in s.get("pair_normal_force_sum", "").split(",") if x]
        tot = float(s.get("normal_force_sum", "nan"))
        check(len(sums) == 3 and abs(sum(sums) - tot) <= 1e-4 * abs(tot),
              f"stack of 4, step {s.get('step')}: pair_normal_force_sum has 3 sums that add up to normal_force_sum",
              f"{s.get('pair_normal_force_sum')} vs {tot}")
    if steps and os.path.exists(h5):
        sums = [float(x) for x in steps[-1].get("pair_normal_force_sum", "").split(",") if x]
        with h5py.File(h5, "r") as f:
            ref = [float(np.sum(f[f"/contact/pair_{k}/normal_force"])) for k in (1, 2, 3)]
        check(len(sums) == 3 and all(abs(a - b) <= 1e-5 * abs(b) for a, b in zip(sums, ref)),
              "stack of 4: the last step's pair sums are those of /contact/pair_K/normal_force", f"{sums} vs {ref}")
        vecs = [[float(c) for c in v.split(":")] for v in steps[-1].get("pair_resultant", "").split(",") if v]
        with h5py.File(h5, "r") as f:
            ref = [f[f"/contact/pair_{k}/resultant_on_first_body"][()] for k in (1, 2, 3)]
        scale = max(abs(c) for r in ref for c in r)
        check(len(vecs) == 3 and all(abs(a - b) <= 1e-4 * scale for v, r in zip(vecs, ref) for a, b in zip(v, r)),
              "stack of 4: the last step's pair_resultant (fx:fy per pair) is /contact/pair_K/resultant_on_first_body",
              f"{vecs} vs {ref}")

    # (c) two bodies: no bodies: line, no per-pair sums
    p, res, h5 = run(work, "two", stack(2))
    asm = line_fields(p.stdout, "assembled") or {}
    check(p.returncode == 0 and not tagged(p.stdout, "bodies")
          and asm.get("dofs") == str(int(asm.get("n1", 0)) + int(asm.get("n2", 0))),
          "two bodies: no bodies: line, dofs = n1 + n2", str(asm))
    steps = tagged(p.stdout, "step")
    check(len(steps) == 2 and not any("pair_normal_force_sum" in ln for ln in steps),
          "two bodies: step: lines without per-pair sums", " | ".join(steps))

    # (d) 23 bodies: the lists are cut at 20
    p, res, h5 = run(work, "stack23", stack(23))
    bl = tagged(p.stdout, "bodies")
    check(p.returncode == 0 and len(bl) == 1 and bl[0].endswith(" 20=" + bl[0].split(" 20=")[-1])
          and " 21=" not in bl[0] and bl[0].endswith(" ... 3 more"),
          "23 bodies: bodies: lists 20 bodies, then '... 3 more'", bl[0] if bl else f"exit {p.returncode}")
    steps = [step_fields(ln) for ln in tagged(p.stdout, "step")]
    check(len(steps) == 2 and all(len(s.get("pair_normal_force_sum", "").split(",")) == 20
                                  and s.get("more_pairs") == "2" for s in steps),
          "23 bodies: step: lines list 20 pair sums, then more_pairs=2", str(steps[-1] if steps else None))
    check(len(steps) == 2 and all(s.get("pair_resultant", "").count(":") == 6
                                  and s.get("pair_resultant", "").endswith(",...") for s in steps),
          "23 bodies: step: lines give the resultants of the first 6 pairs, then ',...'",
          str(steps[-1].get("pair_resultant") if steps else None))
    check(len(max(p.stdout.splitlines(), key=len)) < 600, "23 bodies: every line stays short")
finally:
    shutil.rmtree(work, ignore_errors=True)

print(f"{'FAILED: ' + str(len(check.failed)) if check.failed else 'all checks passed'}")
sys.exit(1 if check.failed else 0)
