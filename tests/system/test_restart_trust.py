#!/usr/bin/python3
"""Checkpoints that cannot lie (run by `make check`).

(a) A NaN or an infinity in any real dataset or attribute of a floating run's checkpoint
    (/state/mu, the floating body's equality multipliers, first; then every other one of
    /state and /history) is refused on --restart: exit 1, one message naming the
    checkpoint file and the dataset or attribute, no runtime error, nothing written.
(b) A mesh file replaced at the same path (one node moved: same counts, same contact
    nodes) is refused on --restart: exit 1 saying that the mesh file (named) changed since
    the checkpoint. The unchanged file, and the original bytes put back, are accepted.
(c) A floating run stopped part-way (by max_outer with periodic checkpoints, and by
    SIGTERM) and restarted ends bitwise identical to the uninterrupted run: every dataset
    of the result file, every root attribute (equality_updates, outer and inner counts
    among them) and the counts of the `result:` line.
"""
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
from rc_run import result_fields, solver_env  # noqa: E402
from plane_decks import PAPER_ROLLER  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", "bin/robin_contact"))
OUT = os.path.abspath(os.path.join(os.environ.get("BUILD", "build/release"), "test-out", "restart_trust"))
ENV = solver_env(2)
check = Checks()
shutil.rmtree(OUT, ignore_errors=True)
os.makedirs(OUT)

# the paper's scene, body 1 on a roller (ux = 0 on its left side): held vertically only by
# contact, so its checkpoint carries SMALBE multipliers /state/mu; about 25 outer iterations
ROLLER = os.path.join(OUT, "roller.nml")
with open(ROLLER, "w") as f:
    f.write(PAPER_ROLLER)


def out(name):
    return os.path.join(OUT, name + ".h5")


def run(deck, *args):
    return subprocess.run([BIN, deck, *args], capture_output=True, text=True, env=ENV, timeout=600)


def clean_refusal(p, what, *needles):
    """exit 1, every needle in the message, no runtime error or backtrace."""
    msg = p.stderr + p.stdout
    good = (p.returncode == 1 and all(n in p.stderr for n in needles)
            and "Fortran runtime" not in msg and "Backtrace" not in msg and "SIGSEGV" not in msg)
    return check(good, what, f"exit {p.returncode}: {p.stderr.strip()[-300:]}")


def real_objects(ck):
    """[(kind, group, name)] of every real dataset and real attribute in /state and /history."""
    objs = []
    with h5py.File(ck, "r") as f:
        for g in ("state", "history"):
            for name, d in f[g].items():
                if d.dtype.kind == "f":
                    objs.append(("dataset", g, name))
            for name, v in f[g].attrs.items():
                if np.asarray(v).dtype.kind == "f":
                    objs.append(("attribute", g, name))
    return objs


