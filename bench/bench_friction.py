#!/usr/bin/env python3
"""Friction: benchmark of robin_contact on the paper's scene with and without friction.

The paper's scene (inputs/default.nml) at nx x ny cells per body (128x64, 256x128, 512x256,
1024x512; `&body id=1, nx=.., ny=.. /` and the same for body 2), each mesh with
  none      frictionless (the deck as it is)
  coulomb   `&contact friction='coulomb', mu=0.3 /`
  tresca    `&contact friction='tresca', slip_bound=5e5 /` (0.5 MPa: about mu times the mean
            pressure, so that part of the line sticks and part slips)
and for each of these
  monolithic  `&solver method='monolithic' /`
  deck        the deck's own Robin settings (steklov, delta 0.95, increment stop, tol 1e-8)
  harmonic    `&solver robin_operator='harmonic', delta=0.5 /`
  steklov     `&solver robin_operator='steklov', delta=0.5 /`
Each run is a separate process, OMP_NUM_THREADS=2, the fastest of --repeat runs.
Reported per run: the phases of the `time:` line, outer and inner counts, peak and factor
memory, the stick and slip counts of the `contact:` line, and the error against the
monolithic run of the same mesh and friction:
  err_n = |lam_n - lam_n,mono| / |lam_n,mono|   (/contact/normal_force)
  err_t = |lam_t - lam_t,mono| / |lam_t,mono|   (/contact/tangential_force)
and, per mesh and solver, the friction run against the frictionless one: total time ratio
and outer counts. A Robin setting that does not converge on a mesh is not run on the larger
meshes (listed as skipped): its runs would only hit max_outer, slowly.

cpu_s is the process's CPU time (user + system, all threads): on a machine shared with other
work it is a steadier measure of the work done than the wall times of the `time:` line.

Timing hygiene: the machine may be shared. busy_before = cores kept busy (by anything) during
the second before a run (runs from 512x256 on wait up to --quiet-wait s for < 0.5 busy core);
busy_during = cores kept busy by other processes during the run; load1 = the 1-minute load
average at the start.

Writes the result files to --workdir (default results/bench_friction/; deleted after
reading), one CSV row per run to --csv (default results/bench_friction.csv), and prints
Markdown tables. A benchmark: it reports, it asserts nothing.

--pairs N: instead, N alternating pairs of runs of the solver's default (harmonic, delta 0.5)
without friction and with Coulomb mu = 0.3 at one size (--sizes, default 1024x512), each run
after waiting for a quiet machine: per pair the two runs' phases, the wall ratio (the `time:`
line's total) and the CPU ratio, then the medians and the fastest against the fastest. This is
the measure of "friction within 1.3x of the frictionless solve".

Usage: bench/bench_friction.py [--bin bin/robin_contact] [--quick] [--sizes 128x64,256x128]
                               [--repeat 1] [--quiet-wait 20] [--timeout 900] [--pairs N]
--quick: 64x32 and 128x64, one run each, no waiting (under a minute). The full bench: about
15-25 minutes on the shared 2-core machine with --repeat 2 (`make bench-friction`).
"""
import argparse
import os
import sys
import time

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))  # the rc_* helpers
from bench import command_text, fmt, table, timed_run, wait_quiet, write_csv  # noqa: E402
from rc_results import rel_err  # noqa: E402
from rc_run import line_fields, result_fields, solver_env, time_fields  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DECK = os.path.join(ROOT, "inputs", "default.nml")
PHASES = ("assemble", "factor", "condense", "iterate", "output", "total")
FRICTIONS = {"none": "", "coulomb": "&contact friction='coulomb', mu=0.3 /",
             "tresca": "&contact friction='tresca', slip_bound=5e5 /"}
SOLVERS = {"monolithic": "&solver method='monolithic' /", "deck": "",
           "harmonic": "&solver robin_operator='harmonic', delta=0.5 /",
           "steklov": "&solver robin_operator='steklov', delta=0.5 /"}
