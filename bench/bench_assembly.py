#!/usr/bin/env python3
"""Assembly rate per DOF: the paper's scene as a Gmsh deck (unstructured triangles, and
unstructured quadrangles: the same .geo recombined) against the structured rectangle deck
at about the same DOF count, P1 against the triangles and Q1 against the quadrangles.

Two measures of each case:
- `assemble=` of the program's `time:` line (wall time, the bodies on --threads threads):
  reading the mesh, building the stiffness pattern, assembling both bodies and the mortar
  coupling. The runs stop after one outer iteration (max_outer=1, exit 2).
- with --harness (build/release/bench/bench_assembly_rate, one per --bin): the same reading
  and assembly on one thread, timed apart in CPU time, which holds on a shared machine:
  read + assemble, and assemble alone (assemble_body: the stiffness pattern, the element
  loop and the loads).
Each binary runs each case --repeat times, interleaved (the machine may be shared), and the
fastest run is kept. The triangle mesh comes from inputs/gmsh/bench_paper_tri.geo at --h,
the quadrangle mesh from the same file with Mesh.RecombineAll at --quad-h (gmsh; both kept
in the work folder).

Usage: /usr/bin/python3 bench/bench_assembly.py [--h 0.005] [--quad-h 0.01] [--repeat 5]
           [--threads 2] [--bin bin/robin_contact[,other/bin/robin_contact]]
           [--harness build/release/bench/bench_assembly_rate[,other/...]]
Prints one Markdown row per binary and case: DOFs, assemble [s], microseconds per DOF and
the ratio to the structured rate of the same element and binary.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
from rc_run import result_fields, solver_env, time_fields  # noqa: E402
from bench_gmsh import DECK as GMSH_DECK, GEO, make_mesh  # noqa: E402  (the same scene and meshes)

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


def run_harness(harness, args, workdir, repeat):
    """(read CPU seconds, assemble CPU seconds, free DOFs) of the one-thread harness."""
    env = solver_env(1)
    env["BENCH_REPEAT"] = str(repeat)
    p = subprocess.run([harness] + args, capture_output=True, text=True, env=env, cwd=workdir)
    f = dict(re.findall(r"(\w+)=([-\d.]+)", p.stdout))
    if "dofs" not in f:
        raise SystemExit(f"bench_assembly: no result from {harness} {args}:\n{p.stdout}{p.stderr}")
    return float(f["read_cpu"]), float(f["assemble_cpu"]), int(f["dofs"])


def quad_mesh(h, workdir):
    """The recombined (quadrangle) mesh of bench_paper_tri.geo at h, generated unless kept."""
    path = os.path.join(workdir, f"bench_paper_quad_h{h:g}.msh")
    if os.path.exists(path) and os.path.getmtime(path) >= os.path.getmtime(GEO):
        return path
    if not shutil.which("gmsh"):
        raise SystemExit(f"bench_assembly: gmsh is not installed and {path} does not exist")
    tmp = path + ".tmp.msh"
    subprocess.run(["gmsh", "-2", "-format", "msh41", "-v", "2", "-setnumber", "h", repr(h),
                    "-string", "Mesh.RecombineAll = 1;", GEO, "-o", tmp], check=True)
    os.replace(tmp, path)
    return path


def structured(elem, ndof):
    """The structured case of element elem whose DOF count (nx = 2 ny per body) is nearest ndof."""
    ny = round(((ndof / 4) / 2) ** 0.5)
    return (f"structured {elem} {2 * ny}x{ny}",
            [DEFAULT_DECK] + [f"&body id={i}, nx={2 * ny}, ny={ny}, element='{elem}' /" for i in (1, 2)])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--h", type=float, default=0.005, help="Gmsh triangle mesh size (upper body)")
    ap.add_argument("--quad-h", type=float, default=0.01, help="Gmsh quadrangle mesh size (upper body)")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"), help="comma list of binaries")
    ap.add_argument("--harness", default="", help="comma list of bench_assembly_rate binaries, one per --bin")
    ap.add_argument("--workdir", default=os.path.join(ROOT, "results", "bench_assembly"))
    a = ap.parse_args()
    os.makedirs(a.workdir, exist_ok=True)
    msh, _, _ = make_mesh(a.h, 1.07, a.workdir, "gmsh")   # bench_paper_tri.geo's default ratio
    qmsh = quad_mesh(a.quad_h, a.workdir)
    decks = {}
    for name, m, h in (("gmsh_tri.nml", msh, a.h), ("gmsh_quad.nml", qmsh, a.quad_h)):
        decks[name] = os.path.join(a.workdir, name)
        with open(decks[name], "w") as f:
            f.write(GMSH_DECK.format(h=f"{h:g}", msh=os.path.abspath(os.path.join(a.workdir, m))))
    bins = [os.path.abspath(b) for b in a.bin.split(",") if b]
    harnesses = [os.path.abspath(b) for b in a.harness.split(",") if b]
    if harnesses and len(harnesses) != len(bins):
        raise SystemExit("bench_assembly: give one --harness per --bin")
    _, ntri = run(bins[0], [decks["gmsh_tri.nml"]], a.threads, a.workdir)
    _, nquad = run(bins[0], [decks["gmsh_quad.nml"]], a.threads, a.workdir)
    # (label, args, label of the structured reference)
    sp1, sq1 = structured("P1", ntri), structured("Q1", nquad)
    cases = [(f"gmsh triangles h={a.h:g}", [decks["gmsh_tri.nml"]], sp1[0]), (sp1[0], sp1[1], sp1[0]),
             (f"gmsh quadrangles h={a.quad_h:g}", [decks["gmsh_quad.nml"]], sq1[0]), (sq1[0], sq1[1], sq1[0])]
    # each measure: (name, function of (binary index, args) giving {name: (seconds, DOFs)})
    measures = [("program assemble= (wall)",
                 lambda i, args: {"program assemble= (wall)": run(bins[i], args, a.threads, a.workdir)})]
    if harnesses:
        def harness(i, args):
            rd, asm, n = run_harness(harnesses[i], args, a.workdir, 1)
            return {"harness read+assemble (CPU, 1 thread)": (rd + asm, n),
                    "harness assemble alone (CPU, 1 thread)": (asm, n)}
        measures.append(("harness read+assemble (CPU, 1 thread)", harness))
        measures.append(("harness assemble alone (CPU, 1 thread)", None))
    best = {}
    for _ in range(a.repeat):
        for i, b in enumerate(bins):
            for label, args, _ in cases:
                for _, fn in measures:
                    if fn is None:
                        continue
                    for mname, (t, n) in fn(i, args).items():
                        key = (b, label, mname)
                        if key not in best or t < best[key][0]:
                            best[key] = (t, n)
    print("| binary | measure | case | DOFs (both bodies) | time [s] | us/DOF | / structured |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for b in bins:
        for mname, _ in measures:
            for label, _, ref_label in cases:
                t, n = best[(b, label, mname)]
                rt, rn = best[(b, ref_label, mname)]
                print(f"| {os.path.relpath(b, ROOT)} | {mname} | {label} | {n:,} | {t:.3f} | {1e6 * t / n:.2f} | "
                      f"{(t / n) / (rt / rn):.2f} |")


if __name__ == "__main__":
    main()
