#!/usr/bin/python3
"""Results are committed whole, by one run, or not at all (run by `make check`).

1. Two runs writing the same result file. Each run writes under
   temporary names of its own (`<file>.<host>.<pid>.<n>.tmp`) and only the final renames
   are shared, under a lock of the folder.
   a. deterministic: while another writer (this test, with h5py) holds `<file>.tmp`
      open and half-written (a shared temporary name), the program writes
      the same result: it succeeds, and the other writer's file is untouched.
   b. concurrent: pairs of runs started together on the same result file, with
      different titles and loads (run A: the deck's loads; run B: an extra traction).
      Both succeed; the final .h5 is wholly one run's (its title and its total contact
      force belong to the same run, the force equal to that run's alone); every XDMF file
      carries the run_id of that .h5; meshio reads the body files back to its data; no
      temporary or kept-aside file is left.
2. A final name that is a folder: `<stem>_body1.xdmf` is a folder.
   a. with an earlier result at the other names: exit 3, the message names the folder,
      the earlier files are byte for byte what they were (nothing replaced, nothing
      deleted), no .tmp or .bak file left;
   b. with nothing there before: exit 3, no result file appears, nothing left over.
"""
import contextlib
import filecmp
import io
import os
import re
import shutil
import subprocess
import sys

import h5py
import meshio
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from rc_checks import Checks  # noqa: E402
from rc_results import text_attr  # noqa: E402
from rc_run import solver_env  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", "bin/robin_contact"))
OUT = os.path.abspath(os.path.join(os.environ.get("BUILD", "build/release"), "test-out", "result_commit"))
DECK = os.path.abspath("inputs/table1/q1_16x8.nml")
MESH = ["&body id=1, nx=96, ny=32 /", "&body id=2, nx=96, ny=32 /", "&solver method='monolithic' /"]
RUN = {"A": ["&scene title='run A' /"],
       "B": ["&scene title='run B' /", "&traction body=1, side='top', t0=0.0,-4.0e6 /"]}
ENV = solver_env(1)
check = Checks()


def names(h5):
    stem = h5[:-3]
    return [h5] + [stem + s for s in (".xdmf", "_body1.xdmf", "_body2.xdmf", "_contact.xdmf")]


def out(h5):
    return f"&output file='{h5}' /"


def leftovers(d):
    return [n for n in os.listdir(d) if n.endswith((".tmp", ".bak"))]


def total_force(h5):
    if not os.path.isfile(h5):
        return float("nan"), None, None
    with h5py.File(h5, "r") as f:
        return float(np.sum(f["/contact/normal_force"][()])), text_attr(f, "title"), text_attr(f, "run_id")


def xdmf_run_id(path):
    if not os.path.isfile(path):
        return None
    m = re.search(r"<!-- robin_contact \S+ run_id (\S+) -->", open(path, encoding="utf-8").read())
    return m.group(1) if m else None


def meshio_points(path):
    with contextlib.redirect_stdout(io.StringIO()):
        try:
            return np.asarray(meshio.read(path).points)
        except (Exception, SystemExit):  # noqa: BLE001
            return None


shutil.rmtree(OUT, ignore_errors=True)
os.makedirs(OUT)

# reference forces of each run alone
ref = {}
for k in RUN:
    h5 = os.path.join(OUT, f"alone_{k}.h5")
    p = subprocess.run([BIN, DECK, *MESH, *RUN[k], out(h5)], capture_output=True, text=True, env=ENV)
    check(p.returncode == 0, f"run {k} alone converges", f"exit {p.returncode}")
    ref[k] = total_force(h5)[0] if p.returncode == 0 else float("nan")
check(abs(ref["A"] - ref["B"]) > 1e-3 * abs(ref["A"]), "runs A and B have different total forces",
      f"{ref['A']:.6e} vs {ref['B']:.6e}")

# 1a. another writer holds <file>.tmp (a shared temporary name), half-written
d = os.path.join(OUT, "held")
os.makedirs(d)
h5 = os.path.join(d, "r.h5")
with h5py.File(h5 + ".tmp", "w") as other:
    other["/contact/normal_force"] = np.arange(5.0)
    other.flush()
    p = subprocess.run([BIN, DECK, *MESH, *RUN["A"], out(h5)], capture_output=True, text=True, env=ENV)
    check(p.returncode == 0, "a run beside another writer's open <file>.tmp succeeds",
          f"exit {p.returncode}: {p.stderr.strip()[-200:]}")
    check(np.array_equal(other["/contact/normal_force"][()], np.arange(5.0)),
          "the other writer's half-written file is untouched")
