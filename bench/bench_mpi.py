#!/usr/bin/env python3
"""The MPI binary against the serial one, measured: the paper's scene
(inputs/default.nml) at nx x ny Q1 cells per body, with factorization='mumps' under
mpirun -np N beside the serial CHOLMOD binary; then a ladder of body sizes per path.

Table 1 (--size, default 1024x512, 1.05M DOFs per body): the serial binary with CHOLMOD
(OMP_NUM_THREADS=2: one thread per body, the same two cores as -np 2, and 1 thread), and
the MPI binary at -np in --ranks (default 2,4,8; OMP_NUM_THREADS=1, idle ranks yield).
Columns: the phases of rank 0's `time:` line, rank 0's peak RSS (peak_mb), the largest
peak RSS of any rank and the sum over the ranks (the binary's `mpi:` line: getrusage's
ru_maxrss = VmHWM of each rank, gathered to rank 0), the largest rank's peak when the
factorization starts (meshes, DOF numbering, loads: every rank meshes both bodies), the
largest rank's MUMPS factorization memory (INFOG(21), body 1 / body 2), and the contact
forces against the serial run (relative 2-norm). This machine has 2 cores: -np 4 and 8
are oversubscribed, so their times are not speed-ups; what they show is the memory.

Table 2: -np 2 against serial CHOLMOD (2 threads) side by side: the ratio of each phase
and the factorization's share of each total.

Table 3 (--ladder): per path (cholmod serial 2 threads, mumps -np 2, mumps -np 4) the
bodies of --levels in turn, until a run fails or the next level is predicted to take more
than --max-run-s or to need more than --mem-limit-mb in total on this machine (or its
MemAvailable); the prediction scales the last measured run by n log2 n (memory) and
n^1.5 (time). The largest solved level and its measured peaks are reported; a level
skipped by prediction is marked as such (an extrapolation, not a measurement).

Table 4 (--bodies, default 64; 0 skips it): an assembly of many bodies, columns of 8
blocks of --bodies-size cells each (the bottom block clamped, the others held by a
roller, a pressure on each column's top), solved by --bodies-method (default monolithic:
one QP, so that the run is short) with the serial CHOLMOD binary (1 thread) and with the
MPI binary at -np in --bodies-ranks (default 2,4,8; fewer ranks than bodies: several
bodies per rank, each on one). Per rank: its bodies, its MUMPS factor share (INFO(9)) and
its peak RSS (the binary's `mpi: rank=` lines). Memory, not time, is the measure.

Writes --csv (default results/bench_mpi.csv; table 4 to its *_bodies.csv) and prints
Markdown tables. A benchmark reports; it asserts nothing.

Usage: bench/bench_mpi.py [--bin bin/robin_contact] [--mpi-bin bin/robin_contact_mpi]
         [--size 1024x512] [--ranks 2,4,8] [--ladder] [--levels 1024x512,1448x724,...]
         [--max-run-s 600] [--mem-limit-mb 22528] [--workdir results/bench_mpi] [--quick]
         [--bodies 64] [--bodies-size 64x32] [--bodies-ranks 2,4,8] [--bodies-method monolithic]
--quick: 128x64, -np 2 and 4, no ladder, 16 bodies of 16x8 (a smoke run of a few seconds).
"""
import argparse
import csv
import math
import os
import re
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))  # the rc_* helpers
from rc_results import md_header, md_row, read_lam, rel_err  # noqa: E402
from rc_run import line_fields, result_fields, solver_env, time_fields  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DECK = os.path.join(ROOT, "inputs", "default.nml")
RANK_LINE = re.compile(r"^mpi: rank=(\d+) bodies=([0-9,]+) factor_mb=([0-9.]+) peak_rss_mb=([0-9.]+)$", re.M)
MUMPS_MEM = re.compile(r"^mumps: largest rank's factorization memory: body 1 ([0-9.]+) MB, body 2 ([0-9.]+) MB", re.M)
PHASES = ("assemble", "factor", "condense", "iterate", "output", "total")
COLUMNS = ["table", "path", "np", "threads", "nx", "ny", "n_per_body", "status", "exit", "outer", "inner"] + \
          [p + "_s" for p in PHASES] + ["process_wall_s", "rank0_peak_mb", "peak_max_rank_mb", "peak_max_rank",
                                        "peak_sum_mb", "assembly_peak_max_rank_mb", "factor_mb",
                                        "mumps_rank_mb_body1", "mumps_rank_mb_body2", "lam_rel_err_vs_serial",
                                        "load1_before", "note"]


