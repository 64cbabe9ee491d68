#!/usr/bin/env python3
"""Reproduce the paper's Table 1: outer/inner iteration counts of the Robin method on
the paper's scene for four meshes and five relaxation parameters, beside the paper's
numbers, plus per mesh the largest relative difference of the contact force lam from
the monolithic solution of the same discrete problem.

Usage: tools/table1.py [--bin bin/robin_contact] [--out results/table1] [--csv FILE]
                       [--meshes 3x1,6x2,16x8,24x16] [--deltas 0.1,0.5,0.7,0.95,1]
                       [--extra '&solver ... /']
"""
import os
import sys

import numpy as np

from rc_results import read_lam
from rc_run import run_solver, tool_parser

PAPER = {  # n/m -> {delta: (outer, inner) or None}
    "3x1": ("12/3", {0.1: (287, 903), 0.5: (76, 243), 0.7: (62, 208), 0.95: (47, 160), 1.0: None}),
    "6x2": ("36/6", {0.1: (285, 899), 0.5: (79, 272), 0.7: (66, 237), 0.95: (49, 179), 1.0: None}),
    "16x8": ("288/16", {0.1: (270, 878), 0.5: (74, 282), 0.7: (79, 295), 0.95: (45, 188), 1.0: None}),
    "24x16": ("816/24", {0.1: (296, 957), 0.5: (92, 332), 0.7: (93, 340), 0.95: (47, 204), 1.0: None}),
}

def run(binary, deck, overrides):
    p, fields = run_solver(binary, deck, *overrides)
    if fields is None:
        sys.stderr.write(p.stdout[-2000:] + p.stderr[-2000:])
        raise SystemExit(f"table1: no result line from {deck} {overrides} (exit {p.returncode})")
    fields["exit"] = p.returncode
    return fields


def main():
    ap = tool_parser(__doc__)
    ap.add_argument("--decks", default="inputs/table1")
    ap.add_argument("--out", default="results/table1")
    ap.add_argument("--csv", default=None)
    ap.add_argument("--meshes", default="3x1,6x2,16x8,24x16")
    ap.add_argument("--deltas", default="0.1,0.5,0.7,0.95,1")
    ap.add_argument("--extra", action="append", default=[], help="extra namelist override for every run")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    meshes = a.meshes.split(",")
    deltas = [float(x) for x in a.deltas.split(",")]
    rows = []
    csv = ["mesh,n,m,delta,status,outer,inner,residual,lam_rel_diff,wall_s"]
    for mesh in meshes:
        deck = os.path.join(a.decks, f"q1_{mesh}.nml")
        mono_file = os.path.join(a.out, f"q1_{mesh}_mono.h5")
        mono = run(a.bin, deck, a.extra + ["&solver method='monolithic' /", f"&output file='{mono_file}' /"])
        lam_ref = read_lam(mono_file)
        cells, diffs = [], []
        for dl in deltas:
            f = os.path.join(a.out, f"q1_{mesh}_d{dl:g}.h5")
            r = run(a.bin, deck, a.extra + [f"&solver method='robin', delta={dl} /", f"&output file='{f}' /"])
            diff = float("nan")
            if r["status"] == "converged":
                lam = read_lam(f)
                diff = np.linalg.norm(lam - lam_ref) / max(np.linalg.norm(lam_ref), 1e-300)
                diffs.append(diff)
                cells.append(f"{r['outer']}/{r['inner']}")
            else:
                cells.append("—")
            csv.append(f"{mesh},{r['n1']},{r['m']},{dl:g},{r['status']},{r['outer']},{r['inner']},"
                       f"{r['residual']},{diff:.3e},{r['wall_s']}")
        rows.append((mesh, f"{mono['n1']}/{mono['m']}", cells, max(diffs) if diffs else float("nan"), mono))
    w = 11
    head = "| n/m      | " + " | ".join(f"delta={d:<5g}".ljust(w) for d in deltas) + " | max |lam-lam_mono|/|lam_mono| |"
    print("Robin method (this code), cells IT_outer/IT_inner, '—' = not converged in 800:")
    print(head)
    print("|" + "-" * (len(head) - 2) + "|")
    for mesh, nm, cells, diff, mono in rows:
        print(f"| {nm:<8} | " + " | ".join(c.ljust(w) for c in cells) + f" | {diff:.2e} |")
    print()
    print("Paper (Sassi, Ipopa, Roux, Table 1):")
    print(head.split(" max")[0])
    for mesh in meshes:
        nm, pd = PAPER.get(mesh, (mesh, {}))
        cells = []
        for d in deltas:
            v = pd.get(d)
            cells.append("—" if v is None else f"{v[0]}/{v[1]}")
        print(f"| {nm:<8} | " + " | ".join(c.ljust(w) for c in cells) + " |")
    print()
    print("Monolithic reference (same discrete problem, MPRGP on the condensed interface QP):")
    for mesh, nm, cells, diff, mono in rows:
        print(f"  {nm:<8} inner={mono['inner']} residual={mono['residual']} status={mono['status']}")
    if a.csv:
        with open(a.csv, "w") as fh:
            fh.write("\n".join(csv) + "\n")


if __name__ == "__main__":
    main()
