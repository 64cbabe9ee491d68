#!/usr/bin/env python3
"""Whole-program tests of the MPI binary bin/robin_contact_mpi (run by `make check`, which
builds it where mpif90 and libmumps-dev are installed; without it this test says so and
passes): factorization='mumps' under mpirun -np 1, 2 and 4 gives the CHOLMOD path's
contact forces to 1e-10 relative, Robin and monolithic, on the paper's scene and on a
partial-contact scene (a parabolic initial gap); factorization='mumps' in the serial binary
is bad input naming the MPI binary; bad input and an injected MUMPS failure end every rank
with exit 1 / 3 and one message, within a timeout (no rank left hanging); SIGTERM to
the ranks (as srun sends it) in the Robin iteration: exit 4, a checkpoint, and a restart
that converges as an uninterrupted run; an eight-body deck at -np 1 to 12 (several bodies
per rank, one, several ranks per body) gives the serial binary's contact forces, and each
rank holds the factors of its own bodies only; the four solid bodies of inputs/cube_stack.nml
(three held only by contact) at -np 1, 2 and 4 give the serial contact forces and
displacements to 1e-10, and so does Hertz's sphere (a curved slave, factored in its contact
frames) at -np 1 and 2."""
import os
import re
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from rc_checks import Checks  # noqa: E402
from rc_results import read_lam, rel_err, text_attr  # noqa: E402
from rc_run import result_fields, run_solver, solver_env  # noqa: E402

BIN = os.environ.get("BIN", "bin/robin_contact")
MPI_BIN = os.environ.get("MPI_BIN", "bin/robin_contact_mpi")
OUT = os.path.join(os.environ.get("BUILD", "build/release"), "test-out", "mpi")
os.makedirs(OUT, exist_ok=True)
check = Checks()
TIMEOUT = 120
MUMPS = "&solver factorization='mumps' /"
GAP = "&contact gap_radius=5.0, gap_center=1.5 /"


def mpi_env(extra=None):
    """The environment of an mpirun: root allowed (OpenMPI refuses it otherwise), idle ranks
    yield their core (the runs are oversubscribed), one OpenMP thread per rank."""
    env = solver_env(1)
    env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_mpi_yield_when_idle="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    env.update(extra or {})
    return env


def mpirun(np_, *args, name, extra_env=None):
    """mpirun -np np_ MPI_BIN args, result file OUT/name.h5; (process or None on timeout, file)."""
    out = os.path.join(OUT, name + ".h5")
    if os.path.exists(out):
        os.remove(out)
    cmd = ["mpirun", "--oversubscribe", "-np", str(np_), MPI_BIN, *args, f"&output file='{out}' /"]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, env=mpi_env(extra_env), timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        return None, out
    return p, out


def fresh(name):
    """(OUT/name.h5, its checkpoint OUT/name.h5.ckpt.h5), neither left from an earlier run."""
    out = os.path.join(OUT, name + ".h5")
    for f in (out, out + ".ckpt.h5"):
        if os.path.exists(f):
            os.remove(f)
    return out, out + ".ckpt.h5"


def error_lines(p):
    return [ln for ln in p.stderr.splitlines() if ln.startswith("robin_contact: error:")]


if not (os.path.exists(MPI_BIN) and shutil.which("mpirun")):
    print(f"SKIP  {MPI_BIN} or mpirun absent (make MPI=1 after tools/install-deps.sh): nothing to test")
    sys.exit(0)

# 1. the serial binary refuses factorization='mumps' as bad input, naming the MPI binary
p, _ = run_solver(BIN, "inputs/default.nml", MUMPS, env=solver_env(1))
check(p.returncode == 1, "serial binary: factorization='mumps' exits 1", f"exit {p.returncode}")
check("bin/robin_contact_mpi" in p.stderr and "mpirun" in p.stderr, "its message says to use bin/robin_contact_mpi "
      "under mpirun", p.stderr.strip()[-200:])

