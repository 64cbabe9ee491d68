#!/usr/bin/python3
"""Scenes of several bodies and contact pairs, whole program (run by `make check`;
doc/verification.md, "Several bodies and contact pairs"). Every run of a deck with more than
two bodies or pairs must converge: a refusal of the deck ("this version solves two bodies in
one contact pair") is a failed check, and so is every check that needs its result.

(1) inputs/stack3.nml, three blocks (aluminium, steel, aluminium) of different widths with
    non-matching meshes, the top one pressed by 1 MPa on its width 0.6, the middle one held
    vertically only by its two contacts: with robin_operator 'steklov', 'harmonic' and
    'constant' (alpha = 1e-12, about h/E) and with method='monolithic', each pair's vertical
    resultant is the load 6e5 (1e-9, from the result file; the console line to its printed
    digits) and each pair's nodal forces equal the monolithic ones (1e-8 of the largest).
(2) inputs/disc_plates.nml, a disc (R = 1, msh_disc.py) between two plates 2 x 1 (h = 0.005):
    the upper plate pressed by 3 on its top (P = 6) and held laterally by a roller, the disc by
    ux = 0 on its vertical axis, the lower plate clamped below; both pairs carry P (1e-9), Robin = monolithic (1e-8),
    and each contact's half-width a and peak pressure p0 are Hertz's for a cylinder on a
    half-space (1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2) within 1%: the plates are ten half-widths
    thick (a ~ 0.1), enough for the half-space model (five half-widths give a 0.75% error).
    The same comparison on the disc pressed into the lower plate alone by a displacement of its
    upper arc (two bodies, one pair) checks the mesh writer and the Hertz fit on their own.
(3) 32 equal blocks stacked, the top one loaded, the bottom one clamped, the others on
    rollers: the default solver settings with tol = 1e-11 converge, equal the monolithic
    solution (1e-8) and every interface carries the load (1e-9).
(4) 1,000 blocks (40 columns x 25 rows, 2 x 2 cells each), each column loaded on its top by
    its own pressure, the bottom row clamped: with tol = 1e-11 converges, equals monolithic
    (1e-8), every interface carries its column's load (1e-9). The wall time is printed (INFO),
    not checked. (Information crosses one contact per outer iteration: a column of 100 blocks
    does not converge within the default max_outer; doc/method.md.)
"""
import math
import os
import re
import shutil
import sys
import tempfile
import time

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, HERE)
from rc_checks import Checks  # noqa: E402
from rc_run import line_fields, namelist_groups, result_fields, run_solver, solver_env  # noqa: E402
from hertz_study import hertz_fit  # noqa: E402
from msh_disc import write_disc  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
REFUSAL = "this version solves two bodies in one contact pair"
MONO = "&solver method='monolithic' /"
check = Checks()
ENV = solver_env()


def info(what):
    print("INFO  " + what, flush=True)


class Run:
    """One run of the program into tmp/<name>.h5: exit code, console text, result fields, and ok
    (exit 0, status converged, the result file written)."""

    def __init__(self, tmp, name, deck, *over, timeout=600):
        self.name = name
        self.h5 = os.path.join(tmp, name + ".h5")
        t0 = time.perf_counter()
        p, self.res = run_solver(BIN, deck, *over, f"&output file='{self.h5}' /", cwd=tmp, env=ENV,
                                 timeout=timeout)
        self.wall = time.perf_counter() - t0
        self.rc = p.returncode
        self.text = p.stdout + p.stderr
        self.stdout = p.stdout
        self.ok = (self.rc == 0 and self.res is not None and self.res.get("status") == "converged"
                   and os.path.exists(self.h5))
        self.pairs = {}                  # pair_data's, by pair count

    def why(self):
        if REFUSAL in self.text:
            return f"exit {self.rc}: the deck is refused by this version ({REFUSAL})"
        return f"exit {self.rc}: {self.text.strip()[-300:]}"


