#!/usr/bin/python3
"""Batch workflows lose no result and never report a false one (run by `make check`).

One section per class of defect, each failing when the defect is there (the defect's
symptom in brackets):
  restart  a resubmit from a checkpoint taken at max_outer reproduces the result (zeros
           written); a rejected --restart (missing, not HDF5, not a checkpoint: the result file
           given by mistake) exits 1 and deletes nothing (the result removed first)
  signals  SIGTERM at any moment of a large run, the METIS ordering included, ends in exit 4
           with a message ('invalid input' or SIGSEGV); the monolithic method honours it too
           (ignored)
  sizes    decks whose meshes overflow 32-bit indices or cannot fit the memory this process
           may use are refused at once with the estimate and the limit (SIGSEGV or the OOM
           killer); max_outer = 2^31-1 does not reserve memory for the history
  parsing  100000 &traction groups are read in linear time (a CPU-time cap of 120 s; a
           quadratic reader needs about an hour; the time is printed, not asserted)
  loads    a traction of 1e308 is bad input (exit 0 with Inf stresses)
  pipe     a deck read from a pipe (/dev/stdin) gives the same result as from its file (read
           as empty)
  rtol     monolithic_rtol=1e-300 ends converged at working precision, not 'not SPD'
  stdout   standard output on /dev/full ends in exit 3 (exit 0 with the result line lost)
Every run must be free of Fortran runtime text, backtraces and HDF5 error stacks.
"""
import os
import resource
import shutil
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import result_fields  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", "bin/robin_contact"))
DECK = os.path.abspath("inputs/default.nml")
SMALL = os.path.abspath("inputs/table1/q1_16x8.nml")
OUT = os.path.abspath(os.path.join(os.environ.get("BUILD", "build/release"), "test-out", "batch_safety"))
ENV = dict(os.environ, OMP_NUM_THREADS="2")
BAD_TEXT = ("Fortran runtime error", "Backtrace", "Error termination", "HDF5-DIAG", "Segmentation")
check = Checks()


def run(*args, cwd=None, stdin=None, stdout=subprocess.PIPE, preexec=None, timeout=600):
    p = subprocess.run([BIN, *args], cwd=cwd or OUT, stdin=stdin, stdout=stdout, stderr=subprocess.PIPE,
                       text=True, env=ENV, preexec_fn=preexec, timeout=timeout)
    clean(p.stderr + (p.stdout or ""), " ".join(args)[:60])
    return p


def clean(text, what):
    bad = [t for t in BAD_TEXT if t in text]
    if bad:
        check(False, f"no runtime/HDF5 text: {what}", ", ".join(bad))


def out(name):
    return f"&output file='{name}' /"


def fresh_dir(name):
    d = os.path.join(OUT, name)
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    return d


def snapshot(d):
    return {f: open(os.path.join(d, f), "rb").read() for f in sorted(os.listdir(d))}


def section_restart():
    import h5py
    import numpy as np
    d = fresh_dir("restart")
    p = run(DECK, "&solver max_outer=20 /", "&output checkpoint_every=5, file='r.h5' /", cwd=d)
    check(p.returncode == 2, "restart: a run stopped at max_outer exits 2", p.returncode)
    with h5py.File(os.path.join(d, "r.h5")) as f:
        lam0 = f["contact/lam"][()] if "contact/lam" in f else None
        ref = {k: f[k][()] for k in walk(f)}
    p = run(DECK, "&solver max_outer=20 /", "&output checkpoint_every=5, file='r.h5' /",
            "--restart", "r.h5.ckpt.h5", cwd=d)
    r = result_fields(p.stdout) or {}
    check(p.returncode == 2 and r.get("status") == "max_outer" and r.get("outer") == "20",
          "restart at max_outer: same status and outer count", f"rc {p.returncode}, {r}")
    check("nothing left to do" in p.stdout, "restart at max_outer: says there is nothing left to do")
    with h5py.File(os.path.join(d, "r.h5")) as f:
        worst = 0.0
        for k, v in ref.items():
            w = f[k][()]
            if v.dtype.kind == "f" and v.size:
                worst = max(worst, float(np.max(np.abs(w - v)) / max(np.max(np.abs(v)), 1e-300)))
    check(worst <= 1e-10, "restart at max_outer: every dataset equals the checkpointed run's", f"{worst:.1e}")
    del lam0

    # rejected restarts delete nothing
    before = snapshot(d)
    with open(os.path.join(d, "junk.ckpt.h5"), "wb") as f:
        f.write(b"not an HDF5 file\n" * 10)
    for bad, why in (("missing.ckpt.h5", "does not exist"), ("junk.ckpt.h5", "not an HDF5 file"),
                     ("r.h5", "not a robin_contact checkpoint")):
        p = run(DECK, out("r.h5"), "--restart", bad, cwd=d)
        after = {k: v for k, v in snapshot(d).items() if k != "junk.ckpt.h5"}
        check(p.returncode == 1 and why in p.stderr, f"rejected --restart {bad}: exit 1, '{why}'",
              f"rc {p.returncode}: {p.stderr.strip()[-120:]}")
        check(after == before, f"rejected --restart {bad}: every file kept byte for byte")


def walk(g, prefix=""):
    import h5py
    for k, v in g.items():
        if isinstance(v, h5py.Group):
            yield from walk(v, prefix + k + "/")
        elif k != "wall_s":
            yield prefix + k


