#!/usr/bin/env python3
"""Speed against error: benchmark of robin_contact on the paper's scene.

Runs (each a separate process of bin/robin_contact, OMP_NUM_THREADS=2 unless said):
  ladder   meshes 16x8 ... 1024x512 per body (level k: 16*2^k x 8*2^k), for
           monolithic, robin/steklov delta=0.5 and robin/harmonic delta=0.5
           (CHOLMOD + METIS);
  ordering the same meshes with robin/steklov and CHOLMOD + AMD, and with the
           banded Cholesky while its predicted time stays below --banded-limit s;
  threads  robin/steklov at 512x256 and 1024x512 with OMP_NUM_THREADS=1 and 2,
           METIS and AMD orderings, run back to back;
  sweep    256x128, tol 1e-2 ... 1e-10, stop='residual' and 'increment', both Robin
           operators, plus monolithic with monolithic_rtol 1e-2 ... 1e-10;
  floating the paper's size (24x16) and the finest level, contact by groups, body 1 clamped
           on its left side (supported) against body 1 with ux = 0 only there (held only
           by contact, floating vertically: doc/method.md, "Bodies held only by contact"), Robin
           harmonic delta 0.5 and monolithic: the extra cost of a floating body.

Error columns:
  alg_err   |lam - lam_mono| / |lam_mono| against the monolithic run of the same mesh
            (ladder/ordering/threads rows against the ladder's monolithic run; sweep rows
            against it too, the monolithic sweep rows included);
  p_err     discretisation error: relative L2 error of the contact pressure along the line
            against the finest mesh of the ladder (its monolithic run), the fine pressure
            taken at the coarse nodes (meshes double, nodes nest), weights = the coarse
            tributary lengths;
  force_err |F - F_fine| / |F_fine| of the total contact force F = sum(lam);
  p_order, force_order   log2(err(previous mesh) / err(this mesh)) within one series;
  force_order3           log2(|F(k-2) - F(k-1)| / |F(k-1) - F(k)|), no reference needed.

Timing hygiene: the machine may be shared. busy_before = cores kept busy (by anything)
during the second before the run; runs at >= 512x256 and the thread comparison wait up
to --quiet-wait s for < 0.5 busy core. load1 = the 1-minute load average at the start.

Writes results/bench.csv (one row per run, all columns) and prints markdown tables.

Usage: bench/bench.py [--max-level N] [--quick] [--bin bin/robin_contact]
                      [--deck inputs/default.nml] [--csv results/bench.csv]
Levels: 0 = 16x8, 1 = 32x16, 2 = 64x32, 3 = 128x64, 4 = 256x128, 5 = 512x256, 6 = 1024x512.
--max-level N (default 6) is the finest level; --quick caps it at 4 (256x128) and runs
each case once (a smoke run, about a minute; the full bench takes about 15 minutes on
2 cores, 2.5 of them in the deliberately slow OMP_NUM_THREADS=1 runs).
"""
import argparse
import csv
import math
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))  # the rc_* helpers
from rc_results import md_header, md_row, rel_err  # noqa: E402
from rc_run import contact_force, run_solver, solver_env, time_fields  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

COLUMNS = [
    "group", "level", "nx", "ny", "label", "method", "operator", "delta", "factorization",
    "ordering", "threads", "omp_env", "tol", "stop", "mono_rtol", "exit", "status", "n1", "n2", "m",
    "outer", "inner", "residual", "assemble_s", "factor_s", "condense_s", "iterate_s",
    "output_s", "total_s", "solve_s", "solve_over_factor", "peak_mb", "factor_mb",
    "repeats", "total_s_all", "process_wall_s", "load1", "busy_before", "busy_during", "force", "alg_err", "p_err", "p_err_away", "force_err", "p_order",
    "p_away_order", "force_order", "force_order3", "cmdline",
]


def mesh_of(level):
    return 16 * 2 ** level, 8 * 2 ** level