COLUMNS = ["nx", "ny", "dofs", "m", "friction", "solver", "status", "exit", "outer", "inner", "residual"] + \
          [p + "_s" for p in PHASES] + \
          ["cpu_s", "peak_mb", "factor_mb", "stick", "slip", "tangential_force_sum", "normal_force_sum", "err_n", "err_t",
           "repeats", "total_s_all", "process_wall_s", "load1", "busy_before", "busy_during", "cmdline"]


class Runner:
    def __init__(self, binary, workdir, quiet_wait, timeout):
        self.binary = binary
        self.workdir = workdir
        self.quiet_wait = quiet_wait
        self.timeout = timeout
        self.count = 0


    def run(self, row, repeats, wait):
        """Run the case of row `repeats` times; fill row with the fastest (least total_s) and
        return its (normal, tangential) forces (None when the run gave no result)."""
        best, best_f, totals = None, None, []
        for _ in range(max(1, repeats)):
            trial, forces = self._once(dict(row), wait)
            ok = trial["status"] not in ("error", "timeout")
            if ok:
                totals.append(trial["total_s"])
            if best is None or (ok and (best["status"] in ("error", "timeout") or trial["total_s"] < best["total_s"])):
                best, best_f = trial, forces
        row.update(best)
        row["repeats"] = max(1, repeats)
        row["total_s_all"] = ";".join(f"{t:g}" for t in totals)
        return best_f

    def _once(self, row, wait):
        self.count += 1
        h5 = os.path.join(self.workdir, f"run{self.count:04d}.h5")
        args = [self.binary, DECK, f"&body id=1, nx={row['nx']}, ny={row['ny']} /",
                f"&body id=2, nx={row['nx']}, ny={row['ny']} /"]
        args += [g for g in (FRICTIONS[row["friction"]], SOLVERS[row["solver"]]) if g]
        args.append(f"&output file='{h5}', progress_lines=0 /")
        env = solver_env(2)
        row["load1"] = round(os.getloadavg()[0], 2)
        row["busy_before"] = wait_quiet(wait, self.quiet_wait)
        row["cmdline"] = command_text(args[:-1], 2)
        rc, out, err, wall, mine, row["busy_during"], timed_out = timed_run(args, env, self.timeout)
        if timed_out:
            row["status"] = "timeout"
        row["cpu_s"] = round(mine, 3)
        row["process_wall_s"] = round(wall, 3)
        row["exit"] = rc
        forces = None
        r, t, c = result_fields(out), time_fields(out), line_fields(out, "contact")
        if row.get("status") != "timeout":
            if r is None or t is None:
                sys.stderr.write(f"bench_friction: no result/time line from: {row['cmdline']} (exit {rc})\n")
                sys.stderr.write(out[-1500:] + err[-1500:] + "\n")
                row["status"] = "error"
            else:
                row.update(status=r["status"], outer=int(r["outer"]), inner=int(r["inner"]), m=int(r["m"]),
                           residual=float(r["residual"]))
                for ph in PHASES:
                    row[ph + "_s"] = float(t[ph])
                row["peak_mb"], row["factor_mb"] = float(t["peak_mb"]), float(t["factor_mb"])
                if c:
                    row["normal_force_sum"] = float(c.get("normal_force_sum", "nan"))
                    row["tangential_force_sum"] = float(c["tangential_force_sum"]) if "tangential_force_sum" in c else ""
                    row["stick"] = int(c["stick"]) if "stick" in c else ""
                    row["slip"] = int(c["slip"]) if "slip" in c else ""
                if os.path.isfile(h5):
                    with h5py.File(h5, "r") as f:
                        g = f["contact"]
                        forces = (np.array(g["normal_force"], dtype=float),
                                  np.array(g["tangential_force"], dtype=float) if "tangential_force" in g else None)
        for name in os.listdir(self.workdir):
            if name.startswith(f"run{self.count:04d}"):
                os.remove(os.path.join(self.workdir, name))
        return row, forces


