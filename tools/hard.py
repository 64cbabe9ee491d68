#!/usr/bin/env python3
"""Hard cases of robin_contact: numerical stability on badly scaled, nearly incompressible,
curved and floating scenes.

Runs every deck of inputs/hard/ (and inputs/table1/q1_24x16.nml as the unscaled reference
of the scale cases): each Robin variant of a deck plus the monolithic reference of the same
deck and mesh, and prints

  * the main table: case, operator/delta, status, outer, inner, residual, error against
    the monolithic solution (relative L2 of lam; '-' if lam_mono = 0), wall time, and
    whether the outcome is the one the deck's header expects;
  * Hertz: computed half-width a and pressure p(x) against Hertz for 4 meshes;
  * scaling: linearity error of the scaled loads and of the mm/N/MPa deck;
  * locking: total force and pressure roughness for nu = 0.3, 0.49, 0.4999, Q1 and P1,
    4 meshes.

Exit status: 1 if some run is a bug: 'converged' with an error against the monolithic
solution above 1e-5 (a wrong 'converged'), or a crash (exit code other than 0/2, an exit code
that contradicts the status, no result line, no result file, or a NaN/Inf in any numeric
dataset of the result file). Not-converged runs (status max_outer/diverged, exit 2) are
outcomes, not bugs; a different outcome than the deck header expects is only flagged in the
'expect' column. Wall times are printed, never asserted.

Outputs in results/hard/ (or --out): one .h5 and one .log per run, hard.txt (everything
printed), hard.md (the tables in Markdown), hard.csv (the main table).

Usage: tools/hard.py [--bin bin/robin_contact] [--out results/hard] [--only SUBSTRING]
Runs with OMP_NUM_THREADS=2 unless set. About 40 s on 2 cores.
"""
import math
import os
import re
import shlex
import sys
import time

import h5py
import numpy as np

from rc_results import contact_edges, hertz_pressure, hertz_zone, md_header, md_row, rel_err
from rc_run import run_solver, solver_env, tool_parser

BUG_TOL = 1.0e-5          # largest error against monolithic accepted from a 'converged' run

HARD = "inputs/hard"
PAPER = "inputs/table1/q1_24x16.nml"   # unscaled reference of the scale cases (not modified)


def solver(op, delta, acc="none", stop="increment"):
    return f"&solver method='robin', robin_operator='{op}', delta={delta}, acceleration='{acc}', stop='{stop}' /"


# Robin variants: (label, overrides). 'deck' = the deck's own &solver settings.
S95 = ("steklov d=0.95", [solver("steklov", 0.95)])
S50 = ("steklov d=0.5", [solver("steklov", 0.5)])
H50 = ("harmonic d=0.5", [solver("harmonic", 0.5)])
H50R = ("harmonic d=0.5 residual", [solver("harmonic", 0.5, stop="residual")])
S50AIT = ("steklov d=0.5 aitken", [solver("steklov", 0.5, "aitken")])
S50AND = ("steklov d=0.5 anderson", [solver("steklov", 0.5, "anderson")])
MONO = ["&solver method='monolithic' /"]
NOT = "not"    # expected not converged (max_outer or diverged)
CONV = "conv"  # expected converged
ANY = "any"    # either, honestly


def mesh_over(nx, ny):
    return [f"&body id=1, nx={nx}, ny={ny} /", f"&body id=2, nx={nx}, ny={ny} /"]


# Main table: (case label, deck, mesh overrides, [(variant, expectation)])
CASES = []
for c, lab in (("1e3", "1e3"), ("1e6", "1e6"), ("1em3", "1e-3"), ("1em6", "1e-6")):
    CASES.append((f"contrast E1/E2={lab}", f"{HARD}/contrast_{c}.nml", [],
                  [(S95, NOT), (S50, NOT), (H50, CONV), (H50R, CONV), (S50AIT, ANY), (S50AND, ANY)]))
