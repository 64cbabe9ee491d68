"""Reading robin_contact's result files and comparing results.

HDF5 attributes and datasets as Python values (text_attr, num_attr, text_dataset, read_lam),
the units of a result (result_units, dataset_unit), relative errors (rel_err), the Hertz line
contact (hertz_zone, hertz_pressure, contact_edges) and Markdown tables (md_header, md_row).
Importing it loads numpy only; h5py is imported by read_lam.
"""
import numpy as np


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


# ---- comparing results -------------------------------------------------------------------
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


# ---- tables ---------------------------------------------------------------------------------
def md_header(head):
    """The two header lines of a Markdown table."""
    return ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]


def md_row(cells):
    """One Markdown table row."""
    return "| " + " | ".join(str(c) for c in cells) + " |"