# 2. the same contact forces as CHOLMOD, np = 1, 2, 4, two scenes, Robin and monolithic
for scene, over in (("paper", []), ("gap", [GAP])):
    for method in ("robin", "monolithic"):
        ref = os.path.join(OUT, f"ref_{scene}_{method}.h5")
        meth = f"&solver method='{method}' /"
        p, m = run_solver(BIN, "inputs/default.nml", *over, meth, f"&output file='{ref}' /", env=solver_env(1))
        if not check(p.returncode == 0, f"CHOLMOD reference {scene} {method} exits 0", f"exit {p.returncode}"):
            continue
        lam_ref = read_lam(ref)
        if scene == "gap":
            check(0 < np.count_nonzero(lam_ref > 0) < lam_ref.size, "the gap scene is in partial contact",
                  f"{np.count_nonzero(lam_ref > 0)} of {lam_ref.size} nodes active")
        for np_ in (1, 2, 4):
            q, out = mpirun(np_, "inputs/default.nml", *over, meth, MUMPS, name=f"{scene}_{method}_np{np_}")
            what = f"mpirun -np {np_} {scene} {method}"
            if not check(q is not None, f"{what} ends within {TIMEOUT} s"):
                continue
            if not check(q.returncode == 0, f"{what} exits 0", f"exit {q.returncode}: {q.stderr.strip()[-300:]}"):
                continue
            e = rel_err(read_lam(out), lam_ref)
            check(e is not None and e < 1e-10, f"{what}: contact forces = CHOLMOD's to 1e-10", f"rel. error {e}")
            r = result_fields(q.stdout)
            check(r is not None and r["status"] == "converged", f"{what}: one result line, converged")
            with h5py.File(out, "r") as f:
                fa, ra = text_attr(f, "factorization"), int(f.attrs.get("ranks", -1))
            check(fa == "mumps" and ra == np_, f"{what}: the file says factorization='mumps', ranks={np_}",
                  f"{fa!r}, {ra}")
            mp = re.findall(r"^mpi: ranks=(\d+) peak_rss_max_rank_mb=([0-9.]+) max_rank=(\d+) peak_rss_sum_mb=([0-9.]+)",
                            q.stdout, re.M)
            check(len(mp) == 1 and int(mp[0][0]) == np_ and 0 < float(mp[0][1]) <= float(mp[0][3]),
                  f"{what}: one line with the largest peak memory of any rank and the sum over ranks", f"{mp}")
            check(q.stdout.count("result: ") == 1 and q.stdout.count("phase: assembly") == 1,
                  f"{what}: progress and summary printed once", f"{q.stdout.count('result: ')} result lines")

# 3. bad input under mpirun: every rank exits 1, one message
for np_ in (1, 4):
    q, _ = mpirun(np_, "inputs/default.nml", "&body id=2, left='free' /", MUMPS, name=f"bad_np{np_}")
    if check(q is not None, f"-np {np_} unsupported body: every rank ends within {TIMEOUT} s"):
        check(q.returncode == 1, f"-np {np_} unsupported body exits 1", f"exit {q.returncode}")
        check(len(error_lines(q)) == 1, f"-np {np_} unsupported body: one error message", f"{len(error_lines(q))}")
q, _ = mpirun(2, "inputs/default.nml", name="cholmod_np2")
if check(q is not None, "-np 2 with factorization='cholmod' ends"):
    check(q.returncode == 1 and "mumps" in q.stderr, "-np 2 with factorization='cholmod' exits 1, pointing to "
          "'mumps'", f"exit {q.returncode}")