def mem_available_mb():
    with open("/proc/meminfo") as f:
        for ln in f:
            if ln.startswith("MemAvailable:"):
                return int(ln.split()[1]) / 1024.0
    return float("inf")


def mpi_env():
    """One OpenMP thread per rank, idle ranks yield their core (oversubscribed runs); root
    allowed (OpenMPI refuses it otherwise)."""
    env = solver_env(1)
    env.update(OMPI_MCA_mpi_yield_when_idle="1", OPENBLAS_NUM_THREADS="1")
    if os.geteuid() == 0:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return env


class Bench:
    def __init__(self, args):
        self.a = args
        self.rows = []
        self.count = 0
        self.lam_serial = {}   # (nx, ny) -> lam of the serial run

    def run(self, table, path, np_, nx, ny, threads=1, timeout=None):
        """One run; returns its row (status 'error'/'timeout' when no result line came)."""
        self.count += 1
        h5 = os.path.join(self.a.workdir, f"run{self.count:03d}.h5")
        over = [f"&body id=1, nx={nx}, ny={ny} /", f"&body id=2, nx={nx}, ny={ny} /",
                f"&output file='{h5}', progress_lines=0 /"]
        if path == "cholmod":
            cmd = [self.a.bin, DECK] + over
            env = solver_env(threads)
        else:
            cmd = ["mpirun", "--oversubscribe", "-np", str(np_), self.a.mpi_bin, DECK,
                   "&solver factorization='mumps' /"] + over
            env = mpi_env()
        row = dict(table=table, path=path, np=np_ if path == "mumps" else 1, threads=threads, nx=nx, ny=ny,
                   n_per_body=2 * (nx + 1) * (ny + 1), load1_before=round(os.getloadavg()[0], 2), note="")
        t0 = time.monotonic()
        p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                             start_new_session=True)
        try:
            out, err = p.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            out, err = p.communicate()
            row.update(status="timeout", exit=None, note=f"killed after {timeout:.0f} s")
            self._done(row, h5)
            return row
        row["process_wall_s"] = round(time.monotonic() - t0, 2)
        row["exit"] = p.returncode
        r, t = result_fields(out), time_fields(out)
        if r is None or t is None:
            row["status"] = "error"
            row["note"] = (err.strip().splitlines() or ["no output"])[-1][:200]
            self._done(row, h5)
            return row
        row.update(status=r["status"], outer=int(r["outer"]), inner=int(r["inner"]))
        for k in PHASES:
            row[k + "_s"] = float(t[k])
        row["rank0_peak_mb"] = float(t["peak_mb"])
        row["factor_mb"] = float(t["factor_mb"])
        m = line_fields(out, "mpi")
        if m:
            row["peak_max_rank_mb"] = float(m["peak_rss_max_rank_mb"])
            row["peak_max_rank"] = int(m["max_rank"])
            row["peak_sum_mb"] = float(m["peak_rss_sum_mb"])
            row["assembly_peak_max_rank_mb"] = float(m["assembly_peak_max_rank_mb"])
        else:   # one process: its own peak
            row["peak_max_rank_mb"] = row["peak_sum_mb"] = row["rank0_peak_mb"]
            row["peak_max_rank"] = 0
        mm = MUMPS_MEM.findall(out)
        if mm:
            row["mumps_rank_mb_body1"], row["mumps_rank_mb_body2"] = float(mm[-1][0]), float(mm[-1][1])
        if os.path.exists(h5):
            lam = read_lam(h5)
            if path == "cholmod" and (nx, ny) not in self.lam_serial:
                self.lam_serial[(nx, ny)] = lam
            e = rel_err(lam, self.lam_serial.get((nx, ny)))
            row["lam_rel_err_vs_serial"] = "" if e is None else f"{e:.2e}"
        self._done(row, h5)
        return row

    def _done(self, row, h5):
        for f in (h5, h5 + ".ckpt.h5", os.path.splitext(h5)[0] + ".xdmf"):
            if os.path.exists(f):
                os.remove(f)
        self.rows.append(row)
        sys.stderr.write(f"  {row['table']:7s} {row['path']:7s} np={row['np']} thr={row['threads']} "
                         f"{row['nx']}x{row['ny']}: {row['status']} total={row.get('total_s', '-')} s "
                         f"peak max rank {row.get('peak_max_rank_mb', '-')} MB, sum {row.get('peak_sum_mb', '-')} MB"
                         f" {row['note']}\n")
        sys.stderr.flush()


