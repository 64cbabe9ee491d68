#!/usr/bin/python3
"""Deformed shape of both bodies of a robin_contact run, coloured by the nodal von Mises
stress, with the contact line marked.

Usage: tools/plot_solution.py FILE.h5 [-o solution.png] [--scale S] [--title TEXT]

Draws x + S u for both bodies (/bodyN/coordinates, /bodyN/displacement, /bodyN/cells,
/bodyN/von_mises; results.f90 layout) on one shared colour scale (Gouraud shading of the
nodal values; quadrilaterals are split into two triangles for the colouring only, the
element edges are drawn as they are). The undeformed outlines are drawn dashed grey.
The magnification S is stated in the title; by default (or --scale auto) it is 10% of
the larger body size (max of width and height of either body) over the largest nodal
displacement |u|, rounded to 3 significant digits. The contact line (/contact/coordinates)
is drawn on both deformed bodies; its active nodes (/contact/active = 1) are marked.
Exit 0 on success, 1 on a missing or unreadable file.
Run with /usr/bin/python3 (numpy, h5py and matplotlib come from Debian packages).
"""
import argparse
import os
import sys

import numpy as np
import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection, PolyCollection  # noqa: E402
from matplotlib.colors import Normalize  # noqa: E402
import matplotlib.tri as mtri  # noqa: E402

from rc_common import finish_plot, text_attr  # noqa: E402


def read_body(g):
    xy = np.array(g["coordinates"], dtype=float)          # (2, nnode)
    u = np.array(g["displacement"], dtype=float)           # (2, nnode)
    cells = np.array(g["cells"], dtype=np.int64)           # (ncell, nvert), 0-based
    vm = np.array(g["von_mises"], dtype=float)             # (nnode,)
    if xy.ndim != 2 or xy.shape[0] != 2 or u.shape != xy.shape or vm.shape != (xy.shape[1],):
        raise KeyError(f"{g.name}: unexpected shapes coordinates {xy.shape}, displacement {u.shape}, "
                       f"von_mises {vm.shape}")
    if cells.ndim != 2 or cells.shape[1] not in (3, 4) or cells.min(initial=0) < 0 \
            or cells.max(initial=0) >= xy.shape[1]:
        raise KeyError(f"{g.name}: bad cells array {cells.shape}")
    return dict(xy=xy, u=u, cells=cells, vm=vm, element=text_attr(g, "element", "?"))


def triangles(cells):
    """Triangles for colouring: quads (0,1,2,3) -> (0,1,2), (0,2,3)."""
    if cells.shape[1] == 3:
        return cells
    return np.vstack([cells[:, [0, 1, 2]], cells[:, [0, 2, 3]]])


def boundary_edges(cells):
    """Edges used by one cell only (the outline of the body)."""
    nv = cells.shape[1]
    e = np.vstack([np.column_stack([cells[:, k], cells[:, (k + 1) % nv]]) for k in range(nv)])
    key = np.sort(e, axis=1)
    _, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return e[cnt[inv.reshape(-1)] == 1]