# 3b. the memory check sizes each rank (its share of its body's factor, the meshes of both
# bodies) and sums the ranks of a node: with the node's memory declared at 3000 MB
# (ROBIN_MEMORY_LIMIT_MB) a 1024x512 body per rank is refused before anything is
# allocated, exit 1, one message naming the estimate per rank; the estimate per rank falls
# with the ranks per body (nearly halves from 1 to 2, the factor share exactly)
PER_RANK = re.compile(r"a rank needs about ([0-9.]+) GiB \(rank \d+: its share of the MUMPS factor ([0-9.]+) GiB")
est = {}
for np_ in (2, 4):
    q, out = mpirun(np_, "inputs/default.nml", "&body id=1, nx=1024, ny=512 /", "&body id=2, nx=1024, ny=512 /",
                    MUMPS, name=f"budget_np{np_}", extra_env={"ROBIN_MEMORY_LIMIT_MB": "3000"})
    if not check(q is not None, f"-np {np_} over the node's memory: every rank ends within {TIMEOUT} s"):
        continue
    el = error_lines(q)
    m = PER_RANK.search(el[0]) if len(el) == 1 else None
    lim = re.search(r"may use only ([0-9.]+) GiB", el[0]) if len(el) == 1 else None
    check(q.returncode == 1 and m is not None and f"the {np_} rank(s) on its node" in el[0] and lim is not None
          and float(lim.group(1)) <= 2.93,
          f"-np {np_} over the node's memory: exit 1, one message naming the estimate per rank, the node's sum "
          "and the limit", f"exit {q.returncode}: {el[0][:300] if el else q.stderr[-300:]}")
    check(not os.path.exists(out) and "phase: assembly" not in q.stdout, f"-np {np_}: refused before assembly, "
          "nothing written")
    if m:
        est[np_] = (float(m.group(1)), float(m.group(2)))
if len(est) == 2:
    check(est[4][0] < 0.65 * est[2][0] and abs(est[4][1] - est[2][1] / 2) <= 0.011,
          "the estimate per rank falls with the ranks per body (2 per body against 1)", f"{est}")

# 4. a MUMPS failure (working memory capped at 1 MB per rank): exit 3 on every rank, one message
for np_ in (1, 2, 4):
    q, out = mpirun(np_, "inputs/default.nml", "&body id=2, ny=256 /", MUMPS, name=f"memfail_np{np_}",
                    extra_env={"ROBIN_MUMPS_MAX_MB": "1"})
    if check(q is not None, f"-np {np_} MUMPS failure: every rank ends within {TIMEOUT} s"):
        check(q.returncode == 3, f"-np {np_} MUMPS failure exits 3", f"exit {q.returncode}")
        el = error_lines(q)
        check(len(el) == 1 and "MUMPS" in el[0] and "INFO(1) = -19" in el[0], f"-np {np_} MUMPS failure: one "
              "message with the code and its meaning", el[0] if el else q.stderr[-200:])
        check(not os.path.exists(out), f"-np {np_} MUMPS failure writes no result file")

# 5. SIGTERM to the ranks (as srun delivers it; OpenMPI's mpirun kills its ranks instead)
# during the Robin iteration: every rank exits 4, rank 0 writes the checkpoint, and the
# same command with --restart resumes from it and converges as an uninterrupted run (at
# 256x128 per body and delta 0.005: about 1460 outer iterations, 5 s at -np 2)
small = ["inputs/default.nml", "&body id=1, nx=256, ny=128 /", "&body id=2, nx=256, ny=128 /",
         "&solver factorization='mumps', delta=0.005, max_outer=20000 /"]