def converged(run, what, nbodies=None, npairs=None):
    """Checks that the run converged (and names its bodies and pairs on the result line)."""
    good = check(run.ok, f"{what}: exit 0, status converged", "" if run.ok else run.why())
    if good and npairs is not None:
        nb, npr = run.res.get("bodies"), run.res.get("pairs")
        check(nb == str(nbodies) and npr == str(npairs), f"{what}: result line bodies={nbodies} pairs={npairs}",
              f"bodies={nb} pairs={npr}")
    return good


def deck_valid(run, what, nbodies, npairs):
    """The deck passes the input checks: it runs, or only the two-body limit stops it (with the
    deck's own counts), never another complaint about the deck."""
    limit = f"{REFUSAL}; the deck has {nbodies} bodies and {npairs} pairs"
    check(run.rc in (0, 2) or (run.rc == 1 and limit in run.text and run.text.count("error:") == 1),
          f"{what}: the deck passes the input checks ({nbodies} bodies, {npairs} pairs)",
          f"exit {run.rc}" + ("" if run.rc in (0, 2) or limit in run.text else f": {run.text.strip()[-300:]}"))


def pair_data(run, npairs):
    """Per pair k (1..npairs): dict of its result-file datasets (x, normal, normal_force, pressure)
    and attribute bodies; one pair: /contact itself. None where the file lacks it. Read once per
    run (kept in run.pairs: 960 pairs take about 1.5 s to read)."""
    if npairs in run.pairs:
        return run.pairs[npairs]
    out = run.pairs[npairs] = {}
    with h5py.File(run.h5, "r") as f:
        for k in range(1, npairs + 1):
            path = "/contact" if npairs == 1 else f"/contact/pair_{k}"
            if path not in f:
                out[k] = None
                continue
            g = f[path]
            d = {key: np.array(g[key], dtype=float) for key in ("x", "normal", "normal_force", "pressure") if key in g}
            d["bodies"] = [int(b) for b in np.asarray(g.attrs["bodies"]).reshape(-1)] if "bodies" in g.attrs else None
            out[k] = d
    return out


PAIR_LINE = re.compile(r"^contact: pair=(\d+) (.*)$", re.M)


def pair_lines(text):
    """The console's per-pair lines: {k: {field: value}}."""
    return {int(m.group(1)): dict(kv.split("=", 1) for kv in m.group(2).split() if "=" in kv)
            for m in PAIR_LINE.finditer(text)}


def printed_tol(s):
    """The relative precision of a number as printed (its mantissa's digits), at least 1e-9."""
    digits = len(re.sub(r"[^0-9]", "", re.split(r"[eE]", s)[0]).lstrip("0")) or 1
    return max(1e-9, 10.0 ** (1 - digits))


def vertical(d):
    """|sum lam n_y| of one pair's datasets: the vertical force it transmits."""
    n = d["normal"]
    ny = n[1, :] if n.shape[0] == 2 else n[:, 1]
    return abs(float(np.sum(d["normal_force"] * ny)))