def f1(x, spec=".1f"):
    return "-" if x is None or x == "" else format(x, spec)


def label(r):
    if r["path"] == "cholmod":
        return f"CHOLMOD serial, {r['threads']} thread{'s' if r['threads'] > 1 else ''}"
    g = r["np"] // 2
    over = ", **oversubscribed**" if r["np"] > (os.cpu_count() or 2) else ""
    return f"MUMPS -np {r['np']} ({g}{'+' + str(r['np'] - g) if r['np'] - g != g else ''} per body{over})" \
        if r["np"] > 1 else "MUMPS -np 1"


def table1(rows):
    out = md_header(["run", "assemble", "factor", "condense", "iterate", "output", "total",
                     "rank 0 peak MB", "largest rank peak MB (rank)", "sum of ranks MB",
                     "largest rank at factorization start MB", "MUMPS largest rank MB (b1/b2)", "lam vs CHOLMOD"])
    for r in rows:
        if r["status"] in ("error", "timeout"):
            out.append(md_row([label(r), r["status"], r["note"]] + [""] * 10))
            continue
        mum = f"{r['mumps_rank_mb_body1']:.0f} / {r['mumps_rank_mb_body2']:.0f}" if "mumps_rank_mb_body1" in r \
            else f"(CHOLMOD {r['factor_mb']:.0f} for both)"
        out.append(md_row([label(r)] + [f1(r[k + "_s"], ".2f") for k in PHASES] +
                          [f1(r["rank0_peak_mb"], ".0f"), f"{r['peak_max_rank_mb']:.0f} ({r['peak_max_rank']})",
                           f1(r["peak_sum_mb"], ".0f"), f1(r.get("assembly_peak_max_rank_mb"), ".0f"), mum,
                           r.get("lam_rel_err_vs_serial", "") or "-"]))
    return out


def table2(ser, par):
    out = md_header(["phase", "CHOLMOD serial (2 threads) s", "MUMPS -np 2 s", "ratio MUMPS/CHOLMOD"])
    for k in PHASES:
        a, b = ser[k + "_s"], par[k + "_s"]
        out.append(md_row([k, f"{a:.2f}", f"{b:.2f}", f"{b / a:.2f}" if a > 0 else "-"]))
    out.append(md_row(["factorization share of total", f"{ser['factor_s'] / ser['total_s']:.0%}",
                       f"{par['factor_s'] / par['total_s']:.0%}", ""]))
    out.append(md_row(["(factor + condense) share", f"{(ser['factor_s'] + ser['condense_s']) / ser['total_s']:.0%}",
                       f"{(par['factor_s'] + par['condense_s']) / par['total_s']:.0%}", ""]))
    out.append(md_row(["peak MB (largest rank / sum)", f"{ser['peak_max_rank_mb']:.0f}",
                       f"{par['peak_max_rank_mb']:.0f} / {par['peak_sum_mb']:.0f}", ""]))
    return out


