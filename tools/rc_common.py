"""Helpers shared by the robin_contact tools (tools/*.py) and the Python tests (tests/*.py).

The program's console output ends with key=value lines (see README, "Output"):
  result: status=converged method=robin outer=189 inner=2491 n1=816 n2=816 m=24 delta=0.5 residual=... wall_s=0.036
  time: assemble=... factor=... condense=... iterate=... output=... total=... peak_mb=... factor_mb=...
  contact: total normal force= ...
This module parses them (result_fields, time_fields, line_fields, contact_force), runs
the program (solver_env, run_solver), reads result files (text_attr, num_attr,
text_dataset, read_lam), computes shared quantities (rel_err, hertz_zone, hertz_pressure),
reads the units of a result (result_units, dataset_unit), labels, scales and saves figures
(run_label, axis_label, si_scale, plain_axis, clip_limits, save_figure, finish_plot), guards a
plot tool's main (tool_main: a message and exit 1 on any error, never a silent death), prints
Markdown tables (md_header, md_row) and counts the PASS/FAIL lines of the tests (Checks).

Tools in tools/ import it directly (`import rc_common`: a script's own folder is on
sys.path); tests put tools/ on sys.path first. Importing it loads numpy only: h5py and
matplotlib are imported by the functions that need them.
"""
import os
import re
import subprocess

import numpy as np

# ---- the program's output lines -------------------------------------------------------
RESULT_KEYS = ("status", "method", "outer", "inner", "n1", "n2", "m", "delta", "residual", "wall_s")
# the documented shape of the result and time lines, checked to the letter by tests/test_runs.py
RESULT_LINE = re.compile(r"^result: status=(\w+) method=(\w+) outer=(\d+) inner=(\d+) n1=(\d+) n2=(\d+) "
                         r"m=(\d+) delta=([0-9.eE+-]+) residual=([0-9.eE+-]+) wall_s=([0-9.eE+-]+)$", re.M)
TIME_LINE = re.compile(r"^time: assemble=[0-9.]+ factor=[0-9.]+ condense=[0-9.]+ iterate=[0-9.]+ output=[0-9.]+ "
                       r"total=[0-9.]+", re.M)
FORCE_RE = re.compile(r"^contact: total normal force=\s*(\S+)", re.M)


def line_fields(text, tag):
    """The key=value fields (strings) of the last line `<tag>: ...` of the output text, as a
    dict in line order, or None when there is no such line. Words without '=' are skipped."""
    lines = re.findall(r"^" + re.escape(tag) + r": (.*)$", text, re.M)
    if not lines:
        return None
    return dict(kv.split("=", 1) for kv in lines[-1].split() if "=" in kv)


def result_fields(text):
    """Fields of the last `result:` line (status, method, outer, inner, ... as strings), or None."""
    return line_fields(text, "result")


def time_fields(text):
    """Fields of the last `time:` line (assemble, factor, ..., total, peak_mb, factor_mb), or None."""
    return line_fields(text, "time")


def contact_force(text):
    """The total normal force of the last `contact:` line, as a string, or None."""
    m = FORCE_RE.findall(text)
    return m[-1] if m else None


# ---- running the program ----------------------------------------------------------------
def solver_env(threads=None, base=None):
    """A copy of the environment (base, default os.environ) for a run: OMP_NUM_THREADS =
    threads if given, else the inherited value, else 2."""
    env = dict(os.environ if base is None else base)
    if threads is None:
        env.setdefault("OMP_NUM_THREADS", "2")
    else:
        env["OMP_NUM_THREADS"] = str(threads)
    return env


def run_solver(binary, *args, env=None, **kwargs):
    """Run `binary args...` with its output captured as text (env: default solver_env()).
    Extra keyword arguments go to subprocess.run (cwd, timeout, ...).
    Returns (CompletedProcess, result_fields(stdout))."""
    p = subprocess.run([binary, *args], capture_output=True, text=True,
                       env=solver_env() if env is None else env, **kwargs)
    return p, result_fields(p.stdout)