def poison(src, dst, kind, group, name, value):
    """A copy of checkpoint src with one element of a real object set to value."""
    shutil.copy2(src, dst)
    with h5py.File(dst, "r+") as f:
        if kind == "dataset":
            a = np.array(f[group][name])
            if a.size == 0:
                return False
            flat = a.reshape(-1)
            flat[flat.size // 2] = value
            f[group][name][...] = flat.reshape(a.shape)
        else:
            f[group].attrs[name] = np.float64(value)
    return True


def every_difference(a, b):
    """Datasets and root attributes of result files a and b that differ (timing and
    wall-clock values, run_id, and input_deck, which names the output file, aside)."""
    diff = []
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        names = []
        fa.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        namesb = []
        fb.visititems(lambda n, o: namesb.append(n) if isinstance(o, h5py.Dataset) else None)
        if sorted(names) != sorted(namesb):
            diff.append("dataset names: " + str(sorted(set(names) ^ set(namesb))))
        for n in names:
            if n.startswith("timing") or n.endswith("wall_s") or n == "input_deck" or n not in fb:
                continue
            x, y = np.array(fa[n]), np.array(fb[n])
            same = x.shape == y.shape and (np.array_equal(x, y, equal_nan=True) if x.dtype.kind == "f"
                                           else np.array_equal(x, y))
            if not same:
                diff.append(n)
        for k in sorted(set(fa.attrs) | set(fb.attrs)):
            if k in ("run_id",):
                continue
            if k not in fa.attrs or k not in fb.attrs or not np.array_equal(np.asarray(fa.attrs[k]),
                                                                            np.asarray(fb.attrs[k])):
                diff.append("attribute " + k)
    return diff


def counts(text):
    r = result_fields(text)
    return None if r is None else {k: r[k] for k in ("status", "method", "outer", "inner", "n1", "n2", "m", "residual")}


# ---- reference: the uninterrupted floating run ----------------------------------------------------
full = run(ROLLER, f"&output file='{out('full')}' /")
check(full.returncode == 0 and os.path.exists(out("full")), "uninterrupted floating run converges",
      f"exit {full.returncode}")
with h5py.File(out("full"), "r") as f:
    eq_full = int(f.attrs["equality_updates"])
check(eq_full > 0, "the uninterrupted run counts SMALBE multiplier updates", eq_full)

# a checkpoint after 10 outer iterations (exit 2: max_outer reached)
p = run(ROLLER, "&solver max_outer=10 /", f"&output file='{out('part')}', checkpoint_every=5 /")
CK = out("part") + ".ckpt.h5"
check(p.returncode == 2 and os.path.exists(CK), "a floating run stopped at max_outer=10 leaves a checkpoint",
      f"exit {p.returncode}")
with h5py.File(CK, "r") as f:
    mu = np.array(f["state/mu"])
check(np.any(mu != 0.0), "its /state/mu holds the floating body's multipliers", str(mu.ravel()))

# ---- (a) NaN or Inf anywhere in the stored state --------------------------------------------------
target = out("poisoned")
p = run(ROLLER, f"&output file='{target}' /", "--restart", CK + ".x")   # no such file: sanity of the refusal
clean_refusal(p, "a missing checkpoint: exit 1", CK + ".x")
objs = real_objects(CK)
check(("dataset", "state", "mu") in objs and ("dataset", "history", "criterion") in objs
      and ("attribute", "state", "omega") in objs, "the real objects of the checkpoint are found", len(objs))
# /state/mu first (the reported case), then every other real object; Inf on a few
objs.sort(key=lambda o: (o != ("dataset", "state", "mu"), o))
for i, (kind, group, name) in enumerate(objs):
    for value, label in ((np.nan, "NaN"), (np.inf, "Inf")):
        if label == "Inf" and i % 4 != 0:
            continue
        bad = os.path.join(OUT, f"bad_{group}_{name}_{label}.ckpt.h5")
        if not poison(CK, bad, kind, group, name, value):
            continue
        p = run(ROLLER, f"&output file='{target}' /", "--restart", bad)
        obj = f"dataset /{group}/{name}" if kind == "dataset" else f"attribute {name} of /{group}"
        clean_refusal(p, f"{label} in {obj}: exit 1 naming the checkpoint and {obj}", bad, obj)
check(not os.path.exists(target), "no refused restart wrote a result")

# ---- (b) a mesh file replaced at the same path ----------------------------------------------------
MSH = os.path.join(OUT, "patch.msh")
shutil.copy2("inputs/gmsh/patch.msh", MSH)
PATCH = os.path.join(OUT, "patch.nml")
with open("inputs/patch.nml") as f:
    open(PATCH, "w").write(f.read().replace("gmsh/patch.msh", "patch.msh"))
original = open(MSH, "rb").read()


def moved_node(text):
    """The mesh text with the first node of the first surface entity moved by 1e-3 in x."""
    lines = text.split("\n")
    i = lines.index("$Nodes") + 2
    while not lines[i].startswith("$EndNodes"):
        dim, _, _, n = (int(v) for v in lines[i].split())
        if dim == 2 and n > 0:
            j = i + 1 + n
            xyz = [float(v) for v in lines[j].split()]
            xyz[0] += 1.0e-3
            lines[j] = " ".join(repr(v) for v in xyz)
            return "\n".join(lines)
        i += 1 + 2 * n
    raise RuntimeError("no surface node in the mesh")


p = run(PATCH, "&solver max_outer=2 /", f"&output file='{out('patch_part')}', checkpoint_every=1 /")
PCK = out("patch_part") + ".ckpt.h5"
check(p.returncode == 2 and os.path.exists(PCK), "a mesh-file run stopped at max_outer=2 leaves a checkpoint",
      f"exit {p.returncode}")
with open(MSH, "w") as f:
    f.write(moved_node(original.decode()))
p = run(PATCH, f"&output file='{out('patch_moved')}' /", "--restart", PCK)
clean_refusal(p, "a mesh file replaced at the same path: exit 1 naming it as changed since the checkpoint",
              f"mesh file {MSH} changed since the checkpoint")
check(not os.path.exists(out("patch_moved")), "the refused restart wrote nothing")
with open(MSH, "wb") as f:   # the original bytes again (a new modification time): accepted
    f.write(original)
p = run(PATCH, f"&output file='{out('patch_restart')}' /", "--restart", PCK)
check(p.returncode == 0, "the original mesh bytes put back: the restart is accepted and converges",
      f"exit {p.returncode}: {p.stderr.strip()[-200:]}")
with h5py.File(PCK, "r") as f:
    text = f["mesh_files"][()].decode() if "mesh_files" in f else "(no /mesh_files)"
check(text.count("\n") == 0 and text.endswith("  " + MSH), "one mesh file recorded once for both bodies", text)

# ---- (c) a floating run restarted: bitwise the uninterrupted one ----------------------------------
p = run(ROLLER, f"&output file='{out('restart')}' /", "--restart", CK)
check(p.returncode == 0, "restart from the max_outer checkpoint converges", f"exit {p.returncode}")
if p.returncode == 0:
    d = every_difference(out("full"), out("restart"))
    check(not d, "restart from the max_outer checkpoint: every dataset and root attribute identical", d)
    check(counts(p.stdout) == counts(full.stdout), "restart from the max_outer checkpoint: the result line's counts",
          f"{counts(p.stdout)} vs {counts(full.stdout)}")

# interrupted by SIGTERM part-way: a larger roller under 'steklov' at delta 0.9 (about 200
# outer iterations of about a millisecond each), signalled as soon as its first iteration's
# progress line appears (a progress line per iteration), so the run cannot end first
BIG = os.path.join(OUT, "roller_big.nml")
with open(BIG, "w") as f:
    f.write(open(ROLLER).read().replace("nx=24, ny=16", "nx=192, ny=64")
            .replace("robin_operator='harmonic', delta=0.5", "robin_operator='steklov', delta=0.9"))
    f.write("&output progress_lines=100000 /\n")
bfull = run(BIG, f"&output file='{out('big_full')}' /")
check(bfull.returncode == 0, "uninterrupted large floating run converges", f"exit {bfull.returncode}")
t_full = float(result_fields(bfull.stdout)["wall_s"]) if bfull.returncode == 0 else 0.0
proc = subprocess.Popen([BIN, BIG, f"&output file='{out('big_sig')}' /"], stdout=subprocess.PIPE,
                        stderr=subprocess.PIPE, text=True, env=ENV)
# wait for the outer iteration to start, then a bit more
t0 = time.time()
buf = ""
while "outer   criterion" not in buf and time.time() - t0 < 120:
    line = proc.stdout.readline()
    if not line:
        break
    buf += line
proc.stdout.readline()  # the first iteration's line
proc.send_signal(signal.SIGTERM)
so, se = proc.communicate(timeout=300)
BCK = out("big_sig") + ".ckpt.h5"
check(proc.returncode == 4 and os.path.exists(BCK), "SIGTERM during a floating run: exit 4 with a checkpoint",
      f"exit {proc.returncode}, full run {t_full:.2f} s")
if os.path.exists(BCK):
    with h5py.File(BCK, "r") as f:
        it = int(f["state"].attrs["it"])
    p = run(BIG, f"&output file='{out('big_restart')}' /", "--restart", BCK)
    check(p.returncode == 0, f"restart after SIGTERM (checkpoint at outer iteration {it}) converges",
          f"exit {p.returncode}")
    if p.returncode == 0:
        d = every_difference(out("big_full"), out("big_restart"))
        check(not d, "restart after SIGTERM: every dataset and root attribute identical", d)
        check(counts(p.stdout) == counts(bfull.stdout), "restart after SIGTERM: the result line's counts",
              f"{counts(p.stdout)} vs {counts(bfull.stdout)}")

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
