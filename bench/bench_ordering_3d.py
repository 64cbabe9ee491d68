#!/usr/bin/env python3
"""The orderings of a solid body (`make bench-ordering-3d`): METIS on the node graph against
METIS on the DOF graph and CHOLMOD's own analysis, on the k^3 cubes of METHOD-3D's table.

Each (k, ordering) is one run of build/release/bench/bench_ordering_3d (its header says
what it factors: the unit cube of k^3 hexahedra, bottom clamped, the top face's normal DOFs
ordered last), in its own process so that its peak resident memory is its own:

  nodes        METIS on the node graph, contact DOFs last (ordering='nd' of a solid body)
  metis        METIS on the DOF graph (CHOLMOD's cholmod_metis of the interior), contact last
  auto         CHOLMOD's own analysis, default strategy (AMD; METIS too when AMD fills much;
               the better kept), nothing last
  nodes-plain, metis-plain   nodes and metis with nothing last (to compare with auto)

Columns: the ordering's own time (part of analyze; 0 where CHOLMOD's analysis orders by
itself), analyze (ordering + symbolic), numeric factor [s], nnz(L), the entries CHOLMOD
stores (supernodal, with padding), flops, CHOLMOD's peak memory and the process's peak RSS
[MiB], the ordering CHOLMOD kept (given, AMD, METIS), and the cores kept busy by other
processes during the run (the whole machine's busy time less this run's). The memory check's
estimate (src/input/budget.f90: 13 N^1.4 factor entries, N the box's DOFs with the prescribed
ones, 8.25 bytes each) is set beside the node ordering's stored entries and CHOLMOD's peak.

Timing hygiene: before each run the script waits up to --quiet-wait s for fewer than 0.5
busy cores, then measures anyway; the fastest of --repeat runs is kept.

Usage: bench/bench_ordering_3d.py [--k 10,15,20,25,30,40] [--orderings nodes,metis,auto,...]
       [--bench build/release/bench/bench_ordering_3d] [--threads 1] [--repeat 1]
       [--csv results/bench_ordering_3d.csv]
"""
import argparse
import csv
import os
import re
import resource
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))  # the rc_* helpers
from bench import busy_cores, cpu_times  # noqa: E402
from rc_results import md_header, md_row  # noqa: E402

ORDERINGS = ("nodes", "metis", "auto", "nodes-plain", "metis-plain")
USED = {"1": "given", "2": "AMD", "3": "METIS"}
KEYS = ["k", "ordering", "last", "n", "ndof", "m", "t_order", "t_analyze", "t_factor", "lnz", "lsize", "flops",
        "mem_mib", "rss_mib", "used", "est_entries", "est_factor_mib", "est_body_mib", "wall", "busy_before",
        "busy_during"]


def wait_quiet(limit):
    deadline = time.monotonic() + limit
    while True:
        b = busy_cores(1.0)
        if b < 0.5 or time.monotonic() >= deadline:
            return round(b, 2)
        sys.stderr.write(f"  (machine busy: {b:.2f} cores; waiting)\n")
        time.sleep(3.0)