def fnum(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return float("nan")


def cpu_times():
    with open("/proc/stat") as f:
        v = [int(x) for x in f.readline().split()[1:]]
    return sum(v), v[3] + v[4]


def busy_cores(dt):
    """Average number of busy cores over dt seconds (whole machine)."""
    t0, i0 = cpu_times()
    time.sleep(dt)
    t1, i1 = cpu_times()
    return (1.0 - (i1 - i0) / max(t1 - t0, 1)) * (os.cpu_count() or 1)


def measured_run(args, env):
    """Run the solver; returns (process, result fields, wall time [s], busy_during = cores kept
    busy by other processes during the run, the whole machine's busy time less this run's)."""
    t0 = time.monotonic()
    tot0, idle0 = cpu_times()
    ch0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    p, r = run_solver(*args, env=env)
    tot1, idle1 = cpu_times()
    ch1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    wall = time.monotonic() - t0
    mine = (ch1.ru_utime + ch1.ru_stime) - (ch0.ru_utime + ch0.ru_stime)
    hz = os.sysconf("SC_CLK_TCK")
    busy = round(max(0.0, ((tot1 - tot0) - (idle1 - idle0)) / hz - mine) / max(wall, 1e-3), 2)
    return p, r, wall, busy


def wait_quiet(wait, quiet_wait):
    """Cores kept busy by other processes (over a second; over 0.2 s without wait); with wait,
    wait up to quiet_wait s for fewer than 0.5."""
    deadline = time.monotonic() + (quiet_wait if wait else 0.0)
    while True:
        b = busy_cores(1.0 if wait else 0.2)
        if b < 0.5 or time.monotonic() >= deadline:
            return round(b, 2)
        sys.stderr.write(f"  (machine busy: {b:.2f} cores; waiting)\n")
        time.sleep(4.0)


def command_text(args, threads):
    """The command line of a run as a user would type it from the repository root."""
    return f"OMP_NUM_THREADS={threads} " + " ".join(
        os.path.relpath(a, ROOT) if os.path.isabs(a) and a.startswith(ROOT) else
        (a if re.fullmatch(r"[\w./=-]+", a) else '"' + a + '"') for a in args)


def timed_run(args, env, timeout):
    """Run a command in its own session, killed (with its children) after timeout s; returns
    (exit code, stdout, stderr, wall [s], its CPU time [s], busy_during = cores kept busy by
    other processes during the run, timed out)."""
    t0 = time.monotonic()
    tot0, idle0 = cpu_times()
    ch0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                         start_new_session=True)
    timed_out = False
    try:
        out, err = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        out, err = p.communicate()
        timed_out = True
    wall = time.monotonic() - t0
    tot1, idle1 = cpu_times()
    ch1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    mine = (ch1.ru_utime + ch1.ru_stime) - (ch0.ru_utime + ch0.ru_stime)
    hz = os.sysconf("SC_CLK_TCK")
    busy = round(max(0.0, ((tot1 - tot0) - (idle1 - idle0)) / hz - mine) / max(wall, 1e-3), 2)
    return p.returncode, out, err, wall, mine, busy, timed_out