CASES.append(("contrast E1/E2=1e-7", f"{HARD}/contrast_1em7.nml", [], [(S50, NOT), (H50, CONV), (H50R, CONV)]))
for el in ("q1", "p1"):
    for nu, lab in (("049", "0.49"), ("04999", "0.4999")):
        if (el, nu) == ("p1", "04999"):   # locked P1 bodies differ: an effective contrast
            v = [(S50, NOT), (("steklov d=0.1", [solver("steklov", 0.1)]), CONV), (H50, CONV), (H50R, CONV)]
        else:
            v = [(S50, CONV), (H50, CONV), (H50R, CONV)]
        CASES.append((f"incompressible {el.upper()} nu={lab}", f"{HARD}/incomp_{el}_nu{nu}.nml", [], v))
CASES += [
    ("partial: parabolic gap", f"{HARD}/partial_gap.nml", [], [(S95, CONV), (S50, CONV), (H50, CONV), (H50R, CONV)]),
    ("partial: lift-off", f"{HARD}/partial_lift.nml", [], [(S95, CONV), (S50, CONV), (H50, CONV), (H50R, CONV)]),
    ("Hertz 160x80", f"{HARD}/hertz.nml", mesh_over(160, 80), [(H50, CONV), (H50R, CONV)]),
    ("m=1 (1x1 cells)", f"{HARD}/single_node.nml", [], [(S95, CONV), (S50, CONV), (H50, CONV), (H50R, CONV)]),
    # cond(F1 + F2) ~ 5e6 here: a residual of 1e-6 (100 tol) is at the edge of what double
    # precision resolves, so either outcome is honest as long as a 'converged' is right
    ("m=2048 (2048x4 cells)", f"{HARD}/many_nodes.nml", [], [(S50, ANY), (H50, ANY), (H50R, ANY)]),
    # 300x1 cells: cond(F1 + F2) ~ 1e6, the residual 1e-8 is out of reach of double precision
    ("aspect 100 (300x1 cells)", f"{HARD}/aspect_tall.nml", [], [(S95, CONV), (S50, CONV), (H50, CONV), (H50R, ANY)]),
    ("aspect 100 (3x100 cells)", f"{HARD}/aspect_flat.nml", [], [(S95, CONV), (S50, CONV), (H50, CONV), (H50R, CONV)]),
    ("paper scene (unscaled)", PAPER, [], [(S95, CONV), (S50, CONV), (H50, CONV), (H50R, CONV)]),
    ("loads x1e-6", f"{HARD}/scale_1em6.nml", [], [(S95, CONV), (S50, CONV), (H50, CONV), (H50R, CONV)]),
    ("loads x1e6", f"{HARD}/scale_1e6.nml", [], [(S95, CONV), (S50, CONV), (H50, CONV), (H50R, CONV)]),
    ("paper scene in mm/N/MPa", f"{HARD}/paper_mm.nml", [], [(S95, CONV), (S50, CONV), (H50, CONV), (H50R, CONV)]),
    # bodies held only by contact: SMALBE-M subproblems, the projected inverse in the
    # harmonic operator. A soft floating body on a stiff one (E1/E2 = 1e-6) stalls near a
    # residual of 2e-7: the penalty-augmented Hessian's rounding, amplified by the contrast
    ("floating, contrast 1e6", f"{HARD}/floating_contrast_1e6.nml", [], [(S50, ANY), (H50, CONV), (H50R, ANY)]),
    ("floating, contrast 1e-6", f"{HARD}/floating_contrast_1em6.nml", [], [(S50, ANY), (H50, ANY), (H50R, ANY)]),
    ("floating, Q1 nu=0.4999", f"{HARD}/floating_incomp_q1_nu04999.nml", [], [(S50, ANY), (H50, CONV), (H50R, CONV)]),
    ("floating, sinks and tilts, partial", f"{HARD}/floating_partial_tilt.nml", [],
     [(S50, ANY), (H50, CONV), (H50R, CONV)]),
    ("delta=1", f"{HARD}/delta_1.nml", [], [(("steklov d=1", []), NOT)]),
    ("delta=0.01", f"{HARD}/delta_001.nml", [], [(("steklov d=0.01", []), ANY)]),
    ("constant alpha=1e-16", f"{HARD}/alpha_tiny.nml", [], [(("constant d=0.95", []), NOT)]),
    ("constant alpha=1e-6", f"{HARD}/alpha_huge.nml", [], [(("constant d=0.95", []), NOT)]),
]

