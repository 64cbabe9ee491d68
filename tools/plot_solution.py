#!/usr/bin/python3
"""Deformed shape of every body of a robin_contact run, coloured by a nodal field (von
Mises stress by default), with the contact lines marked. Cheap at any mesh size: the field
is rasterised, the element edges are drawn only for small meshes.

Usage: tools/plot_solution.py FILE.h5 [-o solution.png] [--field NAME] [--scale S]
                              [--clip P] [--edges N] [--pixels W] [--title TEXT]

Reads /bodyN/coordinates, /bodyN/displacement, /bodyN/cells and the field (results.f90
layout) and draws x + S u for all bodies (N = the root attribute `bodies`, 2 in files
without it) on one shared colour scale:
  * the field is rasterised: each cell is sampled (bilinear on quadrilaterals, linear on
    triangles) finely enough for every image pixel, the samples are averaged per pixel
    (W pixels along the longer side of the picture, --pixels, default 1000) and drawn as
    one image. Time and memory grow with the cell count only linearly and stay small
    (about 2 s and 150 MB for 512x256 cells per body);
  * the element edges are drawn when the bodies have at most N cells in all (--edges,
    default 5000); beyond that only the outlines (a million edges make a black picture);
  * the colour scale spans the (100-P)th to the P-th percentile of the nodal values
    (--clip, default 99.5; 100: min to max), so that a stress singularity at a corner does
    not leave the rest of the picture in one colour; the colour bar says so, with the true
    extreme values, and shows arrows when values lie beyond the scale.
Fields (--field): von_mises (default), sxx, syy, sxy, szz (/bodyN/stress rows),
contact_pressure, ux, uy, u (the magnitude |u|).
Units from the result (root attributes unit_length/unit_stress, the datasets' `units`
attributes; SI m, Pa when absent), written in the axis labels and the colour bar, with the
values scaled to an SI prefix (MPa, mm); no matplotlib offset text.
The undeformed outlines are drawn dashed grey, the deformed ones black. The
magnification S is stated in the title; by default (or --scale auto) it is 10% of the
larger body size (max of width and height of any body) over the largest nodal
displacement |u|, rounded to 3 significant digits. The contact line (/contact/coordinates)
is drawn on both deformed bodies; its active nodes (/contact/active = 1) are marked (for at
most 200 contact nodes; beyond, the active part of the line is drawn thick). With several
contact pairs each pair's line (/contact/pair_<k>) is drawn on its two bodies in a colour
of its own, its active nodes marked on its first body.
Exit 0 on success, 1 with a message on a missing or unreadable file or any other failure
(out of memory included).
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
from matplotlib.cm import ScalarMappable  # noqa: E402
from matplotlib.collections import LineCollection, PolyCollection  # noqa: E402
from matplotlib.colors import Normalize  # noqa: E402

from rc_figures import axis_label, clip_limits, plain_axis, save_figure, si_scale, tool_main  # noqa: E402
from rc_results import dataset_unit, result_units, text_attr  # noqa: E402

STRESS_ROWS = {"sxx": 0, "syy": 1, "sxy": 2, "szz": 3}
FIELDS = ["von_mises", "sxx", "syy", "sxy", "szz", "contact_pressure", "ux", "uy", "u"]
NAMES = {"von_mises": "von Mises stress", "sxx": "stress σxx", "syy": "stress σyy", "sxy": "stress σxy",
         "szz": "stress σzz", "contact_pressure": "contact pressure", "ux": "displacement ux",
         "uy": "displacement uy", "u": "displacement |u|"}
CHUNK = 500_000            # samples per rasterisation chunk (about 30 MB of temporaries)


def read_body(g, field, units):
    """Coordinates, displacement, cells and the nodal field of one body group; (body, unit)."""
    xy = np.array(g["coordinates"], dtype=float)          # (2, nnode)
    u = np.array(g["displacement"], dtype=float)           # (2, nnode)
    cells = np.array(g["cells"], dtype=np.int64)           # (ncell, nvert), 0-based
    n = xy.shape[1] if xy.ndim == 2 else -1
    if xy.ndim != 2 or xy.shape[0] != 2 or u.shape != xy.shape:
        raise KeyError(f"{g.name}: unexpected shapes coordinates {xy.shape}, displacement {u.shape}")
    if cells.ndim != 2 or cells.shape[1] not in (3, 4) or cells.min(initial=0) < 0 \
            or cells.max(initial=0) >= n:
        raise KeyError(f"{g.name}: bad cells array {cells.shape}")
    if field in STRESS_ROWS:
        v = np.array(g["stress"][STRESS_ROWS[field]], dtype=float)
        unit = dataset_unit(g["stress"], units["stress"])
    elif field in ("ux", "uy", "u"):
        v = u[0] if field == "ux" else u[1] if field == "uy" else np.hypot(u[0], u[1])
        unit = dataset_unit(g["displacement"], units["length"])
    else:
        v = np.array(g[field], dtype=float)
        unit = dataset_unit(g[field], units["stress"])
    if v.shape != (n,):
        raise KeyError(f"{g.name}: field {field} has shape {v.shape}, expected ({n},)")
    return dict(xy=xy, u=u, cells=cells, v=v, element=text_attr(g, "element", "?")), unit


def boundary_edges(cells, nnode):
    """Edges used by one cell only (the outline of the body), as (nedge, 2) node pairs."""
    nv = cells.shape[1]
    e = np.concatenate([np.column_stack([cells[:, k], cells[:, (k + 1) % nv]]) for k in range(nv)])
    key = np.minimum(e[:, 0], e[:, 1]) * nnode + np.maximum(e[:, 0], e[:, 1])
    _, first, cnt = np.unique(key, return_index=True, return_counts=True)
    return e[first[cnt == 1]]


def sample_cells(d, v, cells, n):
    """n x n samples (positions and linearly/bilinearly interpolated values) in each cell."""
    t = (np.arange(n) + 0.5) / n
    r, s = (q.reshape(-1) for q in np.meshgrid(t, t))
    if cells.shape[1] == 4:    # bilinear quadrilateral
        w = np.stack([(1 - r) * (1 - s), r * (1 - s), r * s, (1 - r) * s])           # (4, n^2)
    else:                      # triangle: v0 + r (v1 - v0) + r s (v2 - v1)
        w = np.stack([1 - r, r * (1 - s), r * s])
    x = d[0][cells] @ w
    y = d[1][cells] @ w
    val = v[cells] @ w
    return x.reshape(-1), y.reshape(-1), val.reshape(-1)


def rasterise(bodies, pixels):
    """The field of all bodies, deformed, as a masked image (pixel = mean of the samples in
    it; masked where no body is) and its extent [x0, x1, y0, y1]."""
    lo = np.min([b["def"].min(axis=1) for b in bodies], axis=0)
    hi = np.max([b["def"].max(axis=1) for b in bodies], axis=0)
    span = np.maximum(hi - lo, 1e-300)
    h = float(max(span) / pixels)
    nx, ny = int(np.ceil(span[0] / h)) + 1, int(np.ceil(span[1] / h)) + 1
    total = np.zeros(nx * ny)
    count = np.zeros(nx * ny)
    for b in bodies:
        d, cells = b["def"], b["cells"]
        ext = np.maximum(np.ptp(d[0][cells], axis=1), np.ptp(d[1][cells], axis=1))
        need = np.maximum(1, np.ceil(2.0 * ext / h)).astype(np.int64)          # samples per side
        level = np.minimum(np.ceil(np.log2(need)).astype(np.int64), 11)       # n = 2^level
        for lev in np.unique(level):
            n = 1 << int(lev)
            idx = np.nonzero(level == lev)[0]
            step = max(1, CHUNK // (n * n))
            for c0 in range(0, idx.size, step):
                x, y, val = sample_cells(d, b["v"], cells[idx[c0:c0 + step]], n)
                ix = np.clip(((x - lo[0]) / h).astype(np.int64), 0, nx - 1)
                iy = np.clip(((y - lo[1]) / h).astype(np.int64), 0, ny - 1)
                k = iy * nx + ix
                total += np.bincount(k, weights=val, minlength=nx * ny)
                count += np.bincount(k, minlength=nx * ny)
    img = np.ma.masked_array(total / np.maximum(count, 1), mask=count == 0).reshape(ny, nx)
    return img, [lo[0], lo[0] + nx * h, lo[1], lo[1] + ny * h]


def contact_lines(f):
    """The contact lines to draw: one per pair, each a dict with the 0-based indices of its
    two bodies, its node coordinates (2, n), its active flags and its legend labels. One
    pair (and files without pair groups): /contact, bodies 1 and 2."""
    npair = int(f.attrs.get("pairs", 1))
    out = []
    for k in range(1, npair + 1):
        g = f[f"contact/pair_{k}"] if npair > 1 else f["contact"]
        if "coordinates" in g:
            cxy = np.array(g["coordinates"], dtype=float)
        elif "x" in g:
            cxy = np.array([g["x"], g["y"]], dtype=float)
        else:
            cxy = np.zeros((2, 0))
        if cxy.ndim != 2 or cxy.shape[0] != 2:
            cxy = cxy.reshape(-1, 2).T if cxy.size else np.zeros((2, 0))
        active = np.array(g["active"]) if "active" in g else np.zeros(cxy.shape[-1])
        if npair > 1:
            a, b = (int(v) for v in np.asarray(g.attrs["bodies"]).reshape(-1)[:2])
            c = f"C{(k - 1) % 10}"
            styles = [dict(color=c, lw=1.8, label=f"contact line, pair {k} (bodies {a},{b})"),
                      dict(color=c, lw=1.4, ls="--")]
            mark, tag = c, f"pair {k}: "
        else:
            a, b = 1, 2
            styles = [dict(color="red", lw=1.8, label="contact line, body 1"),
                      dict(color="orange", lw=1.4, ls="--", label="contact line, body 2")]
            mark, tag = "red", ""
        out.append(dict(bodies=(a - 1, b - 1), cxy=cxy, active=active, styles=styles, mark=mark, tag=tag))
    return out


def draw_contact_line(ax, pair, ln, tol, fl):
    """One contact line drawn on the deformed boundary of its two bodies `pair` (styles of
    ln), its active nodes marked on the body that holds the contact nodes (the side whose
    boundary nodes match most of them: the slave side of non-matching meshes); the legend
    counts the active contact nodes of the whole line (/contact/active = 1, or the pair's);
    lengths divided by fl."""
    cxy = ln["cxy"]
    act_all = np.asarray(ln["active"]).reshape(-1) > 0
    n = cxy.shape[1]
    act_line = np.zeros(n, dtype=bool)
    act_line[:min(n, act_all.size)] = act_all[:n]
    side = None                                           # (matched count, body, idx, ok)
    for b, st in zip(pair, ln["styles"]):
        if n == 0:
            break
        bn = b["boundary"]
        idx = np.empty(n, dtype=np.int64)
        ok = np.zeros(n, dtype=bool)
        for c0 in range(0, n, 256):                       # (256 x boundary nodes) distances at a time
            cc = cxy[:, c0:c0 + 256]
            dist = np.hypot(b["xy"][0][bn][None, :] - cc[0][:, None], b["xy"][1][bn][None, :] - cc[1][:, None])
            j = np.argmin(dist, axis=1)
            idx[c0:c0 + cc.shape[1]] = bn[j]
            ok[c0:c0 + cc.shape[1]] = dist[np.arange(j.size), j] <= tol
        if not ok.any():
            continue
        # the contact nodes come in the order of the contact chain; a closed loop (a rim) is
        # drawn closed: its ends are as near each other as two neighbours
        p = b["def"][:, idx[ok]] / fl
        if p.shape[1] > 2:
            step = np.hypot(*np.diff(p, axis=1))
            if np.hypot(*(p[:, -1] - p[:, 0])) <= 1.5 * step.max():
                p = np.hstack([p, p[:, :1]])
        ax.plot(p[0], p[1], zorder=4, **st)
        if side is None or int(ok.sum()) > side[0]:
            side = (int(ok.sum()), b, idx, ok)
    if side is None:
        return
    _, b, idx, ok = side
    pa = b["def"][:, idx[act_line & ok]] / fl
    lab = f"{ln['tag']}active contact nodes ({int(act_line.sum())} of {n})"
    if n <= 200:
        ax.plot(pa[0], pa[1], "o", ms=3.5, mfc=ln["mark"], mec="white", mew=0.5, ls="none", zorder=5,
                label=lab)
    else:
        o = np.argsort(pa[0], kind="stable")
        ax.plot(pa[0][o], pa[1][o], ".", color=ln["mark"], ms=1.5, zorder=5, label=lab)


def nice(x):
    return float(f"{x:.3g}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("file", metavar="FILE.h5", help="robin_contact result file")
    ap.add_argument("-o", "--output", default="solution.png", help="output image (default solution.png)")
    ap.add_argument("--field", default="von_mises", choices=FIELDS, help="nodal field to colour by")
    ap.add_argument("--scale", default="auto", help="displacement magnification S, or 'auto' (default)")
    ap.add_argument("--clip", type=float, default=99.5,
                    help="colour scale from the (100-P)th to the P-th percentile (default 99.5; 100: min-max)")
    ap.add_argument("--edges", type=int, default=5000,
                    help="draw element edges up to this many cells in all (default 5000)")
    ap.add_argument("--pixels", type=int, default=1000,
                    help="raster width along the longer side of the picture (default 1000)")
    ap.add_argument("--title", default=None, help="first title line (default: file name, status)")
    a = ap.parse_args(argv)
    if not 50.0 <= a.clip <= 100.0:
        print(f"plot_solution: --clip must be in [50, 100], not {a.clip:g}", file=sys.stderr)
        return 1
    if not 50 <= a.pixels <= 8000:
        print(f"plot_solution: --pixels must be in [50, 8000], not {a.pixels}", file=sys.stderr)
        return 1

    try:
        with h5py.File(a.file, "r") as f:
            units = result_units(f)
            nbody = int(f.attrs.get("bodies", 2))
            read = [read_body(f[f"body{b}"], a.field, units) for b in range(1, nbody + 1)]
            bodies = [r[0] for r in read]
            funit = read[0][1]
            lunit = dataset_unit(f["body1/coordinates"], units["length"])
            lines = contact_lines(f)
            status = text_attr(f, "status", "?")
            method = text_attr(f, "method", "?")
    except (OSError, KeyError, ValueError) as e:
        print(f"plot_solution: cannot read {a.file}: {e}", file=sys.stderr)
        return 1
    if any(not 0 <= i < len(bodies) for ln in lines for i in ln["bodies"]):
        print(f"plot_solution: cannot read {a.file}: a contact pair names a body the file does not have",
              file=sys.stderr)
        return 1

    size = max(max(np.ptp(b["xy"][0]), np.ptp(b["xy"][1])) for b in bodies)
    umax = max(float(np.max(np.hypot(b["u"][0], b["u"][1]), initial=0.0)) for b in bodies)
    if a.scale == "auto":
        S = nice(0.1 * size / umax) if umax > 0.0 and size > 0.0 else 1.0
        how = f"auto: 10% of body size {size:.3g} {lunit} / max|u| {umax:.3g} {lunit}"
    else:
        try:
            S = float(a.scale)
        except ValueError:
            print(f"plot_solution: --scale must be a number or 'auto', not {a.scale!r}", file=sys.stderr)
            return 1
        how = f"max|u| {umax:.3g} {lunit}"
    for b in bodies:
        b["def"] = b["xy"] + S * b["u"]

    allv = np.concatenate([b["v"] for b in bodies])
    lo, hi, clipped = clip_limits(allv, a.clip)
    vmin, vmax = float(np.nanmin(allv)), float(np.nanmax(allv))
    fv, lv = si_scale([lo, hi, vmin, vmax], funit)
    norm = Normalize(vmin=lo / fv, vmax=hi / fv)
    fl, ll = si_scale(np.concatenate([b["def"].reshape(-1) for b in bodies]), lunit)
    cmap = "viridis"

    fig, ax = plt.subplots(figsize=(9.0, 6.5), dpi=120)
    img, ext = rasterise(bodies, a.pixels)
    ax.imshow(img / fv, origin="lower", extent=[e / fl for e in ext], cmap=cmap, norm=norm,
              interpolation="nearest", aspect="equal", rasterized=True, zorder=1)
    ncell = sum(b["cells"].shape[0] for b in bodies)
    notes = [f"field rasterised at {img.shape[1]}x{img.shape[0]} pixels"]
    for b in bodies:
        d = b["def"] / fl
        if ncell <= a.edges:
            polys = d[:, b["cells"]].transpose(1, 2, 0)                     # (ncell, nvert, 2)
            ax.add_collection(PolyCollection(polys, facecolors="none", edgecolors="k", linewidths=0.25,
                                             alpha=0.45, zorder=2))
        be = boundary_edges(b["cells"], b["xy"].shape[1])
        b["boundary"] = np.unique(be)
        x0 = b["xy"] / fl
        ax.add_collection(LineCollection(np.stack([x0[:, be[:, 0]].T, x0[:, be[:, 1]].T], axis=1),
                                         colors="0.45", linewidths=0.8, linestyles="dashed", zorder=2))
        ax.add_collection(LineCollection(np.stack([d[:, be[:, 0]].T, d[:, be[:, 1]].T], axis=1),
                                         colors="k", linewidths=0.6, zorder=3))
    if ncell > a.edges:
        notes.append(f"element edges not drawn ({ncell} cells > {a.edges})")

    # contact lines: boundary nodes of each pair's bodies at the contact coordinates, deformed
    tol = 1e-8 * max(size, 1e-300)
    for ln in lines:
        draw_contact_line(ax, [bodies[i] for i in ln["bodies"]], ln, tol, fl)

    extend =    extend = {(False, False): "neither", (True, False): "min", (False, True): "max", (True, True): "both"}[
        (vmin < lo, vmax > hi)]
    cb = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.85, extend=extend)
    name = NAMES[a.field]
    if clipped:
        side = {"min": f"below the {100 - a.clip:g}th", "max": f"above the {a.clip:g}th",
                "both": f"outside the {100 - a.clip:g}th-{a.clip:g}th"}[extend]
        clip_note = f"colour scale clipped {side} percentile of the nodal values"
        cb.set_label(f"{axis_label(name, lv)}\n{clip_note}\n(all values: {vmin / fv:.4g} to {vmax / fv:.4g} {lv})",
                     fontsize=8)
    else:
        clip_note = "colour scale: full range"
        cb.set_label(f"{axis_label(name, lv)} (full range)", fontsize=9)
    cb.ax.ticklabel_format(useOffset=False, style="plain")
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.margins(0.04)
    plain_axis(ax)
    ax.set_xlabel(axis_label("x", ll))
    ax.set_ylabel(axis_label("y", ll))
    ax.legend(fontsize=7, loc="best")
    fname = os.path.basename(a.file)
    first = a.title or f"{fname}: {method}, {status}, {'/'.join(b['element'] for b in bodies)}"
    ax.set_title(f"{first}\ndeformed shape, displacement magnified ×{S:g} ({how})\n"
                 f"colour: {name}, {clip_note}\n" + "; ".join(notes), fontsize=8)
    save_figure(fig, a.output)
    print(f"plot_solution: wrote {a.output} (magnification {S:g}, {a.field}, colour scale {lo:.4g} to "
          f"{hi:.4g} {funit}{', ' + clip_note if clipped else ''}, {ncell} cells)")
    return 0


if __name__ == "__main__":
    tool_main(main, "plot_solution")