def check_statics(what, run, pairs, loads):
    """Each pair k, bodies (A, B) with A above B, carries loads[k] (> 0) upward on A: the vertical
    force |sum lam n_y| of the result file to 1e-9, the console's resultant_on_body<A> to its
    printed digits (and its sign). pairs: {k: (A, B)}. A missing line or dataset fails."""
    if not run.ok:
        check(False, f"{what}: every pair carries its load", "no result: " + run.why())
        return
    data = pair_data(run, len(pairs))
    lines = pair_lines(run.stdout) if len(pairs) > 1 else {1: line_fields(run.stdout, "contact") or {}}
    worst_file = worst_line = 0.0
    bad = []
    for k, (a, b) in pairs.items():
        d, ln = data.get(k), lines.get(k)
        if d is None or "normal_force" not in d or "normal" not in d:
            bad.append(f"pair {k}: no /contact/pair_{k} datasets")
            continue
        if len(pairs) > 1 and d["bodies"] != [a, b]:
            bad.append(f"pair {k}: attribute bodies {d['bodies']}, want [{a}, {b}]")
        fy = vertical(d)
        e = abs(fy / loads[k] - 1.0)
        worst_file = max(worst_file, e)
        if e > 1e-9:
            bad.append(f"pair {k}: vertical force {fy!r}, load {loads[k]!r}")
        key = f"resultant_on_body{a}"
        if not ln or key not in ln or (len(pairs) > 1 and (ln.get("bodies") != f"{a},{b}")):
            bad.append(f"pair {k}: no console line with bodies={a},{b} and {key}")
            continue
        s = ln[key].split(",")[1]
        e = abs(float(s) / loads[k] - 1.0)
        worst_line = max(worst_line, e)
        if e > printed_tol(s):
            bad.append(f"pair {k}: console {key} y = {s}, load {loads[k]!r}")
    check(not bad, f"{what}: every pair's vertical resultant is its load ({len(pairs)} pairs; file 1e-9, "
          "console to its digits)", "; ".join(bad[:3]) if bad else f"worst {worst_file:.1e} (file), "
          f"{worst_line:.1e} (console)")


def check_same(what, run, ref, npairs, tol=1e-8):
    """Per pair: max |lam - lam_ref| / max |lam_ref| <= tol."""
    if not (run.ok and ref.ok):
        check(False, f"{what}: = monolithic per pair ({tol:g})",
              "no result: " + (run.why() if not run.ok else ref.why()))
        return
    a, b = pair_data(run, npairs), pair_data(ref, npairs)
    worst, bad = 0.0, []
    for k in range(1, npairs + 1):
        la, lb = (a.get(k) or {}).get("normal_force"), (b.get(k) or {}).get("normal_force")
        if la is None or lb is None or la.shape != lb.shape:
            bad.append(f"pair {k}: missing or of another size")
            continue
        e = float(np.abs(la - lb).max() / np.abs(lb).max())
        worst = max(worst, e)
        if not e <= tol:
            bad.append(f"pair {k}: {e:.2e}")
    check(not bad, f"{what}: nodal forces = monolithic per pair ({tol:g} of the largest)",
          "; ".join(bad[:3]) if bad else f"worst {worst:.2e}")


def hertz_check(what, d, P, R, E1, nu1, E2, nu2, tol=0.01):
    """a and p0 fitted to the pressure of one contact against Hertz's for the force P."""
    if d is None or "pressure" not in d or "x" not in d:
        check(False, f"{what}: Hertz half-width and peak pressure within {tol:.0%}", "no contact data")
        return
    estar = 1.0 / ((1.0 - nu1 ** 2) / E1 + (1.0 - nu2 ** 2) / E2)
    a_h = math.sqrt(4.0 * P * R / (math.pi * estar))
    p0_h = 2.0 * P / (math.pi * a_h)
    try:
        a, p0, _ = hertz_fit(d["x"], d["pressure"])
    except ValueError as e:
        check(False, f"{what}: Hertz half-width and peak pressure within {tol:.0%}", str(e))
        return
    check(abs(a / a_h - 1.0) <= tol, f"{what}: half-width a within {tol:.0%} of Hertz",
          f"a={a:.5f}, Hertz {a_h:.5f}, {a / a_h - 1.0:+.2%}, {int(np.count_nonzero(d['pressure'] > 0))} nodes")
    check(abs(p0 / p0_h - 1.0) <= tol, f"{what}: peak pressure p0 within {tol:.0%} of Hertz",
          f"p0={p0:.4f}, Hertz {p0_h:.4f}, {p0 / p0_h - 1.0:+.2%}")


def write(tmp, name, lines):
    path = os.path.join(tmp, name + ".nml")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path