def ladder(b, levels, paths):
    """Climb the levels per path; returns the Markdown lines."""
    out = md_header(["path", "level", "DOFs per body", "status", "total s", "factor s", "largest rank peak MB",
                     "sum of ranks MB", "note"])
    summary = []
    for path, np_, thr in paths:
        last = None
        best = None
        for nx, ny in levels:
            n = 2 * (nx + 1) * (ny + 1)
            limit = min(b.a.mem_limit_mb, 0.95 * mem_available_mb())
            if last is not None:
                n0 = last["n_per_body"]
                s_mem = (n * math.log2(n)) / (n0 * math.log2(n0))
                pred_mem = last["peak_sum_mb"] * s_mem
                pred_rank = last["peak_max_rank_mb"] * s_mem
                pred_t = last["total_s"] * (n / n0) ** 1.5
                if pred_mem > limit or pred_t > b.a.max_run_s:
                    why = (f"predicted sum {pred_mem / 1024:.1f} GB > limit {limit / 1024:.1f} GB" if pred_mem > limit
                           else f"predicted {pred_t:.0f} s > {b.a.max_run_s:.0f} s")
                    out.append(md_row([lbl(path, np_, thr), f"{nx}x{ny}", f"{n:,}", "not run (extrapolated)",
                                       f"~{pred_t:.0f}", "", f"~{pred_rank:.0f}", f"~{pred_mem:.0f}", why]))
                    b.rows.append(dict(table="ladder", path=path, np=np_, threads=thr, nx=nx, ny=ny, n_per_body=n,
                                       status="skipped", note="extrapolated: " + why,
                                       total_s=round(pred_t), peak_max_rank_mb=round(pred_rank),
                                       peak_sum_mb=round(pred_mem)))
                    break
            r = b.run("ladder", path, np_, nx, ny, threads=thr, timeout=2.0 * b.a.max_run_s)
            ok = r["status"] == "converged"
            out.append(md_row([lbl(path, np_, thr), f"{nx}x{ny}", f"{n:,}", r["status"], f1(r.get("total_s"), ".1f"),
                               f1(r.get("factor_s"), ".1f"), f1(r.get("peak_max_rank_mb"), ".0f"),
                               f1(r.get("peak_sum_mb"), ".0f"), r["note"]]))
            if not ok:
                break
            last = best = r
        if best is not None:
            summary.append(f"- {lbl(path, np_, thr)}: largest solved {best['nx']}x{best['ny']} "
                           f"({best['n_per_body']:,} DOFs per body), {best['total_s']:.0f} s, largest rank "
                           f"{best['peak_max_rank_mb']:.0f} MB, all ranks {best['peak_sum_mb']:.0f} MB")
    return out, summary


