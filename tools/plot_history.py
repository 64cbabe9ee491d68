#!/usr/bin/python3
"""Convergence history of robin_contact runs against the outer iteration, one colour per
result file (label from the file name and the method/delta attributes):

  top, log scale:  the stopping criterion (solid), the true residual (dashed) and the
                   run's tolerance tol (dotted horizontal line), all dimensionless;
  bottom:          the active-set count (contact nodes with lam > 0) of each iteration,
                   out of the m contact nodes.

What they are (doc/method.md, "Stopping"; the run's `stop` setting is read from /input_deck):
  criterion  the quantity the run tests against tol: with stop='increment' (default) the
             relative obstacle increment |G1^k - G1^k-1|/|G1^k| + |G2^k - G2^k-1|/|G2^k|;
             with stop='residual' the residual below;
  residual   max(imbalance, penetration, complementarity): |lam1 - lam2|/|lam|,
             max(gap, 0)/u_scale, max lam_i |gap_i| / (max lam u_scale).

Usage: tools/plot_history.py FILE.h5 [FILE.h5 ...] [-o history.png] [--title TEXT]

Reads /history/criterion, /history/residual, /history/active and the root attributes
tol, method, status, delta (results.f90 layout). Non-positive values cannot be drawn on a
log axis and are left out. A run without history (method='monolithic') is listed in the
legend with a note and no curve. Exit 0 on success, 1 (with a message) on a missing or
unreadable file or any other failure.
Run with /usr/bin/python3 (numpy, h5py and matplotlib come from Debian packages).
"""
import re
import sys

import numpy as np
import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from rc_figures import plain_axis, plot_parser, run_label, save_figure, tool_main  # noqa: E402
from rc_results import num_attr, text_attr, text_dataset  # noqa: E402

CRITERION = {"increment": "relative obstacle increment Σ|ΔG_a|/|G_a|",
             "residual": "residual max(imbalance, penetration, complementarity)"}


def positive(v):
    v = np.asarray(v, dtype=float).copy()
    v[~(v > 0.0)] = np.nan
    return v


def stop_kind(f):
    """The run's stop setting ('increment' or 'residual') from its effective deck."""
    text = text_dataset(f, "input_deck") or ""
    hits = re.findall(r"(?<![\w%])stop\s*=\s*['\"]\s*(\w+)", text, flags=re.I)
    return hits[-1].lower() if hits else "increment"


def read_run(path):
    with h5py.File(path, "r") as f:
        def arr(k):
            return np.array(f[k]) if k in f else np.zeros(0)
        return dict(method=text_attr(f, "method", "?"), status=text_attr(f, "status", "?"),
                    delta=num_attr(f, "delta", float("nan")), tol=num_attr(f, "tol"),
                    m=int(num_attr(f, "contact_nodes", 0) or 0), stop=stop_kind(f),
                    crit=arr("/history/criterion"), res=arr("/history/residual"),
                    active=arr("/history/active"))


def main(argv=None):
    ap = plot_parser(__doc__, "history.png")
    a = ap.parse_args(argv)

    runs = []
    for path in a.files:
        try:
            runs.append((path, read_run(path)))
        except (OSError, KeyError) as e:
            print(f"plot_history: cannot read {path}: {e}", file=sys.stderr)
            return 1

    fig, (ax, axa) = plt.subplots(2, 1, figsize=(8.0, 7.0), dpi=120, sharex=True,
                                  gridspec_kw=dict(height_ratios=[2.3, 1.0]))
    colours = plt.rcParams["axes.prop_cycle"].by_key().get("color", ["C0"])
    drawn = 0
    tols = set()
    stops = set()
    for k, (path, r) in enumerate(runs):
        _, label = run_label(path, r["method"], r["status"], r["delta"])
        c = colours[k % len(colours)]
        if r["crit"].size == 0 and r["res"].size == 0:
            ax.plot([], [], color=c, label=label + ": no outer history")
            continue
        stops.add(r["stop"])
        if r["crit"].size:
            ax.semilogy(np.arange(1, r["crit"].size + 1), positive(r["crit"]), "-", color=c, lw=1.5,
                        label=f"{label}: criterion (stop='{r['stop']}')")
        if r["res"].size:
            ax.semilogy(np.arange(1, r["res"].size + 1), positive(r["res"]), "--", color=c, lw=1.2,
                        label=f"{label}: residual")
        if r["tol"] is not None and r["tol"] > 0.0 and r["tol"] not in tols:
            ax.axhline(r["tol"], color="k", ls=":", lw=1.3, label=f"tol = {r['tol']:g} (stopping tolerance)")
            tols.add(r["tol"])
        if r["active"].size:
            axa.step(np.arange(1, r["active"].size + 1), r["active"], where="mid", color=c, lw=1.3,
                     label=f"{label}" + (f" (of m = {r['m']})" if r["m"] else ""))
        drawn += 1
    ax.set_yscale("log")
    ax.grid(True, which="major", alpha=0.4)
    ax.grid(True, which="minor", alpha=0.15)
    lines = [a.title or "robin_contact convergence history"]
    lines += [f"criterion (stop='{s}'): {CRITERION.get(s, s)}" for s in sorted(stops) if s != "residual"]
    lines.append("residual: max(imbalance, penetration, complementarity), the criterion when stop='residual'")
    ax.set_ylabel("criterion (solid), residual (dashed),\ntol (dotted black) [-]")
    ax.set_title("\n".join(lines), fontsize=9)
    ax.legend(fontsize=7, loc="best")
    axa.set_xlabel("outer iteration")
    axa.set_ylabel("active contact nodes")
    axa.grid(True, alpha=0.4)
    plain_axis(axa)
    if drawn:
        axa.legend(fontsize=7, loc="best")
    save_figure(fig, a.output)
    print(f"plot_history: wrote {a.output} ({drawn} of {len(a.files)} runs with history)")
    return 0


if __name__ == "__main__":
    tool_main(main, "plot_history")