def err_of(forces, ref, k):
    if forces is None or ref is None or forces[k] is None or ref[k] is None:
        return ""
    e = rel_err(forces[k], ref[k])
    return float("nan") if e is None else e


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"))
    ap.add_argument("--quick", action="store_true", help="64x32 and 128x64, one run each, no waiting")
    ap.add_argument("--sizes", default=None, help="comma-separated NXxNY cells per body")
    ap.add_argument("--repeat", type=int, default=1, help="runs per case from 512x256 on (fastest kept)")
    ap.add_argument("--quiet-wait", type=float, default=20.0)
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds per run")
    ap.add_argument("--workdir", default=os.path.join(ROOT, "results", "bench_friction"))
    ap.add_argument("--csv", default=os.path.join(ROOT, "results", "bench_friction.csv"))
    ap.add_argument("--pairs", type=int, default=0, help="alternating frictionless / Coulomb pairs at one size")
    a = ap.parse_args()
    if a.pairs > 0:
        return pairs(a)
    sizes = a.sizes or ("64x32,128x64" if a.quick else "128x64,256x128,512x256,1024x512")
    sizes = [tuple(int(v) for v in s.split("x")) for s in sizes.split(",")]
    os.makedirs(a.workdir, exist_ok=True)
    runner = Runner(os.path.abspath(a.bin), a.workdir, 0.0 if a.quick else a.quiet_wait, a.timeout)
    rows, failed = [], set()
    t_start = time.monotonic()
    for nx, ny in sizes:
        big = nx * ny >= 512 * 256 and not a.quick
        for fr in FRICTIONS:
            ref = None
            for sv in SOLVERS:
                row = {k: "" for k in COLUMNS}
                row.update(nx=nx, ny=ny, dofs=2 * (nx + 1) * (ny + 1), friction=fr, solver=sv)
                if (fr, sv) in failed:
                    row["status"] = "skipped"
                    rows.append(row)
                    continue
                forces = runner.run(row, a.repeat if big else 1, big)
                if sv == "monolithic":
                    ref = forces
                row["err_n"], row["err_t"] = err_of(forces, ref, 0), err_of(forces, ref, 1)
                if row["status"] != "converged":
                    failed.add((fr, sv))
                rows.append(row)
                sys.stderr.write(f"  {nx}x{ny} {fr:8s} {sv:10s}: {row['status']} outer={row['outer']} "
                                 f"inner={row['inner']} total={row['total_s_all']} s err_n={fmt(row['err_n'], '.1e')} "
                                 f"err_t={fmt(row['err_t'], '.1e')} (busy before {row['busy_before']}, "
                                 f"during {row['busy_during']})\n")
                sys.stderr.flush()
    write_csv(a.csv, rows, COLUMNS)

    def ph(r):
        return " / ".join(fmt(r[p + "_s"], ".3g") for p in ("factor", "condense", "iterate")) if r["total_s"] != "" else ""

    print(f"\nbench_friction: {len(rows)} rows, {time.monotonic() - t_start:.0f} s; {os.path.relpath(a.csv, ROOT)}\n")
    print("### Runs\n")
    print(table(["mesh / body", "friction", "solver", "status", "outer/inner", "f / c / i [s]", "total [s]", "cpu [s]",
                 "peak MB",
                 "stick/slip", "err_n", "err_t", "busy"],
                [[f"{r['nx']}x{r['ny']}", r["friction"], r["solver"], r["status"],
                  f"{r['outer']}/{r['inner']}" if r["outer"] != "" else "", ph(r), fmt(r["total_s"], ".3g"),
                  fmt(r["cpu_s"], ".3g"), fmt(r["peak_mb"], ".0f"), f"{r['stick']}/{r['slip']}" if r["stick"] != "" else "",
                  fmt(r["err_n"], ".1e"), fmt(r["err_t"], ".1e"), fmt(r["busy_during"], ".2f")] for r in rows]))
    print("\n### Friction against frictionless (same mesh, same solver)\n")
    key = {(r["nx"], r["ny"], r["friction"], r["solver"]): r for r in rows}
    out = []
    for nx, ny in sizes:
        for fr in ("coulomb", "tresca"):
            for sv in SOLVERS:
                r0, r1 = key[(nx, ny, "none", sv)], key[(nx, ny, fr, sv)]
                if r0["total_s"] == "" or r1["total_s"] == "":
                    out.append([f"{nx}x{ny}", fr, sv, r0["status"], r1["status"], "", "", "", "", "", "", ""])
                    continue
                ratio = r1["total_s"] / r0["total_s"] if r0["total_s"] > 0 else float("nan")
                extra = {p: r1[p + "_s"] - r0[p + "_s"] for p in ("factor", "condense", "iterate")}
                out.append([f"{nx}x{ny}", fr, sv, f"{r0['outer']}/{r0['inner']}", f"{r1['outer']}/{r1['inner']}",
                            f"{fmt(r0['total_s'], '.3g')} -> {fmt(r1['total_s'], '.3g')}", fmt(ratio, ".2f"),
                            fmt(r1["cpu_s"] / r0["cpu_s"] if r0["cpu_s"] else float("nan"), ".2f"),
                            " / ".join(f"{extra[p]:+.3g}" for p in ("factor", "condense", "iterate")),
                            f"{r0['m']} -> {r1['m']}", fmt(r1["peak_mb"] - r0["peak_mb"], "+.0f"),
                            r1["status"]])
    print(table(["mesh / body", "friction", "solver", "outer/inner none", "outer/inner friction", "total [s]",
                 "ratio", "cpu ratio", "extra f / c / i [s]", "rows m", "extra peak MB", "status"], out))
    return 0