def columns_deck(path, nbody, nx, ny, rows=8):
    """Write an assembly of nbody blocks (1 x 1, nx x ny cells) in columns of `rows` (the
    last column shorter if need be): each block on the one below, the bottom one clamped,
    the others held by a roller on the left, a pressure on each column's top."""
    lines, bid = [], 0
    while bid < nbody:
        c, top = bid // rows, bid + 1
        k_max = min(rows, nbody - bid)
        for k in range(k_max):
            bid += 1
            lines.append(f"&body id={bid}, x0={1.2 * c}, y0={float(k_max - 1 - k)}, width=1.0, height=1.0, "
                         f"nx={nx}, ny={ny}" + (", bottom='clamped'" if k == k_max - 1 else ", left='roller'") + " /")
        lines.append(f"&traction body={top}, side='top', t0=0.0, -1.0e6 /")
        lines += [f"&contact bodies={b},{b + 1}, groups='bottom','top' /" for b in range(top, bid)]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def many_bodies(a, nbody, nx, ny, ranks, method):
    """Table 4: the serial binary and the MPI binary at each -np on the many-body deck;
    returns (Markdown lines, one row per run, one row per rank)."""
    deck = os.path.join(a.workdir, f"bodies{nbody}.nml")
    columns_deck(deck, nbody, nx, ny)
    runs, per_rank, lam_ref = [], [], None
    for np_ in [0] + ranks:   # 0: the serial binary
        h5 = os.path.join(a.workdir, f"bodies{nbody}_np{np_}.h5")
        over = [f"&solver method='{method}'" + (", factorization='mumps'" if np_ else "") + " /",
                f"&output file='{h5}', progress_lines=0 /"]
        if np_:
            cmd, env = ["mpirun", "--oversubscribe", "-np", str(np_), a.mpi_bin, deck] + over, mpi_env()
        else:
            cmd, env = [a.bin, deck] + over, solver_env(1)
        t0 = time.monotonic()
        p = subprocess.run(cmd, capture_output=True, text=True, env=env)
        row = dict(np=np_, bodies=nbody, nx=nx, ny=ny, method=method, exit=p.returncode,
                   process_wall_s=round(time.monotonic() - t0, 2), status="error", note="")
        r, t = result_fields(p.stdout), time_fields(p.stdout)
        if r is None or t is None:
            row["note"] = (p.stderr.strip().splitlines() or ["no output"])[-1][:200]
        else:
            row.update(status=r["status"], total_s=float(t["total"]), factor_s=float(t["factor"]))
            ranks_here = [(int(k), bs, float(f), float(m)) for k, bs, f, m in RANK_LINE.findall(p.stdout)]
            if not np_:
                ranks_here = [(0, "all", float(t["factor_mb"]), float(t["peak_mb"]))]
            for k, bs, f, m in ranks_here:
                per_rank.append(dict(np=np_, rank=k, bodies=bs, factor_mb=f, peak_rss_mb=m))
            peaks = [x[3] for x in ranks_here]
            facts = [x[2] for x in ranks_here]
            nb = [len(x[1].split(",")) if x[1] != "all" else nbody for x in ranks_here]
            row.update(peak_max_rank_mb=max(peaks), peak_min_rank_mb=min(peaks), peak_sum_mb=sum(peaks),
                       factor_max_rank_mb=max(facts), factor_sum_mb=sum(facts),
                       bodies_per_rank=f"{min(nb)}-{max(nb)}" if min(nb) != max(nb) else str(nb[0]))
            if os.path.exists(h5):
                lam = read_lam(h5)
                if not np_:
                    lam_ref = lam
                e = rel_err(lam, lam_ref) if np_ else None
                row["lam_rel_err_vs_serial"] = "" if e is None else f"{e:.2e}"
        for f in (h5, h5 + ".ckpt.h5", os.path.splitext(h5)[0] + ".xdmf"):
            if os.path.exists(f):
                os.remove(f)
        sys.stderr.write(f"  bodies  np={np_} {nbody} x {nx}x{ny}: {row['status']} "
                         f"largest rank peak {row.get('peak_max_rank_mb', '-')} MB {row['note']}\n")
        runs.append(row)
    out = [f"{nbody} bodies of {nx}x{ny} Q1 cells ({2 * (nx + 1) * (ny + 1):,} DOFs each), method {method}, "
           f"{os.cpu_count()} cores (the runs beyond are oversubscribed: memory is the measure):", ""]
    out += md_header(["run", "bodies per rank", "largest rank peak MB", "smallest rank peak MB", "sum of ranks MB",
                      "largest rank factor MB", "factors, all ranks MB", "total s", "lam vs CHOLMOD"])
    for r in runs:
        name = "CHOLMOD serial, 1 thread" if not r["np"] else f"MUMPS -np {r['np']}"
        if r["status"] == "error":
            out.append(md_row([name, "error", r["note"]] + [""] * 6))
            continue
        out.append(md_row([name, r["bodies_per_rank"], f1(r["peak_max_rank_mb"]), f1(r["peak_min_rank_mb"]),
                           f1(r["peak_sum_mb"]), f1(r["factor_max_rank_mb"]), f1(r["factor_sum_mb"]),
                           f1(r["total_s"], ".2f"), r.get("lam_rel_err_vs_serial", "") or "-"]))
    out += ["", "Per rank (bodies, factor MB, peak RSS MB):", ""]
    for np_ in ranks:
        rows = [x for x in per_rank if x["np"] == np_]
        out.append(f"- -np {np_}: " + "; ".join(f"rank {x['rank']}: {len(x['bodies'].split(','))} bodies, "
                                              f"{x['factor_mb']:.1f} / {x['peak_rss_mb']:.0f}" for x in rows))
    return out, runs, per_rank