class Runner:
    def __init__(self, binary, deck, workdir, keep):
        self.binary = binary
        self.deck = deck
        self.workdir = workdir
        self.keep = keep
        self.count = 0
        self.contact = {}     # row id -> dict of contact arrays
        self.quiet_wait = 0.0

    def run(self, row, overrides, threads=2, extra_env=None, repeats=1):
        """Run one case `repeats` times; fill row with the fastest run (least total_s) and
        keep its contact arrays; total_s_all lists every repetition."""
        row["threads"] = threads
        row["omp_env"] = " ".join(f"{k}={v}" for k, v in sorted((extra_env or {}).items()))
        best, best_c, totals = None, None, []
        for _ in range(max(1, repeats)):
            trial, c = self._once(dict(row), overrides, threads, extra_env)
            if trial["status"] != "error":
                totals.append(trial["total_s"])
            if best is None or (trial["status"] != "error" and
                                (best["status"] == "error" or trial["total_s"] < best["total_s"])):
                best, best_c = trial, c
        row.update(best)
        row["repeats"] = max(1, repeats)
        row["total_s_all"] = ";".join(f"{t:g}" for t in totals)
        if best_c is not None:
            self.contact[id(row)] = best_c
        sys.stderr.write(f"  {row['group']:8s} {row['nx']}x{row['ny']:<4} {row['label']:16s} "
                         f"{row['factorization']}/{row['ordering']} thr={threads} {row['omp_env']} "
                         f"tol={row['tol'] or row['mono_rtol']} {row['stop']}: {row['status']} "
                         f"outer={row['outer']} inner={row['inner']} total={row['total_s_all']} s "
                         f"(busy before {row['busy_before']}, during {row['busy_during']})\n")
        return row

    def _once(self, row, overrides, threads, extra_env):
        self.count += 1
        stem = f"run{self.count:03d}"
        h5 = os.path.join(self.workdir, stem + ".h5")
        args = [self.binary, self.deck] + overrides + [f"&output file='{h5}', progress_lines=0 /"]
        env = solver_env(threads)
        env.pop("OMP_THREAD_LIMIT", None)
        env.update(extra_env or {})
        row["load1"] = round(os.getloadavg()[0], 2)
        row["busy_before"] = self.wait_quiet(row)
        row["cmdline"] = "OMP_NUM_THREADS=%d %s%s" % (threads, row["omp_env"] + " " if row["omp_env"] else "", " ".join(
            a if re.fullmatch(r"[\w./=-]+", a) else '"' + a + '"' for a in args[:-1]))
        p, r, wall, row["busy_during"] = measured_run(args, env)
        row["process_wall_s"] = round(wall, 3)
        row["exit"] = p.returncode
        t = time_fields(p.stdout)
        if r is None or t is None:
            sys.stderr.write(f"bench: no result/time line from: {row['cmdline']} (exit {p.returncode})\n")
            sys.stderr.write(p.stdout[-1500:] + p.stderr[-1500:] + "\n")
            row["status"] = "error"
            self._clean(stem)
            return row, None
        row["status"] = r.get("status")
        for k in ("n1", "n2", "m", "outer", "inner"):
            row[k] = int(r[k])
        row["residual"] = fnum(r.get("residual"))
        for k in ("assemble", "factor", "condense", "iterate", "output", "total"):
            row[k + "_s"] = fnum(t.get(k))
        row["peak_mb"] = fnum(t.get("peak_mb"))
        row["factor_mb"] = fnum(t.get("factor_mb"))
        row["solve_s"] = row["factor_s"] + row["condense_s"] + row["iterate_s"]
        row["solve_over_factor"] = row["solve_s"] / row["factor_s"] if row["factor_s"] > 0 else float("nan")
        fm = contact_force(p.stdout)
        c = None
        if os.path.exists(h5):
            with h5py.File(h5, "r") as f:
                c = {k: np.array(f["/contact/" + k]) for k in
                     ("normal_force", "pressure", "s", "tributary_length", "active")}
            row["force"] = float(np.sum(c["normal_force"]))
        elif fm is not None:
            row["force"] = fnum(fm)
        self._clean(stem)
        return row, c

    def wait_quiet(self, row):
        """Cores kept busy by other processes; for the big runs (level >= 5 and the thread
        comparison) wait up to quiet_wait s for < 0.5."""
        return wait_quiet(row["level"] >= 5 or row["group"] == "threads", self.quiet_wait)

    def _clean(self, stem):
        if self.keep:
            return
        for fn in os.listdir(self.workdir):
            if fn.startswith(stem):
                os.remove(os.path.join(self.workdir, fn))


def new_row(group, level, label, method, operator, factorization="cholmod", ordering="metis",
            tol=1e-8, stop="increment", mono_rtol=1e-12, delta=0.5):
    nx, ny = mesh_of(level)
    row = {k: "" for k in COLUMNS}
    row.update(group=group, level=level, nx=nx, ny=ny, label=label, method=method,
               operator=operator if method == "robin" else "", delta=delta if method == "robin" else "",
               factorization=factorization, ordering=ordering if factorization == "cholmod" else "rcm",
               tol=tol if method == "robin" else "", stop=stop if method == "robin" else "",
               mono_rtol=mono_rtol if method == "monolithic" else "")
    return row


