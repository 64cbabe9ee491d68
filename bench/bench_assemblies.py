#!/usr/bin/env python3
"""Assemblies: the inner solvers on inputs/lap_joint.nml (a bolted lap joint: four bodies,
Coulomb on three pairs, thin plates, m = 214 interface unknowns).

For load histories of 1 + 1 and 1 + 20 steps (`&solver load_steps=...`), by Robin (the
default operator) and monolithically, with each inner solver (`&solver inner_solver=`
'auto', 'active_set', 'mprgp'): the wall time (the `time:` line's total, fastest of
--repeat runs), the outer and inner counts (inner: products with the QPs' Hessians, the
active-set method's factorizations counted as the products of the same work), and the
largest difference of the nodal normal and tangential forces from the monolithic 'auto'
run of the same history, relative to the largest force. MPRGP alone is run only where
--mprgp says (its 1 + 20-step Robin run took 694 s before this benchmark existed); runs
longer than --timeout are reported as such.

  /usr/bin/python3 bench/bench_assemblies.py [--bin bin/robin_contact] [--repeat 3]
        [--mprgp 1] [--timeout 900]

Prints a Markdown table. A benchmark: it reports, it asserts nothing.
"""
import argparse
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_run import line_fields, result_fields, solver_env  # noqa: E402

DECK = os.path.join(ROOT, "inputs", "lap_joint.nml")


def forces(path):
    out = []
    with h5py.File(path, "r") as f:
        k = 1
        while f"contact/pair_{k}" in f:
            g = f[f"contact/pair_{k}"]
            out += [g["normal_force"][()], g["tangential_force"][()]]
            k += 1
    return np.concatenate(out)


def run(binary, steps, method, inner, tmp, timeout):
    h5 = os.path.join(tmp, f"{steps}_{method}_{inner}.h5")
    args = [binary, DECK, f"&solver load_steps=1,{steps}, method='{method}', inner_solver='{inner}' /",
            f"&output file='{h5}' /"]
    try:
        p = subprocess.run(args, capture_output=True, text=True, env=solver_env(), timeout=timeout)
    except subprocess.TimeoutExpired:
        return None
    res, tm = result_fields(p.stdout), line_fields(p.stdout, "time")
    if res is None or tm is None or not os.path.exists(h5):
        return {"status": f"exit {p.returncode}", "wall": float("nan"), "outer": "", "inner": "", "f": None}
    rec = {"status": res["status"], "wall": float(tm["total"]), "outer": res["outer"], "inner": res["inner"],
           "f": forces(h5)}
    os.remove(h5)
    return rec


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--mprgp", type=int, default=1, help="largest stage-2 step count run with MPRGP alone")
    ap.add_argument("--timeout", type=float, default=900.0)
    a = ap.parse_args()
    binary = os.path.abspath(a.bin)
    print("| steps | method | inner_solver | status | wall [s] | outer | inner | vs monolithic auto |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as tmp:
        for steps in (1, 20):
            ref = None
            for method in ("monolithic", "robin"):
                for inner in ("auto", "active_set", "mprgp"):
                    if inner == "mprgp" and steps > a.mprgp:
                        print(f"| 1 + {steps} | {method} | {inner} | not run (--mprgp {a.mprgp}) | | | | |")
                        continue
                    best = None
                    for _ in range(a.repeat if inner != "mprgp" else 1):
                        r = run(binary, steps, method, inner, tmp, a.timeout)
                        if r is None:
                            best = None
                            break
                        if best is None or r["wall"] < best["wall"]:
                            best = r
                    if best is None:
                        print(f"| 1 + {steps} | {method} | {inner} | over {a.timeout:.0f} s | | | | |")
                        continue
                    if method == "monolithic" and inner == "auto":
                        ref = best["f"]
                    d = ""
                    if ref is not None and best["f"] is not None:
                        d = f"{np.abs(best['f'] - ref).max() / np.abs(ref).max():.1e}"
                    print(f"| 1 + {steps} | {method} | {inner} | {best['status']} | {best['wall']:.3f} | "
                          f"{best['outer']} | {best['inner']} | {d} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
