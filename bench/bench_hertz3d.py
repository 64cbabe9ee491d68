#!/usr/bin/python3
"""Hertz in 3D, a ladder of meshes: the sphere on a block of inputs/sphere_block.nml (a quarter
model, R = 1, E = 1000, nu = 0.3, the sphere's top pushed down by 0.012) on Gmsh tetrahedra of
size hc within rc = 0.15 of the contact point (inputs/gmsh/sphere_block.geo), at the default
outer tolerance (1e-8; see tools/hertz3d_study.py for why not the deck's 1e-10).

Meshes: written by gmsh into the work folder (default results/bench_hertz3d/) and reused while
the .geo is unchanged; never committed. Measured with gmsh 4.8 on the 2-core VM: hc = 0.005
(82k DOFs) in about 10 s, hc = 0.0028 (about 470k DOFs) in about 2 min.

Per level: DOFs of each body, contact rows, status, outer iterations, the phase times of the
program's `time:` line (factor, condense, iterate, total), the contact phases (condense +
iterate) and the whole run as multiples of the factorization, the peak memory, the factor
memory against the estimate the memory check printed before factoring, and a and p0 of the
fitted Hertz shape against Hertz for the run's force (tools/hertz3d_study.py's fit). Prints a
Markdown table and writes results/bench_hertz3d.csv (with the inner products, `inner`, too);
exit 1 when a run fails (the table first).

The pair's slave is the deck's default (the sphere, whose contact group has the shorter mean
edge) unless --slave names a body (2: the block, whose flat top gives each row one displacement
component per node on both bodies); --method monolithic solves the same discrete problem in
one piece; --mu gives the pair Coulomb friction (the same meshes and factorizations; the
interface has three rows per contact node instead of one, less the tangents across the two
planes of symmetry).

Usage: bench/bench_hertz3d.py [--hc 0.01,0.005,0.0035] [--bin bin/robin_contact] [--gmsh gmsh]
                              [--workdir results/bench_hertz3d] [--threads 2] [--slave 0|1|2]
                              [--method robin|monolithic] [--mu 0.3]
  --hc 0.01,0.005,0.0035,0.0028   adds a level of about 2 x 235k DOFs (12 GB, several minutes)
"""
import argparse
import csv
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tools"))
from hertz3d_study import measure  # noqa: E402

RC = 0.15


def mesh(gmsh, geo, hc, work):
    out = os.path.join(work, f"sphere_block_hc{hc}.msh")
    if os.path.isfile(out) and os.path.getmtime(out) > os.path.getmtime(geo):
        return out
    tmp = out + ".part.msh"
    subprocess.run([gmsh, "-3", "-format", "msh41", "-v", "2", "-setnumber", "hc", repr(hc),
                    "-setnumber", "rc", repr(RC), geo, "-o", tmp], check=True)
    os.replace(tmp, out)
    return out


def solve(binary, msh, out, threads, slave=0, method="robin", mu=0.0):
    deck = os.path.join(ROOT, "inputs", "sphere_block.nml")
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    law = f", friction='coulomb', mu={mu}" if mu > 0 else ""
    cmd = [binary, deck, f"&body id=1, mesh='{msh}' /", f"&body id=2, mesh='{msh}' /",
           f"&solver tol=1e-8, method='{method}' /", f"&output file='{out}' /",
           f"&contact body1_group='sphere_arc', body2_group='block_top', slave={slave}{law} /"]
    t0 = time.time()
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    wall = time.time() - t0
    text = r.stdout + r.stderr
    line = lambda key: next((ln for ln in text.splitlines() if ln.startswith(key)), "")  # noqa: E731
    res = dict(re.findall(r"(\w+)=(\S+)", line("result:")))
    tim = {k: float(v) for k, v in re.findall(r"(\w+)=([0-9.]+)", line("time:"))}
    est = re.findall(r"body \d+ ([0-9.]+) (MiB|GiB)", line("phase: ordering"))
    est_mb = sum(float(v) * (1024.0 if u == "GiB" else 1.0) for v, u in est)
    row = {"exit": r.returncode, "status": res.get("status", "?"), "outer": res.get("outer", "?"),
           "inner": res.get("inner", "?"),
           "n1": res.get("n1", "?"), "n2": res.get("n2", "?"), "m": res.get("m", "?"), "wall": wall,
           "estimate_mb": est_mb}
    row.update(tim)
    if r.returncode == 0:
        P, a_h, p0_h, a_f, p0_f = measure(out)
        row.update(P=P, ea=a_f / a_h - 1, ep=p0_f / p0_h - 1)
    else:
        row["tail"] = text[-600:]
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--hc", default="0.01,0.005,0.0035")
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"))
    ap.add_argument("--gmsh", default="gmsh")
    ap.add_argument("--workdir", default=os.path.join(ROOT, "results", "bench_hertz3d"))
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--csv", default=os.path.join(ROOT, "results", "bench_hertz3d.csv"))
    ap.add_argument("--slave", type=int, default=0, choices=(0, 1, 2))
    ap.add_argument("--method", default="robin", choices=("robin", "monolithic"))
    ap.add_argument("--mu", type=float, default=0.0, help="Coulomb friction on the pair (0: frictionless)")
    a = ap.parse_args()
    os.makedirs(a.workdir, exist_ok=True)
    geo = os.path.join(ROOT, "inputs", "gmsh", "sphere_block.geo")
    rows = []
    for hc in [float(h) for h in a.hc.split(",")]:
        t0 = time.time()
        msh = mesh(a.gmsh, geo, hc, a.workdir)
        print(f"hc = {hc}: mesh {os.path.basename(msh)} ({time.time() - t0:.0f} s)", flush=True)
        row = solve(a.bin, msh, os.path.join(a.workdir, f"r{hc}.h5"), a.threads, a.slave, a.method, a.mu)
        row["hc"] = hc
        rows.append(row)
        print(f"hc = {hc}: exit {row['exit']}, {row.get('total', 0):.1f} s", flush=True)
    print(f"\nslave: {a.slave or 'the default'}, method: {a.method}, mu: {a.mu or 'none (frictionless)'}")
    print("\n| hc | DOFs (body 1 + 2) | rows | outer | inner | factor s | condense s | iterate s | total s "
          "| contact / factor | total / factor | peak MB | factor MB (estimate) | a error | p0 error |")
    print("| --- " * 15 + "|")
    bad = 0
    for r in rows:
        if r["exit"] != 0:
            bad += 1
            print(f"| {r['hc']} | {r['n1']} + {r['n2']} | {r['m']} | run failed (exit {r['exit']}, {r['status']}) |")
            continue
        f = r.get("factor", 0.0)
        print(f"| {r['hc']} | {r['n1']} + {r['n2']} | {r['m']} | {r['outer']} | {r['inner']} | {f:.1f} | {r['condense']:.1f} "
              f"| {r['iterate']:.1f} | {r['total']:.1f} | {(r['condense'] + r['iterate']) / f:.2f} "
              f"| {r['total'] / f:.2f} | {r['peak_mb']:.0f} | {r['factor_mb']:.0f} ({r['estimate_mb']:.0f}) "
              f"| {100 * r['ea']:+.2f}% | {100 * r['ep']:+.2f}% |")
    os.makedirs(os.path.dirname(a.csv), exist_ok=True)
    keys = ["hc", "n1", "n2", "m", "exit", "status", "outer", "inner", "factor", "condense", "iterate", "total", "peak_mb",
            "factor_mb", "estimate_mb", "P", "ea", "ep"]
    with open(a.csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    print(f"\nwritten: {a.csv}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