HERTZ_MESHES = [(80, 40), (160, 80), (320, 160), (640, 320)]
# scale cases: deck -> factor of lam against the unscaled paper scene (lam_case = f * lam_ref)
SCALES = [("loads x1e-6", f"{HARD}/scale_1em6.nml", 1.0e-6),
          ("loads x1e6", f"{HARD}/scale_1e6.nml", 1.0e6),
          ("mm/N/MPa", f"{HARD}/paper_mm.nml", 1.0e-3)]
LOCK_MESHES = [(24, 16), (48, 32), (96, 64), (192, 128)]


class Runner:
    def __init__(self, binary, out, log):
        self.bin = binary
        self.out = out
        self.log = log
        self.bugs = []
        self.env = solver_env()

    def run(self, tag, deck, overrides):
        """Run one deck; returns a dict (status, outer, inner, residual, wall, lam, file, ok...)."""
        h5 = os.path.join(self.out, tag + ".h5")
        if os.path.exists(h5):
            os.remove(h5)
        cmd = [self.bin, deck] + list(overrides) + [f"&output file='{h5}' /"]
        cmdline = f"OMP_NUM_THREADS={self.env['OMP_NUM_THREADS']} " + " ".join(shell_word(c) for c in cmd)
        t0 = time.time()
        p, fields = run_solver(*cmd, env=self.env)
        elapsed = time.time() - t0
        with open(os.path.join(self.out, tag + ".log"), "w") as f:
            f.write("$ " + cmdline + "\n" + p.stdout + p.stderr + f"\n[exit {p.returncode}]\n")
        r = {"tag": tag, "cmd": cmdline, "exit": p.returncode, "elapsed": elapsed, "file": h5,
             "status": "crash", "outer": "-", "inner": "-", "residual": float("nan"),
             "wall": elapsed, "lam": None, "bound": float("nan"),
             "message": (p.stderr.strip().splitlines() or [""])[-1]}
        problems = []
        if p.returncode not in (0, 2):
            problems.append(f"exit code {p.returncode}")
        if fields is None:
            problems.append("no result line")
        else:
            r["status"] = fields.get("status", "?")
            r["outer"] = fields.get("outer", "-")
            r["inner"] = fields.get("inner", "-")
            r["m"] = fields.get("m", "-")
            r["residual"] = float(fields.get("residual", "nan"))
            r["wall"] = float(fields.get("wall_s", "nan"))
            if p.returncode == 0 and r["status"] != "converged":
                problems.append(f"exit 0 with status {r['status']}")
            if p.returncode == 2 and r["status"] == "converged":
                problems.append("exit 2 with status converged")
            if p.returncode == 2 and r["status"] not in ("max_outer", "diverged"):
                problems.append(f"exit 2 with status {r['status']}")
        if p.returncode in (0, 2):
            if not os.path.exists(h5):
                problems.append("no result file")
            else:
                try:
                    bad = nonfinite_datasets(h5)
                    if bad:
                        problems.append("NaN/Inf in " + ", ".join(bad[:6]) + (" ..." if len(bad) > 6 else ""))
                    with h5py.File(h5, "r") as f:
                        r["lam"] = np.array(f["/contact/normal_force"], dtype=float)
                        r["x"] = np.array(f["/contact/s"], dtype=float)
                        r["p"] = np.array(f["/contact/pressure"], dtype=float)
                        r["trib"] = np.array(f["/contact/tributary_length"], dtype=float)
                        r["deck_text"] = f["input_deck"][()].decode()
                        r["bound"] = float(f.attrs.get("error_bound", float("nan")))
                except (OSError, KeyError) as e:
                    problems.append(f"unreadable result file: {e}")
        if problems:
            self.bug(r, "; ".join(problems))
        return r

    def bug(self, r, what):
        r["bug"] = what
        self.bugs.append((r["tag"], what, r["cmd"]))

    def say(self, line=""):
        print(line, flush=True)
        self.log.append(line)

    def head(self, head, widths):
        """Print a table header in columns of the given widths; returns the table's Markdown lines."""
        self.say("  ".join(h.ljust(w) for h, w in zip(head, widths)))
        return md_header(head)

    def row(self, md, cells, widths):
        """Print a table row in columns of the given widths and add it to the Markdown lines md."""
        self.say("  ".join(c.ljust(w) for c, w in zip(cells, widths)))
        md.append(md_row(cells))