# ---- result files -------------------------------------------------------------------------
def text_attr(obj, name, default=""):
    """A string attribute of an HDF5 object as str: fixed-length HDF5 strings come back as
    bytes or numpy bytes (possibly blank-padded by Fortran), sometimes inside a 1-element
    array. default when there is no such attribute."""
    if name not in obj.attrs:
        return default
    v = obj.attrs[name]
    if isinstance(v, np.ndarray):
        v = v.reshape(-1)[0] if v.size else b""
    if isinstance(v, (bytes, np.bytes_)):
        v = v.decode("utf-8", "replace")
    return str(v).strip().strip("\x00").strip()


def num_attr(obj, name, default=None):
    """A numeric attribute as float (first element of an array), or default."""
    if name not in obj.attrs:
        return default
    v = np.asarray(obj.attrs[name]).reshape(-1)
    return float(v[0]) if v.size else default


def text_dataset(f, name):
    """A string dataset (e.g. input_deck) as str, or None when there is none."""
    if name not in f:
        return None
    v = f[name][()]
    if isinstance(v, np.ndarray):
        v = b"".join(x if isinstance(x, (bytes, np.bytes_)) else str(x).encode() for x in v.reshape(-1))
    if isinstance(v, (bytes, np.bytes_)):
        v = v.decode("utf-8", "replace")
    return str(v)


def read_lam(path):
    """The contact force lam (/contact/normal_force) of a result file."""
    import h5py
    with h5py.File(path, "r") as f:
        return np.array(f["/contact/normal_force"])


# ---- units ---------------------------------------------------------------------------------
DEFAULT_UNITS = {"length": "m", "force": "N", "stress": "Pa"}


def result_units(f):
    """The units of a result file (h5py File): dict with 'length', 'force', 'stress' from the
    root attributes unit_length, unit_force, unit_stress (SI 'm', 'N', 'Pa' when absent: files
    written before the units were recorded), 'line_force' (force per unit thickness, e.g.
    'N/m' = force unit / length unit) and 'from_file' (True when all three were stored)."""
    u = {k: text_attr(f, "unit_" + k, "") or d for k, d in DEFAULT_UNITS.items()}
    u["line_force"] = f"{u['force']}/{u['length']}"
    u["from_file"] = all(("unit_" + k) in f.attrs for k in DEFAULT_UNITS)
    return u


def dataset_unit(ds, default):
    """The `units` attribute of an HDF5 dataset (string), or default when it has none."""
    return text_attr(ds, "units", "") or default


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


# ---- decks ----------------------------------------------------------------------------------
def strip_comments(text):
    """Drop Fortran '!' comments (outside quotes) from namelist text."""
    out = []
    for line in text.splitlines():
        q = None
        for i, ch in enumerate(line):
            if q:
                if ch == q:
                    q = None
            elif ch in "'\"":
                q = ch
            elif ch == "!":
                line = line[:i]
                break
        out.append(line)
    return "\n".join(out)


def namelist_groups(text, group):
    """The bodies of every `&group ... /` in namelist text (comments dropped; a '/' inside a
    quoted string does not end the group), in order."""
    text = strip_comments(text)
    out = []
    for m in re.finditer(r"&" + re.escape(group) + r"\b", text, flags=re.I):
        q = None
        for i in range(m.end(), len(text)):
            ch = text[i]
            if q:
                if ch == q:
                    q = None
            elif ch in "'\"":
                q = ch
            elif ch == "/":
                out.append(text[m.end():i])
                break
    return out


def deck_result_file(deck, overrides=()):
    """The result file a run of `robin_contact deck overrides...` writes: the last
    `file = '...'` of the &output groups of the deck, then of the overrides; by default
    results/<deck name without .nml>.h5 (deck.f90). Relative to the working directory."""
    with open(deck, encoding="utf-8", errors="replace") as fh:
        texts = [fh.read(), *overrides]
    result = None
    for t in texts:
        for body in namelist_groups(t, "output"):
            for m in re.finditer(r"(?<![\w%])file\s*=\s*(?:'([^']*)'|\"([^\"]*)\")", body, flags=re.I):
                result = (m.group(1) if m.group(1) is not None else m.group(2)).strip()
    if not result:
        base = os.path.basename(deck)
        result = "results/" + (base[:-4] if base.lower().endswith(".nml") else base) + ".h5"
    return result


