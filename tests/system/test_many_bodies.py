#!/usr/bin/python3
"""A deck of many bodies and contact pairs, whole program (run by `make check`; the
`&contact bodies=A,B, groups=...` form of doc/deck-reference.md):

(a) a stack of 1,000 small rectangles and 999 pairs, written by this script, is read and
    checked: the run reaches its assembly phase, whose line gives the time the deck took
    (printed as INFO, never asserted: the machine may be shared); a SIGTERM then stops it
    with exit 4 and nothing written;
(c) 1,000 floating blocks on a clamped one are accepted and converge in at most 5 outer
    iterations (4,995 contact rows: the sparse K of the group operator); 40 and 300 with
    nothing below are refused as free together (exit 1; the group check's dense and sparse
    paths, with no LAPACK "illegal value" text: from 22 rigid rows its eigenproblem once had
    too small a workspace and was skipped), the 300 named by the first and last few; 20 and
    300 on a clamped one whose lowest block is pulled up by twice the top block's load are
    refused as a group whose loads no compressive force balances (each block alone is
    balanced: the one above it holds it down); the unbalanced part is the least residual
    |G lam - e| over lam >= 0: the n - 1 floating blocks' residuals must sum to the net
    pull 1e6, least when equal, 1e6/sqrt(n - 1);
(b) the same stack with a fault far down the deck gets its own message, exit 1, nothing
    written: a group of a body in two pairs with the same body (naming both pairs' lines), a body in no pair,
    a pair naming a body the deck does not have.
"""
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402

check = Checks()
BIN = os.path.abspath(os.path.join(ROOT, os.environ.get("BIN", "bin/robin_contact")))
N = 1000


def stack(n, pairs=None):
    """Deck lines of n unit blocks stacked downwards (body 1 on top, body n clamped below, the
    others clamped on their left sides: no floating body, so the assembly phase is short),
    the top one loaded, and the pairs (k, k+1) of block k's bottom on block k+1's top."""
    lines = [f"&body id={k}, x0=0.0, y0={float(n - k)}, width=1.0, height=1.0, nx=2, ny=2"
             + (", bottom='clamped'" if k == n else ", left='clamped'") + " /" for k in range(1, n + 1)]
    lines.append("&traction body=1, side='top', t0=0.0, -1.0e6 /")
    if pairs is None:
        pairs = [(k, k + 1, "bottom", "top") for k in range(1, n)]
    lines += [f"&contact bodies={a},{b}, groups='{ga}','{gb}' /" for a, b, ga, gb in pairs]
    return lines


def run_deck(work, name, lines):
    """Run the program on the deck in an empty folder: exit code, output, seconds, files made."""
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write("\n".join(lines) + "\n")
    cwd = os.path.join(work, name)
    os.mkdir(cwd)
    t0 = time.perf_counter()
    p = subprocess.run([BIN, deck], cwd=cwd, capture_output=True, timeout=120)
    dt = time.perf_counter() - t0
    return p.returncode, (p.stdout + p.stderr).decode(errors="replace"), dt, os.listdir(cwd)