def shell_word(w):
    """A shell word for a copy-pasteable command line: namelist overrides in double quotes."""
    if re.fullmatch(r"[A-Za-z0-9_./=:+-]+", w):
        return w
    if not re.search(r'["$`\\!]', w):
        return '"' + w + '"'
    return shlex.quote(w)


def nonfinite_datasets(path):
    bad = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "fiuc":
            v = np.asarray(obj[()])
            if v.dtype.kind in "fc" and not np.all(np.isfinite(v)):
                bad.append("/" + name)
    with h5py.File(path, "r") as f:
        f.visititems(visit)
        for k, v in f.attrs.items():
            if isinstance(v, (float, np.floating)) and not np.isfinite(v):
                bad.append("@" + k)
    return bad


def fmt(v, spec=".2e"):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    return format(v, spec)


def tagname(deck, extra=""):
    return os.path.splitext(os.path.basename(deck))[0] + extra


def slug(label):
    return re.sub(r"[^A-Za-z0-9.]+", "_", label).strip("_")


# ---------------------------------------------------------------- main table
def main_table(R, only):
    rows = []
    results = {}
    for case, deck, mesh, variants in CASES:
        if only and only not in case and only not in deck:
            continue
        mtag = ""
        if mesh:
            mtag = "_" + "x".join(re.findall(r"nx=(\d+), ny=(\d+)", mesh[0])[0])
        base = tagname(deck, mtag)
        mono = R.run(base + "_mono", deck, mesh + MONO)
        results[(case, "monolithic")] = mono
        rows.append((case, "monolithic", mono, None, "conv"))
        for (label, over), expect in variants:
            r = R.run(base + "_" + slug(label), deck, mesh + over)
            err = rel_err(r["lam"], mono["lam"])
            r["err"] = err
            # a wrong 'converged' (lam_mono = 0 leaves no relative error: '-', not checked)
            if r["status"] == "converged" and "bug" not in r and mono["lam"] is not None \
                    and np.linalg.norm(mono["lam"]) > 0.0 and (err is None or err > BUG_TOL):
                R.bug(r, f"'converged' but error against monolithic {fmt(err)} > {BUG_TOL:g}")
            # the reported a posteriori bound must hold for every run that produced a result
            # (the bound is relative to the run's own |lam|, the error to |lam_mono|)
            # (the monolithic reference is itself inexact: its own bound is added, triangle
            # inequality; it matters where both are near rounding)
            if "bug" not in r and r["lam"] is not None and mono["lam"] is not None:
                e_abs = float(np.linalg.norm(r["lam"] - mono["lam"]))
                allowed = (r["bound"] * float(np.linalg.norm(r["lam"]))
                           + (mono["bound"] if math.isfinite(mono["bound"]) else 0.0)
                           * float(np.linalg.norm(mono["lam"])))
                if not e_abs <= allowed * (1 + 1e-9):
                    R.bug(r, f"error against monolithic {e_abs:.3e} above the reported bounds "
                             f"{allowed:.3e} (absolute, the run's plus the reference's)")
            results[(case, label)] = r
            rows.append((case, label, r, err, expect))
    head = ("case", "operator/delta", "status", "outer", "inner", "residual", "err_vs_mono", "bound", "wall_s",
            "expect")
    widths = (26, 25, 10, 6, 7, 9, 11, 9, 7, 14)
    R.say("== main table (err_vs_mono: |lam - lam_mono| / |lam_mono|; bound: the run's reported a posteriori")
    R.say("   bound of err_vs_mono, which must hold; wall_s: the solver's own) ==")
    md = R.head(head, widths)
    csv = [",".join(head) + ",exit,bug"]
    for case, label, r, err, expect in rows:
        st = r["status"]
        if expect == CONV:
            ok = st == "converged"
        elif expect == NOT:
            ok = st in ("max_outer", "diverged")
        else:
            ok = st in ("converged", "max_outer", "diverged")
        exp = {CONV: "conv", NOT: "not conv", ANY: "either"}[expect] + ("" if ok else " UNEXPECTED")
        if "bug" in r:
            exp = "BUG"
        cells = (case, label, st, str(r["outer"]), str(r["inner"]), fmt(r["residual"], ".1e"),
                 "ref" if label == "monolithic" else fmt(err), fmt(r["bound"], ".1e"), fmt(r["wall"], ".2f"), exp)
        R.row(md, cells, widths)
        csv.append(",".join(c.replace(",", ";") for c in cells) + f",{r['exit']},{r.get('bug', '')}")
    return results, md, csv