# the floating group: the paper's scene with contact by groups; body 1 supported (ux, uy = 0
# on its left side) or floating vertically (ux = 0 only)
FLOAT_SCENE = ["&body id=1, left='free', bottom='free' /", "&body id=2, left='free', top='free' /",
               "&boundary body=2, group='left', ux=0.0, uy=0.0 /",
               "&contact body1_group='bottom', body2_group='top' /"]


def overrides_of(row):
    nx, ny = row["nx"], row["ny"]
    ov = [f"&body id=1, nx={nx}, ny={ny} /", f"&body id=2, nx={nx}, ny={ny} /"]
    if row["group"] == "floating":
        ov += FLOAT_SCENE + ["&boundary body=1, group='left', ux=0.0 /" if row["label"].startswith("floating")
                             else "&boundary body=1, group='left', ux=0.0, uy=0.0 /"]
    s = f"&solver method='{row['method']}', factorization='{row['factorization']}'"
    if row["factorization"] == "cholmod":
        s += f", ordering='{row['ordering']}'"
    if row["method"] == "robin":
        s += (f", robin_operator='{row['operator']}', delta={row['delta']}, tol={row['tol']:.0e}"
              f", stop='{row['stop']}'")
    else:
        s += f", monolithic_rtol={row['mono_rtol']:.0e}"
    return ov + [s + " /"]


def pressure_error(coarse, fine, edge_window=None):
    """Relative L2 error of the coarse pressure against the fine one at the coarse nodes;
    with edge_window, leave out the nodes within edge_window * (line length) of a change
    active <-> inactive of the fine solution (the contact-zone edges)."""
    xc, xf = coarse["s"], fine["s"]
    hf = np.min(np.diff(xf)) if xf.size > 1 else 1.0
    pos = np.interp(xc, xf, np.arange(xf.size))
    if np.max(np.abs(pos - np.rint(pos))) > 1e-6:
        raise SystemExit("bench: coarse contact nodes do not nest in the fine mesh")
    pf = fine["pressure"][np.rint(pos).astype(int)]
    w = coarse["tributary_length"].copy()
    if edge_window is not None:
        act = np.asarray(fine["active"]).astype(bool)
        flips = np.nonzero(act[1:] != act[:-1])[0]
        edges = 0.5 * (xf[flips] + xf[flips + 1])
        length = xf[-1] - xf[0] + hf
        for e in edges:
            w[np.abs(xc - e) <= edge_window * length] = 0.0
    return float(np.sqrt(np.sum(w * (coarse["pressure"] - pf) ** 2) / np.sum(w * pf ** 2)))


def order(e_prev, e):
    if not (e_prev > 0 and e > 0) or math.isnan(e_prev) or math.isnan(e):
        return ""
    return round(math.log2(e_prev / e), 3)


def fmt(x, spec):
    if x == "" or x is None:
        return ""
    if isinstance(x, float) and math.isnan(x):
        return "nan"
    return format(x, spec)


def write_csv(path, rows, columns):
    """rows (dicts with the keys columns) to the CSV file path, its folder created; floats
    with 10 significant digits."""
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=columns)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.10g}" if isinstance(v, float) else v) for k, v in r.items()})


