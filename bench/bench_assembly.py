#!/usr/bin/env python3
"""Assembly rate per DOF: the paper's scene as a Gmsh (unstructured P1) deck against the
structured rectangle deck at about the same DOF count, P1 and Q1.

The `assemble=` field of the program's `time:` line covers reading the mesh, building the
stiffness pattern, assembling both bodies and the mortar coupling. The runs stop after one
outer iteration (max_outer=1, exit 2): only the assembly phase is measured. Each binary of
--bin runs each case --repeat times, interleaved (the machine may be shared), and the
fastest run is kept. The mesh comes from inputs/gmsh/bench_paper_tri.geo (gmsh, kept in the
work folder).

Usage: /usr/bin/python3 bench/bench_assembly.py [--h 0.005] [--repeat 5] [--threads 2]
                                               [--bin bin/robin_contact[,other/bin/robin_contact]]
Prints one Markdown row per binary and case: DOFs, assemble [s], microseconds per DOF and the
ratio to the structured P1 rate of the same binary.
"""
import argparse
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
from rc_run import result_fields, solver_env, time_fields  # noqa: E402
from bench_gmsh import DECK as GMSH_DECK, make_mesh  # noqa: E402  (the same scene and meshes)

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DEFAULT_DECK = os.path.join(ROOT, "inputs", "default.nml")

SOLVER = "&solver method='robin', robin_operator='harmonic', delta=0.5, max_outer=1 /"


def run(binary, args, threads, workdir):
    out = os.path.join(workdir, "run.h5")
    p = subprocess.run([binary] + args + [SOLVER, f"&output file='{out}', progress_lines=0 /"],
                       capture_output=True, text=True, env=solver_env(threads))
    t, r = time_fields(p.stdout), result_fields(p.stdout)
    if t is None or r is None:
        raise SystemExit(f"bench_assembly: no time/result line from {binary} {args}:\n{p.stdout}{p.stderr}")
    return float(t["assemble"]), int(r["n1"]) + int(r["n2"])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--h", type=float, default=0.005, help="Gmsh mesh size (upper body)")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"), help="comma list of binaries")
    ap.add_argument("--workdir", default=os.path.join(ROOT, "results", "bench_assembly"))
    a = ap.parse_args()
    os.makedirs(a.workdir, exist_ok=True)
    msh, _, _ = make_mesh(a.h, 1.07, a.workdir, "gmsh")   # bench_paper_tri.geo's default ratio
    deck = os.path.join(a.workdir, "gmsh.nml")
    with open(deck, "w") as f:
        f.write(GMSH_DECK.format(h=f"{a.h:g}", msh=msh))
    bins = [os.path.abspath(b) for b in a.bin.split(",") if b]
    # the structured meshes: nx = 2 ny per body, the DOF count of the Gmsh scene
    _, ndof = run(bins[0], [deck], a.threads, a.workdir)
    ny = round(((ndof / 4) / 2) ** 0.5)
    cases = [("gmsh P1", [deck])]
    for elem in ("P1", "Q1"):
        cases.append((f"structured {elem} {2 * ny}x{ny}",
                      [DEFAULT_DECK] + [f"&body id={i}, nx={2 * ny}, ny={ny}, element='{elem}' /" for i in (1, 2)]))
    best = {}
    for _ in range(a.repeat):
        for b in bins:
            for label, args in cases:
                t, n = run(b, args, a.threads, a.workdir)
                key = (b, label)
                if key not in best or t < best[key][0]:
                    best[key] = (t, n)
    print("| binary | case | DOFs (both bodies) | assemble [s] | us/DOF | / structured P1 |")
    print("| --- | --- | --- | --- | --- | --- |")
    for b in bins:
        ref = best[(b, cases[1][0])]
        for label, _ in cases:
            t, n = best[(b, label)]
            print(f"| {os.path.relpath(b, ROOT)} | {label} | {n:,} | {t:.3f} | {1e6 * t / n:.2f} | "
                  f"{(t / n) / (ref[0] / ref[1]):.2f} |")


if __name__ == "__main__":
    main()