def nice(x):
    return float(f"{x:.3g}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("file", metavar="FILE.h5", help="robin_contact result file")
    ap.add_argument("-o", "--output", default="solution.png", help="output image (default solution.png)")
    ap.add_argument("--scale", default="auto", help="displacement magnification S, or 'auto' (default)")
    ap.add_argument("--title", default=None, help="first title line (default: file name, status)")
    a = ap.parse_args(argv)

    try:
        with h5py.File(a.file, "r") as f:
            bodies = [read_body(f[f"body{b}"]) for b in (1, 2)]
            cxy = np.array(f["/contact/coordinates"], dtype=float) if "/contact/coordinates" in f \
                else np.zeros((2, 0))
            active = np.array(f["/contact/active"]) if "/contact/active" in f else np.zeros(cxy.shape[1])
            status = text_attr(f, "status", "?")
            method = text_attr(f, "method", "?")
    except (OSError, KeyError) as e:
        print(f"plot_solution: cannot read {a.file}: {e}", file=sys.stderr)
        return 1
    if cxy.ndim != 2 or cxy.shape[0] != 2:
        cxy = cxy.reshape(-1, 2).T if cxy.size else np.zeros((2, 0))

    size = max(max(np.ptp(b["xy"][0]), np.ptp(b["xy"][1])) for b in bodies)
    umax = max(float(np.max(np.hypot(b["u"][0], b["u"][1]), initial=0.0)) for b in bodies)
    if a.scale == "auto":
        S = nice(0.1 * size / umax) if umax > 0.0 and size > 0.0 else 1.0
        how = f"auto: 10% of body size {size:.3g} / max|u| {umax:.3g}"
    else:
        try:
            S = float(a.scale)
        except ValueError:
            print(f"plot_solution: --scale must be a number or 'auto', not {a.scale!r}", file=sys.stderr)
            return 1
        how = f"max|u| {umax:.3g}"

    vmin = min(float(np.min(b["vm"])) for b in bodies)
    vmax = max(float(np.max(b["vm"])) for b in bodies)
    if not vmax > vmin:
        vmax = vmin + 1.0
    norm = Normalize(vmin=vmin, vmax=vmax)

    fig, ax = plt.subplots(figsize=(9.0, 6.5), dpi=120)
    tpc = None
    for b in bodies:
        d = b["xy"] + S * b["u"]
        b["def"] = d
        tri = mtri.Triangulation(d[0], d[1], triangles(b["cells"]))
        tpc = ax.tripcolor(tri, b["vm"], shading="gouraud", cmap="viridis", norm=norm)
        polys = np.stack([d[:, c].T for c in b["cells"]])
        ax.add_collection(PolyCollection(polys, facecolors="none", edgecolors="k", linewidths=0.25, alpha=0.45))
        be = boundary_edges(b["cells"])
        ax.add_collection(LineCollection(np.stack([b["xy"][:, be[:, 0]].T, b["xy"][:, be[:, 1]].T], axis=1),
                                         colors="0.45", linewidths=0.8, linestyles="dashed"))
    # contact line: nodes of each body at the contact coordinates, deformed
    tol = 1e-8 * max(size, 1e-300)
    styles = [dict(color="red", lw=1.8, label="contact line, body 1"),
              dict(color="orange", lw=1.4, ls="--", label="contact line, body 2")]
    for b, st in zip(bodies, styles):
        if cxy.shape[1] == 0:
            break
        dist = np.hypot(b["xy"][0][None, :] - cxy[0][:, None], b["xy"][1][None, :] - cxy[1][:, None])
        idx = np.argmin(dist, axis=1)
        ok = dist[np.arange(idx.size), idx] <= tol
        if not ok.any():
            continue
        p = b["def"][:, idx[ok]]
        order = np.lexsort((p[1], p[0]))
        ax.plot(p[0][order], p[1][order], **st)
        if b is bodies[0]:
            act = (np.asarray(active).reshape(-1)[:ok.size] > 0) & ok
            pa = b["def"][:, idx[act]]
            ax.plot(pa[0], pa[1], "o", ms=3.5, mfc="red", mec="white", mew=0.5, ls="none",
                    label=f"active contact nodes ({int(act.sum())} of {ok.size})")
    cb = fig.colorbar(tpc, ax=ax, shrink=0.85)
    cb.set_label("von Mises stress")
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.margins(0.04)
    name = os.path.basename(a.file)
    first = a.title or f"{name}: {method}, {status}, {bodies[0]['element']}/{bodies[1]['element']}"
    return finish_plot(fig, ax, a.output, "plot_solution", f"magnification {S:g}", "x", "y",
                       f"{first}\ndeformed shape, displacement magnified ×{S:g} ({how})", fontsize=10)


if __name__ == "__main__":
    sys.exit(main())