# ---------------------------------------------------------------- Hertz
def deck_value(text, body, key):
    """Value of `key` in &body id=<body> of an effective deck (None for other groups)."""
    if body is None:
        m = re.search(key + r"=([-+0-9.eE]+)", text)
        return float(m.group(1)) if m else None
    for grp in re.findall(r"&body(.*?)/", text, re.S):
        if re.search(rf"\bid={body}\b", grp):
            m = re.search(key + r"=([-+0-9.eE]+)", grp)
            return float(m.group(1)) if m else None
    return None


def hertz_analysis(r):
    t = r["deck_text"]
    E1, E2 = deck_value(t, 1, "young"), deck_value(t, 2, "young")
    n1, n2 = deck_value(t, 1, "poisson"), deck_value(t, 2, "poisson")
    R_ = deck_value(t, None, "gap_radius")
    xc = deck_value(t, None, "gap_center")
    Es = 1.0 / ((1 - n1 ** 2) / E1 + (1 - n2 ** 2) / E2)          # plane strain
    lam, x, p, trib = r["lam"], r["x"], r["p"], r["trib"]
    P = float(lam.sum())
    a_h, p0 = hertz_zone(P, R_, Es)
    act = np.nonzero(lam > 0)[0]
    i0, i1 = act[0], act[-1]
    h = float(np.median(np.diff(x)))
    # edge of the contact zone: zero of p^2 extrapolated from the two outermost active
    # nodes, kept between the last active and the first open node (rc_results.contact_edges)
    xl, xr = contact_edges(x, p, lam)
    a_num = 0.5 * (xr - xl)
    ph = hertz_pressure(x, xc, a_h, p0)
    zone = (ph > 0) | (lam > 0)
    l2 = math.sqrt(np.sum(trib[zone] * (p[zone] - ph[zone]) ** 2) / np.sum(trib[zone] * ph[zone] ** 2))
    core = np.abs(x - xc) < 0.8 * a_h
    l2c = math.sqrt(np.sum(trib[core] * (p[core] - ph[core]) ** 2) / np.sum(trib[core] * ph[core] ** 2))
    # a must lie between the half extent of the active nodes and that of the first open ones
    lo = 0.5 * (x[i1] - x[i0])
    hi = 0.5 * (x[min(i1 + 1, len(x) - 1)] - x[max(i0 - 1, 0)])
    return {"l2core": l2c, "bracket": lo <= a_h <= hi, "h": h, "m": len(x), "active": len(act), "P": P, "a_h": a_h, "a_num": a_num,
            "err_a": abs(a_num - a_h) / a_h, "p0": p0, "pmax": float(p.max()),
            "err_p0": abs(float(p.max()) - p0) / p0, "l2": l2, "center": 0.5 * (xl + xr) - xc,
            "nodes_in_a": int(np.sum(np.abs(x - xc) < a_h))}