def run_once(bench, k, ordering, threads, quiet_wait):
    """One run: the bench's key=value line as a dict, with the wall time and the busy cores."""
    before = wait_quiet(quiet_wait)
    t0 = time.monotonic()
    tot0, idle0 = cpu_times()
    ch0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run([bench, str(k), ordering, str(threads)], capture_output=True, text=True)
    tot1, idle1 = cpu_times()
    ch1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    wall = time.monotonic() - t0
    if p.returncode != 0:
        raise RuntimeError(f"{bench} {k} {ordering} failed (exit {p.returncode}):\n{p.stdout[-1500:]}{p.stderr[-1500:]}")
    line = [ln for ln in p.stdout.splitlines() if ln.startswith("k=")][-1]
    row = dict(re.findall(r"(\w+)=\s*(\S+)", line))
    mine = (ch1.ru_utime + ch1.ru_stime) - (ch0.ru_utime + ch0.ru_stime)
    hz = os.sysconf("SC_CLK_TCK")
    row.update(wall=round(wall, 3), busy_before=before,
               busy_during=round(max(0.0, ((tot1 - tot0) - (idle1 - idle0)) / hz - mine) / max(wall, 1e-3), 2))
    for key in ("k", "n", "ndof", "m", "lnz", "lsize"):
        row[key] = int(row[key])
    for key in ("t_order", "t_analyze", "t_factor", "flops", "mem_mib", "rss_mib", "est_entries", "est_factor_mib",
                "est_body_mib"):
        row[key] = float(row[key])
    row["last"] = row["last"] == "T"
    row["used"] = USED.get(row["used"], row["used"])
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--k", default="10,15,20,25,30,40", help="cube sizes (cells per edge)")
    ap.add_argument("--orderings", default=",".join(ORDERINGS))
    ap.add_argument("--bench", default="build/release/bench/bench_ordering_3d")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--csv", default="results/bench_ordering_3d.csv")
    ap.add_argument("--quiet-wait", type=float, default=60.0)
    a = ap.parse_args()
    ks = [int(x) for x in a.k.split(",") if x]
    ords = [o for o in a.orderings.split(",") if o]
    for o in ords:
        if o not in ORDERINGS:
            ap.error(f"unknown ordering {o!r} (one of {', '.join(ORDERINGS)})")

    rows = []
    os.makedirs(os.path.dirname(a.csv) or ".", exist_ok=True)
    for k in ks:
        for o in ords:
            best = None
            for _ in range(max(1, a.repeat)):
                r = run_once(a.bench, k, o, a.threads, a.quiet_wait)
                if best is None or r["t_analyze"] + r["t_factor"] < best["t_analyze"] + best["t_factor"]:
                    best = r
            rows.append(best)
            sys.stderr.write(f"  {k}^3 {o:11s}: order {best['t_order']:.2f} analyze {best['t_analyze']:.2f} "
                             f"factor {best['t_factor']:.2f} s, nnz(L) {best['lnz']:.3e}, flops {best['flops']:.3e}, "
                             f"rss {best['rss_mib']:.0f} MiB, used {best['used']} (busy {best['busy_during']})\n")
            with open(a.csv, "w", newline="") as f:      # written as it goes: a long run keeps what it measured
                w = csv.DictWriter(f, fieldnames=KEYS, extrasaction="ignore")
                w.writeheader()
                w.writerows(rows)

    print(f"Orderings of the k^3 cube, {a.threads} thread(s), fastest of {a.repeat} (times in s):\n")
    print("\n".join(md_header(["cube", "DOFs", "m", "ordering", "order", "analyze", "factor", "nnz(L)", "flops",
                               "nnz(L) / nodes'", "flops / nodes'", "CHOLMOD MiB", "peak RSS MiB", "kept",
                               "busy"])))
    for k in ks:
        ref = next((r for r in rows if r["k"] == k and r["ordering"] == "nodes"), None)
        for i, r in enumerate(r for r in rows if r["k"] == k):
            print(md_row([f"{k}^3" if i == 0 else "", f"{r['n']:,}", r["m"],
                          r["ordering"], f"{r['t_order']:.2f}", f"{r['t_analyze']:.2f}", f"{r['t_factor']:.2f}",
                          f"{r['lnz']:.3e}", f"{r['flops']:.3e}",
                          f"{r['lnz'] / ref['lnz']:.3f}" if ref else "", f"{r['flops'] / ref['flops']:.3f}" if ref else "",
                          f"{r['mem_mib']:.0f}", f"{r['rss_mib']:.0f}", r["used"], r["busy_during"]]))
    print("\nThe memory check's estimate (budget.f90: 13 N^1.4 entries of 8.25 bytes) against the node "
          "ordering with the contact face last:\n")
    print("\n".join(md_header(["cube", "N (all DOFs)", "13 N^1.4", "nnz(L)", "stored", "13 N^1.4 / stored",
                               "estimate MiB", "CHOLMOD peak MiB", "estimate / peak", "body estimate MiB",
                               "peak RSS MiB"])))
    for r in (r for r in rows if r["ordering"] == "nodes"):
        print(md_row([f"{r['k']}^3", f"{r['ndof']:,}", f"{r['est_entries']:.3e}", f"{r['lnz']:.3e}",
                      f"{r['lsize']:.3e}", f"{r['est_entries'] / r['lsize']:.2f}", f"{r['est_factor_mib']:.0f}",
                      f"{r['mem_mib']:.0f}", f"{r['est_factor_mib'] / r['mem_mib']:.2f}",
                      f"{r['est_body_mib']:.0f}", f"{r['rss_mib']:.0f}"]))
    print(f"\nCSV: {a.csv}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
