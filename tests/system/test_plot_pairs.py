#!/usr/bin/python3
"""The plot tools on a result of several contact pairs (a stack of three blocks, non-matching
meshes; a small deck written here): tools/plot_contact.py --hertz picks a pair with --pair K
(the Hertz curve from that pair's normal forces and its two bodies' moduli; without --pair
the note names the option; a pair that is not there: exit 1 with a message), and
tools/plot_solution.py's legend counts every active contact node of each pair (the count in
the file), also where the pair's first body is the side whose nodes are not the contact
nodes. Solid bodies: three boxes stacked (hexahedra on tetrahedra on hexahedra, two pairs,
a uniform pressure p on the top: the contact patch test, every contact pressure p):
plot_contact maps each pair's contact surface (its nodes and faces those of
/contact/pair_<k>, quadrilaterals on pair 1, triangles on pair 2) and the CSV of the line
across both has the pressure p at every sample."""
import os
import re
import subprocess
import sys
import tempfile

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import run_solver  # noqa: E402
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from solid_decks import THREE_BOXES  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", "bin/robin_contact"))
PYTHON = os.environ.get("PYTHON", "/usr/bin/python3")
check = Checks()
tmp = tempfile.mkdtemp(prefix="test_plot_pairs.")
deck = os.path.join(tmp, "stack.nml")
with open(deck, "w") as f:
    f.write("""&scene title = 'three blocks, two pairs', plane = 'strain' /
&body id = 1, x0 = 0.2, y0 = 2.0, width = 0.6, height = 0.5, nx = 7, ny = 4, young = 7.0e10, poisson = 0.33,
      left = 'roller' /
&body id = 2, x0 = 0.0, y0 = 1.0, width = 1.0, height = 1.0, nx = 16, ny = 8, young = 2.1e11, poisson = 0.3,
      left = 'roller' /
&body id = 3, x0 = -0.25, y0 = 0.0, width = 1.5, height = 1.0, nx = 9, ny = 6, young = 7.0e10, poisson = 0.33,
      bottom = 'clamped' /
&traction body = 1, side = 'top', t0 = 0.0, -1.0e6 /
&contact bodies = 1, 2, groups = 'bottom', 'top' /
&contact bodies = 2, 3, groups = 'bottom', 'top' /
&solver method = 'robin', robin_operator = 'harmonic', delta = 0.5, tol = 1.0e-10 /
""")
h5 = os.path.join(tmp, "stack.h5")
p, _ = run_solver(BIN, deck, f"&output file='{h5}' /")
if not check(p.returncode == 0, "the three-block deck solved", f"exit {p.returncode} {p.stderr.strip()[-200:]}"):
    sys.exit(1)
with h5py.File(h5, "r") as f:
    active = [int(np.sum(f[f"contact/pair_{k}/active"][()] > 0)) for k in (1, 2)]
    nodes = [f[f"contact/pair_{k}/active"].shape[0] for k in (1, 2)]
    P2 = float(np.sum(f["contact/pair_2/normal_force"][()]))


def tool(name, *args):
    q = subprocess.run([PYTHON, os.path.join(ROOT, "tools", name), *args], capture_output=True, text=True,
                       timeout=300)
    return q.returncode, q.stdout, q.stderr


png = os.path.join(tmp, "c.png")
rc, so, se = tool("plot_contact.py", h5, "--hertz", "-o", png)
check(rc == 0 and "no Hertz curve" in se and "--pair K" in se, "--hertz on two pairs: the note names --pair",
      se.strip())
rc, so, se = tool("plot_contact.py", h5, "--hertz", "--pair", "2", "--radius", "1.0", "-o", png)
m = re.search(r"Hertz for \S+ pair 2 \(bodies 2,3\): P=(\S+) R=1 ", so)
check(rc == 0 and m and abs(float(m.group(1)) - P2) <= 1e-5 * P2 and "1 Hertz curves" in so
      and "pair 1 (bodies 1,2): no Hertz curve" in se,
      "--hertz --pair 2 --radius 1: the Hertz curve of pair 2 (its P), none on pair 1",
      f"exit {rc} {so.strip()} {se.strip()}")
rc, so, se = tool("plot_contact.py", h5, "--hertz", "--pair", "3", "-o", os.path.join(tmp, "bad.png"))
check(rc == 1 and "--pair 3: the file has 2 contact pairs" in se and not os.path.exists(os.path.join(tmp, "bad.png")),
      "--pair 3 of 2: exit 1 with a message", f"exit {rc} {se.strip()}")

# solid bodies: three boxes, two pairs, the contact patch test (every pressure p)
deck3 = os.path.join(tmp, "boxes3.nml")
with open(deck3, "w") as f:
    f.write(THREE_BOXES + "&solver tol = 1.0e-10 /\n")
h53 = os.path.join(tmp, "boxes3.h5")
p, _ = run_solver(BIN, deck3, f"&output file='{h53}' /")
if check(p.returncode == 0, "three boxes, two pairs (3D) solved", f"exit {p.returncode} {p.stderr.strip()[-200:]}"):
    with h5py.File(h53, "r") as f:
        sizes = [(f[f"contact/pair_{k}/pressure"].shape[0], f[f"contact/pair_{k}/faces"].shape) for k in (1, 2)]
    csv_path = os.path.join(tmp, "line3.csv")
    rc, so, se = tool("plot_contact.py", h53, "--csv", csv_path, "-o", os.path.join(tmp, "c3.png"))
    for k, (n, shape) in enumerate(sizes, start=1):
        m = re.search(rf"pair {k} \(bodies {k},{k + 1}\): contact surface of (\d+) nodes, (\d+) faces", so)
        check(rc == 0 and m is not None and (int(m.group(1)), int(m.group(2))) == (n, shape[0])
              and shape[1] == (4 if k == 1 else 3),
              f"plot_contact on a solid result: pair {k}'s surface mapped, the nodes and faces of /contact/pair_{k}",
              f"exit {rc} {m.group(0) if m else so.strip()[-300:]} against {n} nodes, faces {shape}")
    import csv  # noqa: E402
    rows = list(csv.DictReader(open(csv_path))) if os.path.isfile(csv_path) else []
    pres = np.array([float(r["pressure"]) for r in rows])
    curves = sorted({r["curve"] for r in rows})
    check(len(curves) == 2 and pres.size > 600 and np.abs(pres / 1.0e6 - 1.0).max() <= 1e-6,
          "the line across both surfaces: the patch test's pressure p at every sample",
          f"curves {curves}, {pres.size} samples, "
          f"max |p/p_exact - 1| = {np.abs(pres / 1e6 - 1).max() if pres.size else None}")

# plot_solution's legend: the labels of the figure it saves
import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.figure  # noqa: E402
import plot_solution  # noqa: E402
labels = []
save = matplotlib.figure.Figure.savefig


def record(fig, *a, **k):
    for ax in fig.axes:
        labels.extend(ax.get_legend_handles_labels()[1])
    return save(fig, *a, **k)


matplotlib.figure.Figure.savefig = record
rc = plot_solution.main([h5, "-o", os.path.join(tmp, "s.png")])
for k in (1, 2):
    want = f"pair {k}: active contact nodes ({active[k - 1]} of {nodes[k - 1]})"
    check(rc == 0 and want in labels, f"plot_solution legend: {want}", str([t for t in labels if "active" in t]))
import shutil  # noqa: E402
shutil.rmtree(tmp, ignore_errors=True)
print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
