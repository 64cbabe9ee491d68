#!/usr/bin/python3
"""A result or checkpoint that cannot be written whole is not left behind (run by `make check`).

Real write failures, no test hook in the program:
  1. full disk: the result folder is a 200 KiB tmpfs (the result is about 1.2 MB), mounted
     in a private mount namespace (`unshare --mount --map-root-user`, which needs no root
     where user namespaces are allowed; as root without unshare, a plain mount). HDF5 fails
     while writing a dataset or flushing on close. Skipped, saying so, when neither works.
  2. the result's temporary name is a symbolic link to /dev/full (fails for root too):
     creating the HDF5 file fails. Temporary names are unique per run,
     `<file>.<host>.<pid>.<n>.tmp` with n counting the names the run makes (the HDF5 file
     takes the first); a shell makes the link for its own pid and then execs the program.
  In both: exit code 3, one message `output: cannot write <file> (...)` on stderr, no HDF5
  error stack or Fortran runtime text, and no file under the result's names (.h5, .xdmf,
  _body1.xdmf, _body2.xdmf, _contact.xdmf) nor a `.tmp` leftover.
  With two threads (the XDMF companions written while the HDF5 file is) the HDF5 file's
  temporary a link to /dev/full, or the .xdmf's a folder: exit 3, no `.tmp` file left, and
  an earlier result at these names unchanged; the same after a restart (HDF5 first used on
  the main thread) prints no HDF5 error stack whichever thread writes the result, 20 runs.
  3. a checkpoint that fails keeps the previous one, byte for byte: (a) the checkpoint's
     temporary name (`<file>.ckpt.h5.<host>.<pid>.1.tmp`, the run's first) a link to
     /dev/full: warning naming the checkpoint, run continues (exit 2), old checkpoint
     unchanged, link removed; (b) on the full tmpfs (a filler file takes the free space):
     checkpoint and result fail with ENOSPC, exit 3, old checkpoint unchanged.
"""
import filecmp
import os
import re
import socket
import shutil
import subprocess
import sys

BIN = os.path.abspath(os.environ.get("BIN", "bin/robin_contact"))
OUT = os.path.abspath(os.path.join(os.environ.get("BUILD", "build/release"), "test-out", "output_failure"))
DECK = os.path.abspath("inputs/table1/q1_16x8.nml")
BIG = ["&body id=1, nx=128, ny=32 /", "&body id=2, nx=128, ny=32 /"]   # result about 1.2 MB
ENV = dict(os.environ, OMP_NUM_THREADS="1")
FAILS = []


def check(ok, what, detail=""):
    print(("PASS  " if ok else "FAIL  ") + what + (f" ({detail})" if detail else ""), flush=True)
    if not ok:
        FAILS.append(what)


def result_names(h5):
    stem = h5[:-3]
    return [h5, stem + ".xdmf", stem + "_body1.xdmf", stem + "_body2.xdmf", stem + "_contact.xdmf"]


# the host part of the program's temporary names: the host name reduced to [A-Za-z0-9_-]
HOST_TOKEN = re.sub(r"[^A-Za-z0-9_-]", "_", socket.gethostname())[:64]


def run_with_devfull_temp(final, args, n=1, threads=1, folder=False):
    """Run BIN args with the run's n-th temporary name, <final>.<host>.<pid>.<n>.tmp, a
    symbolic link to /dev/full (folder: a folder, which a text file opened with
    status='replace' cannot replace, as it does a link): the shell makes it for its own
    pid, then execs BIN."""
    make = 'mkdir' if folder else 'ln -s /dev/full'
    script = make + ' "$0.$HOST_TOKEN.$$.$N.tmp" || exit 99; exec "$@"'
    return subprocess.run(["sh", "-c", script, final, BIN, *args], capture_output=True, text=True,
                          env=dict(ENV, HOST_TOKEN=HOST_TOKEN, N=str(n), OMP_NUM_THREADS=str(threads)))