work = tempfile.mkdtemp(prefix="rc_many_bodies_")
try:
    # (a) the whole stack: read and checked up to the assembly, then stopped by a signal
    deck = os.path.join(work, "stack.nml")
    with open(deck, "w") as f:
        f.write("\n".join(stack(N)) + "\n")
    cwd = os.path.join(work, "stack")
    os.mkdir(cwd)
    p = subprocess.Popen([BIN, deck], cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    seen = None
    for line in p.stdout:
        if line.startswith("phase: assembly"):
            seen = line.strip()
            p.send_signal(signal.SIGTERM)
            break
    rest = p.stdout.read()
    code = p.wait(timeout=120)
    check(seen is not None, f"a stack of {N} bodies and {N - 1} pairs is read and checked (assembly starts)",
          rest.strip()[-300:])
    check(code == 4, "a SIGTERM during the assembly exits 4", f"exit {code}")
    check(not os.listdir(cwd), "nothing is written", " ".join(os.listdir(cwd)))
    if seen:
        print(f"INFO  reading and checking {N} bodies and {N - 1} pairs: {seen.split('(at ')[-1].rstrip(')')} "
              "(the assembly phase's line)")

    # (b) faults deep in the deck get their own message first
    pairs = [(k, k + 1, "bottom", "top") for k in range(1, N)]
    twice = pairs + [(2, 1, "left", "bottom")]   # body 1's bottom again with body 2
    code, out, _, made = run_deck(work, "twice", stack(N, twice))
    first = N + 1 + 1          # line of the first pair: after the bodies and the traction
    last = first + len(twice) - 1
    check(code == 1 and f"the &contact at line {first} and the &contact at line {last} both name group "
          "'bottom' of body 1 with body 2" in out,
          "a group in two pairs is named with both pairs' lines", out.strip()[-300:])
    check(not made, "nothing is written (group in two pairs)", " ".join(made))

    code, out, _, _ = run_deck(work, "lonely", stack(N, pairs[:-1]))
    check(code == 1 and f"body {N} (&body at line {N}) is in no contact pair" in out,
          "a body in no pair is named", out.strip()[-300:])

    unknown = pairs[:500] + [(501, N + 1, "bottom", "top")] + pairs[501:]
    code, out, _, _ = run_deck(work, "unknown", stack(N, unknown))
    check(code == 1 and f"unknown.nml:{first + 500}: in group &contact: bodies = 501,{N + 1} names body "
          f"{N + 1}, which does not exist" in out, "a pair naming a body the deck lacks is named at its line",
          out.strip()[-300:])

    # (c) floating chains: 1,000 blocks on rollers on a clamped one (held, though the joint
    # motion's ratio is small) are accepted and solved in a few outer iterations (4,995
    # contact rows: the group operator's sparse K); 40 blocks on rollers with nothing
    # below are refused as free together, with no LAPACK text on the way
    def floating(n, clamped, cells=2, pull=False):
        lines = [f"&body id={k}, x0=0.0, y0={float(n - k)}, width=1.0, height=1.0, nx={cells}, ny={cells}"
                 + (", bottom='clamped'" if k == n and clamped else ", left='roller'") + " /"
                 for k in range(1, n + 1)]
        lines.append("&traction body=1, side='top', t0=0.0, -1.0e6 /")
        if pull:   # the lowest floating block pulled up by 2e6 on its free side
            lines.append(f"&traction body={n - 1}, side='right', t0=0.0, 2.0e6 /")
        return lines + [f"&contact bodies={k},{k + 1}, groups='bottom','top' /" for k in range(1, n)]
    code, out, dt, _ = run_deck(work, "floating1000", floating(1000, True, cells=4))
    outer = re.search(r"^result: .* outer=(\d+) .* m=(\d+) ", out, re.M)
    check(code == 0 and "illegal value" not in out and outer is not None and int(outer.group(1)) <= 5
          and int(outer.group(2)) > 4096,
          "1,000 floating blocks on a clamped one (more than 4096 contact rows): exit 0 within 5 outer iterations",
          out.strip()[-300:])
    print(f"INFO  1,000 floating blocks: {dt:.2f} s for the whole run", flush=True)
    code, out, _, made = run_deck(work, "free40", floating(40, False))
    check(code == 1 and "together they are free" in out and "translation along y" in out
          and "illegal value" not in out, "40 floating blocks with nothing below: exit 1, free together",
          out.strip()[-300:])
    check(not made, "nothing is written (free together)", " ".join(made))
    code, out, _, made = run_deck(work, "free300", floating(300, False))
    check(code == 1 and "together they are free" in out and "translation along y" in out
          and "bodies 1, 2, 3, 4, 5, ..., 299 and 300 (300 bodies) are all" in out,
          "300 floating blocks with nothing below: exit 1, free together, the group named in short",
          out.strip()[-300:])
    check(not made, "nothing is written (300 free together)", " ".join(made))
    for n in (20, 300):
        code, out, _, made = run_deck(work, f"pulled{n}", floating(n, True, pull=True))
        part = f"(unbalanced part {1.0e6 / (n - 1) ** 0.5:.3E})"
        check(code == 1 and "are all held only by contact, and their loads cannot be balanced by compressive "
              f"contact forces between them {part}" in out and not made,
              f"{n} floating blocks whose lowest is pulled up: exit 1, the group's loads unbalanced, {part}",
              out.strip()[-300:])
finally:
    shutil.rmtree(work, ignore_errors=True)

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
