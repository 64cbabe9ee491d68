#!/usr/bin/python3
"""Every thread count gives the same result to the last bit (run by `make check`; doc/batch.md,
"Threads"). The program uses the threads OMP_NUM_THREADS gives it (over the bodies, the
largest first, and over the interface-sized loops), and nothing it computes may depend on how
many: with 1, 2, 3, 4 and 8 threads (8 oversubscribes this 2-core machine) each scene's
`assembled:` line says that many threads and its result file has the same contact forces,
tangential forces, displacements and convergence history as the one-thread run, bitwise.

Scenes: inputs/default.nml (two bodies), inputs/stack3.nml (three, non-matching),
inputs/lap_joint.nml at 1 mm cells (four bodies, Coulomb on three pairs, 1 + 4 load steps,
the active-set inner solver on), 12 blocks of unequal sizes in 3 columns (more bodies than
threads, uneven work, Anderson acceleration), and the paper's two blocks at 256x128 cells
over 256x64 (unequal bodies whose factorizations run dense-kernel tiles, which threads
without a body take: /timing's factor_tiles is the same non-zero count at every thread
count).
"""
import os
import re
import shutil
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import run_solver, solver_env  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
THREADS = (1, 2, 3, 4, 8)
check = Checks()


def lap_joint():
    text = open(os.path.join(ROOT, "inputs", "lap_joint.nml")).read()
    text = text.replace("nx = 32, ny = 16", "nx = 16, ny = 8").replace("nx = 120, ny = 10", "nx = 60, ny = 5")
    return text.replace("&solver load_steps = 1, 20 /", "&solver load_steps = 1, 4 /")


def blocks():
    lines = ["&scene title = '12 blocks of unequal sizes' /"]
    k = 0
    for c in range(3):
        for r in range(4):
            k += 1
            n = 4 + 3 * ((k * 7) % 5)
            bc = ", bottom = 'clamped'" if r == 0 else ", left = 'roller'"
            lines.append(f"&body id = {k}, x0 = {1.5 * c}, y0 = {r}.0, width = 1.0, height = 1.0, nx = {n}, ny = {n}, "
                         f"young = {1e11 * (1 + (k % 3))}, poisson = 0.3{bc} /")
            if r > 0:
                lines.append(f"&contact bodies = {k - 1}, {k}, groups = 'top', 'bottom' /")
        lines.append(f"&traction body = {k}, side = 'top', t0 = 0.0, {-1e5 * (c + 1)} /")
    return "\n".join(lines) + "\n"


def tiled():
    """The paper's scene with bodies large enough for tiles, the harmonic operator (18 outer)."""
    text = open(os.path.join(ROOT, "inputs", "default.nml")).read()
    text = text.replace("nx = 24, ny = 16,                ! cells along x and y", "nx = 256, ny = 128,", 1)
    text = text.replace("nx = 24, ny = 16,", "nx = 256, ny = 64,", 1)
    return (text.replace("robin_operator = 'steklov',", "robin_operator = 'harmonic',", 1)
                .replace("delta = 0.95,", "delta = 0.5,", 1))


def datasets(path):
    """Every dataset of the result that holds numbers, but wall times."""
    out = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "fiu" and "wall" not in name:
                out[name] = obj[()]
        f.visititems(visit)
    return out


def main():
    tmp = tempfile.mkdtemp(prefix="test_threads_")
    try:
        scenes = [("default", os.path.join(ROOT, "inputs", "default.nml")),
                  ("stack3", os.path.join(ROOT, "inputs", "stack3.nml"))]
        for name, text in (("lap joint", lap_joint()), ("12 blocks", blocks()), ("tiled factors", tiled())):
            path = os.path.join(tmp, name.replace(" ", "_") + ".nml")
            with open(path, "w") as f:
                f.write(text)
            scenes.append((name, path))
        for name, deck in scenes:
            ref = None
            for t in THREADS:
                h5 = os.path.join(tmp, f"{name.replace(' ', '_')}_{t}.h5")
                p, res = run_solver(BIN, deck, f"&output file='{h5}' /", cwd=tmp, env=solver_env(t), timeout=600)
                ok = p.returncode == 0 and res is not None and res.get("status") == "converged"
                m = re.search(r"^assembled:.*threads=(\d+)", p.stdout, re.M)
                check(ok and m and int(m.group(1)) == t, f"{name}, {t} threads: converged, the run uses {t} threads",
                      f"exit {p.returncode}, {m.group(0) if m else 'no assembled: line'}")
                if not ok:
                    continue
                d = datasets(h5)
                with h5py.File(h5, "r") as f:
                    tiles = float(f["timing"].attrs["factor_tiles"])
                if ref is None:
                    ref = d
                    ref_tiles = tiles
                    if name == "tiled factors":
                        check(tiles > 0, f"{name}: the factorizations ran tiles ({tiles:.0f})")
                    continue
                if name == "tiled factors":
                    check(tiles == ref_tiles, f"{name}, {t} threads: the same tiles as the one-thread run ({tiles:.0f})")
                differ = [k for k in ref if k not in d or not np.array_equal(ref[k], d[k])]
                check(not differ and len(d) == len(ref), f"{name}, {t} threads: every dataset bitwise the one-thread run's "
                      f"({len(ref)} datasets)", ", ".join(differ[:4]))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"{len(check.failed)} failed checks")
    return 1 if check.failed else 0


if __name__ == "__main__":
    sys.exit(main())
