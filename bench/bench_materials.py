#!/usr/bin/python3
"""What a body of several materials costs: the bimaterial bar of tests/system/test_materials.py
scaled up (body 1 a mesh file of two surface entities, N x N/4 Q1 cells each half; body 2 a
rectangle pressing on it), assembled with (a) one material (no &region), (b) its right half a
&region of another isotropic material (the same kernel), (c) that region orthotropic (the
general B'DB kernel), (d) the whole body orthotropic. The assemble phase's time per DOF of the
run (fastest of --repeat runs, the variants interleaved), as the program prints it.

  /usr/bin/python3 bench/bench_materials.py [--bin bin/robin_contact] [--n 800] [--repeat 5]

Reports, asserts nothing.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "system"))
from msh_bar import write_bar  # noqa: E402



ORTHO = "e1=1.0e11, e2=4.0e10, nu12=0.15, g12=3.0e10"
VARIANTS = [
    ("one material", "&body id=1, mesh='bar.msh', region='bar', material='steel' /", ""),
    ("two isotropic", "&body id=1, mesh='bar.msh', region='bar', material='steel' /",
     "&material name='soft', young=1.0e11, poisson=0.3 /\n&region body=1, name='soft', material='soft' /"),
    ("isotropic + orthotropic region", "&body id=1, mesh='bar.msh', region='bar', material='steel' /",
     f"&material name='soft', {ORTHO} /\n&region body=1, name='soft', material='soft' /"),
    ("all orthotropic", "&body id=1, mesh='bar.msh', region='bar', material='ply' /", ""),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"))
    ap.add_argument("--n", type=int, default=800)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix="rc_bench_materials_")
    write_bar(os.path.join(work, "bar.msh"), a.n, max(1, a.n // 4))
    best = {}
    for rep in range(a.repeat):
        for label, body1, extra in VARIANTS:
            deck = "\n".join(["&scene plane='stress' /", "&material name='steel', young=2.0e11, poisson=0.3 /",
                              f"&material name='ply', {ORTHO} /", extra, body1,
                              "&body id=2, x0=2.0, y0=0.0, width=0.5, height=0.5, nx=8, ny=8, young=1.0e11, "
                              "poisson=0.15, bottom='roller' /",
                              "&traction body=2, side='right', t0=-1.0e6, 0.0 /",
                              "&boundary body=1, group='bar_left', ux=0.0 /",
                              "&boundary body=1, group='bar_bottom', uy=0.0 /",
                              "&contact bodies=1,2, groups='bar_right','left' /",
                              "&output file='b.h5' /"]) + "\n"
            path = os.path.join(work, "b.nml")
            with open(path, "w") as f:
                f.write(deck)
            p = subprocess.run([a.bin, path], cwd=work, capture_output=True, text=True)
            if p.returncode != 0:
                sys.exit(f"bench_materials: {label}: exit {p.returncode}\n{p.stdout[-1500:]}")
            t = float(re.search(r"^time: assemble=(\S+)", p.stdout, re.M).group(1))
            dofs = int(re.search(r" dofs=(\d+)", p.stdout).group(1))
            best[label] = min(best.get(label, (1e9, dofs))[0], t), dofs
    base = best["one material"][0]
    print("| body 1 | DOFs | assemble [s] (fastest of %d) | per DOF [us] | vs one material |" % a.repeat)
    print("| --- | --- | --- | --- | --- |")
    for label, _, _ in VARIANTS:
        t, dofs = best[label]
        print(f"| {label} | {dofs} | {t:.3f} | {1e6 * t / dofs:.3f} | {t / base - 1:+.1%} |")


if __name__ == "__main__":
    main()
