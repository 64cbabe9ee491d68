#!/usr/bin/python3
"""Hertz ladder up to millions of DOFs: the force-controlled half-disc on a block
(inputs/hertz_force.nml: R = 1, E = 1000, nu = 0.3, P = 2 per unit thickness, the disc held
only by contact) with the deck's own solver (Robin, harmonic operator, delta 0.5, tol 1e-10),
at mesh sizes h = a/n near the contact point for the Hertz half-width a = 0.0683.

Meshes: inputs/gmsh/hertz_force.geo by gmsh with `-setnumber h a/n -setnumber dmin 0.1` (the
fine size within 0.1 of the contact point), written into the work folder (default
results/bench_hertz/) and reused while the .geo is unchanged; never committed. Measured with
gmsh 4.8 on the 2-core VM: n = 64 about 2 s, 256 about 1 min, 512 about 6 min (4.1M DOFs,
240 MB .msh), and the n = 512 solve needs about 7 GB.

Per level: DOFs, m (contact rows), status, outer / inner iterations, the factor, iterate and
total times of the program's `time:` line, its peak memory, and the contact pressure against
Hertz's for the computed force (the fit of tools/hertz_study.py: p^2 quadratic in x on the
nodes in contact): the relative errors of a and p0. Prints a Markdown table; exit 1 when a
run does not converge (the table is printed first).

Usage: bench/bench_hertz.py [--n 64,256] [--bin bin/robin_contact] [--gmsh gmsh]
                            [--workdir results/bench_hertz] [--threads 2]
  --n 64,256,512   adds the 4M-DOF level (about 6 min of meshing, 1.5 min of solving, 7 GB)
"""
import argparse
import math
import os
import re
import subprocess
import sys


HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tools"))
from hertz_study import hertz_fit, read_contact  # noqa: E402

A_HERTZ = 0.0683       # the half-width of inputs/hertz_force.nml's contact (P = 2, E = 1000, nu = 0.3, R = 1)
R = 1.0


def mesh(gmsh, geo, n, work):
    out = os.path.join(work, f"hertz_force_n{n}.msh")
    if os.path.isfile(out) and os.path.getmtime(out) > os.path.getmtime(geo):
        return out
    tmp = out + ".part.msh"
    subprocess.run([gmsh, "-2", "-format", "msh41", "-v", "2", "-setnumber", "h", repr(A_HERTZ / n),
                    "-setnumber", "dmin", "0.1", geo, "-o", tmp], check=True)
    os.replace(tmp, out)
    return out


def solve(binary, msh, out, threads):
    deck = os.path.join(ROOT, "inputs", "hertz_force.nml")
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    cmd = [binary, deck, f"&body id=1, mesh='{msh}' /", f"&body id=2, mesh='{msh}' /", f"&output file='{out}' /"]
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    text = r.stdout + r.stderr
    res = dict(re.findall(r"(\w+)=(\S+)", next((ln for ln in text.splitlines() if ln.startswith("result:")), "")))
    tim = dict(re.findall(r"(\w+)=([0-9.]+)", next((ln for ln in text.splitlines() if ln.startswith("time:")), "")))
    row = {"exit": r.returncode, "status": res.get("status", "?"), "outer": res.get("outer", "?"),
           "inner": res.get("inner", "?"), "dofs": res.get("dofs", "?"), "m": res.get("m", "?"),
           "factor": tim.get("factor", "?"), "iterate": tim.get("iterate", "?"), "total": tim.get("total", "?"),
           "peak": tim.get("peak_mb", "?"), "err_a": None, "err_p0": None}
    if r.returncode == 0:
        x, p, P, E, nu, _ = read_contact(out)
        es = E / (2.0 * (1.0 - nu ** 2))
        ah = math.sqrt(4.0 * P * R / (math.pi * es))
        a, p0, _ = hertz_fit(x, p)
        row["err_a"] = abs(a / ah - 1.0)
        row["err_p0"] = abs(p0 / (2.0 * P / (math.pi * ah)) - 1.0)
    else:
        row["tail"] = text.strip().splitlines()[-1] if text.strip() else ""
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", default="64,256", help="a/h levels, comma separated")
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"))
    ap.add_argument("--gmsh", default="gmsh")
    ap.add_argument("--workdir", default=os.path.join(ROOT, "results", "bench_hertz"))
    ap.add_argument("--threads", type=int, default=int(os.environ.get("OMP_NUM_THREADS", "2")))
    args = ap.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    geo = os.path.join(ROOT, "inputs", "gmsh", "hertz_force.geo")
    print(f"Hertz ladder (inputs/hertz_force.nml, its own solver), OMP_NUM_THREADS={args.threads}")
    print("| a/h | DOFs | m | status | outer / inner | factor [s] | iterate [s] | total [s] | peak MB "
          "| err a | err p0 |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    bad = 0
    for n in [int(v) for v in args.n.split(",")]:
        msh = mesh(args.gmsh, geo, n, args.workdir)
        r = solve(args.bin, msh, os.path.join(args.workdir, f"hertz_force_n{n}.h5"), args.threads)
        ea = "" if r["err_a"] is None else f"{r['err_a']:.2%}"
        ep = "" if r["err_p0"] is None else f"{r['err_p0']:.2%}"
        print(f"| {n} | {r['dofs']} | {r['m']} | {r['status']} | {r['outer']} / {r['inner']} | {r['factor']} | "
              f"{r['iterate']} | {r['total']} | {r['peak']} | {ea} | {ep} |", flush=True)
        if r["exit"] != 0:
            bad += 1
            print(f"  exit {r['exit']}: {r.get('tail', '')}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
