#!/usr/bin/env python3
"""Plots of bench/bench.py's results.

Usage: bench/plot_bench.py [results/bench.csv] [--out-dir DIR]
Writes (next to the csv unless --out-dir):
  bench_work_precision.png  time against error, log-log, one curve per method:
      left:  tolerance sweep (one mesh): error of lam against the monolithic solution vs
             the time of the contact iteration (iterate phase) and, dashed, vs the whole
             solve (factor + condense + iterate);
      right: mesh ladder: discretisation error against the finest mesh of the contact
             pressure away from the contact-zone edge (solid) and of the total contact force
             (dotted) vs total run time; CHOLMOD with METIS, and robin/steklov with AMD.
  bench_phases.png  stacked bars of the time per phase, one panel per mesh, one bar per
      method / factorization (ladder and ordering rows, 2 threads).
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))  # the rc_* helpers
from rc_figures import save_figure  # noqa: E402

PHASES = ["assemble_s", "factor_s", "condense_s", "iterate_s", "output_s"]
COLORS = {"monolithic": "tab:gray", "robin-steklov": "tab:blue", "robin-harmonic": "tab:orange"}


def num(x):
    try:
        v = float(x)
        return v if math.isfinite(v) else None
    except (TypeError, ValueError):
        return None


def load(path):
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    for r in rows:
        r["level"] = int(r["level"])
    return rows


def work_precision(rows, out):
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5.2))
    sweep = [r for r in rows if r["group"] == "sweep" and r["status"] != "error"]
    styles = {"residual": "o", "increment": "s", "": "^"}
    curves = {}
    for r in sweep:
        curves.setdefault((r["label"], r["stop"]), []).append(r)
    for (label, stop), rr in sorted(curves.items()):
        pts = [(num(r["alg_err"]), num(r["iterate_s"]), num(r["solve_s"]), r["status"]) for r in rr]
        pts = [p for p in pts if p[0] and p[1] is not None]
        if not pts:
            continue
        name = label + (f", stop={stop}" if stop else ", monolithic_rtol")
        c = COLORS.get(label, "k")
        ls = "-" if stop != "increment" else "--"
        ax1.loglog([p[0] for p in pts], [max(p[1], 1e-3) for p in pts], ls, marker=styles[stop], color=c,
                   label=name + " (iterate)")
        bad = [p for p in pts if p[3] != "converged"]
        if bad:
            ax1.loglog([p[0] for p in bad], [max(p[1], 1e-3) for p in bad], "x", color="red", ms=10)
    if sweep:
        r0 = sweep[0]
        solve = [num(r["solve_s"]) for r in sweep if num(r["solve_s"])]
        if solve:
            ax1.axhline(min(solve), color="k", lw=0.8, ls=":")
            ax1.text(ax1.get_xlim()[0] * 1.5, min(solve) * 1.08, "fastest factor+condense+iterate", fontsize=8)
        ax1.set_title(f"tolerance sweep at {r0['nx']}x{r0['ny']} per body (red x: not converged)")
    ref = [r for r in rows if r["group"] == "ladder" and r["label"] == "monolithic" and r["mono_rtol"]]
    ax1.set_xlabel("relative L2 error of lam against monolithic"
                   + (f" (monolithic_rtol {ref[0]['mono_rtol']})" if ref else ""))
    ax1.set_ylabel("iterate phase [s] (floored at 1 ms)")
    ax1.grid(True, which="both", alpha=0.3)
    ax1.legend(fontsize=7)

    ladder = [r for r in rows if r["group"] in ("ladder", "ordering") and r["status"] != "error"]
    series = [("monolithic", "metis", "tab:gray"), ("robin-steklov", "metis", "tab:blue"),
              ("robin-harmonic", "metis", "tab:orange"), ("robin-steklov", "amd", "tab:green")]
    for label, ordering, c in series:
        rr = sorted([r for r in ladder if r["label"] == label and r["factorization"] == "cholmod"
                     and r["ordering"] == ordering and num(r["p_err"])], key=lambda r: r["level"])
        if not rr:
            continue
        t = [num(r["total_s"]) for r in rr]
        name = f"{label} ({ordering})"
        if num(rr[0].get("p_err_away")):
            ax2.loglog([num(r["p_err_away"]) for r in rr], t, "-o", color=c,
                       label=name + ": pressure L2 away from the zone edge")
        ax2.loglog([num(r["force_err"]) for r in rr], t, ":s", color=c, label=name + ": total force")
        if label == "robin-steklov" and ordering == "metis":
            for r, ti in zip(rr, t):
                ax2.annotate(f"{r['nx']}x{r['ny']}", (num(r["force_err"]), ti), fontsize=7,
                             textcoords="offset points", xytext=(4, -10))
    fin = [r for r in ladder if r["p_err"] == ""]
    ttl = "mesh ladder, error against the finest mesh"
    if fin:
        ttl += f" ({fin[0]['nx']}x{fin[0]['ny']})"
    ax2.set_title(ttl)
    ax2.set_xlabel("relative discretisation error")
    ax2.set_ylabel("total run time [s]")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=7)
    save_figure(fig, out, dpi=120)


def phases(rows, out):
    rr = [r for r in rows if r["group"] in ("ladder", "ordering") and r["status"] != "error"]
    levels = sorted(set(r["level"] for r in rr))
    if not levels:
        return
    ncol = min(4, len(levels))
    nrow = (len(levels) + ncol - 1) // ncol
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.2 * ncol, 3.8 * nrow), squeeze=False)
    pcol = ["tab:purple", "tab:blue", "tab:green", "tab:orange", "tab:gray"]
    for k, lv in enumerate(levels):
        ax = axes[k // ncol][k % ncol]
        bars = [r for r in rr if r["level"] == lv]
        names = []
        for i, r in enumerate(bars):
            bottom = 0.0
            for j, ph in enumerate(PHASES):
                v = num(r[ph]) or 0.0
                ax.bar(i, v, bottom=bottom, color=pcol[j], label=ph[:-2] if (k == 0 and i == 0) else None)
                bottom += v
            short = {"monolithic": "mono", "robin-steklov": "steklov", "robin-harmonic": "harmonic"}[r["label"]]
            names.append(f"{short}\n{r['ordering'] if r['factorization'] == 'cholmod' else 'banded'}")
        ax.set_xticks(range(len(bars)))
        ax.set_xticklabels(names, fontsize=7)
        ax.set_title(f"{bars[0]['nx']}x{bars[0]['ny']} per body (n={bars[0]['n1']})", fontsize=9)
        ax.set_ylabel("time [s]")
    for k in range(len(levels), nrow * ncol):
        axes[k // ncol][k % ncol].axis("off")
    fig.legend(loc="lower right", fontsize=8)
    fig.suptitle("time per phase (2 threads; CHOLMOD with METIS/AMD ordering, banded = RCM + LAPACK band)")
    save_figure(fig, out, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv", nargs="?", default="results/bench.csv")
    ap.add_argument("--out-dir", default=None)
    a = ap.parse_args()
    rows = load(a.csv)
    out = a.out_dir or os.path.dirname(a.csv) or "."
    os.makedirs(out, exist_ok=True)
    wp = os.path.join(out, "bench_work_precision.png")
    ph = os.path.join(out, "bench_phases.png")
    work_precision(rows, wp)
    phases(rows, ph)
    print(f"wrote {wp} and {ph}")


if __name__ == "__main__":
    main()