def out(h5, extra=""):
    return f"&output file='{h5}'{extra} /"


def check_failed_result(tag, rc, err, h5, listing):
    """Exit 3, one clean message naming the file, nothing under its names, no .tmp."""
    check(rc == 3, f"{tag}: exit code 3", f"exit {rc}")
    check(f"output: cannot write {h5}" in err, f"{tag}: message names the result file", err.strip()[-300:])
    check("HDF5" not in err and "Fortran runtime" not in err and "Segmentation" not in err,
          f"{tag}: no HDF5 error stack or runtime error text", err.strip()[:300])
    left = [n for n in result_names(h5) if os.path.basename(n) in listing]
    check(not left, f"{tag}: no file under the result's names", " ".join(left))
    tmp = [n for n in listing if n.endswith(".tmp")]
    check(not tmp, f"{tag}: no .tmp leftovers", " ".join(tmp))


# A shell script run inside a private mount namespace (or as root with a plain mount):
# mount a 200 KiB tmpfs on $D, optionally copy a checkpoint in and fill the free space,
# run the solver, list $D into $LIST, exit with the solver's code (97: mount failed).
TMPFS_SCRIPT = r'''
mount -t tmpfs -o size=200k tmpfs "$D" || exit 97
if [ -n "$CKPT" ]; then
  cp "$CKPT" "$D/r.h5.ckpt.h5" || exit 98
  # leave FREE_KB free: the new checkpoint file is created, its data do not fit
  avail=$(df -k --output=avail "$D" | tail -n 1)
  dd if=/dev/zero of="$D/filler" bs=1k count=$((avail - FREE_KB)) 2>/dev/null
fi
"$@" > "$LOG" 2> "$ERR"
rc=$?
ls -A "$D" > "$LIST"
if [ -n "$CKPT" ]; then cp "$D/r.h5.ckpt.h5" "$KEEP" 2>/dev/null; fi
exit $rc
'''


def run_on_tmpfs(name, args, ckpt="", free_kb=0):
    """Run BIN args on a full tmpfs; returns (rc, stderr, listing) or None when no tmpfs."""
    d = os.path.join(OUT, name)
    os.makedirs(d, exist_ok=True)
    files = {k: os.path.join(OUT, f"{name}.{k}") for k in ("log", "err", "list", "keep")}
    env = dict(ENV, D=d, CKPT=ckpt, FREE_KB=str(free_kb), LOG=files["log"], ERR=files["err"], LIST=files["list"], KEEP=files["keep"])
    shell = ["sh", "-c", TMPFS_SCRIPT, "sh", BIN, *args]
    attempts = []
    if shutil.which("unshare"):
        attempts.append(["unshare", "--mount", "--map-root-user", *shell])
        attempts.append(["unshare", "--mount", *shell])
    for cmd in attempts:
        p = subprocess.run(cmd, env=env, capture_output=True, text=True)
        if p.returncode not in (1, 97) or os.path.exists(files["list"]):
            break
    else:
        if os.geteuid() != 0:
            return None
        # root without usable unshare: a plain mount, always unmounted
        try:
            p = subprocess.run(shell, env=env, capture_output=True, text=True)
        finally:
            subprocess.run(["umount", d], capture_output=True)
        if p.returncode == 97:
            return None
    if p.returncode in (97, 98):
        return None
    err = open(files["err"]).read() if os.path.exists(files["err"]) else ""
    listing = open(files["list"]).read().split() if os.path.exists(files["list"]) else []
    return p.returncode, err, listing, files["keep"]


shutil.rmtree(OUT, ignore_errors=True)
os.makedirs(OUT)

# 0. the same run on a normal disk succeeds (so the failures below are the disk's)
ok_h5 = os.path.join(OUT, "ok", "r.h5")
p = subprocess.run([BIN, DECK, *BIG, out(ok_h5)], capture_output=True, text=True, env=ENV)
check(p.returncode == 0 and all(os.path.exists(n) for n in result_names(ok_h5)),
      "reference run on a normal disk writes its result", f"exit {p.returncode}")