out, ckpt = fresh("sigterm")
cmd = ["mpirun", "--oversubscribe", "-np", "2", MPI_BIN, *small, f"&output file='{out}', checkpoint_every=50 /"]
log = os.path.join(OUT, "sigterm.log")
with open(log, "w") as lf:
    pr = subprocess.Popen(cmd, stdout=lf, stderr=subprocess.STDOUT, env=mpi_env())
    t0 = time.time()
    while time.time() - t0 < TIMEOUT and "phase: Robin" not in open(log).read() and pr.poll() is None:
        time.sleep(0.1)
    time.sleep(1.0)
    ranks = subprocess.run(["pgrep", "-P", str(pr.pid)], capture_output=True, text=True).stdout.split()
    for r in ranks:
        os.kill(int(r), signal.SIGTERM)
    try:
        rc = pr.wait(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        pr.kill()
        rc = None
text = open(log).read()
check(rc == 4, "SIGTERM to the ranks in the Robin iteration: exit 4", f"exit {rc}, {len(ranks)} ranks signalled")
check("status=interrupted" in text and os.path.exists(ckpt), "status=interrupted, checkpoint written")
if os.path.exists(ckpt):
    q, _ = mpirun(2, *small, "--restart", ckpt, name="sigterm")
    check(q is not None and q.returncode == 0 and "resuming after outer iteration" in q.stdout,
          "the same command with --restart resumes and converges", f"exit {q.returncode if q else None}")
    r = result_fields(q.stdout) if q else None
    check(r is not None and (r["outer"], r["inner"]) == ("1462", "6077"), "its outer/inner counts are those of "
          "an uninterrupted run (1462/6077, the serial binary's)", f"{r and (r['outer'], r['inner'])}")

# 6. SIGUSR1 to mpirun itself (OpenMPI forwards SIGUSR1 to its ranks, while it answers
# SIGTERM by killing them): the binary takes it as SIGTERM, so rank 0 writes the checkpoint
# and mpirun exits 4 (the ranks' code); the run of section 5
out, ckpt = fresh("sigusr1")


def signal_in_robin(cmd, env, log, sig):
    """Run cmd (output to log), send sig once the Robin iteration has started; the exit
    code (None after TIMEOUT) and the log's text."""
    with open(log, "w") as lf:
        pr = subprocess.Popen(cmd, stdout=lf, stderr=subprocess.STDOUT, env=env)
        t0 = time.time()
        while time.time() - t0 < TIMEOUT and "phase: Robin" not in open(log).read() and pr.poll() is None:
            time.sleep(0.05)
        time.sleep(0.3)
        pr.send_signal(sig)
        try:
            rc = pr.wait(timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            pr.kill()
            rc = None
    return rc, open(log).read()


rc, text = signal_in_robin(["mpirun", "--oversubscribe", "-np", "2", MPI_BIN, *small,
                            f"&output file='{out}', checkpoint_every=50 /"], mpi_env(),
                           os.path.join(OUT, "sigusr1.log"), signal.SIGUSR1)
check(rc == 4 and "status=interrupted" in text and os.path.exists(ckpt), "SIGUSR1 to mpirun in the Robin "
      "iteration: exit 4, status=interrupted, checkpoint written", f"exit {rc}")

# 7. the Slurm MPI script without srun (mpirun, NP ranks): a SIGTERM to the script (as a
# scheduler or a user sends it) becomes SIGUSR1 for mpirun: exit 4 and a checkpoint
out, ckpt = fresh("sigusr1")
env = mpi_env({"NP": "2", "BIN": MPI_BIN})
for k in [k for k in env if k.startswith("SLURM_")]:
    del env[k]
rc, text = signal_in_robin(["bash", "tools/slurm/run_deck_mpi.sbatch", *small,
                            f"&output file='{out}', checkpoint_every=50 /"], env,
                           os.path.join(OUT, "sbatch_term.log"), signal.SIGTERM)
check(rc == 4 and "status=interrupted" in text and os.path.exists(ckpt) and "resubmit with --restart" in text,
      "tools/slurm/run_deck_mpi.sbatch under mpirun: SIGTERM to the script gives exit 4 and a checkpoint",
      f"exit {rc}")

# 8. eight bodies (two columns of four blocks of different meshes, the lower ones clamped,
# the others held by a roller on the left, a pressure on each column's top) at -np 1, 2,
# 4, 8, 12: fewer ranks than bodies put several bodies on a rank, more give the larger
# bodies more ranks. The contact forces equal the serial CHOLMOD binary's to 1e-10 of the
# largest (tol=1e-11: the default 1e-8 leaves both runs 1e-10 from the fixed point); each
# rank reports its bodies, its share of their MUMPS factors and its peak memory; a rank's
# factor is the sum of its own bodies' factors (each body's measured at -np 8, one body per
# rank), never all bodies'
COLUMNS = [[(8 * (k + 1), 4 * (k + 1)) for k in range(1, 5)], [(6 * (k + 1), 3 * (k + 1)) for k in range(1, 5)]]


def columns_deck(path):
    """Write the eight-body deck (bodies 1-4 the left column top to bottom, 5-8 the right)."""
    lines, bid = [], 0
    for c, col in enumerate(COLUMNS):
        top = bid + 1
        for k, (nx, ny) in enumerate(col):
            bid += 1
            lines.append(f"&body id={bid}, x0={1.2 * c}, y0={3.0 - k}, width=1.0, height=1.0, nx={nx}, ny={ny}"
                         + (", bottom='clamped'" if k == 3 else ", left='roller'") + " /")
        lines.append(f"&traction body={top}, side='top', t0=0.0, -1.0e6 /")
        lines += [f"&contact bodies={b},{b + 1}, groups='bottom','top' /" for b in range(top, top + 3)]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


RANK_LINE = re.compile(r"^mpi: rank=(\d+) bodies=([0-9,]+) factor_mb=([0-9.]+) peak_rss_mb=([0-9.]+)$", re.M)
deck8 = os.path.join(OUT, "columns8.nml")
columns_deck(deck8)
cells = [nx * ny for col in COLUMNS for nx, ny in col]
ref8 = os.path.join(OUT, "columns8_serial.h5")
TOL = "tol=1e-11"
p, r = run_solver(BIN, deck8, f"&solver {TOL} /", f"&output file='{ref8}' /", env=solver_env(1))
ranks_of = {}
if check(p.returncode == 0 and r is not None and r["bodies"] == "8", "8 bodies: the serial CHOLMOD reference "
         "exits 0", f"exit {p.returncode}: {p.stderr.strip()[-200:]}"):
    lam8 = read_lam(ref8)
    for np_ in (8, 1, 2, 4, 12):
        q, out = mpirun(np_, deck8, f"&solver factorization='mumps', {TOL} /", name=f"columns8_np{np_}")
        what = f"8 bodies, mpirun -np {np_}"
        if not check(q is not None and q.returncode == 0, f"{what} exits 0",
                     f"{'timeout' if q is None else q.stderr.strip()[-300:]}"):
            continue
        lam = read_lam(out)
        e = float(np.abs(lam - lam8).max() / np.abs(lam8).max()) if lam.shape == lam8.shape else None
        check(e is not None and e < 1e-10, f"{what}: contact forces = the serial binary's to 1e-10 of the largest",
              f"max difference / max force {e}")
        rows = [(int(a), [int(b) for b in bs.split(",")], float(f), float(m)) for a, bs, f, m in
                RANK_LINE.findall(q.stdout)]
        if not check(sorted(x[0] for x in rows) == list(range(np_)) and all(x[3] > 0 for x in rows),
                     f"{what}: one line per rank with its bodies, factor and peak memory", f"{len(rows)} lines"):
            continue
        print(f"INFO  {what}: per-rank peak RSS MB " + " ".join(f"{x[3]:.1f}" for x in rows)
              + "; factor MB " + " ".join(f"{x[2]:.3f}" for x in rows))
        ranks_of[np_] = rows
        hosted = sorted(b for x in rows for b in x[1])
        if np_ <= 8:
            check(hosted == list(range(1, 9)), f"{what}: each body on one rank", f"{hosted}")
        else:
            per_body = [sum(b in x[1] for x in rows) for b in range(1, 9)]
            order = sorted(range(8), key=lambda i: cells[i])
            check(min(per_body) >= 1 and sum(per_body) == np_ and all(
                per_body[order[i]] <= per_body[order[i + 1]] for i in range(7)) and max(per_body) > 1,
                f"{what}: every rank on one body, the larger bodies on more ranks", f"ranks per body {per_body}")
if 8 in ranks_of:
    size = {x[1][0]: x[2] for x in ranks_of[8]}   # one body per rank: each body's factor
    total = sum(size.values())
    check(all(size[b] < 0.5 * total for b in size), "-np 8: no rank holds more than its own body's factor "
          "(each less than half of all bodies')", f"{size}, all {total:.3f} MB")
    for np_ in (1, 2, 4):
        if np_ not in ranks_of:
            continue
        bad = [(a, f, sum(size[b] for b in bs)) for a, bs, f, _ in ranks_of[np_]
               if abs(f - sum(size[b] for b in bs)) > 0.002 + 0.01 * f]
        check(not bad, f"-np {np_}: each rank's factor = the sum of its own bodies' factors (as measured at -np 8)",
              f"(rank, factor, its bodies' sum): {bad}")
    if 12 in ranks_of:
        share = {}
        for _, bs, f, _ in ranks_of[12]:
            share[bs[0]] = share.get(bs[0], 0.0) + f
        bad = [b for b in share if not 0.5 * size[b] < share[b] < 2.0 * size[b] + 0.002]
        check(not bad, "-np 12: a body's factor over its group is about its factor on one rank, and each rank "
              "holds a share of one body's only", f"bodies {bad}: {share} against {size}")

# 8b. a MUMPS failure on one of the ranks that hold several bodies (-np 3, eight bodies,
# working memory capped at 1 MB per rank, body 3 enlarged so that its factor cannot fit):
# every rank exits 3, one message, no result file
q, out = mpirun(3, deck8, "&body id=3, nx=64, ny=128 /", "&solver factorization='mumps' /", name="columns8_memfail",
                extra_env={"ROBIN_MUMPS_MAX_MB": "1"})
if check(q is not None, f"8 bodies, -np 3, MUMPS failure: every rank ends within {TIMEOUT} s"):
    el = error_lines(q)
    check(q.returncode == 3 and len(el) == 1 and "INFO(1) = -19" in el[0] and not os.path.exists(out),
          "8 bodies, -np 3, MUMPS failure: exit 3, one message with the code, no result file",
          f"exit {q.returncode}: {el}")

# 9. load steps (two stages, the upper block held only by contact): -np 2 gives every step of
# the serial binary's history to 1e-10
steps_deck = os.path.join(OUT, "steps.nml")
with open(steps_deck, "w") as fh:
    fh.write("&body id=1, x0=0, y0=1, width=1, height=0.5, nx=8, ny=4, young=1e9, poisson=0.3, "
             "bottom='contact', left='roller' /\n"
             "&body id=2, x0=0, y0=0, width=1, height=1, nx=8, ny=8, young=1e9, poisson=0.3, top='contact', "
             "bottom='clamped' /\n"
             "&traction body=1, side='top', t0=0.0,-1.0e6 /\n"
             "&traction body=1, side='top', t0=2.0e5,0.0, stage=2 /\n"
             "&solver tol=1e-11, load_steps=2,3 /\n")
ref = os.path.join(OUT, "steps_serial.h5")
p, _ = run_solver(BIN, steps_deck, f"&output file='{ref}' /", env=solver_env(1))
q, out = mpirun(2, steps_deck, MUMPS, name="steps_np2")
if check(p.returncode == 0 and q is not None and q.returncode == 0, "load steps: the serial run and -np 2 converge",
         f"exit {p.returncode}, {None if q is None else q.returncode}"):
    with h5py.File(ref, "r") as a, h5py.File(out, "r") as b:
        n = len(a["steps"]) if "steps" in a else 0
        errs = [rel_err(np.array(b[f"steps/step_{k}/{name}"]).ravel(), np.array(a[f"steps/step_{k}/{name}"]).ravel())
                for k in range(1, n + 1) for name in ("contact/normal_force", "body1/displacement")]
        check(n == 5 and len(b["steps"]) == 5 and all(e is not None and e < 1e-10 for e in errs),
              "load steps: -np 2 = serial, every step's contact forces and displacements to 1e-10",
              f"{n} steps, errors {errs}")
    check(q.stdout.count("step: ") == 5, "load steps: -np 2 prints one step: line per step")

# 8. solid (3D) bodies: the four-body stack of inputs/cube_stack.nml (three cubes held along y
# only by contact, SMALBE) at -np 1, 2 and 4 (several bodies per rank, one each) = the serial binary
ref = os.path.join(OUT, "cube_stack_serial.h5")
p, _ = run_solver(BIN, "inputs/cube_stack.nml", f"&output file='{ref}' /", env=solver_env(1))
if check(p.returncode == 0, "3D stack: the serial run converges", f"exit {p.returncode}"):
    for np_ in (1, 2, 4):
        q, out = mpirun(np_, "inputs/cube_stack.nml", MUMPS, name=f"cube_stack_np{np_}")
        if check(q is not None and q.returncode == 0, f"3D stack: mpirun -np {np_} converges"):
            with h5py.File(ref, "r") as a, h5py.File(out, "r") as b:
                e = rel_err(np.array(b["contact/normal_force"]), np.array(a["contact/normal_force"]))
                eu = max(rel_err(np.array(b[f"body{k}/displacement"]).ravel(),
                                 np.array(a[f"body{k}/displacement"]).ravel()) for k in (1, 2, 3, 4))
            check(e is not None and e < 1e-10 and eu is not None and eu < 1e-10,
                  f"3D stack: -np {np_} = serial (contact forces, displacements of the four bodies) to 1e-10",
                  f"{e}, {eu}")

# 8c. a curved slave in 3D: Hertz's sphere on the block (hc = 0.02 mesh), whose slave nodes
# are factored in their contact frames (the MUMPS triplets rotated, condense
# `rotated_triplets`), at -np 1 and 2 = the serial binary (CHOLMOD on rotated CSC values)
msh = os.path.abspath(os.path.join("inputs", "gmsh", "sphere_block_h0.02.msh"))
over = (f"&body id=1, mesh='{msh}' /", f"&body id=2, mesh='{msh}' /")
ref = os.path.join(OUT, "sphere_serial.h5")
p, _ = run_solver(BIN, "inputs/sphere_block.nml", *over, f"&output file='{ref}' /", env=solver_env(1))
if check(p.returncode == 0, "3D sphere: the serial run converges", f"exit {p.returncode}"):
    for np_ in (1, 2):
        q, out = mpirun(np_, "inputs/sphere_block.nml", *over, MUMPS, name=f"sphere_np{np_}")
        if check(q is not None and q.returncode == 0, f"3D sphere: mpirun -np {np_} converges"):
            with h5py.File(ref, "r") as a, h5py.File(out, "r") as b:
                e = rel_err(np.array(b["contact/normal_force"]), np.array(a["contact/normal_force"]))
                eu = max(rel_err(np.array(b[f"body{k}/displacement"]).ravel(),
                                 np.array(a[f"body{k}/displacement"]).ravel()) for k in (1, 2))
            check(e is not None and e < 1e-10 and eu is not None and eu < 1e-10,
                  f"3D sphere (curved slave in contact frames): -np {np_} = serial (forces, displacements) to 1e-10",
                  f"{e}, {eu}")

print(f"{'FAILED: ' + str(len(check.failed)) if check.failed else 'all checks passed'}")
sys.exit(1 if check.failed else 0)
