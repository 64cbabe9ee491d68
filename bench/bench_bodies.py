#!/usr/bin/env python3
"""Many-body assemblies: benchmark of robin_contact on stacks and columns of equal blocks.

Every deck is made of unit squares (E = 2.1e11, nu = 0.3, Q1 plane strain) stacked in columns:
in each column the top block is loaded by a pressure of 1e6 on its top side, the bottom
block is clamped below, the others stand on a roller on their left side (held vertically only
by contact); block k's bottom is paired with block k+1's top (`&contact bodies=k,k+1,
groups='bottom','top' /`). Columns stand 1 apart, so they never touch.

Groups (each run a separate process of bin/robin_contact):
  chain    one stack of N = 2, 4, 8, 16, 32 blocks of 8x8 cells, for each Robin operator
           (harmonic, steklov, constant with --alpha) x acceleration (none, anderson), with
           stop='residual', tol=1e-8, max_outer=5000 (delta 0.5), and method='monolithic';
           err = |lam - lam_mono| / |lam_mono| against the monolithic run of the same deck
           (/contact/normal_force of the result files). OMP_NUM_THREADS=2.
  scale    N = 32, 128, 512 blocks of 64x64 cells as columns of 8 (the chain, and so the
           outer count, fixed while N grows): time per phase, peak and factor memory, for the
           default Robin solver (harmonic, anderson, residual stop, tol 1e-8) and monolithic.
           OMP_NUM_THREADS=2, fastest of --repeat runs.
  threads  64 blocks of 32x32 cells (8 columns of 8), default Robin, OMP_NUM_THREADS=1 and 2
           alternating back to back, --repeat runs each; per phase the fastest of each
           thread count, the speed-up and the serial share it implies (Amdahl with 2 threads:
           s = 2/speed-up - 1), the runs' CPU time, the load, and whether the contact
           forces of 1 and 2 threads are bitwise equal. --only threads runs this group alone.

Timing hygiene: the machine may be shared. busy_before = cores kept busy (by anything) during
the second before a run; the scale and threads runs wait up to --quiet-wait s for < 0.5 busy
core. busy_during = cores kept busy by other processes during the run. load1 = the 1-minute
load average at the start.

Writes the decks to --workdir (default results/bench_bodies/; result files are deleted after
reading), one CSV row per run to --csv (default results/bench_bodies.csv) and prints Markdown
tables. A benchmark: it reports, it asserts nothing.

Usage: bench/bench_bodies.py [--bin bin/robin_contact] [--quick] [--skip chain,scale,threads]
                             [--only chain,scale,threads] [--alpha 1e-12] [--repeat 3] [--quiet-wait 30]
--quick: chain N = 2, 4, 8; scale N = 8, 32 of 16x16; threads 16 bodies of 16x16; one run
each, no waiting (a smoke run of about 15 s). The full bench takes 11-15 minutes on the
shared 2-core machine, most of it waiting for a quiet machine (about 3 minutes of runs).
"""
import argparse
import glob
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))  # the rc_* helpers
from bench import command_text, fmt, table, timed_run, wait_quiet, write_csv  # noqa: E402
from rc_results import read_lam, rel_err  # noqa: E402
from rc_run import result_fields, solver_env, time_fields  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PHASES = ("assemble", "factor", "condense", "iterate", "output", "total")
COLUMNS = ["group", "n_bodies", "columns", "per_column", "nx", "ny", "dofs", "pairs", "m", "method", "operator",
           "alpha", "acceleration", "stop", "tol", "max_outer", "threads", "status", "exit", "outer", "inner",
           "residual"] + [p + "_s" for p in PHASES] + \
          ["peak_mb", "factor_mb", "err", "repeats", "total_s_all", "process_wall_s", "cpu_s", "load1", "busy_before",
           "busy_during", "cmdline"]
OPERATORS = ("harmonic", "steklov", "constant")
ACCELERATIONS = ("none", "anderson")


def assembly(ncol, per, nx, ny):
    """Deck lines of ncol columns of per unit blocks of nx x ny cells. Column c holds the
    bodies c*per+1 (top, loaded) ... c*per+per (bottom, clamped) at x0 = 2c; every other
    block stands on a roller on its left side; the pairs join each block's bottom to the top
    of the block below."""
    lines, pairs = [], []
    for c in range(ncol):
        for k in range(1, per + 1):
            i = c * per + k
            lines.append(f"&body id={i}, x0={2.0 * c}, y0={float(per - k)}, width=1.0, height=1.0, "
                         f"nx={nx}, ny={ny}" + (", bottom='clamped'" if k == per else ", left='roller'") + " /")
        lines.append(f"&traction body={c * per + 1}, side='top', t0=0.0, -1.0e6 /")
        pairs += [f"&contact bodies={c * per + k},{c * per + k + 1}, groups='bottom','top' /" for k in range(1, per)]
    return lines + pairs