def hertz_study(R, results):
    deck = f"{HARD}/hertz.nml"
    R.say("")
    R.say("== Hertz line contact (monolithic; 40x20 blocks, R = 100, E = 2.1e11, nu = 0.3, plane strain) ==")
    R.say("a_H = sqrt(4 P R / (pi E*)) and p0 = 2 P / (pi a_H) from the computed P = sum(lam); a_num: zero of p^2")
    R.say("extrapolated from the two outermost active nodes on each side; L2: relative L2 of p - p_Hertz over the")
    R.say("nodes where either is > 0 (weights: tributary lengths), L2 core: the same over |x - xc| < 0.8 a_H;")
    R.say("order: log2 of the error ratio to the coarser mesh; in: a_H between the half extents of the active")
    R.say("nodes and of the first open ones. Last row: blocks twice as large (80x40 m) at h = 1/8: the finite-block")
    R.say("error (plateau of 'L2 core' and 'err p0') shrinks, the blocks of the study are not half-planes.")
    head = ("mesh", "h", "active", "P [N/m]", "a_H", "a_num", "in", "err a", "p0 [Pa]", "err p0", "L2 err p",
            "L2 core", "order a", "order L2", "order core")
    widths = (15, 7, 6, 10, 7, 7, 3, 8, 9, 8, 8, 8, 7, 8, 10)
    md = R.head(head, widths)
    prev = None
    out = []
    runs = [(f"{nx}x{ny}", nx, ny, []) for nx, ny in HERTZ_MESHES]
    runs.append(("640x320 big", 640, 320, ["&body id=1, y0=40.0, width=80.0, height=40.0 /",
                                           "&body id=2, width=80.0, height=40.0 /", "&contact gap_center=40.0 /"]))
    for name, nx, ny, extra in runs:
        key = ("Hertz 160x80", "monolithic") if (nx, ny) == (160, 80) else None
        r = results.get(key) if key else None
        if r is None:
            r = R.run(f"hertz_{slug(name)}_mono", deck, mesh_over(nx, ny) + extra + MONO)
        if r["lam"] is None or "bug" in r:
            R.say(f"{nx}x{ny}: no result ({r.get('bug', r['status'])})")
            continue
        a = hertz_analysis(r)
        o_a = o_l2 = o_c = None
        if prev is not None and not extra:
            o_a = math.log2(prev["err_a"] / a["err_a"]) if a["err_a"] > 0 and prev["err_a"] > 0 else None
            o_l2 = math.log2(prev["l2"] / a["l2"])
            o_c = math.log2(prev["l2core"] / a["l2core"])
        cells = (name, f"{a['h']:.4g}", str(a["active"]), f"{a['P']:.4e}",
                 f"{a['a_h']:.4f}", f"{a['a_num']:.4f}", "yes" if a["bracket"] else "NO", f"{a['err_a']:.2e}",
                 f"{a['p0']:.3e}", f"{a['err_p0']:.2e}", f"{a['l2']:.2e}", f"{a['l2core']:.2e}",
                 fmt(o_a, ".2f"), fmt(o_l2, ".2f"), fmt(o_c, ".2f"))
        R.row(md, cells, widths)
        out.append(a)
        prev = a
    return md