def lbl(path, np_, thr):
    return f"CHOLMOD serial ({thr} thr)" if path == "cholmod" else f"MUMPS -np {np_}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"))
    ap.add_argument("--mpi-bin", default=os.path.join(ROOT, "bin", "robin_contact_mpi"))
    ap.add_argument("--size", default="1024x512")
    ap.add_argument("--ranks", default="2,4,8")
    ap.add_argument("--ladder", action="store_true")
    ap.add_argument("--levels", default="1024x512,1448x724,2048x1024,2508x1254,2896x1448,4096x2048")
    ap.add_argument("--paths", default="cholmod,mumps2,mumps4", help="ladder paths: cholmod, mumpsN (-np N)")
    ap.add_argument("--no-phases", action="store_true", help="skip table 1 (the ladder only)")
    ap.add_argument("--max-run-s", type=float, default=600.0)
    ap.add_argument("--mem-limit-mb", type=float, default=22528.0)
    ap.add_argument("--workdir", default=os.path.join(ROOT, "results", "bench_mpi"))
    ap.add_argument("--csv", default=os.path.join(ROOT, "results", "bench_mpi.csv"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--bodies", type=int, default=64, help="bodies of table 4 (0: no table 4)")
    ap.add_argument("--bodies-size", default="64x32", help="cells of each body of table 4")
    ap.add_argument("--bodies-ranks", default="2,4,8")
    ap.add_argument("--bodies-method", default="monolithic", choices=("monolithic", "robin"))
    a = ap.parse_args()
    if a.quick:
        a.size, a.ranks, a.ladder = "128x64", "2,4", False
        a.bodies, a.bodies_size, a.bodies_ranks = min(a.bodies, 16), "16x8", "2,4"
    for exe in (a.bin, a.mpi_bin):
        if not os.access(exe, os.X_OK):
            sys.exit(f"bench_mpi: no executable {exe} (make && make MPI=1)")
    os.makedirs(a.workdir, exist_ok=True)
    os.makedirs(os.path.dirname(os.path.abspath(a.csv)), exist_ok=True)
    nx, ny = (int(v) for v in a.size.split("x"))
    b = Bench(a)
    sys.stderr.write(f"bench_mpi: {nx}x{ny} per body, {os.cpu_count()} cores, "
                     f"{mem_available_mb() / 1024:.1f} GB available\n")
    lines = []
    if not a.no_phases:
        ser2 = b.run("phases", "cholmod", 1, nx, ny, threads=2)
        ser1 = b.run("phases", "cholmod", 1, nx, ny, threads=1)
        par = [b.run("phases", "mumps", int(k), nx, ny) for k in a.ranks.split(",")]
        lines += [f"Paper's scene, {nx}x{ny} Q1 per body ({2 * (nx + 1) * (ny + 1):,} DOFs per body), "
                  f"{os.cpu_count()} cores: -np > {os.cpu_count()} is oversubscribed (times are not speed-ups)", ""]
        lines += table1([ser2, ser1] + par)
        p2 = [r for r in par if r["np"] == 2 and r["status"] == "converged"]
        if p2 and ser2["status"] == "converged":
            lines += ["", "-np 2 against serial CHOLMOD (2 threads), same scene:", ""] + table2(ser2, p2[0])
    if a.ladder:
        levels = [tuple(int(v) for v in s.split("x")) for s in a.levels.split(",")]
        paths = [("cholmod", 1, 2) if p == "cholmod" else ("mumps", int(p[5:]), 1) for p in a.paths.split(",")]
        lad, summ = ladder(b, levels, paths)
        lines += ["", f"Ladder (limits: {a.max_run_s:.0f} s per run, {a.mem_limit_mb / 1024:.1f} GB "
                      "for all ranks on this machine):", ""] + lad + [""] + summ
    if a.bodies > 0:
        bx, by = (int(v) for v in a.bodies_size.split("x"))
        tab, runs, per_rank = many_bodies(a, a.bodies, bx, by, [int(k) for k in a.bodies_ranks.split(",")],
                                          a.bodies_method)
        lines += [""] + tab
        bodies_csv = os.path.splitext(a.csv)[0] + "_bodies.csv"
        with open(bodies_csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=["np", "rank", "bodies", "factor_mb", "peak_rss_mb"])
            w.writeheader()
            for r in per_rank:
                w.writerow(r)
    with open(a.csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in b.rows:
            w.writerow(r)
    print("\n".join(lines))
    print(f"\nbench_mpi: wrote {a.csv}" + (f" and {os.path.splitext(a.csv)[0]}_bodies.csv" if a.bodies > 0 else ""))
    bad = [r for r in b.rows if r["table"] == "phases" and r["status"] != "converged"]
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