# 1. full disk (tmpfs of 200 KiB)
h5 = os.path.join(OUT, "full", "r.h5")
r = run_on_tmpfs("full", [DECK, *BIG, out(h5)])
if r is None:
    print("SKIP  full disk: cannot mount a tmpfs here (no unshare --mount and not root); "
          "the /dev/full variant below still runs")
else:
    rc, err, listing, _ = r
    check_failed_result("full disk", rc, err, h5, listing)
    check("failed to" in err, "full disk: message says what failed", err.strip()[-200:])

# 2. the temporary name is a link to /dev/full
d = os.path.join(OUT, "devfull")
os.makedirs(d)
h5 = os.path.join(d, "r.h5")
p = run_with_devfull_temp(h5, [DECK, out(h5)])
check_failed_result("/dev/full", p.returncode, p.stderr, h5, os.listdir(d))

# 2b. two threads write the HDF5 file and its XDMF companions at once: when either fails
# (the HDF5 file's temporary, the run's first, a link to /dev/full; the .xdmf's, its
# second, a folder) the run ends with exit 3, every temporary it made removed and the
# earlier result at these names unchanged
d = os.path.join(OUT, "devfull2")
os.makedirs(d)
h5 = os.path.join(d, "r.h5")
p = subprocess.run([BIN, DECK, out(h5)], capture_output=True, text=True, env=dict(ENV, OMP_NUM_THREADS="2"))
check(p.returncode == 0 and all(os.path.exists(n) for n in result_names(h5)),
      "two threads: the earlier result is written", f"exit {p.returncode}")
keep = os.path.join(OUT, "devfull2_keep")
os.makedirs(keep)
for n in result_names(h5):
    shutil.copyfile(n, os.path.join(keep, os.path.basename(n)))
for n, what, msg in ((1, "the HDF5 file's temporary a link to /dev/full", f"output: cannot write {h5}"),
                     (2, "the .xdmf's temporary a folder", f"output: cannot write the XDMF files beside {h5}")):
    tag = f"two threads, {what}"
    p = run_with_devfull_temp(h5 if n == 1 else h5[:-3] + ".xdmf", [DECK, out(h5)], n=n, threads=2,
                              folder=n > 1)
    check(p.returncode == 3, f"{tag}: exit code 3", f"exit {p.returncode}")
    check(msg in p.stderr, f"{tag}: the message says which file failed", p.stderr.strip()[-300:])
    listing = os.listdir(d)
    tmp = [x for x in listing if x.endswith(".tmp") and not os.path.isdir(os.path.join(d, x))]
    check(not tmp, f"{tag}: no .tmp leftovers", " ".join(tmp))
    same = [os.path.basename(x) for x in result_names(h5)
            if os.path.exists(x) and filecmp.cmp(x, os.path.join(keep, os.path.basename(x)), shallow=False)]
    check(len(same) == len(result_names(h5)), f"{tag}: the earlier result is unchanged",
          f"unchanged: {' '.join(same)}")

# 2c. the same after a restart (HDF5 first used by the main thread, to read the checkpoint):
# whichever thread writes the result file, a failure prints no HDF5 error stack (a
# thread-safe HDF5 keeps its error printing per thread); repeated, as the thread that takes
# the HDF5 part varies from run to run
d = os.path.join(OUT, "devfull3")
os.makedirs(d)
h5 = os.path.join(d, "r.h5")
ck0 = os.path.join(OUT, "devfull3_part.h5")
p = subprocess.run([BIN, DECK, "&solver max_outer=10 /", out(ck0, ", checkpoint_every=5")],
                   capture_output=True, text=True, env=ENV)
check(p.returncode == 2 and os.path.exists(ck0 + ".ckpt.h5"), "restart case: a checkpoint to restart from",
      f"exit {p.returncode}")