def rel_err(a, ref):
    """|a - ref| / |ref| (2-norms), or None when either is None, the shapes differ or ref = 0."""
    if a is None or ref is None or np.shape(a) != np.shape(ref):
        return None
    n = np.linalg.norm(ref)
    if n == 0.0:
        return None
    return float(np.linalg.norm(a - ref) / n)


# ---- Hertz line contact --------------------------------------------------------------------
def hertz_zone(P, R, Es):
    """Half-width a = sqrt(4 P R / (pi E*)) and peak pressure p0 = 2 P / (pi a) of the Hertz
    line contact: total force P per unit thickness, gap radius R, contact modulus E*."""
    a = np.sqrt(4.0 * P * R / (np.pi * Es))
    return a, 2.0 * P / (np.pi * a)


def hertz_pressure(x, xc, a, p0):
    """Hertz pressure p0 sqrt(1 - (x - xc)^2 / a^2) at x (0 outside the contact zone)."""
    return p0 * np.sqrt(np.clip(1.0 - ((x - xc) / a) ** 2, 0.0, None))


def hertz_edge(x, p, i, j):
    """Zero of p^2, linear through nodes i (active, the edge) and j (its active neighbour inward)."""
    p2i, p2j = p[i] ** 2, p[j] ** 2
    if p2j <= p2i:
        return x[i]
    return x[i] - p2i * (x[j] - x[i]) / (p2j - p2i)


def contact_edges(x, p, lam):
    """Edges (xl, xr) of the contact zone along a line sorted by x: the zero of p^2
    extrapolated from the two outermost active nodes (lam > 0) on each side, kept between
    the last active and the first open node; an active end node of the line is the edge
    there (no extrapolation beyond the line). None when no node is active."""
    act = np.nonzero(np.asarray(lam) > 0)[0]
    if not act.size:
        return None
    i0, i1 = act[0], act[-1]
    xl = hertz_edge(x, p, i0, i0 + 1) if i1 > i0 else x[i0]
    xr = hertz_edge(x, p, i1, i1 - 1) if i1 > i0 else x[i1]
    xl = max(xl, x[i0 - 1]) if i0 > 0 else x[0]
    xr = min(xr, x[i1 + 1]) if i1 < len(x) - 1 else x[-1]
    return float(xl), float(xr)


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


# ---- tables ---------------------------------------------------------------------------------
def md_header(head):
    """The two header lines of a Markdown table."""
    return ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]


def md_row(cells):
    """One Markdown table row."""
    return "| " + " | ".join(str(c) for c in cells) + " |"


# ---- tests ------------------------------------------------------------------------------------
class Checks:
    """The PASS/FAIL lines of a test script: checks(ok, what, detail="") prints
    'PASS  what (detail)' or 'FAIL  what (detail)' and returns bool(ok); the failed ones
    are listed in checks.failed."""

    def __init__(self):
        self.failed = []

    def __call__(self, ok, what, detail=""):
        print(("PASS  " if ok else "FAIL  ") + what + (f" ({detail})" if detail else ""), flush=True)
        if not ok:
            self.failed.append(what)
        return bool(ok)


if __name__ == "__main__":
    # command-line use by the shell tools: rc_common.py result-file DECK [OVERRIDE ...]
    import sys
    if len(sys.argv) >= 3 and sys.argv[1] == "result-file":
        try:
            print(deck_result_file(sys.argv[2], sys.argv[3:]))
        except OSError as e:
            print(f"rc_common: cannot read deck {sys.argv[2]}: {e}", file=sys.stderr)
            sys.exit(1)
        sys.exit(0)
    print("usage: rc_common.py result-file DECK.nml [OVERRIDE ...]", file=sys.stderr)
    sys.exit(1)