ok = os.path.exists(h5) and total_force(h5)[1] == "run A"
check(ok and abs(total_force(h5)[0] - ref["A"]) <= 1e-12 * abs(ref["A"]), "the result is the run's own")

# 1b. pairs of runs started together on the same result file
for rnd in range(4):
    d = os.path.join(OUT, f"pair{rnd}")
    os.makedirs(d)
    h5 = os.path.join(d, "r.h5")
    procs = {k: subprocess.Popen([BIN, DECK, *MESH, *RUN[k], out(h5)], stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True, env=ENV) for k in RUN}
    rcs = {k: (pr.wait(timeout=300), pr.communicate()) for k, pr in procs.items()}
    check(all(rc == 0 for rc, _ in rcs.values()), f"pair {rnd}: both runs succeed",
          "; ".join(f"{k}: exit {rc} {io_[1].strip()[-150:]}" for k, (rc, io_) in rcs.items()))
    if not os.path.exists(h5):
        check(False, f"pair {rnd}: result file written")
        continue
    force, title, rid = total_force(h5)
    who = {"run A": "A", "run B": "B"}.get(title)
    check(who is not None and abs(force - ref[who]) <= 1e-12 * abs(ref[who]),
          f"pair {rnd}: the .h5 is wholly one run's (title {title!r}, force {force:.6e})")
    ids = {os.path.basename(n): xdmf_run_id(n) for n in names(h5)[1:]}
    check(rid and all(v == rid for v in ids.values()), f"pair {rnd}: every XDMF file belongs to the run of the .h5",
          f"h5 {rid}, xdmf {ids}")
    with h5py.File(h5, "r") as f:
        pts = meshio_points(names(h5)[2])
        check(pts is not None and np.array_equal(pts, f["/body1/geometry_xyz"][()]),
              f"pair {rnd}: meshio reads {os.path.basename(names(h5)[2])} back to the .h5 data")
    check(not leftovers(d), f"pair {rnd}: no .tmp or .bak left", " ".join(leftovers(d)))

# 2a. a final name is a folder, with an earlier result at the other names
d = os.path.join(OUT, "folder")
os.makedirs(d)
h5 = os.path.join(d, "r.h5")
p = subprocess.run([BIN, DECK, *MESH, *RUN["A"], out(h5)], capture_output=True, text=True, env=ENV)
check(p.returncode == 0, "earlier result written", f"exit {p.returncode}")
body1 = names(h5)[2]
os.remove(body1)
os.mkdir(body1)
keep = os.path.join(OUT, "folder_keep")
os.makedirs(keep)
for n in names(h5):
    if os.path.isfile(n):
        shutil.copy2(n, keep)
p = subprocess.run([BIN, DECK, *MESH, *RUN["B"], out(h5)], capture_output=True, text=True, env=ENV)
check(p.returncode == 3, "a folder at <stem>_body1.xdmf: exit 3", f"exit {p.returncode}")
check(f"output: cannot write {h5}" in p.stderr and f"{body1} is a folder" in p.stderr,
      "a folder at <stem>_body1.xdmf: the message names it", p.stderr.strip()[-300:])
same = [os.path.isfile(n) and filecmp.cmp(n, os.path.join(keep, os.path.basename(n)), shallow=False)
        for n in names(h5) if n != body1]
check(all(same) and os.path.isdir(body1), "a folder at <stem>_body1.xdmf: the earlier result is intact, byte for byte")
check(total_force(h5)[1] == "run A", "a folder at <stem>_body1.xdmf: the .h5 is still the earlier run's")
check(not leftovers(d), "a folder at <stem>_body1.xdmf: no .tmp or .bak left", " ".join(leftovers(d)))

# 2b. the same with nothing there before
d = os.path.join(OUT, "folder_new")
os.makedirs(d)
h5 = os.path.join(d, "r.h5")
os.mkdir(names(h5)[2])
p = subprocess.run([BIN, DECK, *MESH, *RUN["B"], out(h5)], capture_output=True, text=True, env=ENV)
check(p.returncode == 3 and "is a folder" in p.stderr, "a folder at <stem>_body1.xdmf, nothing before: exit 3",
      f"exit {p.returncode}")
check(sorted(os.listdir(d)) == ["r_body1.xdmf"], "a folder at <stem>_body1.xdmf, nothing before: no file appears",
      " ".join(sorted(os.listdir(d))))

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