noisy = []
codes = []
for k in range(20):
    p = run_with_devfull_temp(h5, [DECK, out(h5), "--restart", ck0 + ".ckpt.h5"], threads=2)
    codes.append(p.returncode)
    if "HDF5" in p.stderr or "Fortran runtime" in p.stderr:
        noisy.append(p.stderr.strip()[:200])
check(codes == [3] * 20, "two threads after a restart, the result's temporary a link to /dev/full: exit 3",
      f"exit codes {codes}")
check(not noisy, "two threads after a restart: no HDF5 error stack on stderr (20 runs)",
      f"{len(noisy)} runs printed one: {noisy[:1]}")
tmp = [x for x in os.listdir(d) if x.endswith(".tmp")]
check(not tmp, "two threads after a restart: no .tmp leftovers", " ".join(tmp))

# 3a. a checkpoint that cannot be written keeps the previous one
d = os.path.join(OUT, "ckpt")
os.makedirs(d)
h5 = os.path.join(d, "r.h5")
ck = h5 + ".ckpt.h5"
p = subprocess.run([BIN, DECK, "&solver max_outer=10 /", out(h5, ", checkpoint_every=5")],
                   capture_output=True, text=True, env=ENV)
check(p.returncode == 2 and os.path.exists(ck), "checkpoint run: exit 2 with a checkpoint", f"exit {p.returncode}")
good = os.path.join(OUT, "good.ckpt.h5")
if os.path.exists(ck):
    shutil.copyfile(ck, good)
    # one checkpoint is due (iteration 15), and it fails
    p = run_with_devfull_temp(ck, [DECK, "&solver max_outer=20 /", out(h5, ", checkpoint_every=15")])
    check(p.returncode == 2, "failed checkpoint: the run goes on (exit 2)", f"exit {p.returncode}")
    check("warning" in p.stderr and ck in p.stderr, "failed checkpoint: a warning names the checkpoint",
          p.stderr.strip()[-300:])
    check("HDF5" not in p.stderr, "failed checkpoint: no HDF5 error stack", p.stderr.strip()[:200])
    check(os.path.isfile(ck) and not os.path.islink(ck) and filecmp.cmp(ck, good, shallow=False),
          "failed checkpoint: the previous checkpoint is kept unchanged")
    tmp = [n for n in os.listdir(d) if n.endswith(".tmp")]
    check(not tmp, "failed checkpoint: no .tmp leftover", " ".join(tmp))

    # 3b. full disk: the checkpoint (of a larger mesh) is created, its data do not fit
    d = os.path.join(OUT, "ckbig")
    os.makedirs(d)
    p = subprocess.run([BIN, DECK, *BIG, "&solver max_outer=10 /", out(os.path.join(d, "r.h5"), ", checkpoint_every=5")],
                       capture_output=True, text=True, env=ENV)
    good = os.path.join(d, "r.h5.ckpt.h5")
    check(p.returncode == 2 and os.path.exists(good), "larger checkpoint run: exit 2 with a checkpoint",
          f"exit {p.returncode}")
    h5 = os.path.join(OUT, "ckfull", "r.h5")
    r = run_on_tmpfs("ckfull", [DECK, *BIG, "&solver max_outer=20 /", out(h5, ", checkpoint_every=15")],
                     ckpt=good, free_kb=12)
    if r is None:
        print("SKIP  checkpoint on a full disk: cannot mount a tmpfs here")
    else:
        rc, err, listing, keep = r
        check_failed_result("checkpoint on a full disk", rc, err, h5, listing)
        check("checkpoint could not be written" in err and "r.h5.ckpt.h5" in err,
              "checkpoint on a full disk: a warning names the checkpoint", err.strip()[-300:])
        check(os.path.exists(keep) and filecmp.cmp(keep, good, shallow=False),
              "checkpoint on a full disk: the previous checkpoint is kept unchanged")

print(f"{len(FAILS)} failed checks")
sys.exit(1 if FAILS else 0)
