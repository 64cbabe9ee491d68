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

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from rc_checks import Checks  # noqa: E402
from rc_results import text_attr  # noqa: E402
from rc_run import run_solver, solver_env  # noqa: E402

BIN = os.environ.get("BIN", "bin/robin_contact")
OUT = os.path.join(os.environ.get("BUILD", "build/release"), "test-out", "restart")
shutil.rmtree(OUT, ignore_errors=True)
os.makedirs(OUT)
check = Checks()
DECK = "inputs/table1/q1_16x8.nml"
MESH = ["&body id=1, nx=256, ny=8 /", "&body id=2, nx=256, ny=8 /"]
SLOW = "&solver delta=0.998, max_outer=40000 /"   # about 4900 outer iterations, about 5 s


def out(name):
    return f"&output file='{OUT}/{name}.h5' /"


def same(a, b):
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        for k in ["/contact/normal_force", "/contact/gap", "/body1/displacement", "/body2/displacement",
                  "/history/criterion", "/history/residual", "/history/inner", "/history/active"]:
            if not np.array_equal(np.array(fa[k]), np.array(fb[k])):
                return False, k
        for k in ["outer_iterations", "inner_iterations", "status"]:
            if text_attr(fa, k) != text_attr(fb, k):
                return False, k
    return True, ""


def run(*args):
    p, _ = run_solver(BIN, DECK, *args, env=env)
    return p


def restart(ck, name, converges, identical):
    """Restart the slow run from checkpoint ck into <name>.h5; checks (labels converges,
    identical) that it converges and ends bitwise identical to the uninterrupted run."""
    p = run(*MESH, SLOW, out(name), "--restart", ck)
    check(p.returncode == 0, converges, f"exit {p.returncode}")
    ok, k = same(f"{OUT}/full.h5", f"{OUT}/{name}.h5")
    check(ok, identical, k)


env = solver_env(2)
# reference: uninterrupted
p = run(*MESH, SLOW, out("full"))
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
        st = text_attr(f, "status")
        check(st == "interrupted", "SIGTERM: result flagged interrupted", st)
        n = int(f.attrs["outer_iterations"])
        check(0 < n < 4500, "SIGTERM: stopped part-way", f"outer {n}")
else:
    check(False, "SIGTERM: result file written")
if os.path.exists(ck):
    restart(ck, "sig_restart", "restart after SIGTERM converges",
            "restart after SIGTERM is bitwise identical to the uninterrupted run")
    check(not os.path.exists(f"{OUT}/sig_restart.h5.ckpt.h5"), "a converged run leaves no checkpoint")

# 2. periodic checkpoints: stop at max_outer, resume with a larger limit
p = run(*MESH, "&solver delta=0.998, max_outer=1500 /", out("part").replace(" /", ", checkpoint_every=500 /"))
check(p.returncode == 2, "max_outer run exits 2", f"exit {p.returncode}")
ck2 = f"{OUT}/part.h5.ckpt.h5"
check(os.path.exists(ck2), "periodic checkpoint written")
if os.path.exists(ck2):
    restart(ck2, "part_restart", "restart from the periodic checkpoint converges",
            "restart from a periodic checkpoint is bitwise identical")
    # 3. refused: another deck (delta) or another mesh
    for over, what in [("&solver delta=0.7 /", "another delta"), ("&body id=1, nx=128, ny=8 /", "another mesh")]:
        extra = [over] if "body" not in over else [over, "&body id=2, nx=128, ny=8 /"]
        p = run(*MESH, *extra, out("refused"), "--restart", ck2)
        msg = p.stderr + p.stdout
        check(p.returncode == 1 and "different" in msg and "Fortran runtime" not in msg,
              f"restart refused for {what}", f"exit {p.returncode}")
    p = run("&solver method='monolithic' /", out("mono"), "--restart", ck2)
    check(p.returncode == 1, "restart refused for method='monolithic'", f"exit {p.returncode}")

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