# ---------------------------------------------------------------- scaling
def scaling_study(R, results):
    R.say("")
    R.say("== scaling (linear problem: lam_case / factor must equal lam of the unscaled paper scene) ==")
    head = ("case", "factor", "variant", "outer", "outer ref", "linearity err", "x err", "p err")
    widths = (12, 7, 23, 6, 9, 13, 8, 8)
    md = R.head(head, widths)
    variants = ["monolithic"] + [v[0][0] for v in CASES[[c[0] for c in CASES].index("paper scene (unscaled)")][3]]
    for case, deck, fac in SCALES:
        label = [c[0] for c in CASES if c[1] == deck][0]
        for v in variants:
            r = results.get((label, v))
            ref = results.get(("paper scene (unscaled)", v))
            if r is None or ref is None or r["lam"] is None or ref["lam"] is None:
                continue
            lin = rel_err(r["lam"] / fac, ref["lam"])
            xf = 1.0e3 if "mm" in case else 1.0
            pf = 1.0e-6 if "mm" in case else fac    # mm: pressure in MPa = 1e-6 Pa
            xe = float(np.max(np.abs(r["x"] / xf - ref["x"])) / np.max(np.abs(ref["x"])))
            pe = rel_err(r["p"] / pf, ref["p"])
            cells = (case, f"{fac:g}", v, str(r["outer"]), str(ref["outer"]), fmt(lin), fmt(xe, ".1e"), fmt(pe, ".1e"))
            R.row(md, cells, widths)
    return md


# ---------------------------------------------------------------- contrast ladder
LADDER = [(16, 8), (32, 16), (64, 32), (128, 64), (256, 128)]
CONTRASTS = [1e-6, 1e-3, 1.0, 1e3, 1e6]


def contrast_ladder(R):
    """The harmonic operator's target: at most 20 outer iterations at tol 1e-8 for every
    contrast E1/E2 from 1e-6 to 1e6 and every mesh of the ladder (pushed scene)."""
    R.say("")
    R.say("== contrast ladder: harmonic operator, delta 0.5, tol 1e-8 (pushed scene); cells: outer/inner, err vs monolithic ==")
    head = ["mesh"] + [f"E1/E2={c:g}" for c in CONTRASTS]
    widths = [22] * len(head)
    md = R.head(head, widths)
    worst = 0
    for nx, ny in LADDER:
        cells = [f"{nx}x{ny}"]
        for c in CONTRASTS:
            e2 = 2.1e11 / c
            over = [f"&body id=1, nx={nx}, ny={ny} /", f"&body id=2, nx={nx}, ny={ny}, young={e2:.6e} /"]
            tag = f"ladder_{nx}x{ny}_c{c:g}"
            r = R.run(tag, f"{HARD}/contrast_1e6.nml", over + [solver("harmonic", 0.5)])
            m = R.run(tag + "_mono", f"{HARD}/contrast_1e6.nml", over + MONO)
            err = rel_err(r["lam"], m["lam"]) if r["lam"] is not None and m["lam"] is not None else None
            if r["status"] == "converged" and err is not None and err > BUG_TOL:
                R.bug(r, f"converged but err {err:.2e} > {BUG_TOL:g}")
            if r["status"] == "converged":
                worst = max(worst, int(r["outer"]))
                cells.append(f"{r['outer']}/{r['inner']} {fmt(err)}")
            else:
                worst = 10 ** 9
                cells.append(f"{r['status']} {r['outer']}")
        R.row(md, cells, widths)
    R.say("largest outer count: " + (str(worst) if worst < 10 ** 9 else "not all converged") +
          " (target <= 20)")
    return md


