#!/usr/bin/env python3
"""Many Gmsh bodies: is their assembly bound by the reader? The scene of bench_bodies.py
(columns of unit blocks, E = 2.1e11, nu = 0.3, plane strain; the top block of each column
pressed by 1e6 on its top, the bottom one clamped below, the others on a roller on their
left side; block k's bottom paired with block k+1's top) twice: as built-in rectangles of
nx x nx Q1 cells, and as Gmsh bodies, all in one .msh file that holds one physical surface
per block ('b1', 'b2', ...) and the physical curves 'bottom', 'right', 'top' and 'left'
gathering those sides of every block (a body keeps the lines on its own boundary), so the
decks name the same groups. The .geo (OpenCASCADE rectangles, one surface per block, so no
two blocks share a node) is generated; --element quad meshes each block as a transfinite
nx x nx grid recombined into quadrangles (the DOFs of the rectangles), tri as unstructured
triangles of size 1/nx. The bodies sharing the file, the program parses it once
(msh_read_shared) and builds the bodies on the threads.

Measures, each the fastest of --repeat runs, the two decks interleaved:
- the program (robin/harmonic, max_outer=1, so it stops after one outer iteration, exit 2;
  --threads threads): its `assemble` phase (reading, DOF numbering, stiffness and loads of
  every body, mortar coupling) and the process's wall time;
- with --harness (build/release/bench/bench_assembly_rate): reading all bodies (one parse,
  then each body built) and assembling them, one thread, CPU time: the reader's share.

Usage: /usr/bin/python3 bench/bench_gmsh_bodies.py [--n 1000] [--per 8] [--cells 8]
           [--element quad|tri] [--repeat 3] [--threads 2] [--bin bin/robin_contact]
           [--harness build/release/bench/bench_assembly_rate] [--workdir results/bench_gmsh_bodies]
Prints a Markdown table. A benchmark: it reports, it asserts nothing. Needs gmsh for a new
mesh (kept in the work folder for the next run).
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
from rc_run import result_fields, solver_env, time_fields  # noqa: E402
from bench_bodies import assembly  # noqa: E402  (the rectangles' deck)

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SOLVER = "&solver method='robin', robin_operator='harmonic', delta=0.5, max_outer=1 /"


def geo_text(ncol, per, nx, element):
    """The .geo of the blocks: block i = c*per + k at (2c, per - k), its own surface i."""
    lines = ['SetFactory("OpenCASCADE");']
    for c in range(ncol):
        for k in range(1, per + 1):
            i = c * per + k
            lines.append(f"Rectangle({i}) = {{{2.0 * c}, {float(per - k)}, 0, 1, 1}};")
    n = ncol * per
    for i in range(1, n + 1):
        lines.append(f'Physical Surface("b{i}") = {{{i}}};')
    # OpenCASCADE numbers a rectangle's curves bottom, right, top, left
    for side, name in enumerate(("bottom", "right", "top", "left")):
        tags = ", ".join(str(4 * (i - 1) + side + 1) for i in range(1, n + 1))
        lines.append(f'Physical Curve("{name}") = {{{tags}}};')
    if element == "quad":
        lines += [f"Transfinite Curve{{:}} = {nx + 1};", "Transfinite Surface{:};", "Recombine Surface{:};"]
    else:
        lines += [f"Mesh.MeshSizeMin = {1.0 / nx!r};", f"Mesh.MeshSizeMax = {1.0 / nx!r};"]
    return "\n".join(lines) + "\n"


def gmsh_deck(ncol, per, msh):
    """The deck lines of the Gmsh scene: the conditions of assembly() on the file's groups."""
    lines, pairs = [], []
    for c in range(ncol):
        for k in range(1, per + 1):
            i = c * per + k
            lines.append(f"&body id={i}, mesh='{msh}', region='b{i}' /")
            if k == per:
                lines.append(f"&boundary body={i}, group='bottom', ux=0.0, uy=0.0 /")
            else:
                lines.append(f"&boundary body={i}, group='left', ux=0.0 /")
        lines.append(f"&traction body={c * per + 1}, group='top', t0=0.0, -1.0e6 /")
        pairs += [f"&contact bodies={c * per + k},{c * per + k + 1}, groups='bottom','top' /" for k in range(1, per)]
    return lines + pairs