def table(head, rows):
    return "\n".join(md_header(head) + [md_row(r) for r in rows])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--max-level", type=int, default=6)
    ap.add_argument("--quick", action="store_true", help="cap the ladder at 256x128 (level 4)")
    ap.add_argument("--bin", default="bin/robin_contact")
    ap.add_argument("--deck", default="inputs/default.nml")
    ap.add_argument("--csv", default="results/bench.csv")
    ap.add_argument("--sweep-level", type=int, default=4, help="mesh level of the tolerance sweep (4 = 256x128)")
    ap.add_argument("--banded-limit", type=float, default=60.0,
                    help="skip the banded run when 16x the previous level's banded time exceeds this [s]")
    ap.add_argument("--orderings", default="amd,nd",
                    help="comma list of CHOLMOD orderings compared with metis (ordering and threads "
                         "groups), e.g. amd,nd (default amd)")
    ap.add_argument("--skip", default="", help="comma list of groups to skip: ordering,threads,sweep,floating")
    ap.add_argument("--only-floating", action="store_true", help="run the floating group only")
    ap.add_argument("--quiet-wait", type=float, default=120.0,
                    help="before each run at >= 512x256 and each thread-comparison run, wait up to this "
                         "many s until other processes keep < 0.5 core busy")
    ap.add_argument("--repeat", type=int, default=2,
                    help="runs at >= 512x256: repeat and keep the fastest (default 2)")
    ap.add_argument("--repeat-small", type=int, default=None,
                    help="runs at <= 256x128: repeat and keep the fastest (default 3, 1 with --quick)")
    ap.add_argument("--ref-rtol", type=float, default=1e-15,
                    help="monolithic_rtol of the ladder's monolithic runs, the references of alg_err and "
                         "of the discretisation error (default 1e-15: 1e-12 leaves ~1e-9 error in lam)")
    ap.add_argument("--edge-window", type=float, default=0.1,
                    help="p_err_away leaves out the nodes within this fraction of the line length of a "
                         "contact-zone edge (active/inactive change) of the finest solution")
    ap.add_argument("--keep-h5", action="store_true", help="keep the result files (in --workdir)")
    ap.add_argument("--workdir", default=None, help="folder for the run files (default: a temporary folder)")
    a = ap.parse_args()
    if a.repeat_small is None:
        a.repeat_small = 1 if a.quick else 3
    top = min(a.max_level, 4) if a.quick else a.max_level
    top = max(0, min(top, 6))
    sweep_level = min(a.sweep_level, top)
    skip = set(s for s in a.skip.split(",") if s)
    orderings = [o for o in a.orderings.split(",") if o and o != "metis"]
    if not os.access(a.bin, os.X_OK):
        raise SystemExit(f"bench: no executable {a.bin} (run make first)")
    workdir = a.workdir or tempfile.mkdtemp(prefix="bench_", dir=os.environ.get("TMPDIR", "/tmp"))
    os.makedirs(workdir, exist_ok=True)
    R = Runner(a.bin, a.deck, workdir, a.keep_h5)
    R.quiet_wait = a.quiet_wait
    rows = []

    def go(row, threads=2, extra_env=None, repeats=None):
        if repeats is None:
            repeats = a.repeat if row["level"] >= 5 else a.repeat_small
        R.run(row, overrides_of(row), threads, extra_env, repeats)
        rows.append(row)
        return row

    sys.stderr.write(f"bench: levels 0..{top}, work folder {workdir}\n")
    mono = {}
    banded_prev = None
    for lv in range(-1 if a.only_floating else top + 1):
        mono[lv] = go(new_row("ladder", lv, "monolithic", "monolithic", "", mono_rtol=a.ref_rtol))
        go(new_row("ladder", lv, "robin-steklov", "robin", "steklov"))
        go(new_row("ladder", lv, "robin-harmonic", "robin", "harmonic"))
        if "ordering" not in skip:
            for ordn in orderings:
                go(new_row("ordering", lv, "robin-steklov", "robin", "steklov", ordering=ordn))
            if banded_prev is None or banded_prev * 16.0 < a.banded_limit:
                r = go(new_row("ordering", lv, "robin-steklov", "robin", "steklov", factorization="banded"))
                banded_prev = r["total_s"] if r["status"] != "error" else 1e30
    if a.only_floating:
        skip |= {"threads", "sweep"}
    if "threads" not in skip:
        tlevels = [lv for lv in (5, 6) if lv <= top] or [top]
        for lv in tlevels:
            for ordering in ["metis"] + orderings:
                # OMP_NUM_THREADS=1 as a user would set it, the same with OMP_THREAD_LIMIT=1
                # (truly one thread: see the note on CHOLMOD's own OpenMP loops), then 2
                for thr, env in ((1, None), (1, {"OMP_THREAD_LIMIT": "1"}), (2, None)):
                    go(new_row("threads", lv, "robin-steklov", "robin", "steklov", ordering=ordering),
                       threads=thr, extra_env=env, repeats=None if (thr > 1 or env) else 1)
    if "sweep" not in skip:
        tols = [10.0 ** -k for k in range(2, 11)]
        for op in ("steklov", "harmonic"):
            for stop in ("residual", "increment"):
                for tol in tols:
                    go(new_row("sweep", sweep_level, "robin-" + op, "robin", op, tol=tol, stop=stop))
        for tol in tols:
            go(new_row("sweep", sweep_level, "monolithic", "monolithic", "", mono_rtol=tol))

    if "floating" not in skip:
        for lv in sorted({-1, top}):
            for kind in ("supported", "floating"):
                for meth, op in (("robin", "harmonic"), ("monolithic", "")):
                    r = new_row("floating", max(lv, 0), f"{kind} {meth}", meth, op, tol=1e-10,
                                mono_rtol=1e-12)
                    if lv < 0:   # the paper's own mesh
                        r.update(nx=24, ny=16, level=-1)
                    go(r, repeats=a.repeat if lv >= 5 else a.repeat_small)

    # ---- errors ---------------------------------------------------------------------
    C = R.contact
    fine = C.get(id(mono[top])) if top in mono else None
    for r in rows:
        c = C.get(id(r))
        if c is None or r["group"] == "floating":
            continue
        m = C.get(id(mono[r["level"]]))
        if m is not None and r is not mono[r["level"]]:
            e = rel_err(c["normal_force"], m["normal_force"])
            r["alg_err"] = float("nan") if e is None else e
        if fine is not None and r["level"] < top:
            r["p_err"] = pressure_error(c, fine)
            r["p_err_away"] = pressure_error(c, fine, a.edge_window)
            F = float(np.sum(fine["normal_force"]))
            r["force_err"] = abs(r["force"] - F) / abs(F)
    series = {}
    for r in rows:
        if r["group"] in ("ladder", "ordering") and r["status"] != "error":
            key = (r["label"], r["factorization"], r["ordering"])
            series.setdefault(key, []).append(r)
    for ser in series.values():
        ser.sort(key=lambda r: r["level"])
        for i, r in enumerate(ser):
            if i >= 1 and ser[i - 1]["level"] == r["level"] - 1:
                p = ser[i - 1]
                if r["p_err"] != "":
                    r["p_order"] = order(p["p_err"], r["p_err"])
                    r["p_away_order"] = order(p["p_err_away"], r["p_err_away"])
                    r["force_order"] = order(p["force_err"], r["force_err"])
                if i >= 2 and ser[i - 2]["level"] == r["level"] - 2:
                    q = ser[i - 2]
                    r["force_order3"] = order(abs(q["force"] - p["force"]), abs(p["force"] - r["force"]))

    # floating group: each Robin run against the monolithic run of the same mesh and support
    fl = [r for r in rows if r["group"] == "floating"]
    for r in fl:
        ref = [q for q in fl if q["method"] == "monolithic" and (q["nx"], q["ny"]) == (r["nx"], r["ny"])
               and q["label"].split()[0] == r["label"].split()[0]]
        c, m = C.get(id(r)), (C.get(id(ref[0])) if ref else None)
        if c is not None and m is not None and ref[0] is not r:
            e = rel_err(c["normal_force"], m["normal_force"])
            r["alg_err"] = float("nan") if e is None else e

    write_csv(a.csv, rows, COLUMNS)
    if not a.workdir and not a.keep_h5:
        shutil.rmtree(workdir, ignore_errors=True)

    # ---- tables -----------------------------------------------------------------------
    def oi(r):
        return f"{r['outer']}/{r['inner']}" if r["status"] != "error" else "error"

    def st(r):
        return "" if r["status"] == "converged" else f" ({r['status']})"

    print(f"# robin_contact bench ({a.deck}, Q1 plane strain, OMP_NUM_THREADS=2 unless said)\n")
    print(f"Times: fastest of {a.repeat_small} runs (<= 256x128) / {a.repeat} runs (>= 512x256); busy = cores "
          "kept busy by other processes during the kept run. Monolithic ladder runs use monolithic_rtol="
          f"{a.ref_rtol:g} (the references).\n")
    print("## Ladder: CHOLMOD + METIS, time per phase [s], memory [MB]\n")
    lr = [r for r in rows if r["group"] == "ladder"]
    print(table(["mesh", "DOFs/body", "m", "method", "outer/inner", "assemble", "factor", "condense",
                 "iterate", "output", "total", "(f+c+i)/f", "peak MB", "factor MB", "alg. err", "busy"],
                [[f"{r['nx']}x{r['ny']}", r["n1"], r["m"], r["label"] + st(r), oi(r), fmt(r["assemble_s"], ".3f"),
                  fmt(r["factor_s"], ".3f"), fmt(r["condense_s"], ".3f"), fmt(r["iterate_s"], ".3f"),
                  fmt(r["output_s"], ".3f"), fmt(r["total_s"], ".3f"), fmt(r["solve_over_factor"], ".2f"),
                  fmt(r["peak_mb"], ".0f"), fmt(r["factor_mb"], ".0f"), fmt(r["alg_err"], ".1e"), r["busy_during"]]
                 for r in lr]))
    print("\n## Discretisation error against the finest mesh "
          f"({mesh_of(top)[0]}x{mesh_of(top)[1]}, monolithic)\n")
    print(table(["mesh", "method", "total force [N/m]", "force err", "order", "3-mesh force order",
                 "pressure L2 err", "order", "L2 err away from edge", "order"],
                [[f"{r['nx']}x{r['ny']}", r["label"], fmt(r["force"], ".6e"), fmt(r["force_err"], ".2e"),
                  r["force_order"], r["force_order3"], fmt(r["p_err"], ".2e"), r["p_order"],
                  fmt(r["p_err_away"], ".2e"), r["p_away_order"]]
                 for r in lr if r["label"] != "robin-harmonic"]))
    if fine is not None:
        act = np.asarray(fine["active"]).astype(bool)
        flips = np.nonzero(act[1:] != act[:-1])[0]
        xe = ", ".join(f"{0.5 * (fine['s'][i] + fine['s'][i + 1]):.4f}" for i in flips)
        print(f"\n(contact-zone edges of the finest solution at x = {xe}; "
              f"'away from edge' leaves out +-{a.edge_window:g} of the line length around them)")
    if "ordering" not in skip:
        print("\n## Factorizations side by side (robin/steklov, delta 0.5): factor / condense / total [s], "
              "factor MB\n")
        out = []
        for lv in range(top + 1):
            cells = [f"{mesh_of(lv)[0]}x{mesh_of(lv)[1]}"]
            for fac, ordn in [("cholmod", "metis")] + [("cholmod", o) for o in orderings] + [("banded", "rcm")]:
                grp = "ladder" if ordn == "metis" else "ordering"
                rr = [r for r in rows if r["group"] == grp and r["level"] == lv and r["label"] == "robin-steklov"
                      and r["factorization"] == fac and r["ordering"] == ordn]
                if rr and rr[0]["status"] != "error":
                    r = rr[0]
                    cells.append(f"{r['factor_s']:.3f} / {r['condense_s']:.3f} / {r['total_s']:.3f}")
                    cells.append(fmt(r["factor_mb"], ".0f"))
                    cells.append(fmt(r["alg_err"], ".1e"))
                else:
                    cells += ["—", "", ""]
            out.append(cells)
        head = ["mesh"]
        for name in ["METIS"] + [o.upper() for o in orderings] + ["banded"]:
            head += [f"{name} f/c/total", "MB", "err"]
        print(table(head, out))
    if "threads" not in skip:
        print("\n## Threads: robin/steklov, back to back: OMP_NUM_THREADS=1, OMP_NUM_THREADS=1 with "
              "OMP_THREAD_LIMIT=1, OMP_NUM_THREADS=2; factor+condense [s] (total [s])\n")
        out = []
        tr = [r for r in rows if r["group"] == "threads" and r["status"] != "error"]
        for lv in sorted(set(r["level"] for r in tr)):
            for ordn in ["metis"] + orderings:
                sel = [r for r in tr if r["level"] == lv and r["ordering"] == ordn]
                one = [r for r in sel if r["threads"] == 1 and not r["omp_env"]]
                lim = [r for r in sel if r["threads"] == 1 and r["omp_env"]]
                two = [r for r in sel if r["threads"] == 2]
                if not (one and lim and two):
                    continue
                o, l1, t = one[0], lim[0], two[0]
                fc = [x["factor_s"] + x["condense_s"] for x in (o, l1, t)]
                out.append([f"{o['nx']}x{o['ny']}", ordn] +
                           [f"{f:.2f} ({x['total_s']:.2f})" for f, x in zip(fc, (o, l1, t))] +
                           [f"{fc[1] / fc[2]:.2f}", f"{l1['total_s'] / t['total_s']:.2f}",
                            f"{o['busy_during']}/{l1['busy_during']}/{t['busy_during']}"])
        print(table(["mesh", "ordering", "OMP=1", "OMP=1, limit 1", "OMP=2", "speed-up f+c (limit 1 -> 2)",
                     "speed-up total", "busy"], out))
    if "sweep" not in skip:
        nx, ny = mesh_of(sweep_level)
        print(f"\n## Tolerance sweep at {nx}x{ny}: error of lam against the monolithic solution "
              f"(monolithic_rtol {a.ref_rtol:g})\n")
        sr = [r for r in rows if r["group"] == "sweep"]
        print(table(["method", "stop", "tol", "status", "outer/inner", "iterate [s]", "f+c+i [s]", "residual",
                     "alg. err"],
                    [[r["label"], r["stop"] or "(mono rtol)", fmt(r["tol"] if r["tol"] != "" else r["mono_rtol"], ".0e"),
                      r["status"], oi(r), fmt(r["iterate_s"], ".3f"), fmt(r["solve_s"], ".3f"),
                      fmt(r["residual"], ".1e"), fmt(r["alg_err"], ".1e")] for r in sr]))
    if fl:
        print("\n## A body held only by contact: body 1 clamped on its left side (supported) or with "
              "ux = 0 only there (floating vertically), contact by groups, Robin harmonic delta 0.5 tol 1e-10 "
              "and monolithic; ratio = total / total of the supported run\n")
        out = []
        for r in fl:
            sup = [q for q in fl if q["label"] == r["label"].replace("floating", "supported")
                   and (q["nx"], q["ny"]) == (r["nx"], r["ny"])]
            ratio = (r["total_s"] / sup[0]["total_s"] if sup and r["status"] != "error" and sup[0]["status"] != "error"
                     and sup[0]["total_s"] > 0 else float("nan"))
            out.append([f"{r['nx']}x{r['ny']}", r["n1"], r["m"], r["label"] + st(r), oi(r),
                        fmt(r["factor_s"], ".3f"), fmt(r["condense_s"], ".3f"), fmt(r["iterate_s"], ".3f"),
                        fmt(r["total_s"], ".3f"), fmt(ratio, ".2f"), fmt(r["peak_mb"], ".0f"),
                        fmt(r["force"], ".6e"), fmt(r["alg_err"], ".1e"), r["busy_during"]])
        print(table(["mesh", "DOFs/body", "m", "run", "outer/inner", "factor", "condense", "iterate", "total",
                     "ratio", "peak MB", "total force", "alg. err", "busy"], out))
    fin = [r for r in rows if r["group"] == "ladder" and r["level"] == top and r["label"] == "robin-steklov"]
    if fin and fin[0]["status"] != "error":
        r = fin[0]
        print(f"\nAt {r['nx']}x{r['ny']} ({r['n1']} DOFs per body, m={r['m']}), robin/steklov: "
              f"(factor+condense+iterate)/factor = {r['solve_s']:.2f} / {r['factor_s']:.2f} = "
              f"{r['solve_over_factor']:.2f} (target <= 1.5); total {r['total_s']:.2f} s")
    print(f"\nwrote {a.csv} ({len(rows)} rows, {R.count} runs)")


if __name__ == "__main__":
    main()
