"""Figures of the robin_contact plot tools: axis labels with units, SI-prefix scaling, colour
limits, legend labels, saving, and the guard around a tool's main (tool_main).
Importing it loads numpy only; matplotlib is imported by the functions that draw or save.
"""
import os

import numpy as np


# ---- labels and scales ---------------------------------------------------------------------
def axis_label(what, unit):
    """'what [unit]' ('what [-]' for a dimensionless quantity, unit '' or '1' or '-')."""
    return f"{what} [{unit if unit not in ('', '1', '-') else '-'}]"


_PREFIXES = {-9: "n", -6: "µ", -3: "m", 0: "", 3: "k", 6: "M", 9: "G", 12: "T"}
_PREFIXABLE = ("m", "N", "Pa", "N/m")


def si_scale(values, unit):
    """(factor, unit label) to draw values / factor with an explicit unit instead of
    matplotlib's offset text: an SI prefix for the SI units m, N, Pa, N/m ('MPa', 'mm',
    'kN/m'), else a power of ten written into the label ('1e6 ft'). factor is a power of
    1000 chosen so that the largest |value| is in [1, 1000); (1, unit) for all-zero input."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    top = float(np.max(np.abs(v))) if v.size else 0.0
    if not top > 0.0:
        return 1.0, unit
    k = int(np.floor(np.log10(top) / 3.0)) * 3
    if unit in _PREFIXABLE:
        k = min(max(k, -9), 12)
        if unit == "m" and k > 0:       # km is not what anyone wants on a mesh axis
            k = 0
        return 10.0 ** k, _PREFIXES[k] + unit
    if k == 0:
        return 1.0, unit
    return 10.0 ** k, f"1e{k} {unit}".strip()


def format_quantity(values, unit, digits=4):
    """A value (or a sequence of values, written '(a, b)') with its unit as text for a legend or
    an annotation: an SI prefix for the SI units m, N, Pa, N/m ('3.2 MPa', '(1.5, -2) kN/m'),
    else the plain number in the given unit ('3000 N/mm', '1.235e5 N/mm'; never a power of
    ten beside the number). `digits` significant digits."""
    v = np.atleast_1d(np.asarray(values, dtype=float))
    factor, label = si_scale(v, unit) if unit in _PREFIXABLE else (1.0, unit)

    def num(x):
        t = f"{x / factor:.{digits}g}"
        if "e" in t:                      # 1.235e+05 -> 1.235e5
            mant, exp = t.split("e")
            t = f"{mant}e{int(exp)}"
        return t
    text = num(v[0]) if np.ndim(values) == 0 else "(" + ", ".join(num(x) for x in v) + ")"
    return f"{text} {label}".strip()


def plain_axis(ax, axis="both"):
    """No offset text and no scientific multiplier on the linear axes of ax (they would hide
    the unit: values are scaled explicitly with si_scale). Log axes are left alone."""
    for name in (("x", "y") if axis == "both" else (axis,)):
        if getattr(ax, f"get_{name}scale")() == "linear":
            ax.ticklabel_format(axis=name, useOffset=False, style="plain")


def clip_limits(values, percent):
    """(lo, hi, clipped) colour limits: the (100 - percent)th and percent-th percentiles of
    the finite values (percent >= 100: min and max); clipped tells whether values lie outside."""
    v = np.asarray(values, dtype=float).reshape(-1)
    v = v[np.isfinite(v)]
    if not v.size:
        return 0.0, 1.0, False
    vmin, vmax = float(v.min()), float(v.max())
    if percent >= 100.0:
        lo, hi = vmin, vmax
    else:
        lo, hi = (float(q) for q in np.percentile(v, [100.0 - percent, percent]))
        if vmin >= 0.0 and lo <= 0.01 * hi:   # a non-negative field (von Mises): keep 0 or the min
            lo = vmin
    if not hi > lo:
        lo, hi = min(lo, vmin), max(hi, vmax)
        if not hi > lo:
            hi = lo + (abs(lo) if lo else 1.0)
    return lo, hi, bool(vmin < lo or vmax > hi)


# ---- figures ----------------------------------------------------------------------------------
def run_label(path, method, status, delta=float("nan")):
    """(name, label) of a run in a legend: name = file name without .h5, label =
    'name (method, δ=delta, status)' (δ only for Robin runs with a finite delta)."""
    name = os.path.basename(path)
    if name.endswith(".h5"):
        name = name[:-3]
    label = f"{name} ({method}"
    if method != "monolithic" and np.isfinite(delta):
        label += f", δ={delta:g}"
    return name, label + f", {status})"


def plot_parser(doc, output):
    """The argument parser of a plot tool over result files: the tool's docstring as its help
    (line breaks kept), FILE.h5 ..., -o/--output (default `output`) and --title."""
    import argparse
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="+", metavar="FILE.h5", help="robin_contact result files")
    ap.add_argument("-o", "--output", default=output, help=f"output image (default {output})")
    ap.add_argument("--title", default=None, help="figure title")
    return ap


def save_figure(fig, path, dpi=None):
    """The tail of every plot: tight layout, create the output folder, save (dpi: default the
    figure's), close the figure. Returns path."""
    import matplotlib.pyplot as plt
    fig.tight_layout()
    out_dir = os.path.dirname(path)
    if out_dir:
        os.makedirs(out_dir, exist_ok=True)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def finish_plot(fig, ax, path, tool, note, xlabel, ylabel, title, **title_kw):
    """The tail of the one-axes plot tools: axis labels, title (title_kw: e.g. fontsize),
    legend, save_figure(fig, path), and the line '<tool>: wrote <path> (<note>)'.
    Returns 0, the tool's exit status."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, **title_kw)
    ax.legend(fontsize=7, loc="best")
    save_figure(fig, path)
    print(f"{tool}: wrote {path} ({note})")
    return 0


def tool_main(main, tool):
    """Run a plot tool's main() and exit with its status; any error (out of memory, a
    missing dataset, a matplotlib failure) ends with one line '<tool>: error: ...' on stderr
    and exit 1, never a traceback-less death or a silent 0. Use:
    `if __name__ == "__main__": tool_main(main, "plot_x")`."""
    import sys
    try:
        rc = main()
    except MemoryError:
        print(f"{tool}: error: out of memory (result too large for this tool's settings?)", file=sys.stderr)
        rc = 1
    except KeyboardInterrupt:
        print(f"{tool}: interrupted", file=sys.stderr)
        rc = 130
    except Exception as e:  # noqa: BLE001 - the point is to report every failure
        print(f"{tool}: error: {type(e).__name__}: {e}", file=sys.stderr)
        rc = 1
    sys.exit(rc)