class Runner:
    def __init__(self, binary, workdir, quiet_wait, timeout):
        self.binary = binary
        self.workdir = workdir
        self.quiet_wait = quiet_wait
        self.timeout = timeout
        self.count = 0
        self.rows = []

    def deck(self, ncol, per, nx, ny):
        """The deck file of an assembly (written once into the work folder)."""
        path = os.path.join(self.workdir, f"columns{ncol}x{per}_{nx}x{ny}.nml")
        if not os.path.exists(path):
            tmp = path + ".tmp"
            with open(tmp, "w") as f:
                f.write(f"! bench_bodies: {ncol} column(s) of {per} blocks of {nx}x{ny} Q1 cells\n")
                f.write("\n".join(assembly(ncol, per, nx, ny)) + "\n")
            os.replace(tmp, path)
        return path

    def new_row(self, group, ncol, per, nx, ny, method, operator="", alpha="", acceleration="", stop="",
                tol="", max_outer=""):
        row = {k: "" for k in COLUMNS}
        n = ncol * per
        row.update(group=group, n_bodies=n, columns=ncol, per_column=per, nx=nx, ny=ny,
                   dofs=n * 2 * (nx + 1) * (ny + 1), pairs=ncol * (per - 1), method=method, operator=operator,
                   alpha=alpha, acceleration=acceleration, stop=stop, tol=tol, max_outer=max_outer)
        return row

    def solver_group(self, row):
        if row["method"] == "monolithic":
            return "&solver method='monolithic' /"
        s = "&solver method='robin'"
        if row["operator"]:
            s += f", robin_operator='{row['operator']}'"
        if row["alpha"] != "":
            s += f", alpha={row['alpha']:g}"
        if row["acceleration"]:
            s += f", acceleration='{row['acceleration']}'"
        if row["stop"]:
            s += f", stop='{row['stop']}'"
        if row["tol"] != "":
            s += f", tol={row['tol']:g}"
        if row["max_outer"] != "":
            s += f", max_outer={row['max_outer']}"
        return s + " /"

    def run(self, row, threads=2, repeats=1, wait=False, ref=None):
        """Run the case of row `repeats` times with OMP_NUM_THREADS=threads; fill row with the
        fastest run (least total_s) and err against the lam of ref (a row run before, or None).
        Returns the row (also appended to self.rows)."""
        row["threads"] = threads
        best, best_lam, totals = None, None, []
        for _ in range(max(1, repeats)):
            trial, lam = self._once(dict(row), threads, wait)
            if trial["status"] not in ("error", "timeout"):
                totals.append(trial["total_s"])
                if best is None or best["status"] in ("error", "timeout") or trial["total_s"] < best["total_s"]:
                    best, best_lam = trial, lam
            elif best is None:
                best = trial
        row.update(best)
        row["repeats"] = max(1, repeats)
        row["total_s_all"] = ";".join(f"{t:g}" for t in totals)
        row["_lam"] = best_lam
        if ref is not None and best_lam is not None and ref.get("_lam") is not None:
            e = rel_err(best_lam, ref["_lam"])
            row["err"] = float("nan") if e is None else e
        self.rows.append(row)
        sys.stderr.write(f"  {row['group']:7s} N={row['n_bodies']:<4} {row['nx']}x{row['ny']} {row['method']:10s} "
                         f"{row['operator'] or '-':8s} {row['acceleration'] or '-':8s} thr={threads}: {row['status']} "
                         f"outer={row['outer']} inner={row['inner']} total={row['total_s_all']} s err={row['err']} "
                         f"(busy before {row['busy_before']}, during {row['busy_during']})\n")
        sys.stderr.flush()
        return row

    def _once(self, row, threads, wait):
        self.count += 1
        h5 = os.path.join(self.workdir, f"run{self.count:04d}.h5")
        deck = self.deck(row["columns"], row["per_column"], row["nx"], row["ny"])
        args = [self.binary, deck, self.solver_group(row), f"&output file='{h5}', progress_lines=0 /"]
        env = solver_env(threads)
        env.pop("OMP_THREAD_LIMIT", None)
        row["load1"] = round(os.getloadavg()[0], 2)
        row["busy_before"] = wait_quiet(wait, self.quiet_wait)
        row["cmdline"] = command_text(args[:-1], threads)
        rc, out, err, wall, cpu, row["busy_during"], timed_out = timed_run(args, env, self.timeout)
        row["cpu_s"] = round(cpu, 3)
        if timed_out:
            row["status"] = "timeout"
        row["process_wall_s"] = round(wall, 3)
        row["exit"] = rc
        lam = None
        r, t = result_fields(out), time_fields(out)
        if row["status"] != "timeout":
            if r is None or t is None:
                sys.stderr.write(f"bench_bodies: no result/time line from: {row['cmdline']} (exit {rc})\n")
                sys.stderr.write(out[-1500:] + err[-1500:] + "\n")
                row["status"] = "error"
            else:
                row["status"] = r["status"]
                row["outer"], row["inner"], row["m"] = int(r["outer"]), int(r["inner"]), int(r["m"])
                row["residual"] = float(r["residual"])
                for k in PHASES:
                    row[k + "_s"] = float(t[k])
                row["peak_mb"] = float(t["peak_mb"])
                row["factor_mb"] = float(t["factor_mb"])
                if os.path.exists(h5):
                    lam = read_lam(h5)
        # the result file, its checkpoint and its XDMF companions (one per body and pair too)
        stem = os.path.splitext(h5)[0]
        for fn in [h5, h5 + ".ckpt.h5", stem + ".xdmf"] + glob.glob(stem + "_*.xdmf"):
            if os.path.exists(fn):
                os.remove(fn)
        return row, lam