# ---------------------------------------------------------------- locking
def locking_study(R):
    R.say("")
    R.say("== near incompressibility (monolithic, pushed scene, equal bodies, plane strain) ==")
    R.say("P: total contact force [N/m]; P/P(0.3): against nu = 0.3, same element and mesh; dP: change to the")
    R.say("next finer mesh; open: contact nodes with lam = 0; spike: max |p_i - (p_i-1 + p_i+1)/2| / mean p over the")
    R.say("middle 80% of the line (ends excluded); pmax/pmean over the whole line")
    head = ("element", "nu", "mesh", "open", "P [N/m]", "P/P(0.3)", "dP finer", "spike", "pmax/pmean")
    widths = (7, 6, 7, 4, 10, 8, 9, 8, 10)
    md = R.head(head, widths)
    data = {}
    for el in ("q1", "p1"):
        for nu, deck, over in (("0.3", f"{HARD}/incomp_{el}_nu049.nml", "poisson=0.3, "),
                               ("0.49", f"{HARD}/incomp_{el}_nu049.nml", ""),
                               ("0.4999", f"{HARD}/incomp_{el}_nu04999.nml", "")):
            for nx, ny in LOCK_MESHES:
                r = R.run(f"lock_{el}_nu{nu}_{nx}x{ny}_mono", deck,
                          [f"&body id={b}, {over}nx={nx}, ny={ny} /" for b in (1, 2)] + MONO)
                data[(el, nu, nx)] = r
    for el in ("q1", "p1"):
        for nu in ("0.3", "0.49", "0.4999"):
            for k, (nx, ny) in enumerate(LOCK_MESHES):
                r = data[(el, nu, nx)]
                if r["lam"] is None:
                    continue
                P = float(r["lam"].sum())
                P3 = float(data[(el, "0.3", nx)]["lam"].sum())
                dP = None
                if k + 1 < len(LOCK_MESHES):
                    rf = data[(el, nu, LOCK_MESHES[k + 1][0])]
                    if rf["lam"] is not None:
                        dP = (float(rf["lam"].sum()) - P) / P
                p, x = r["p"], r["x"]
                mid = np.abs(x - 0.5 * (x[0] + x[-1])) < 0.4 * (x[-1] - x[0])
                mid[0] = mid[-1] = False
                idx = np.nonzero(mid)[0]
                spike = float(np.max(np.abs(p[idx] - 0.5 * (p[idx - 1] + p[idx + 1]))) / np.mean(p[idx]))
                cells = (el.upper(), nu, f"{nx}x{ny}", str(int(np.sum(r["lam"] <= 0))), f"{P:.4e}", f"{P / P3:.3f}",
                         fmt(dP, "+.2%"), f"{spike:.3f}", f"{p.max() / np.mean(p):.3f}")
                R.row(md, cells, widths)
    return md


def main():
    ap = tool_parser(__doc__)
    ap.add_argument("--out", default="results/hard")
    ap.add_argument("--only", default="", help="run only the main-table cases whose label or deck contains this")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    log = []
    R = Runner(a.bin, a.out, log)
    t0 = time.time()
    results, md_main, csv = main_table(R, a.only)
    md_h = md_s = md_l = md_c = []
    if not a.only:
        md_h = hertz_study(R, results)
        md_s = scaling_study(R, results)
        md_l = locking_study(R)
        md_c = contrast_ladder(R)
    R.say("")
    if R.bugs:
        R.say(f"== {len(R.bugs)} BUG(S) ==")
        for tag, what, cmd in R.bugs:
            R.say(f"BUG {tag}: {what}")
            R.say(f"    {cmd}")
    else:
        R.say("no bugs: every run is within its reported error bound and every 'converged' run matches the monolithic solution within "
              f"{BUG_TOL:g}; no crash, no NaN")
    R.say(f"hard: total {time.time() - t0:.1f} s, outputs in {a.out}/")
    with open(os.path.join(a.out, "hard.txt"), "w") as f:
        f.write("\n".join(log) + "\n")
    with open(os.path.join(a.out, "hard.csv"), "w") as f:
        f.write("\n".join(csv) + "\n")
    with open(os.path.join(a.out, "hard.md"), "w") as f:
        for title, md in (("Main table", md_main), ("Hertz", md_h), ("Scaling", md_s), ("Locking", md_l),
                          ("Contrast ladder", md_c)):
            if md:
                f.write(f"## {title}\n\n" + "\n".join(md) + "\n\n")
    return 1 if R.bugs else 0


if __name__ == "__main__":
    sys.exit(main())
