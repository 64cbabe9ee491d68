#!/usr/bin/python3
"""Convergence history of robin_contact runs: the stopping criterion and the true
residual against the outer iteration, log scale, one curve pair per result file
(solid: criterion, dashed: residual, same colour; label from the file name and the
method/delta attributes).

Usage: tools/plot_history.py FILE.h5 [FILE.h5 ...] [-o history.png] [--title TEXT]

Reads /history/criterion and /history/residual of each file (results.f90 layout).
Non-positive values (e.g. a residual that is exactly zero) cannot be drawn on a log
axis and are left out. A run without history (method='monolithic') is listed in the
legend with a note and no curve. Exit 0 on success, 1 on a missing or unreadable file.
Run with /usr/bin/python3 (numpy, h5py and matplotlib come from Debian packages).
"""
import argparse
import sys

import numpy as np
import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from rc_common import finish_plot, num_attr, run_label, text_attr  # noqa: E402


def positive(v):
    v = np.asarray(v, dtype=float).copy()
    v[~(v > 0.0)] = np.nan
    return v


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="+", metavar="FILE.h5", help="robin_contact result files")
    ap.add_argument("-o", "--output", default="history.png", help="output image (default history.png)")
    ap.add_argument("--title", default=None, help="figure title")
    a = ap.parse_args(argv)

    fig, ax = plt.subplots(figsize=(8.0, 5.5), dpi=120)
    colours = plt.rcParams["axes.prop_cycle"].by_key().get("color", ["C0"])
    drawn = 0
    for k, path in enumerate(a.files):
        try:
            with h5py.File(path, "r") as f:
                method = text_attr(f, "method", "?")
                status = text_attr(f, "status", "?")
                delta = num_attr(f, "delta", float("nan"))
                crit = np.array(f["/history/criterion"]) if "/history/criterion" in f else np.zeros(0)
                res = np.array(f["/history/residual"]) if "/history/residual" in f else np.zeros(0)
        except (OSError, KeyError) as e:
            print(f"plot_history: cannot read {path}: {e}", file=sys.stderr)
            return 1
        _, label = run_label(path, method, status, delta)
        c = colours[k % len(colours)]
        if crit.size == 0 and res.size == 0:
            ax.plot([], [], color=c, label=label + ": no outer history")
            continue
        if crit.size:
            ax.semilogy(np.arange(1, crit.size + 1), positive(crit), "-", color=c, lw=1.5,
                        label=label + ": criterion")
        if res.size:
            ax.semilogy(np.arange(1, res.size + 1), positive(res), "--", color=c, lw=1.2,
                        label=label + ": residual")
        drawn += 1
    ax.set_yscale("log")
    ax.grid(True, which="major", alpha=0.4)
    ax.grid(True, which="minor", alpha=0.15)
    return finish_plot(fig, ax, a.output, "plot_history", f"{drawn} of {len(a.files)} runs with history",
                       "outer iteration", "criterion (solid), residual (dashed)",
                       a.title or "robin_contact convergence history")


if __name__ == "__main__":
    sys.exit(main())
