#!/usr/bin/python3
"""A forged or foreign checkpoint given to --restart is refused cleanly (run by `make check`).

A real checkpoint is made (q1_16x8, max_outer=10, checkpoint_every=5: exit 2), then
copies of it are altered with h5py, one way each: an array-valued `key` or `it` (which
overflowed a one-element buffer: SIGSEGV, "malloc(): corrupted top size"), `it` beyond
the history length, a short history dataset, `G` or `lam` of the wrong shape, `G` of
integers, `it` as a real number, a non-finite obstacle, a missing dataset, a
variable-length `key`, a scalar `flam`, a negative counter, and a history longer than
max_outer. For each: exit code 1, one message naming the restart file and the dataset
or attribute at fault, no crash or runtime error text, and the result file already at
the output path (from an earlier run) untouched, byte for byte. The unaltered copy
restarts and converges (the checks are not too strict).
"""
import filecmp
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import solver_env  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", "bin/robin_contact"))
OUT = os.path.abspath(os.path.join(os.environ.get("BUILD", "build/release"), "test-out", "restart_forged"))
DECK = os.path.abspath("inputs/table1/q1_16x8.nml")
ENV = solver_env(1)
check = Checks()
shutil.rmtree(OUT, ignore_errors=True)
os.makedirs(OUT)

h5 = os.path.join(OUT, "r.h5")
ck = h5 + ".ckpt.h5"
p = subprocess.run([BIN, DECK, "&solver max_outer=10 /", f"&output file='{h5}', checkpoint_every=5 /"],
                   capture_output=True, text=True, env=ENV)
check(p.returncode == 2 and os.path.exists(ck) and os.path.exists(h5), "a run with a checkpoint and a result",
      f"exit {p.returncode}")
keep = os.path.join(OUT, "earlier.h5")
shutil.copy2(h5, keep)
with h5py.File(ck, "r") as f:
    m = f["state/G"].shape[1]
    it = int(f["state"].attrs["it"])
    key = f["key"][()]


def replace(f, path, value, dtype=None):
    del f[path]
    f.create_dataset(path, data=np.asarray(value, dtype=dtype))


def set_attr(f, path, name, value):
    del f[path].attrs[name]
    f[path].attrs[name] = value


def short_history(f):
    replace(f, "history/inner", np.zeros(it - 2, dtype=np.int32))


FORGERIES = [
    ("array key", "/key", lambda f: replace(f, "key", np.array([key, key]))),
    ("variable-length key", "/key", lambda f: replace(f, "key", key.decode(), dtype=h5py.string_dtype())),
    ("array it", "attribute it", lambda f: set_attr(f, "state", "it", np.arange(1000, dtype=np.int32))),
    ("it as a real number", "attribute it", lambda f: set_attr(f, "state", "it", float(it))),
    ("it beyond the history", "attribute it", lambda f: set_attr(f, "state", "it", np.int32(it + 3))),
    ("short history", "/history/inner", short_history),
    ("history longer than max_outer", "/history/criterion",
     lambda f: [replace(f, f"history/{n}", np.zeros(900, dtype=np.float64 if n in ("criterion", "residual", "wall_s")
                                                     else np.int32)) for n in ("criterion", "residual", "wall_s",
                                                                               "inner", "active")]),
    ("G of the wrong shape", "/state/G", lambda f: replace(f, "state/G", np.zeros((3, m)))),
    ("lam of the wrong shape", "/state/lam", lambda f: replace(f, "state/lam", np.zeros((2, m + 1)))),
    ("G of integers", "/state/G", lambda f: replace(f, "state/G", np.zeros((2, m), dtype=np.int64))),
    ("non-finite G", "/state/G", lambda f: f["state/G"].__setitem__((0, 0), np.nan)),
    ("missing dR", "/state/dR", lambda f: f.__delitem__("state/dR")),
    ("scalar flam", "/state/flam", lambda f: replace(f, "state/flam", 1.0)),
    ("negative counter", "/state", lambda f: set_attr(f, "state", "nacc", np.int32(-4))),
    ("row state out of range", "row_state", lambda f: f["state/row_state"].__setitem__(0, 99)),
    ("settled neither 0 nor 1", "settled", lambda f: set_attr(f, "state", "settled", np.int32(7))),
]

# control: the unaltered copy restarts
good = os.path.join(OUT, "good.ckpt.h5")
shutil.copy2(ck, good)
p = subprocess.run([BIN, DECK, f"&output file='{OUT}/good.h5' /", "--restart", good], capture_output=True, text=True,
                   env=ENV)
check(p.returncode == 0, "the unaltered checkpoint restarts and converges", f"exit {p.returncode}: {p.stderr[-200:]}")

for i, (what, obj, forge) in enumerate(FORGERIES):
    bad = os.path.join(OUT, f"forged{i}.ckpt.h5")
    shutil.copy2(ck, bad)
    with h5py.File(bad, "r+") as f:
        forge(f)
    p = subprocess.run([BIN, DECK, f"&output file='{h5}' /", "--restart", bad], capture_output=True, text=True,
                       env=ENV)
    err = p.stderr.strip()
    check(p.returncode == 1, f"{what}: exit 1", f"exit {p.returncode}")
    check(bad in err and obj in err, f"{what}: the message names the file and {obj}", err[-300:])
    check(not any(s in p.stderr + p.stdout for s in ("Fortran runtime", "Segmentation", "malloc", "HDF5-DIAG",
                                                     "Backtrace")),
          f"{what}: no crash or runtime error text")
    check(os.path.exists(h5) and filecmp.cmp(h5, keep, shallow=False), f"{what}: the earlier result is untouched")

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