def section_signals():
    d = fresh_dir("signals")
    # METIS explicitly (the default ordering is 'nd'): GKlib's own signal handling is what
    # this section must survive
    big = ["&body id=1, nx=512, ny=256 /", "&body id=2, nx=512, ny=256 /", "&solver ordering='metis' /"]
    for delay in (0.2, 0.5, 0.9, 1.4):
        p = subprocess.Popen([BIN, DECK, *big, out("s.h5")], cwd=d, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=ENV)
        time.sleep(delay)
        p.send_signal(signal.SIGTERM)
        o, e = p.communicate(timeout=600)
        clean(o + e, f"SIGTERM at {delay} s")
        check(p.returncode == 4 and "interrupted" in e and "invalid input" not in e,
              f"SIGTERM {delay} s into a 512x256 run (assembly, METIS ordering, factorization): exit 4",
              f"rc {p.returncode}: {e.strip()[-150:]}")
    # the monolithic method honours the signal too
    p = subprocess.Popen([BIN, DECK, *big, "&solver method='monolithic' /", out("m.h5")], cwd=d,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV)
    time.sleep(0.8)
    p.send_signal(signal.SIGTERM)
    o, e = p.communicate(timeout=600)
    check(p.returncode == 4 and "interrupted" in e, "SIGTERM to method='monolithic': exit 4",
          f"rc {p.returncode}: {e.strip()[-150:]}")


def section_sizes():
    d = fresh_dir("sizes")
    cases = [(("&body id=1, nx=65536, ny=65536 /", "&body id=2, nx=65536, ny=65536 /"), "32-bit indices"),
             (("&body id=1, ny=2147483647 /",), "32-bit indices"),
             (("&body id=1, ny=100000000 /",), "32-bit indices"),
             (("&body id=1, nx=1536, ny=1536 /", "&body id=2, nx=1536, ny=1536 /"), "may use only")]
    for ov, why in cases:
        cap = None
        if why == "may use only":   # 3 GB of address space for a run that needs about 9 GiB
            def cap():
                resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))
        t0 = time.time()
        p = run(DECK, *ov, out("z.h5"), cwd=d, preexec=cap)
        check(p.returncode == 1 and why in p.stderr and ("GiB" in p.stderr or "e9" in p.stderr),
              f"too large ({' '.join(ov)[:50]}): exit 1 with the estimate ('{why}')",
              f"rc {p.returncode}, {time.time() - t0:.1f} s: {p.stderr.strip()[-160:]}")
        check(os.listdir(d) == [], f"too large ({' '.join(ov)[:40]}): nothing written")
    p = run(SMALL, "&solver max_outer=2147483647 /", out("h.h5"), cwd=d)
    t = result_fields(p.stdout) or {}
    peak = float(p.stdout.split("peak_mb=")[1].split()[0]) if "peak_mb=" in p.stdout else 1e9
    check(p.returncode == 0 and peak < 200, "max_outer = 2^31-1: converges without reserving the history",
          f"rc {p.returncode}, peak {peak} MB, {t.get('outer')} outer")


def section_parsing():
    d = fresh_dir("parsing")
    deck = os.path.join(d, "many.nml")
    with open(DECK) as f, open(deck, "w") as g:
        g.write(f.read())
        g.write("&traction body=1, side='top', t0=0.0, -1.0 /\n" * 100000)

    def cap():
        resource.setrlimit(resource.RLIMIT_CPU, (120, 120))
    t0 = time.time()
    p = run(deck, out("many.h5"), cwd=d, preexec=cap)
    n = p.stdout.count("&traction body=1")
    check(p.returncode == 0 and n == 100002, "100000 &traction groups: read, echoed and solved within a CPU cap",
          f"rc {p.returncode}, {n} groups echoed, {time.time() - t0:.1f} s")


def section_loads():
    d = fresh_dir("loads")
    p = run(DECK, "&traction body=1, side='top', t0=0.0, -1e308 /", out("l.h5"), cwd=d)
    check(p.returncode == 1 and "overflow double precision" in p.stderr, "traction 1e308: bad input (exit 1)",
          f"rc {p.returncode}: {p.stderr.strip()[-120:]}")
    check(os.listdir(d) == [], "traction 1e308: nothing written")


def section_pipe():
    d = fresh_dir("pipe")
    a = run(SMALL, out("a.h5"), cwd=d)
    with open(SMALL) as f:
        b = run("/dev/stdin", out("b.h5"), cwd=d, stdin=f)
    ra, rb = result_fields(a.stdout) or {}, result_fields(b.stdout) or {}
    same = all(ra.get(k) == rb.get(k) for k in ("status", "outer", "inner", "m", "residual"))
    check(b.returncode == 0 and same, "deck from a pipe (/dev/stdin): the same result as from the file",
          f"rc {b.returncode}: {rb}")


def section_rtol():
    d = fresh_dir("rtol")
    p = run(DECK, "&solver method='monolithic', monolithic_rtol=1e-300 /", out("t.h5"), cwd=d)
    check(p.returncode == 0 and "not SPD" not in p.stdout + p.stderr,
          "monolithic_rtol=1e-300: converged at working precision, no 'not SPD'", f"rc {p.returncode}")


def section_stdout():
    d = fresh_dir("stdout")
    with open("/dev/full", "w") as full:
        p = run(SMALL, out("o.h5"), cwd=d, stdout=full)
    check(p.returncode == 3 and "cannot write the summary" in p.stderr,
          "standard output on /dev/full: exit 3 with a message", f"rc {p.returncode}: {p.stderr.strip()[-100:]}")


def main():
    os.makedirs(OUT, exist_ok=True)
    for section in (section_restart, section_signals, section_sizes, section_parsing, section_loads,
                    section_pipe, section_rtol, section_stdout):
        print(f"--- {section.__name__[8:]}", flush=True)
        section()
    print(f"{'FAILED: ' + ', '.join(check.failed) if check.failed else 'all checks passed'}")
    return 1 if check.failed else 0


if __name__ == "__main__":
    sys.exit(main())
