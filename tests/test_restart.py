#!/usr/bin/python3
"""Checkpoint and restart (run by `make check`): a run stopped by SIGTERM exits 4 with
its result flagged `interrupted` and a checkpoint; the restart from that checkpoint ends
bitwise identical to an uninterrupted run; so does a restart from a periodic checkpoint
(checkpoint_every); a checkpoint from another deck or mesh is refused (exit 1)."""
import os
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np

BIN = os.environ.get("BIN", "bin/robin_contact")
OUT = os.path.join(os.environ.get("BUILD", "build/release"), "test-out", "restart")
shutil.rmtree(OUT, ignore_errors=True)
os.makedirs(OUT)
FAILS = []
DECK = "inputs/table1/q1_16x8.nml"
MESH = ["&body id=1, nx=512, ny=8 /", "&body id=2, nx=512, ny=8 /"]
SLOW = "&solver delta=0.998, max_outer=40000 /"   # about 5000 outer iterations, a few seconds


def check(ok, what, detail=""):
    print(("PASS  " if ok else "FAIL  ") + what + (f" ({detail})" if detail else ""))
    if not ok:
        FAILS.append(what)


def out(name):
    return f"&output file='{OUT}/{name}.h5' /"


def attr(f, k):
    v = f.attrs[k]
    return (v.decode() if isinstance(v, bytes) else str(v)).strip()


def same(a, b):
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        for k in ["/contact/normal_force", "/contact/gap", "/body1/displacement", "/body2/displacement",
                  "/history/criterion", "/history/residual", "/history/inner", "/history/active"]:
            if not np.array_equal(np.array(fa[k]), np.array(fb[k])):
                return False, k
        for k in ["outer_iterations", "inner_iterations", "status"]:
            if attr(fa, k) != attr(fb, k):
                return False, k
    return True, ""


env = dict(os.environ, OMP_NUM_THREADS="2")
# reference: uninterrupted
p = subprocess.run([BIN, DECK, *MESH, SLOW, out("full")], capture_output=True, text=True, env=env)
check(p.returncode == 0, "uninterrupted run converges", f"exit {p.returncode}")

# 1. SIGTERM during the outer iteration
proc = subprocess.Popen([BIN, DECK, *MESH, SLOW, out("sig")], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                        text=True, env=env)
time.sleep(0.6)
proc.send_signal(signal.SIGTERM)
so, se = proc.communicate(timeout=120)
check(proc.returncode == 4, "SIGTERM: exit code 4", f"exit {proc.returncode}")
ck = f"{OUT}/sig.h5.ckpt.h5"
check(os.path.exists(ck), "SIGTERM: checkpoint written", ck)
if os.path.exists(f"{OUT}/sig.h5"):
    with h5py.File(f"{OUT}/sig.h5", "r") as f:
        st = attr(f, "status")
        check(st == "interrupted", "SIGTERM: result flagged interrupted", st)
        n = int(f.attrs["outer_iterations"])
        check(0 < n < 4500, "SIGTERM: stopped part-way", f"outer {n}")
else:
    check(False, "SIGTERM: result file written")
if os.path.exists(ck):
    p = subprocess.run([BIN, DECK, *MESH, SLOW, out("sig_restart"), "--restart", ck], capture_output=True,
                       text=True, env=env)
    check(p.returncode == 0, "restart after SIGTERM converges", f"exit {p.returncode}")
    ok, k = same(f"{OUT}/full.h5", f"{OUT}/sig_restart.h5")
    check(ok, "restart after SIGTERM is bitwise identical to the uninterrupted run", k)
    check(not os.path.exists(f"{OUT}/sig_restart.h5.ckpt.h5"), "a converged run leaves no checkpoint")

# 2. periodic checkpoints: stop at max_outer, resume with a larger limit
p = subprocess.run([BIN, DECK, *MESH, "&solver delta=0.998, max_outer=1500 /", out("part").replace(" /", ", checkpoint_every=500 /")],
                   capture_output=True, text=True, env=env)
check(p.returncode == 2, "max_outer run exits 2", f"exit {p.returncode}")
ck2 = f"{OUT}/part.h5.ckpt.h5"
check(os.path.exists(ck2), "periodic checkpoint written")
if os.path.exists(ck2):
    p = subprocess.run([BIN, DECK, *MESH, SLOW, out("part_restart"), "--restart", ck2], capture_output=True,
                       text=True, env=env)
    check(p.returncode == 0, "restart from the periodic checkpoint converges", f"exit {p.returncode}")
    ok, k = same(f"{OUT}/full.h5", f"{OUT}/part_restart.h5")
    check(ok, "restart from a periodic checkpoint is bitwise identical", k)
    # 3. refused: another deck (delta) or another mesh
    for over, what in [("&solver delta=0.7 /", "another delta"), ("&body id=1, nx=256, ny=8 /", "another mesh")]:
        extra = [over] if "body" not in over else [over, "&body id=2, nx=256, ny=8 /"]
        p = subprocess.run([BIN, DECK, *MESH, *extra, out("refused"), "--restart", ck2], capture_output=True,
                           text=True, env=env)
        msg = p.stderr + p.stdout
        check(p.returncode == 1 and "different" in msg and "Fortran runtime" not in msg,
              f"restart refused for {what}", f"exit {p.returncode}")
    p = subprocess.run([BIN, DECK, "&solver method='monolithic' /", out("mono"), "--restart", ck2],
                       capture_output=True, text=True, env=env)
    check(p.returncode == 1, "restart refused for method='monolithic'", f"exit {p.returncode}")

print(f"{len(FAILS)} failed checks")
sys.exit(1 if FAILS else 0)