def stack_load(deck):
    """The downward load on body 1 of a deck: -t0_y x width of its &traction on body 1's top."""
    text = open(deck).read()
    width = None
    for g in namelist_groups(text, "body"):
        if re.search(r"\bid\s*=\s*1\b", g):
            width = float(re.search(r"\bwidth\s*=\s*([-+0-9.eE]+)", g).group(1))
    load = 0.0
    for g in namelist_groups(text, "traction"):
        if re.search(r"\bbody\s*=\s*1\b", g) and re.search(r"side\s*=\s*'top'", g, re.I):
            load -= float(re.search(r"\bt0\s*=\s*[-+0-9.eE]+\s*,\s*([-+0-9.eE]+)", g).group(1)) * width
    return load


tmp = tempfile.mkdtemp(prefix="rc_nbody_")
try:
    # ---- (1) three blocks, two pairs ------------------------------------------------------------
    deck = os.path.join(ROOT, "inputs", "stack3.nml")
    load = stack_load(deck)
    check(abs(load - 6.0e5) <= 1e-9 * 6.0e5, "stack3: the deck's load on body 1 is 1 MPa x 0.6 = 6e5", repr(load))
    pairs3 = {1: (1, 2), 2: (2, 3)}
    # today's two-body check: the upper two blocks alone, the middle one clamped below
    two = [ln for ln in open(deck).read().splitlines() if "&contact bodies = 2, 3" not in ln]
    text2 = "\n".join(two)
    text2 = text2[:text2.index("&body id = 3")] + text2[text2.index("&traction"):]
    text2 = text2.replace("young = 2.1e11, poisson = 0.3, left = 'roller' /",
                          "young = 2.1e11, poisson = 0.3, left = 'roller', bottom = 'clamped' /")
    d2 = write(tmp, "stack2", [text2])
    m2 = Run(tmp, "stack2_mono", d2, MONO)
    converged(m2, "stack3's upper two blocks (two bodies), monolithic")
    check_statics("upper two blocks, monolithic", m2, {1: (1, 2)}, {1: load})
    for op in ("'steklov'", "'harmonic'", "'constant', alpha=1e-12"):
        r = Run(tmp, "stack2_robin", d2, f"&solver robin_operator={op} /")
        converged(r, f"upper two blocks, robin_operator={op}")
        check_statics(f"upper two blocks, {op}", r, {1: (1, 2)}, {1: load})
        check_same(f"upper two blocks, {op}", r, m2, 1)

    mono = Run(tmp, "stack3_mono", deck, MONO)
    deck_valid(mono, "stack3", 3, 2)
    converged(mono, "stack3 monolithic", 3, 2)
    check_statics("stack3 monolithic", mono, pairs3, {1: load, 2: load})
    for op in ("'steklov'", "'harmonic'", "'constant', alpha=1e-12"):
        r = Run(tmp, "stack3_robin", deck, f"&solver method='robin', robin_operator={op} /")
        converged(r, f"stack3 robin_operator={op}", 3, 2)
        if r.res:
            info(f"stack3 robin_operator={op}: outer {r.res.get('outer')} inner {r.res.get('inner')}")
        check_statics(f"stack3 {op}", r, pairs3, {1: load, 2: load})
        check_same(f"stack3 {op}", r, mono, 2)

    # ---- (2) a disc between two plates ------------------------------------------------------------
    R, E_D, NU_D, E_P, NU_P = 1.0, 1000.0, 0.3, 2000.0, 0.25
    Q, W = 3.0, 2.0                       # pressure on the upper plate's top, its width: P = 6
    P = Q * W
    meshes = {"coarse": dict(n=40, nr=24), "fine": dict(n=80, nr=40)}
    for tag, kw in meshes.items():
        nn, nq = write_disc(os.path.join(tmp, f"disc_{tag}.msh"), R=R, **kw)
        info(f"disc mesh {tag}: {nn} nodes, {nq} quadrangles")
    plate = {"coarse": "nx=200, ny=100", "fine": "nx=400, ny=200"}   # h = 0.01 and 0.005

    # today's two-body check: the disc pressed into the lower plate by its upper arc's displacement
    for tag in meshes:
        lines = [f"&body id=1, mesh='disc_{tag}.msh', region='disc', young={E_D}, poisson={NU_D} /",
                 f"&body id=2, x0=-1.0, y0=-2.0, width=2.0, height=1.0, {plate[tag]}, young={E_P}, poisson={NU_P},"
                 " bottom='clamped' /",
                 "&boundary body=1, group='disc_axis', ux=0.0 /",
                 "&boundary body=1, group='disc_upper', uy=-0.02 /",
                 "&contact body1_group='disc_lower', body2_group='top' /",
                 "&solver tol=1e-11 /"]
        d2 = write(tmp, f"disc_plate_{tag}", lines)
        runs = {m: Run(tmp, f"disc_plate_{tag}_{m}", d2, f"&solver method='{m}' /") for m in ("robin", "monolithic")}
        if tag == "coarse":
            for m, r in runs.items():
                if r.ok:
                    d = pair_data(r, 1)[1]
                    P2 = vertical(d)
                    estar = 1.0 / ((1.0 - NU_D ** 2) / E_D + (1.0 - NU_P ** 2) / E_P)
                    a_h = math.sqrt(4.0 * P2 * R / (math.pi * estar))
                    try:
                        a, p0, _ = hertz_fit(d["x"], d["pressure"])
                    except ValueError as e:
                        info(f"disc on a plate, coarse mesh, {m}: no Hertz fit ({e})")
                        continue
                    info(f"disc on a plate, coarse mesh, {m}: P={P2:.5f}, a {a / a_h - 1.0:+.2%}, "
                         f"p0 {p0 / (2.0 * P2 / (math.pi * a_h)) - 1.0:+.2%} from Hertz")
                else:
                    info(f"disc on a plate, coarse mesh, {m}: no result ({r.why()})")
            continue
        for m, r in runs.items():
            if converged(r, f"disc on the lower plate (two bodies), {m}"):
                d = pair_data(r, 1)[1]
                P2 = vertical(d)
                check(P2 > 1.0, f"disc on the lower plate, {m}: the contact carries a force", f"P={P2:.5f}")
                hertz_check(f"disc on the lower plate, {m}", d, P2, R, E_D, NU_D, E_P, NU_P)
        check_same("disc on the lower plate", runs["robin"], runs["monolithic"], 1)

    # the N-body scene: inputs/disc_plates.nml, upper plate (1), disc (2), lower plate (3)
    d3 = os.path.join(ROOT, "inputs", "disc_plates.nml")
    text = open(d3).read()
    want = [f"width = {W}, height = 1.0, {plate['fine'].replace('=', ' = ')}", f"young = {E_P}, poisson = {NU_P}",
            f"mesh = 'gmsh/disc_plates.msh', region = 'disc', young = {E_D}, poisson = {NU_D}",
            f"side = 'top', t0 = 0.0, {-Q}"]
    check(all(w in text for w in want) and text.count(want[0]) == 2, "disc_plates.nml: the scene of this test",
          "; ".join(w for w in want if w not in text))
    with open(os.path.join(tmp, "disc_fine.msh"), "rb") as f1, \
            open(os.path.join(ROOT, "inputs", "gmsh", "disc_plates.msh"), "rb") as f2:
        check(f1.read() == f2.read(), "inputs/gmsh/disc_plates.msh is msh_disc.py's disc (R = 1, n = 80, nr = 40)")
    pairs_d = {1: (1, 2), 2: (2, 3)}
    runs = {m: Run(tmp, f"disc_plates_{m}", d3, f"&solver method='{m}' /") for m in ("robin", "monolithic")}
    deck_valid(runs["monolithic"], "disc between plates", 3, 2)
    for m, r in runs.items():
        converged(r, f"disc between plates, {m}", 3, 2)
        check_statics(f"disc between plates, {m}", r, pairs_d, {1: P, 2: P})
        data = pair_data(r, 2) if r.ok else {}
        for k, where in ((1, "upper"), (2, "lower")):
            hertz_check(f"disc between plates, {m}, {where} contact", data.get(k), P, R, E_D, NU_D, E_P, NU_P)
    check_same("disc between plates", runs["robin"], runs["monolithic"], 2)

    # ---- (3) 32 equal blocks ----------------------------------------------------------------------
    N = 32
    lines = [f"&body id={k}, x0=0.0, y0={float(N - k)}, width=1.0, height=1.0, nx=4, ny=4"
             + (", bottom='clamped'" if k == N else ", left='roller'") + " /" for k in range(1, N + 1)]
    lines.append("&traction body=1, side='top', t0=0.0, -1.0e6 /")
    lines += [f"&contact bodies={k},{k + 1}, groups='bottom','top' /" for k in range(1, N)]
    d32 = write(tmp, "stack32", lines)
    pairs32 = {k: (k, k + 1) for k in range(1, N)}
    loads32 = {k: 1.0e6 for k in pairs32}
    r = Run(tmp, "stack32_robin", d32, "&solver tol=1e-11 /")
    m = Run(tmp, "stack32_mono", d32, MONO)
    deck_valid(m, f"stack of {N}", N, N - 1)
    converged(r, f"stack of {N} blocks, default solver settings", N, N - 1)
    converged(m, f"stack of {N} blocks, monolithic", N, N - 1)
    if r.res:
        info(f"stack of {N}: outer {r.res.get('outer')} inner {r.res.get('inner')}, {r.wall:.2f} s")
    check_statics(f"stack of {N}", r, pairs32, loads32)
    check_statics(f"stack of {N} monolithic", m, pairs32, loads32)
    check_same(f"stack of {N}", r, m, N - 1)

    # ---- (4) 1,000 blocks: 40 columns of 25 --------------------------------------------------------
    COLS, ROWS = 40, 25
    lines, pairs_g, loads_g = [], {}, {}

    def bid(c, j):                       # column c, row j (0 at the top)
        return c * ROWS + j + 1
    for c in range(COLS):
        for j in range(ROWS):
            lines.append(f"&body id={bid(c, j)}, x0={1.5 * c}, y0={float(ROWS - 1 - j)}, width=1.0, height=1.0, "
                         "nx=2, ny=2" + (", bottom='clamped'" if j == ROWS - 1 else ", left='roller'") + " /")
    for c in range(COLS):
        q = 1.0e5 * (c + 1)
        lines.append(f"&traction body={bid(c, 0)}, side='top', t0=0.0, {-q} /")
        for j in range(ROWS - 1):
            k = len(pairs_g) + 1
            pairs_g[k] = (bid(c, j), bid(c, j + 1))
            loads_g[k] = q
    lines += [f"&contact bodies={a},{b}, groups='bottom','top' /" for a, b in pairs_g.values()]
    dg = write(tmp, "grid1000", lines)
    nb, npr = COLS * ROWS, len(pairs_g)
    r = Run(tmp, "grid_robin", dg, "&solver tol=1e-11 /")
    info(f"{nb} bodies, {npr} pairs, Robin (default settings): {r.wall:.2f} s wall (whole process)")
    m = Run(tmp, "grid_mono", dg, MONO)
    info(f"{nb} bodies, {npr} pairs, monolithic: {m.wall:.2f} s wall (whole process)")
    deck_valid(m, f"{nb} bodies", nb, npr)
    converged(r, f"{nb} bodies, default solver settings", nb, npr)
    converged(m, f"{nb} bodies, monolithic", nb, npr)
    check_statics(f"{nb} bodies", r, pairs_g, loads_g)
    check_same(f"{nb} bodies", r, m, npr)
finally:
    shutil.rmtree(tmp, ignore_errors=True)

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
