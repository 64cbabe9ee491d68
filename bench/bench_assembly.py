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

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
GEO = os.path.join(ROOT, "inputs", "gmsh", "bench_paper_tri.geo")
DEFAULT_DECK = os.path.join(ROOT, "inputs", "default.nml")

GMSH_DECK = """\
&scene title = 'bench_assembly: paper scene, unstructured P1', plane = 'strain', units = 'SI' /
&body id = 1, mesh = '{msh}', region = 'upper', young = 2.1e11, poisson = 0.277 /
&body id = 2, mesh = '{msh}', region = 'lower', young = 2.1e11, poisson = 0.277 /
&boundary body = 1, group = 'upper_left', ux = 0.0, uy = 0.0 /
&boundary body = 2, group = 'lower_left', ux = 0.0, uy = 0.0 /
&traction body = 1, group = 'upper_top', t0 = 0.0, -3.0e6, tx = 0.0, -1.0e6 /
&traction body = 1, group = 'upper_right', t0 = 0.0, 2.0e6 /
&contact body1_group = 'upper_bottom', body2_group = 'lower_top' /
"""
SOLVER = "&solver method='robin', robin_operator='harmonic', delta=0.5, max_outer=1 /"


def mesh_file(h, workdir):
    path = os.path.join(workdir, f"bench_paper_tri_h{h:g}.msh")
    if not (os.path.exists(path) and os.path.getmtime(path) >= os.path.getmtime(GEO)):
        sys.stderr.write(f"bench_assembly: gmsh h={h:g} -> {path}\n")
        subprocess.run(["gmsh", "-2", "-format", "msh41", "-v", "2", "-setnumber", "h", repr(h), GEO,
                        "-o", path], check=True)
    return path


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
    msh = mesh_file(a.h, a.workdir)
    deck = os.path.join(a.workdir, "gmsh.nml")
    with open(deck, "w") as f:
        f.write(GMSH_DECK.format(msh=msh))
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