def make_decks(a):
    os.makedirs(a.workdir, exist_ok=True)
    ncol = a.n // a.per
    stem = f"blocks{ncol}x{a.per}_{a.cells}_{a.element}"
    geo = os.path.join(a.workdir, stem + ".geo")
    msh = os.path.join(a.workdir, stem + ".msh")
    text = geo_text(ncol, a.per, a.cells, a.element)
    if not (os.path.exists(geo) and open(geo).read() == text and os.path.exists(msh)):
        if not shutil.which("gmsh"):
            raise SystemExit("bench_gmsh_bodies: gmsh is not installed and the mesh is not in the work folder")
        with open(geo, "w") as f:
            f.write(text)
        t0 = time.time()
        subprocess.run(["gmsh", "-2", "-format", "msh41", "-v", "2", geo, "-o", msh + ".tmp.msh"], check=True)
        os.replace(msh + ".tmp.msh", msh)
        sys.stderr.write(f"bench_gmsh_bodies: gmsh meshed {a.n} blocks in {time.time() - t0:.1f} s -> {msh}\n")
    decks = {}
    for name, body in (("rectangles", assembly(ncol, a.per, a.cells, a.cells)),
                       ("gmsh", gmsh_deck(ncol, a.per, os.path.abspath(msh)))):
        decks[name] = os.path.join(a.workdir, f"{stem}_{name}.nml")
        with open(decks[name], "w") as f:
            f.write(f"! bench_gmsh_bodies: {a.n} blocks ({ncol} columns of {a.per}), {name}\n")
            f.write("\n".join(body) + "\n")
    return decks, msh


def run_program(binary, deck, threads, workdir):
    out = os.path.join(workdir, "run.h5")
    t0 = time.time()
    p = subprocess.run([binary, deck, SOLVER, f"&output file='{out}', progress_lines=0 /"],
                       capture_output=True, text=True, env=solver_env(threads))
    wall = time.time() - t0
    t, r = time_fields(p.stdout), result_fields(p.stdout)
    if t is None or r is None:
        raise SystemExit(f"bench_gmsh_bodies: no time/result line from {deck}:\n{p.stdout[-2000:]}{p.stderr[-2000:]}")
    return float(t["assemble"]), wall, int(r["n1"]) + int(r["n2"])


def run_harness(harness, deck, workdir):
    env = solver_env(1)
    env["BENCH_REPEAT"] = "1"
    p = subprocess.run([harness, deck], capture_output=True, text=True, env=env, cwd=workdir)
    f = dict(re.findall(r"(\w+)=([-\d.]+)", p.stdout))
    if "dofs" not in f:
        raise SystemExit(f"bench_gmsh_bodies: no result from {harness} {deck}:\n{p.stdout}{p.stderr}")
    return float(f["read_cpu"]), float(f["assemble_cpu"]), int(f["dofs"])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=1000, help="blocks (a multiple of --per)")
    ap.add_argument("--per", type=int, default=8, help="blocks per column")
    ap.add_argument("--cells", type=int, default=8, help="cells per block side")
    ap.add_argument("--element", choices=("quad", "tri"), default="quad")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"))
    ap.add_argument("--harness", default="", help="build/release/bench/bench_assembly_rate (the one-thread split)")
    ap.add_argument("--workdir", default=os.path.join(ROOT, "results", "bench_gmsh_bodies"))
    a = ap.parse_args()
    if a.n % a.per:
        raise SystemExit("bench_gmsh_bodies: --n must be a multiple of --per")
    decks, msh = make_decks(a)
    binary = os.path.abspath(a.bin)
    best = {}
    for _ in range(a.repeat):
        for name, deck in decks.items():
            asm, wall, _ = run_program(binary, deck, a.threads, a.workdir)
            row = best.setdefault(name, {})
            row["assemble"] = min(row.get("assemble", 1e30), asm)
            row["wall"] = min(row.get("wall", 1e30), wall)
            if a.harness:
                rd, asm1, n = run_harness(os.path.abspath(a.harness), deck, a.workdir)
                if rd + asm1 < row.get("read", 1e30) + row.get("asm1", 1e30):
                    row["read"], row["asm1"] = rd, asm1
                row["dofs"] = n
    print(f"{a.n} blocks of {a.cells}x{a.cells} ({a.element}), {os.path.getsize(msh) / 2**20:.1f} MB .msh; "
          f"program with {a.threads} threads, fastest of {a.repeat}")
    print("| scene | DOFs | program assemble [s] | process wall [s] | read CPU [s] | assemble CPU [s] | "
          "read / (read + assemble) |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for name, row in best.items():
        if a.harness:
            rd, asm1 = row["read"], row["asm1"]
            split = f"{row['dofs']:,} | {row['assemble']:.3f} | {row['wall']:.3f} | {rd:.3f} | {asm1:.3f} | " \
                    f"{rd / (rd + asm1):.2f}"
        else:
            split = f"- | {row['assemble']:.3f} | {row['wall']:.3f} | - | - | -"
        print(f"| {name} | {split} |")


if __name__ == "__main__":
    main()