def pairs(a):
    """--pairs: alternating frictionless and Coulomb runs of the default solver at one size."""
    nx, ny = (int(v) for v in (a.sizes or "1024x512").split(",")[0].split("x"))
    os.makedirs(a.workdir, exist_ok=True)
    runner = Runner(os.path.abspath(a.bin), a.workdir, a.quiet_wait, a.timeout)
    rows, out = [], []
    for k in range(a.pairs):
        pair = {}
        for fr in ("none", "coulomb"):
            row = {c: "" for c in COLUMNS}
            row.update(nx=nx, ny=ny, dofs=2 * (nx + 1) * (ny + 1), friction=fr, solver="harmonic")
            runner.run(row, 1, True)
            rows.append(row)
            pair[fr] = row
            sys.stderr.write(f"  pair {k + 1} {fr:8s}: {row['status']} outer={row['outer']} inner={row['inner']} "
                             f"total={row['total_s']} cpu={row['cpu_s']} (busy before {row['busy_before']}, "
                             f"during {row['busy_during']}, load {row['load1']})\n")
            sys.stderr.flush()
        r0, r1 = pair["none"], pair["coulomb"]
        if r0["total_s"] == "" or r1["total_s"] == "":
            continue
        out.append((r0, r1, r1["total_s"] / r0["total_s"], r1["cpu_s"] / r0["cpu_s"]))
    write_csv(a.csv, rows, COLUMNS)

    def phases(r):
        return " / ".join(fmt(r[p + "_s"], ".3g") for p in ("factor", "condense", "iterate", "output"))

    print(f"\n### Coulomb mu = 0.3 against frictionless, {nx}x{ny} per body, harmonic delta 0.5, "
          f"{len(out)} pairs\n")
    print(table(["pair", "outer/inner none", "outer/inner coulomb", "f / c / i / o none [s]", "f / c / i / o coulomb [s]",
                 "total none / coulomb [s]", "wall ratio", "CPU ratio", "busy during"],
                [[str(k + 1), f"{r0['outer']}/{r0['inner']}", f"{r1['outer']}/{r1['inner']}", phases(r0), phases(r1),
                  f"{fmt(r0['total_s'], '.3g')} / {fmt(r1['total_s'], '.3g')}", f"{w:.2f}", f"{c:.2f}",
                  f"{fmt(r0['busy_during'], '.2f')} / {fmt(r1['busy_during'], '.2f')}"]
                 for k, (r0, r1, w, c) in enumerate(out)]))
    if out:
        fastest = min(r[1]["total_s"] for r in out) / min(r[0]["total_s"] for r in out)
        print(f"\nmedian wall ratio {float(np.median([r[2] for r in out])):.3f}, median CPU ratio "
              f"{float(np.median([r[3] for r in out])):.3f}, fastest against fastest {fastest:.3f}; "
              f"{os.path.relpath(a.csv, ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