def ok(r):
    return r["status"] not in ("error", "timeout", "")


def cell_oi(r):
    if not ok(r):
        return r["status"]
    s = f"{r['outer']}/{r['inner']}"
    return s if r["status"] == "converged" else f"{s} ({r['status']})"


def threads_table(thr, repeat):
    """The threads group's table: per phase the fastest 1- and 2-thread time over the repeats,
    the speed-up and the serial share s = 2/speed-up - 1 it implies (Amdahl, 2 threads; 0 for
    a perfectly parallel phase, 1 for a serial one), then the CPU time, load and forces."""
    one, two = thr[1], thr[2]
    o = one[0]
    lines = [f"\n## Threads: {o['n_bodies']} blocks of {o['nx']}x{o['ny']} ({o['columns']} columns of 8), "
             f"default Robin, OMP_NUM_THREADS=1 and 2 alternating, {repeat} runs each; per phase the "
             f"fastest of the runs of each thread count\n"]
    out = []
    for k in PHASES:
        t1 = min(r[k + "_s"] for r in one)
        t2 = min(r[k + "_s"] for r in two)
        sp = t1 / t2 if t2 > 0 else float("nan")
        out.append([k, fmt(t1, ".3f"), fmt(t2, ".3f"), fmt(sp, ".2f"), fmt(2.0 / sp - 1.0, ".2f") if t2 > 0 else ""])
    out.append(["CPU time of the run (user + sys) [s]", fmt(min(r["cpu_s"] for r in one), ".3f"),
                fmt(min(r["cpu_s"] for r in two), ".3f"), "", ""])
    out.append(["outer/inner", cell_oi(one[0]), cell_oi(two[0]), "", ""])
    out.append(["busy (other processes, each run)", " ".join(str(r["busy_during"]) for r in one),
                " ".join(str(r["busy_during"]) for r in two), "", ""])
    out.append(["load average (1 min, each run)", " ".join(str(r["load1"]) for r in one),
                " ".join(str(r["load1"]) for r in two), "", ""])
    out.append(["all totals [s]", " ".join(f"{r['total_s']:g}" for r in one),
                " ".join(f"{r['total_s']:g}" for r in two), "", ""])
    lines.append(table(["phase", "1 thread [s]", "2 threads [s]", "speed-up", "serial share (2/speed-up - 1)"],
                       out))
    if max(r["busy_during"] for r in one + two) > 0.5:
        lines.append("\nother processes kept more than 0.5 cores busy during a run: a second thread waits "
                     "for a core, and the speed-ups and serial shares above are the machine's, not the code's")
    if "equal" in thr:
        lines.append("\ncontact forces of all runs, 1 and 2 threads: " +
                     ("bitwise equal" if thr["equal"] else f"differ (largest relative difference {thr['diff']:.1e})"))
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"))
    ap.add_argument("--quick", action="store_true", help="small sizes, one run each, no waiting")
    ap.add_argument("--skip", default="", help="comma list of groups to skip: chain,scale,threads")
    ap.add_argument("--only", default="", help="comma list of the groups to run (the others skipped)")
    ap.add_argument("--chain-n", default="2,4,8,16,32", help="stack heights of the chain group")
    ap.add_argument("--chain-cells", type=int, default=8, help="nx = ny of the chain group's blocks")
    ap.add_argument("--alpha", type=float, default=1.0e-12,
                    help="alpha of robin_operator='constant' [length/stress] (default 1e-12)")
    ap.add_argument("--scale-n", default="32,128,512", help="numbers of blocks of the scale group (multiples of 8)")
    ap.add_argument("--scale-cells", type=int, default=64, help="nx = ny of the scale group's blocks")
    ap.add_argument("--thread-columns", type=int, default=8, help="columns of 8 blocks of the threads group")
    ap.add_argument("--thread-cells", type=int, default=32, help="nx = ny of the threads group's blocks")
    ap.add_argument("--repeat", type=int, default=3, help="runs per case of the scale and threads groups")
    ap.add_argument("--quiet-wait", type=float, default=30.0,
                    help="seconds a scale or threads run waits for a quiet machine (< 0.5 busy core)")
    ap.add_argument("--max-run-s", type=float, default=1800.0, help="a run is killed after this many seconds")
    ap.add_argument("--workdir", default=os.path.join(ROOT, "results", "bench_bodies"))
    ap.add_argument("--csv", default=os.path.join(ROOT, "results", "bench_bodies.csv"))
    a = ap.parse_args()
    if a.quick:
        a.chain_n, a.scale_n, a.scale_cells = "2,4,8", "8,32", 16
        a.thread_columns, a.thread_cells, a.repeat, a.quiet_wait = 2, 16, 1, 0.0
    skip = set(s for s in a.skip.split(",") if s)
    if a.only:
        skip |= {"chain", "scale", "threads"} - set(s for s in a.only.split(",") if s)
    if not os.access(a.bin, os.X_OK):
        raise SystemExit(f"bench_bodies: no executable {a.bin} (run make first)")
    chain_n = [int(v) for v in a.chain_n.split(",") if v]
    scale_n = [int(v) for v in a.scale_n.split(",") if v]
    if any(n < 2 for n in chain_n) or any(n < 8 or n % 8 for n in scale_n):
        raise SystemExit("bench_bodies: --chain-n needs N >= 2, --scale-n multiples of 8")
    os.makedirs(a.workdir, exist_ok=True)
    R = Runner(os.path.abspath(a.bin), os.path.abspath(a.workdir), a.quiet_wait, a.max_run_s)
    sys.stderr.write(f"bench_bodies: {os.cpu_count()} cores, decks in {a.workdir}\n")

    # ---- chain: outer iterations against the stack height -------------------------------------
    chain = {}
    if "chain" not in skip:
        c = a.chain_cells
        for n in chain_n:
            mono = R.run(R.new_row("chain", 1, n, c, c, "monolithic"))
            chain[(n, "monolithic", "")] = mono
            for op in OPERATORS:
                for acc in ACCELERATIONS:
                    row = R.new_row("chain", 1, n, c, c, "robin", op, a.alpha if op == "constant" else "", acc,
                                    "residual", 1e-8, 5000)
                    chain[(n, op, acc)] = R.run(row, ref=mono)

    # ---- scale: N blocks as columns of 8 ------------------------------------------------------
    scale = []
    if "scale" not in skip:
        c = a.scale_cells
        for n in scale_n:
            mono = R.run(R.new_row("scale", n // 8, 8, c, c, "monolithic"), repeats=a.repeat, wait=True)
            rob = R.run(R.new_row("scale", n // 8, 8, c, c, "robin"), repeats=a.repeat, wait=True, ref=mono)
            scale += [rob, mono]

    # ---- threads: 1 and 2 OpenMP threads back to back ------------------------------------------
    thr = {}
    if "threads" not in skip:
        c, ncol = a.thread_cells, a.thread_columns
        runs = {1: [], 2: []}
        for _ in range(a.repeat):
            for t in (1, 2):
                runs[t].append(R.run(R.new_row("threads", ncol, 8, c, c, "robin"), threads=t, wait=True))
        for t in (1, 2):
            good = [r for r in runs[t] if ok(r)]
            if good:
                thr[t] = good
        if len(thr) == 2:
            lams = [r["_lam"] for t in (1, 2) for r in thr[t] if r.get("_lam") is not None]
            thr["equal"] = len(lams) == 2 * len(thr[1]) and all(np.array_equal(lams[0], x) for x in lams[1:])
            thr["diff"] = max(rel_err(x, lams[0]) or 0.0 for x in lams) if lams else float("nan")

    for r in R.rows:
        r.pop("_lam", None)
    write_csv(a.csv, R.rows, COLUMNS)

    # ---- tables -------------------------------------------------------------------------------
    print("# robin_contact: many-body assemblies (bench/bench_bodies.py)\n")
    if chain:
        c = a.chain_cells
        print(f"## Outer iterations against N: one stack of N blocks of {c}x{c} Q1 cells, stop='residual', "
              f"tol=1e-8, max_outer=5000, delta 0.5, constant alpha={a.alpha:g}, OMP_NUM_THREADS=2\n")
        head = ["operator", "acceleration"] + [f"N={n}" for n in chain_n]
        labels = [(op, acc) for op in OPERATORS for acc in ACCELERATIONS]
        m_row = ["(m = contact nodes)", ""] + [str(chain[(n, "monolithic", "")]["m"]) for n in chain_n]
        print("### outer / inner products (status when not converged)\n")
        print(table(head, [m_row] + [[op, acc] + [cell_oi(chain[(n, op, acc)]) for n in chain_n]
                                     for op, acc in labels]
                    + [["monolithic", ""] + [cell_oi(chain[(n, "monolithic", "")]) for n in chain_n]]))
        print("\n### wall time [s] (the `time:` line's total)\n")
        print(table(head, [[op, acc] + [fmt(chain[(n, op, acc)]["total_s"], ".2f") for n in chain_n]
                           for op, acc in labels]
                    + [["monolithic", ""] + [fmt(chain[(n, "monolithic", "")]["total_s"], ".2f") for n in chain_n]]))
        print("\n### error |lam - lam_mono| / |lam_mono|\n")
        print(table(head, [[op, acc] + [fmt(chain[(n, op, acc)]["err"], ".1e") for n in chain_n]
                           for op, acc in labels]))
    if scale:
        c = a.scale_cells
        print(f"\n## Growth in N: N blocks of {c}x{c} Q1 cells as columns of 8, OMP_NUM_THREADS=2, "
              f"fastest of {a.repeat}; Robin = the defaults (harmonic, anderson, stop residual, tol 1e-8)\n")
        out = []
        for r in scale:
            prev = [q for q in scale if q["method"] == r["method"] and q["n_bodies"] < r["n_bodies"]]
            p = prev[-1] if prev else None
            grow = ""
            if p is not None and ok(r) and ok(p):
                grow = (f"x{r['n_bodies'] / p['n_bodies']:.0f}: total x{r['total_s'] / p['total_s']:.2f}, "
                        f"peak x{r['peak_mb'] / p['peak_mb']:.2f}")
            out.append([r["n_bodies"], f"{r['dofs']:,}", r["m"], r["method"], cell_oi(r)] +
                       [fmt(r[k + "_s"], ".2f") for k in PHASES] +
                       [fmt(r["iterate_s"] / r["factor_s"], ".2f") if ok(r) and r["factor_s"] > 0 else "",
                        fmt(r["peak_mb"], ".0f"), fmt(r["factor_mb"], ".0f"),
                        fmt(1e3 * r["total_s"] / r["n_bodies"], ".1f") if ok(r) else "",
                        fmt(r["peak_mb"] / r["n_bodies"], ".2f") if ok(r) else "", grow,
                        fmt(r["err"], ".1e"), r["busy_during"]])
        print(table(["N", "DOFs", "m", "method", "outer/inner"] + list(PHASES) +
                    ["iterate/factor", "peak MB", "factor MB", "ms per body", "peak MB per body",
                     "growth from the previous N", "err vs mono", "busy"], out))
    if 1 in thr and 2 in thr:
        print(threads_table(thr, a.repeat))
    print(f"\nwrote {a.csv} ({len(R.rows)} rows, {R.count} runs)")


if __name__ == "__main__":
    main()
