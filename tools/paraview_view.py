#!/usr/bin/env pvpython
"""ParaView picture of a robin_contact result: open its XDMF, warp by the displacement,
colour by a chosen point or cell array, write a PNG. Runs headless.

Usage:
  pvpython tools/paraview_view.py RESULT [-o view.png] [--field NAME] [--scale S|auto]
                                  [--clip P] [--range MIN MAX] [--edges] [--size WxH]
                                  [--zoom contact|X0,X1,Y0,Y1] [--step K]
                                  [--cut auto|none|x|y|z|x=V|PX,PY,PZ,NX,NY,NZ]
  pvpython tools/paraview_view.py RESULT --list      (the point and cell arrays, then exit)
RESULT is results/x.xdmf or results/x.h5 (then its sibling results/x.xdmf is opened).
It also runs with pvbatch, or with /usr/bin/python3 when ParaView's Python modules are
installed (Debian's `paraview` package puts them in dist-packages).

  --field NAME   any point or cell array of the file (default von_mises); a vector
                 (displacement) is coloured by its magnitude, NAME:X / :Y / :Z picks a
                 component. A name that is not there: exit 1 and the list of the arrays.
  --scale S      warp magnification (default auto: 10% of the larger extent of the
                 mesh over the largest |displacement|, 3 significant digits; 0: no warp).
  --clip P       colour range from the (100-P)th to the P-th percentile of the array
                 (default 99.5, as tools/plot_solution.py; 100: full range); --range
                 MIN MAX sets it explicitly. The scalar bar title says which.
  --edges        draw the element edges (Surface With Edges).
  --size WxH     image size in pixels (default 1200x800).
  --step K       a result with load steps: draw step K (default the last; the title says which).
                 x.xdmf holds every step (a Temporal collection), which Xdmf3ReaderT reads as
                 one block per step, all drawn on top of each other: the tool reads a copy of
                 the chosen step's grids only (in a temporary folder, removed at the end).
  --zoom Z       frame a part of the picture instead of the whole scene: 'contact' frames
                 the contact zone (the contact nodes with a positive normal force, all
                 contact nodes when none has one), warped like the bodies, with a margin of
                 half its size (at least two contact segments) on every side;
                 X0,X1,Y0,Y1 frames that box (model coordinates, undeformed).
The contact line is drawn on top of the bodies as a black polyline per body (and per contact
pair), through the contact nodes of that body (/contact/coordinates, or a pair's
/contact/pair_<k>, matched to the body's nodes) warped by the
body's displacement (of the step drawn) with the same magnification as the bodies: where the
bodies touch the two lines lie on each other, where they are apart the gap is seen between
them. A side whose nodes are not the contact nodes (the master side of non-matching meshes)
gets no line. The file's own contact-line grids (undeformed) are not drawn, except for an
array that only they have (pressure, shear, state, ...): then they are coloured by it, warped
by their first body's displacement, over the bodies in a solid grey.
Solid (3D) results (root attribute dimension = 3): the bodies are clipped by a plane through
the contact (undeformed, then warped) and drawn in a parallel view along the plane's normal,
the coordinate axis closest to the contact's mean normal up (cut_plane):
  --cut auto     (default) a symmetry plane through the contact zone: a plane of the model's
                 bounding box across the contact normal on which the active zone ends on one
                 side only (x = 0 of a quarter model: the whole model kept, its symmetry face
                 seen); else the plane through the contact centre (the normal-force weighted
                 mean of the active contact nodes) across the first such axis
  --cut x|y|z    the plane normal to that axis through the contact centre; x=V at x = V; an
                 axis plane keeps the side where the model reaches farther
  --cut PX,PY,PZ,NX,NY,NZ  the plane through P with normal N, keeping N's side
  --cut none     no clip
  --zoom contact frames the active contact zone (warped) in that view; a box X0,X1,Y0,Y1 is
                 for plane results only.
The log line names the plane. An array of the contact surfaces only (pressure, gap, ...)
shows the surfaces alone (the file's faces, warped by their slave body's displacement), seen
along their mean normal. No contact lines are drawn.
Tested with Debian 12's ParaView 5.11 (pvpython is in the package python3-paraview).

Headless nodes: rendering needs an X display, or an offscreen (EGL/OSMesa) ParaView build.
Without DISPLAY the tool re-runs itself as `xvfb-run -a pvbatch tools/paraview_view.py ...`
when xvfb-run is installed (Debian: apt-get install xvfb); with an offscreen build set
RC_PV_OFFSCREEN=1 to skip that. Without either it exits 1 and says so (plain pvpython
would crash in the X window code). When xvfb-run hands out a dead display (ParaView:
"bad X server connection", SIGABRT, exit 134; seen in 2 of 36 runs) the re-run is tried
once more; any other abnormal end of the re-run becomes a one-line message and exit 1.
The file is opened with Xdmf3ReaderT, which reads the spatial Collection of x.xdmf
(body1 .. bodyN and the contact lines) as one block per grid. Not Xdmf3ReaderS: it reads the grids of a
spatial Collection as pieces of one dataset, and ParaView merges the pieces for rendering
keeping only the arrays every piece has; the contact line shares none with the bodies, so
the bodies are drawn grey (solid colour) although the scalar bar is shown. The file is
always opened by its absolute path: Debian's Xdmf3 readers abort on a bare file name
(they look for 'default.xdmfdefault.h5').
Exit 0 on success, 1 with a message on any failure.
"""
import argparse
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time

TOOL = "paraview_view"


def fail(msg):
    print(f"{TOOL}: {msg}", file=sys.stderr)
    return 1


def parse(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("result", metavar="RESULT", help="results/x.xdmf or results/x.h5")
    ap.add_argument("-o", "--output", default="view.png", help="output PNG (default view.png)")
    ap.add_argument("--field", default="von_mises", help="point or cell array to colour by (NAME or NAME:X|Y|Z)")
    ap.add_argument("--scale", default="auto", help="warp magnification, 'auto' (default) or a number (0: none)")
    ap.add_argument("--clip", type=float, default=99.5, help="colour range percentile (default 99.5; 100: full)")
    ap.add_argument("--range", type=float, nargs=2, metavar=("MIN", "MAX"), help="explicit colour range")
    ap.add_argument("--edges", action="store_true", help="draw the element edges")
    ap.add_argument("--size", default="1200x800", help="image size WxH in pixels (default 1200x800)")
    ap.add_argument("--list", action="store_true", help="list the point and cell arrays and exit")
    ap.add_argument("--step", type=int, default=None, metavar="K",
                    help="load step K of a result with load steps (default: the last)")
    ap.add_argument("--zoom", default=None, metavar="contact|X0,X1,Y0,Y1",
                    help="frame the contact zone ('contact') or a box X0,X1,Y0,Y1 (plane results)")
    ap.add_argument("--cut", default="auto", metavar="auto|none|x|y|z|x=V|PX,PY,PZ,NX,NY,NZ",
                    help="solid results: the clip plane through the contact (default auto)")
    return ap.parse_args(argv)


def xdmf_path(result):
    """Absolute path of the XDMF file of a result (x.h5 -> x.xdmf), or None."""
    p = os.path.abspath(result)
    if p.endswith(".h5"):
        p = p[:-3] + ".xdmf"
    return p if os.path.isfile(p) else None


def headless_reexec(argv):
    """Without a display: run this script again under xvfb-run (returns its exit code), or
    None when rendering can go ahead here (display present, offscreen build, already
    wrapped, or only --list)."""
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY") or os.environ.get("RC_PV_OFFSCREEN") \
            or os.environ.get("RC_PV_WRAPPED") or "--list" in argv:
        return None
    xvfb = shutil.which("xvfb-run")
    if not xvfb:
        return fail("no X display (DISPLAY unset) and no xvfb-run: install xvfb (apt-get install xvfb), or "
                    "run 'xvfb-run -a pvbatch tools/paraview_view.py ...', or with an offscreen (EGL/OSMesa) "
                    "ParaView build set RC_PV_OFFSCREEN=1")
    interp = shutil.which("pvbatch") or shutil.which("pvpython") or sys.executable
    env = dict(os.environ, RC_PV_WRAPPED="1")
    cmd = [xvfb, "-a", interp, os.path.abspath(__file__), *argv]
    for attempt in (1, 2):
        try:
            q = subprocess.run(cmd, env=env, stderr=subprocess.PIPE, text=True, errors="replace")
        except OSError as e:
            return fail(f"cannot run {xvfb}: {e}")
        err, rc = q.stderr or "", q.returncode
        clean = ANSI.sub("", err)
        dead = DEAD_DISPLAY.search(clean)
        # a dead display: xvfb-run -a can hand out a server number another xvfb-run took at the
        # same moment; ParaView then aborts (SIGABRT, exit 134) or xvfb-run exits 1
        if attempt == 1 and dead and (rc in (134, -signal.SIGABRT) or (rc == 1 and "xvfb-run:" in dead.group(0))):
            print(f"{TOOL}: note: xvfb-run gave a dead X display ({oneline(dead.group(0))}), retrying once",
                  file=sys.stderr)
            time.sleep(1.0 + random.random())
            continue
        if rc in (0, 1):               # the child's own result, its one-line message on exit 1
            sys.stderr.write(err)
            return rc
        how = f"signal {-rc} ({signal.Signals(-rc).name})" if rc < 0 and -rc in signal.valid_signals() \
            else f"exit {rc}" + (f" (signal {signal.Signals(rc - 128).name})" if 128 < rc < 160 and
                                 rc - 128 in signal.valid_signals() else "")
        line = key_line(clean, dead)
        return fail(f"rendering under xvfb-run ended abnormally, {how}"
                    f"{' on the retry' if attempt == 2 else ''}{': ' + line if line else ''}"
                    f"{' (rerun)' if dead else ''}")
    return fail("unreachable")  # pragma: no cover


ANSI = re.compile(r"\x1b\[[0-9;]*m")
DEAD_DISPLAY = re.compile(r"[^\n]*(bad X server connection|cannot open display|can't open display|"
                          r"unable to open display|could not open display|Xvfb failed to start)[^\n]*", re.I)


def oneline(text, n=200):
    """text squeezed to one line of at most n characters (loguru's prefix dropped)."""
    t = re.sub(r"^\(\s*[0-9.]+s\)\s*\[[^]]*\]\s*\S*\s*(ERR|FATL|WARN)\|\s*", "", text.strip())
    t = " ".join(re.sub(r" \(0x[0-9a-fA-F]+\)", "", t).split())          # object addresses
    return t if len(t) <= n else t[: n - 3] + "..."


def key_line(text, dead=None):
    """The line of a crashed child's stderr that says why: the dead display, else the last
    error/fatal/exception line, else the last line that is not part of a stack trace."""
    if dead:
        return oneline(dead.group(0))
    lines = [t for t in text.splitlines() if t.strip()]
    for t in reversed(lines):
        if re.search(r"ERR\||what\(\)|Error|error:|Traceback|Segmentation|Abort", t) and "FATL| Signal" not in t:
            return oneline(t)
    rest = [t for t in lines if not re.match(r"\s*\d+\s+0x[0-9a-f]+", t) and "Stack trace" not in t]
    return oneline(rest[-1]) if rest else ""


def arrays(src):
    """{name: ('POINTS' | 'CELLS', number of components)} of a pipeline source."""
    out = {}
    for assoc, data in (("CELLS", src.CellData), ("POINTS", src.PointData)):
        for name in data.keys():
            out[name] = (assoc, data[name].GetNumberOfComponents())
    return out


def list_text(arr):
    pts = [f"{n} ({c} comp.)" if c > 1 else n for n, (a, c) in sorted(arr.items()) if a == "POINTS"]
    cls = [f"{n} ({c} comp.)" if c > 1 else n for n, (a, c) in sorted(arr.items()) if a == "CELLS"]
    return f"point arrays: {', '.join(pts) or '(none)'}\ncell arrays: {', '.join(cls) or '(none)'}"


def field_unit(xdmf, name):
    """Unit of an XDMF attribute: the `units` attribute of the HDF5 dataset it points to,
    else the root unit_length/unit_stress attributes (SI m, Pa when absent) by the kind of
    field ('' for an unknown one)."""
    import xml.etree.ElementTree as ET
    kind = "length" if name.startswith("displacement") or name in ("gap", "g0") else \
        "stress" if name in ("von_mises", "contact_pressure", "pressure", "sxx", "syy", "sxy", "szz", "syz", "sxz",
                             "stress") \
        else None
    default = {"length": "m", "stress": "Pa", None: ""}[kind]
    try:
        import h5py
        ref = None
        for att in ET.parse(xdmf).getroot().iter("Attribute"):
            if att.get("Name") == name:
                item = att.find("DataItem")
                if item is not None and item.text and ":" in item.text:
                    ref = item.text.strip()
                    break
        h5 = os.path.join(os.path.dirname(xdmf), ref.split(":", 1)[0]) if ref else xdmf[:-5] + ".h5"
        with h5py.File(h5, "r") as f:
            def text(obj, key):
                v = obj.attrs.get(key)
                if hasattr(v, "reshape"):                     # numpy array or scalar
                    v = v.reshape(-1)[0] if v.size else b""
                if isinstance(v, bytes):
                    v = v.decode("utf-8", "replace")
                return "" if v is None else str(v).strip().strip("\x00").strip()
            if ref and ref.split(":", 1)[1] in f:
                u = text(f[ref.split(":", 1)[1]], "units")
                if u:
                    return u
            return (text(f, "unit_" + kind) or default) if kind else default
    except Exception:  # noqa: BLE001 - no h5py, unreadable file: the SI default
        return default


def values(src, name, assoc, comp):
    """The array as a numpy vector (component comp, -1: magnitude) over all blocks, or None."""
    import numpy as np
    from paraview import servermanager
    from paraview.vtk.numpy_interface import dataset_adapter as dsa
    data = dsa.WrapDataObject(servermanager.Fetch(src))
    a = (data.PointData if assoc == "POINTS" else data.CellData)[name]
    chunks = a.Arrays if hasattr(a, "Arrays") else [a]
    out = []
    for c in chunks:
        if c is None or isinstance(c, dsa.VTKNoneArray):      # a block without this array
            continue
        c = np.asarray(c, dtype=float)
        if c.ndim == 2:
            c = np.sqrt((c * c).sum(axis=1)) if comp < 0 else c[:, comp]
        out.append(c.reshape(-1))
    v = np.concatenate(out) if out else np.zeros(0)
    v = v[np.isfinite(v)]
    return v if v.size else None


# ---- the contact line and the zoom box (numpy and h5py only: no ParaView needed) ----------
def contact_lines(h5path, scale, step=None):
    """The contact line of each body warped by that body's displacement times scale: a list of
    (body, points) with points an (n, 2) array in contact-line order, n >= 2. The contact
    nodes (/contact/coordinates) are matched to a body's nodes by identical coordinates;
    a body with fewer than two matching nodes (a non-matching mortar side) has no line.
    With several contact pairs each pair's line (/contact/pair_<k>) is matched to its own two
    bodies: a body in two pairs has two lines.
    Also returns the contact nodes of all pairs (m, 2) and the boolean mask of the active ones
    (normal force > 0)."""
    pieces, c, active = contact_pieces(h5path, scale, step)
    return [(b, p) for b, p, _ in pieces], c, active


def contact_pieces(h5path, scale, step=None):
    """contact_lines with, for each line, the rows of /contact its points come from. step: the
    load step K whose displacements and forces are used (/steps/step_K), None: the final ones."""
    import h5py
    import numpy as np

    def xy_rows(a):
        a = np.asarray(a, dtype=float)
        return a.T if a.shape[0] == 2 and a.shape[-1] != 2 else a

    with h5py.File(h5path, "r") as f:
        c = xy_rows(f["contact/coordinates"][()])                     # (m, 2)
        at = f if step is None or "steps" not in f else f[f"steps/step_{step}"]
        lam = np.asarray(at["contact/normal_force"][()], dtype=float).reshape(-1)
        npair = int(f.attrs.get("pairs", 1))
        # (first row, last row + 1, bodies) of each pair
        if npair > 1:
            spans, first = [], 0
            for k in range(1, npair + 1):
                g = f[f"contact/pair_{k}"]
                n = g["normal_force"].shape[0]
                spans.append((first, first + n, [int(v) for v in np.asarray(g.attrs["bodies"]).reshape(-1)[:2]]))
                first += n
        else:
            spans = [(0, c.shape[0], [1, 2])]
        bodies = {}
        for b in sorted({b for _, _, bs in spans for b in bs}):
            g, gu = f.get(f"body{b}"), at.get(f"body{b}")
            if g is None or gu is None or "coordinates" not in g or "displacement" not in gu:
                continue
            bodies[b] = (xy_rows(g["coordinates"][()]), xy_rows(gu["displacement"][()]))
    pieces = []
    for r0, r1, bs in spans:
        for b in bs:
            if b not in bodies:
                continue
            xy, u = bodies[b]
            index = {(float(x), float(y)): k for k, (x, y) in enumerate(xy)}
            rows = [(i, index.get((float(x), float(y)))) for i, (x, y) in enumerate(c[r0:r1], start=r0)]
            rows = [(i, k) for i, k in rows if k is not None]
            if len(rows) < 2:
                continue
            ci, bi = (np.array(t) for t in zip(*rows))
            pieces.append((b, c[ci] + scale * u[bi], ci))
    return pieces, c, lam > 0.0


def zoom_box(spec, h5path=None, scale=0.0, step=None):
    """(x0, x1, y0, y1) to frame: spec 'X0,X1,Y0,Y1' as given, or 'contact': the active contact
    nodes (all contact nodes when none is active) of both bodies' warped contact lines, with
    a margin of half the box's larger side, at least two contact segments, on every side.
    ValueError for a bad spec or a result without a contact line."""
    import numpy as np
    if spec != "contact":
        try:
            x0, x1, y0, y1 = (float(t) for t in spec.split(","))
        except ValueError:
            raise ValueError(f"--zoom takes 'contact' or X0,X1,Y0,Y1 (four numbers), not {spec!r}") from None
        if not (x1 > x0 and y1 > y0):
            raise ValueError(f"--zoom box {spec!r}: needs X0 < X1 and Y0 < Y1")
        return x0, x1, y0, y1
    pieces, c, active = contact_pieces(h5path, scale, step)
    if c.shape[0] < 2:
        raise ValueError(f"{h5path}: no contact line to zoom on")
    pick = active if active.any() else np.ones(c.shape[0], dtype=bool)
    pts = [c[pick]]
    for _, p, rows in pieces:
        pts.append(p[pick[rows]])
    pts = np.vstack(pts)
    seg = float(np.median(np.hypot(*np.diff(c, axis=0).T)))
    (x0, y0), (x1, y1) = pts.min(axis=0), pts.max(axis=0)
    margin = max(0.5 * max(x1 - x0, y1 - y0), 2.0 * seg)
    return x0 - margin, x1 + margin, y0 - margin, y1 + margin


# ---- solid (3D) results: the clip plane and the contact surfaces (numpy and h5py only) -----
AXES = "xyz"


def result_dimension(h5path):
    """3 for a result of solid bodies (the root attribute `dimension` that 3D runs write), else 2."""
    import h5py
    with h5py.File(h5path, "r") as f:
        return int(f.attrs.get("dimension", 2))


def contact_zone_3d(h5path, step=None):
    """The contact of a solid result, all pairs: the contact nodes (m, 3), their normal forces
    (m) (of load step `step`, None: the final ones), the unit mean normal weighted by the normal
    forces (all nodes alike when none is positive), and the model's bounding box (lo, hi) over
    every body's nodes."""
    import h5py
    import numpy as np
    with h5py.File(h5path, "r") as f:
        c = np.asarray(f["contact/coordinates"][()], dtype=float).T
        nrm = np.asarray(f["contact/normal"][()], dtype=float).T
        at = f if step is None or "steps" not in f else f[f"steps/step_{step}"]
        lam = np.asarray(at["contact/normal_force"][()], dtype=float).reshape(-1)
        xs = [np.asarray(f[f"body{b}/coordinates"][()], dtype=float)
              for b in range(1, int(f.attrs.get("bodies", 2)) + 1)]
    if c.shape[0] == 0:
        raise ValueError(f"{h5path}: no contact node")
    w = np.where(lam > 0.0, lam, 0.0) if np.any(lam > 0.0) else np.ones(lam.size)
    n = (w[:, None] * nrm).sum(axis=0)
    n = n / np.linalg.norm(n) if np.linalg.norm(n) > 0.0 else np.array([0.0, 1.0, 0.0])
    lo = np.min([x.min(axis=1) for x in xs], axis=0)
    hi = np.max([x.max(axis=1) for x in xs], axis=0)
    return c, lam, n, lo, hi


def cut_plane(spec, h5path, step=None):
    """The clip plane of a solid result's picture, or None for --cut none: (origin (3,), unit
    normal (3,), up axis 0-2, note). The picture keeps the part of the bodies on the side the
    normal points to and looks at the cut along the normal; the up axis is the coordinate axis
    closest to the contact's mean normal (contact_zone_3d) that the plane does not face.
    The contact centre is the normal-force weighted mean of the active contact nodes (all
    contact nodes when none is active). spec:
      auto     a symmetry plane through the contact zone: the plane of the model's bounding box
               normal to an axis across the contact normal on which the active zone ends on one
               side only (a half or quarter model: the zone is the part of a whole one); else
               the plane through the contact centre normal to the first such axis (x before y
               before z)
      x, y, z  the plane normal to that axis through the contact centre; x=V at x = V
      PX,PY,PZ,NX,NY,NZ  the plane through point P with normal N (the kept side: N's)
    An axis plane keeps the side where the model reaches farther from it (+ on a tie).
    ValueError for a spec it does not understand or a result without contact nodes."""
    import numpy as np
    spec = spec.strip().lower()
    if spec == "none":
        return None
    c, lam, n, lo, hi = contact_zone_3d(h5path, step)
    pick = lam > 0.0 if np.any(lam > 0.0) else np.ones(lam.size, dtype=bool)
    w = lam[pick] if np.any(lam > 0.0) else np.ones(int(pick.sum()))
    centre = (w[:, None] * c[pick]).sum(axis=0) / w.sum()
    order = [int(i) for i in np.argsort(-np.abs(n), kind="stable")]
    across = [i for i in range(3) if i != order[0]]
    tol = 1e-9 * float(np.max(hi - lo))

    def axis_plane(i, v, note):
        origin = centre.copy()
        origin[i] = v
        normal = np.zeros(3)
        normal[i] = 1.0 if hi[i] - v >= v - lo[i] - tol else -1.0
        return origin, normal, note

    m = re.fullmatch(r"([xyz])(?:\s*=\s*(.+))?", spec)
    if spec == "auto":
        sym = []
        for i in across:
            ends = [v for v in (lo[i], hi[i]) if np.any(np.abs(c[pick, i] - v) <= tol)]
            if len(ends) == 1:
                sym.append((i, float(ends[0])))
        if sym:
            i, v = sym[0]
            origin, normal, note = axis_plane(i, v, f"symmetry plane {AXES[i]} = {v:.4g} (the contact zone ends "
                                                    f"on the model's boundary there)")
        else:
            i = across[0]
            origin, normal, note = axis_plane(i, float(centre[i]),
                                              f"plane {AXES[i]} = {centre[i]:.4g} through the contact centre")
    elif m:
        i = AXES.index(m.group(1))
        if m.group(2) is None:
            origin, normal, note = axis_plane(i, float(centre[i]),
                                              f"plane {AXES[i]} = {centre[i]:.4g} through the contact centre")
        else:
            try:
                v = float(m.group(2))
            except ValueError:
                raise ValueError(f"{m.group(1)}=V takes a number, not {m.group(2)!r}") from None
            origin, normal, note = axis_plane(i, v, f"plane {AXES[i]} = {v:.4g}")
    else:
        try:
            t = [float(x) for x in spec.split(",")]
        except ValueError:
            t = []
        if len(t) != 6 or not np.linalg.norm(t[3:]) > 0.0:
            raise ValueError(f"expected auto, none, x, y, z, x=V (y=V, z=V) or PX,PY,PZ,NX,NY,NZ "
                             f"(a point and a nonzero normal), not {spec!r}")
        origin = np.array(t[:3])
        normal = np.array(t[3:]) / np.linalg.norm(t[3:])
        note = (f"plane through ({', '.join(f'{v:.4g}' for v in origin)}) normal "
                f"({', '.join(f'{v:.3g}' for v in normal)})")
    up = next(i for i in order if abs(normal[i]) < 0.9)
    return origin, normal, up, note


def contact_points_3d(h5path, scale, step=None):
    """The contact nodes of a solid result (m, 3), each pair's warped by scale times its slave
    body's displacement (of load step `step`, None: the final one); a node that is none of its
    slave body's nodes stays where it is."""
    import h5py
    import numpy as np
    with h5py.File(h5path, "r") as f:
        c = np.asarray(f["contact/coordinates"][()], dtype=float).T
        at = f if step is None or "steps" not in f else f[f"steps/step_{step}"]
        npair = int(f.attrs.get("pairs", 1))
        out, first = c.copy(), 0
        for k in range(1, npair + 1):
            g = f[f"contact/pair_{k}"]
            n = g["normal_force"].shape[0]
            b = int(np.asarray(g.attrs.get("slave_body", 1)).reshape(-1)[0])
            if f"body{b}" in f and f"body{b}" in at and "displacement" in at[f"body{b}"]:
                xyz = np.asarray(f[f"body{b}/coordinates"][()], dtype=float).T
                u = np.asarray(at[f"body{b}/displacement"][()], dtype=float).T
                index = {tuple(p): j for j, p in enumerate(xyz.tolist())}
                for i in range(first, first + n):
                    j = index.get(tuple(c[i].tolist()))
                    if j is not None:
                        out[i] = c[i] + scale * u[j]
            first += n
    return out


def zoom_box_3d(h5path, scale, step, origin, normal, up):
    """(focal point (3,), half width, half height) of a view along `normal` (up: the axis up
    in the picture) that frames the active contact nodes (all when none is active) warped by
    scale, with a margin of half the larger side (at least two mean contact-node spacings)."""
    import numpy as np
    pts = contact_points_3d(h5path, scale, step)
    c, lam, _, _, _ = contact_zone_3d(h5path, step)
    pick = lam > 0.0 if np.any(lam > 0.0) else np.ones(lam.size, dtype=bool)
    u = np.zeros(3)
    u[up] = 1.0
    u = u - (u @ normal) * normal
    u /= np.linalg.norm(u)
    r = np.cross(normal, u)
    pr, pu = pts[pick] @ r, pts[pick] @ u
    spacing = float(np.sqrt(np.ptp(c @ r) * np.ptp(c @ u) / max(c.shape[0], 1))) if c.shape[0] > 1 else 0.0
    (r0, r1), (u0, u1) = (pr.min(), pr.max()), (pu.min(), pu.max())
    margin = max(0.5 * max(r1 - r0, u1 - u0), 2.0 * spacing)
    d = float(origin @ normal)
    focal = 0.5 * (r0 + r1) * r + 0.5 * (u0 + u1) * u + d * normal
    return focal, 0.5 * (r1 - r0) + margin, 0.5 * (u1 - u0) + margin


def step_view(xdmf, step, folder):
    """An XDMF of one load step of a result: the grids (bodies and contact lines) of step K
    (1-based; None: the last) of the Temporal collection, or all the grids of a result without
    load steps, their HDF5 references made absolute, written into folder. Xdmf3ReaderT reads
    every step of the Temporal collection of x.xdmf as a block of its own (all drawn on top of
    each other), hence this file. Returns (path, step shown, number of steps, time or None,
    body grid names, contact grid names); ValueError for a step that is not there."""
    import xml.etree.ElementTree as ET
    tree = ET.parse(xdmf)
    domain = tree.getroot().find("Domain")
    top = domain.find("Grid")
    steps = [g for g in top.findall("Grid")] if top.get("CollectionType") == "Temporal" else [top]
    n = len(steps)
    if step is None:
        step = n
    if not 1 <= step <= n:
        raise ValueError(f"--step {step}: the result has {n} load step{'s' if n > 1 else ''} (1 to {n})")
    grid = steps[step - 1]
    t = grid.find("Time")
    time = float(t.get("Value")) if t is not None and n > 1 else None
    if t is not None:
        grid.remove(t)
    here = os.path.dirname(xdmf)
    for item in grid.iter("DataItem"):
        if item.get("Format") == "HDF" and item.text and ":" in item.text:
            file_, path = item.text.strip().split(":", 1)
            item.text = os.path.join(here, file_) + ":" + path
    kids = [g.get("Name", "") for g in grid.findall("Grid")] if grid.get("GridType") == "Collection" \
        else [grid.get("Name", "")]
    bodies = [k for k in kids if re.fullmatch(r"body\d+", k)]
    lines = [k for k in kids if k not in bodies]
    domain.remove(top)
    domain.append(grid)
    out = os.path.join(folder, "step.xdmf")
    tree.write(out, encoding="utf-8", xml_declaration=True)
    return out, step, n, time, bodies, lines


def warped_lines(view_file, h5path, scale, step, line_grids, folder):
    """A copy of the step's XDMF whose contact-line grids have the warped points of their first
    body's contact line as geometry (inline), for an array that lives on the contact lines only;
    a grid whose first body's nodes are not its nodes (a non-matching side) keeps its own,
    undeformed, points. Returns the path."""
    import h5py
    import numpy as np
    if result_dimension(h5path) == 3:
        return warped_surfaces(view_file, h5path, scale, step, line_grids, folder)
    pieces, c, _ = contact_pieces(h5path, scale, step)
    with h5py.File(h5path, "r") as f:
        npair = int(f.attrs.get("pairs", 1))
        sizes = [f[f"contact/pair_{k}/normal_force"].shape[0] for k in range(1, npair + 1)] if npair > 1 \
            else [c.shape[0]]
    first = np.cumsum([0] + sizes)

    def points(pair):
        k = int(pair or 1)
        if k > len(sizes):
            return None
        r0, r1 = first[k - 1], first[k]
        full = [p for _, p, ci in pieces if len(ci) == r1 - r0 and ci[0] == r0 and ci[-1] == r1 - 1]
        return (r1 - r0, " ".join(f"{x!r} {y!r} 0" for x, y in full[0])) if full else None

    return inline_contact_geometry(view_file, line_grids, points, folder)


def warped_surfaces(view_file, h5path, scale, step, line_grids, folder):
    """warped_lines for a solid result: a copy of the step's XDMF whose contact-surface grids
    have the contact nodes warped by their slave body's displacement (contact_points_3d) as
    geometry (inline). Returns the path."""
    import h5py
    import numpy as np
    pts = contact_points_3d(h5path, scale, step)
    with h5py.File(h5path, "r") as f:
        npair = int(f.attrs.get("pairs", 1))
        sizes = [f[f"contact/pair_{k}/normal_force"].shape[0] for k in range(1, npair + 1)]
    first = np.cumsum([0] + sizes)

    def points(pair):
        r0, r1 = (first[int(pair) - 1], first[int(pair)]) if pair else (0, first[-1])
        return r1 - r0, " ".join(f"{x!r} {y!r} {z!r}" for x, y, z in pts[r0:r1])

    return inline_contact_geometry(view_file, line_grids, points, folder)


def inline_contact_geometry(view_file, line_grids, points, folder):
    """A copy of view_file (folder/lines.xdmf) in which each contact grid among line_grids
    ('contact' or 'contact_pair<k>') takes the points that points(k or None) gives, (count,
    'x y z ...'), as inline geometry (None: it keeps its own). Returns the path."""
    import xml.etree.ElementTree as ET
    tree = ET.parse(view_file)
    for g in tree.getroot().iter("Grid"):
        name = g.get("Name", "")
        m = re.fullmatch(r"contact(?:_pair(\d+))?", name)
        if name not in line_grids or m is None:
            continue
        new = points(m.group(1))
        geo = g.find("Geometry")
        item = geo.find("DataItem") if geo is not None else None
        if new is None or item is None:
            continue
        item.set("Format", "XML")
        item.set("Dimensions", f"{new[0]} 3")
        item.text = new[1]
    out = os.path.join(folder, "lines.xdmf")
    tree.write(out, encoding="utf-8", xml_declaration=True)
    return out


def camera_box(box, aspect):
    """(centre x, centre y, parallel scale) of a 2D camera that shows the box whole in a
    picture of width/height = aspect (parallel scale: half the visible height)."""
    x0, x1, y0, y1 = box
    return 0.5 * (x0 + x1), 0.5 * (y0 + y1), max(0.5 * (y1 - y0), 0.5 * (x1 - x0) / aspect)


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    a = parse(argv)
    xdmf = xdmf_path(a.result)
    if xdmf is None:
        return fail(f"no XDMF file for {a.result!r} (expected {os.path.abspath(a.result)}"
                    f"{'' if a.result.endswith('.xdmf') else ' or its .xdmf sibling'})")
    try:
        w, h = (int(t) for t in a.size.lower().split("x"))
        assert 16 <= w <= 8000 and 16 <= h <= 8000
    except (ValueError, AssertionError):
        return fail(f"--size must be WxH in pixels (16-8000), not {a.size!r}")
    field, _, compname = a.field.partition(":")
    h5 = xdmf[:-5] + ".h5"
    if a.zoom not in (None, "contact"):
        try:
            zoom_box(a.zoom)
        except ValueError as e:
            return fail(str(e))
    if a.cut != "auto":
        try:
            if result_dimension(h5) == 3:
                cut_plane(a.cut, h5)          # a bad --cut fails here, before ParaView starts
        except ValueError as e:
            return fail(f"--cut {a.cut}: {e}")
        except Exception:  # noqa: BLE001 - an unreadable file: reported by render()
            pass
    if a.step is not None:
        import tempfile
        tmp = tempfile.mkdtemp(prefix="paraview_view.")
        try:
            step_view(xdmf, a.step, tmp)
        except ValueError as e:
            return fail(str(e))
        except Exception:  # noqa: BLE001 - reported by render()
            pass
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
    rc = headless_reexec(argv)
    if rc is not None:
        return rc
    try:
        import paraview.simple as pvs
    except ImportError as e:
        return fail(f"ParaView's Python modules not found ({e}): run with pvpython or pvbatch "
                    "(Debian: apt-get install paraview xvfb)")

    import tempfile
    tmp = tempfile.mkdtemp(prefix="paraview_view.")
    try:
        return render(a, pvs, xdmf, h5, field, compname, w, h, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def render(a, pvs, xdmf, h5, field, compname, w, h, tmp):
    """The picture (after the checks of main): see the docstring."""
    try:
        view_file, step, nstep, time, body_grids, line_grids = step_view(xdmf, a.step, tmp)
    except ValueError as e:
        return fail(str(e))
    except Exception as e:  # noqa: BLE001 - an XDMF file this tool does not understand
        return fail(f"cannot read the grids of {xdmf}: {type(e).__name__}: {e}")
    reader = pvs.Xdmf3ReaderT(FileName=[view_file])     # T, not S; absolute path: see the docstring
    reader.UpdatePipeline()
    arr = arrays(reader)
    if a.list:
        print(f"{TOOL}: {xdmf}\n{list_text(arr)}")
        return 0
    if field not in arr:
        return fail(f"no array '{field}' in {xdmf}\n{list_text(arr)}")
    assoc, ncomp = arr[field]
    comp = -1
    if compname:
        names = {"X": 0, "Y": 1, "Z": 2, "MAGNITUDE": -1}
        comp = names.get(compname.upper(), int(compname) if compname.isdigit() else None)
        if comp is None or comp >= ncomp:
            return fail(f"component '{compname}' of '{field}' ({ncomp} components): use X, Y, Z or Magnitude")
    elif ncomp == 1:
        comp = 0

    try:
        dim = result_dimension(h5)
    except (OSError, ValueError):
        dim = 2
    if dim == 3 and a.zoom not in (None, "contact"):
        return fail(f"--zoom {a.zoom}: a solid result takes --zoom contact (the view is along the clip plane's normal)")

    # warp
    # the bodies alone (the contact lines are drawn below, warped like them); the reader's
    # contact grids only for an array that no body has (they are not warped)
    bodies, on_lines = reader, False
    if body_grids and line_grids:
        bodies = pvs.ExtractBlock(Input=reader, Selectors=[f"/Root/{g}" for g in body_grids])
        bodies.UpdatePipeline()
        on_lines = field not in arrays(bodies)
    # a solid result: the bodies clipped by a plane through the contact (undeformed, then warped)
    cut, shown = None, bodies
    if dim == 3 and not on_lines:
        try:
            cut = cut_plane(a.cut, h5, step if nstep > 1 else None)
        except (ValueError, OSError, KeyError) as e:
            return fail(f"--cut {a.cut}: {e}")
        if cut is not None:
            shown = pvs.Clip(Input=bodies)
            shown.ClipType = "Plane"
            shown.ClipType.Origin = [float(v) for v in cut[0]]
            shown.ClipType.Normal = [float(v) for v in cut[1]]
            shown.Invert = 0                     # keep the side the normal points to
            if hasattr(shown, "Crinkleclip"):
                shown.Crinkleclip = 0
            shown.UpdatePipeline()
    src, scale, how = shown, 0.0, "no warp"
    if "displacement" in arr and arr["displacement"][0] == "POINTS" and a.scale not in ("0", "0.0", "none"):
        info = bodies.GetDataInformation()
        b = info.GetBounds()
        size = max(b[1] - b[0], b[3] - b[2], b[5] - b[4])
        umax = bodies.PointData["displacement"].GetRange(-1)[1]
        if a.scale == "auto":
            scale = float(f"{0.1 * size / umax:.3g}") if umax > 0.0 and size > 0.0 else 1.0
            how = f"auto: 10% of extent {size:.3g} over largest displacement {umax:.3g}"
        else:
            try:
                scale = float(a.scale)
            except ValueError:
                return fail(f"--scale must be a number or 'auto', not {a.scale!r}")
            how = f"largest displacement {umax:.3g}"
        if scale != 0.0:
            src = pvs.WarpByVector(Input=shown, Vectors=["POINTS", "displacement"], ScaleFactor=scale)
    elif a.scale not in ("0", "0.0", "none"):
        how = "no 'displacement' point array: not warped"

    # an array of the contact lines only: the lines coloured by it, warped like the bodies
    # (their first body's displacement), the bodies in a solid colour
    coloured = src
    if on_lines:
        lines_file = warped_lines(view_file, h5, scale, step if nstep > 1 else None, line_grids, tmp)
        lreader = pvs.Xdmf3ReaderT(FileName=[lines_file])
        coloured = pvs.ExtractBlock(Input=lreader, Selectors=[f"/Root/{g}" for g in line_grids])
        coloured.UpdatePipeline()
    # colour range
    if a.range:
        lo, hi = a.range
        rng_note = "range set by --range"
    else:
        v = values(coloured if on_lines else shown, field, assoc, comp)
        if v is None:
            return fail(f"array '{field}' has no finite values")
        import numpy as np
        vmin, vmax = float(v.min()), float(v.max())
        if a.clip >= 100.0:
            lo, hi, rng_note = vmin, vmax, "full range"
        else:
            lo, hi = (float(q) for q in np.percentile(v, [100.0 - a.clip, a.clip]))
            if vmin >= 0.0 and lo <= 0.01 * hi:
                lo = vmin
            rng_note = f"clipped at the {a.clip:g}th percentile (all: {vmin:.4g} to {vmax:.4g})" \
                if (vmin < lo or vmax > hi) else "full range"
        if not hi > lo:
            hi = lo + (abs(lo) or 1.0)

    view = pvs.CreateRenderView()
    view.ViewSize = [w, h]
    for prop, val in (("UseColorPaletteForBackground", 0), ("Background", [1.0, 1.0, 1.0]),
                      ("OrientationAxesVisibility", 0)):
        if hasattr(view, prop):
            setattr(view, prop, val)
    disp = pvs.Show(src, view)
    disp.Representation = "Surface With Edges" if a.edges else "Surface"
    if on_lines:
        disp.ColorArrayName = ["POINTS", ""]
        disp.AmbientColor = disp.DiffuseColor = [0.8, 0.8, 0.8]
        if dim == 3:                              # the contact surfaces lie inside the bodies: alone
            pvs.Hide(src, view)
        disp = pvs.Show(coloured, view)
        disp.Representation = "Surface With Edges" if a.edges and dim == 3 else "Surface"
    if (on_lines or not a.edges) and hasattr(disp, "LineWidth"):
        disp.LineWidth = 5.0 if on_lines else 3.0     # polyline grids (a contact line) stay visible
    pvs.ColorBy(disp, (assoc, field) if comp < 0 and ncomp > 1 and not compname
                else (assoc, field, "Magnitude" if comp < 0 else "XYZ"[comp] if ncomp <= 3 else str(comp)))
    lut = pvs.GetColorTransferFunction(field)
    lut.ApplyPreset("Viridis (matplotlib)", True)
    if ncomp > 1:
        lut.VectorMode = "Magnitude" if comp < 0 else "Component"
        if comp >= 0:
            lut.VectorComponent = comp
    lut.RescaleTransferFunction(lo, hi)
    if hasattr(lut, "AutomaticRescaleRangeMode"):
        lut.AutomaticRescaleRangeMode = "Never"
    disp.SetScalarBarVisibility(view, True)
    bar = pvs.GetScalarBar(lut, view)
    label = field + (f" ({'magnitude' if comp < 0 else 'XYZ'[comp]})" if ncomp > 1 else "")
    unit = field_unit(xdmf, field)
    bar.Title = f"{label} [{unit or '-'}]"
    bar.ComponentTitle = "(clipped)" if rng_note.startswith("clipped") else ""
    for prop in ("TitleColor", "LabelColor"):
        if hasattr(bar, prop):
            setattr(bar, prop, [0.0, 0.0, 0.0])
    step_note = f", load step {step} of {nstep} (time {time:g})" if nstep > 1 else ""
    title = pvs.Text(Text=f"{os.path.basename(xdmf)}{step_note}: {label} [{unit or '-'}], {rng_note}\n"
                          f"warped by displacement x{scale:g} ({how})")
    td = pvs.Show(title, view)
    td.WindowLocation = "Upper Center"
    td.FontSize = 14
    if hasattr(td, "Color"):
        td.Color = [0.0, 0.0, 0.0]
    # the contact line of each body, warped like the bodies, drawn over them (plane results)
    lines = []
    try:
        if dim == 2:
            lines, _, _ = contact_lines(h5, scale, step if nstep > 1 else None)
    except (OSError, KeyError) as e:
        print(f"{TOOL}: note: no contact line drawn ({e})", file=sys.stderr)
    for _, pts in lines:
        pl = pvs.PolyLineSource(Points=[v for x, y in pts for v in (float(x), float(y), 0.0)])
        ld = pvs.Show(pl, view)
        ld.Representation = "Surface"
        ld.ColorArrayName = ["POINTS", ""]   # solid colour (ColorBy(ld, None) fails in ParaView 5.11)
        ld.AmbientColor = ld.DiffuseColor = [0.0, 0.0, 0.0]
        if hasattr(ld, "LineWidth"):
            ld.LineWidth = 2.0
    zoom_note = ""
    if dim == 3:
        return render_3d(a, pvs, view, h5, w, h, scale, step if nstep > 1 else None, cut, on_lines,
                         (label, assoc, lo, hi, unit, rng_note, step_note))
    view.InteractionMode = "2D"
    view.CameraPosition = [0.0, 0.0, 1.0]
    view.CameraFocalPoint = [0.0, 0.0, 0.0]
    view.CameraViewUp = [0.0, 1.0, 0.0]
    view.ResetCamera()
    if a.zoom is not None:
        try:
            box = zoom_box(a.zoom, h5, scale, step if nstep > 1 else None)
        except (ValueError, OSError, KeyError) as e:
            return fail(f"--zoom {a.zoom}: {e}")
        cx, cy, half = camera_box(box, w / h)
        view.CameraParallelProjection = 1
        view.CameraFocalPoint = [cx, cy, 0.0]
        view.CameraPosition = [cx, cy, 1.0]
        view.CameraParallelScale = half
        zoom_note = f", zoom x {box[0]:.4g} to {box[1]:.4g}, y {box[2]:.4g} to {box[3]:.4g}"
    out = os.path.abspath(a.output)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    pvs.SaveScreenshot(out, view, ImageResolution=[w, h])
    if not os.path.isfile(out):
        return fail(f"ParaView wrote no {out}")
    print(f"{TOOL}: wrote {a.output} ({label}, {assoc.lower()[:-1]} data, colour {lo:.4g} to {hi:.4g}{' ' + unit if unit else ''}, "
          f"{rng_note}, magnification {scale:g}, {len(lines)} contact lines{zoom_note}{step_note})")
    return 0


def render_3d(a, pvs, view, h5, w, h, scale, step, cut, on_lines, what):
    """The camera and the picture of a solid result (render's end): a parallel view of the clip
    plane's kept part along its normal, its up axis up (cut_plane); the contact surfaces alone
    (an array of theirs) along the contact's mean normal; --zoom contact frames the active
    contact zone (zoom_box_3d)."""
    import numpy as np
    label, assoc, lo, hi, unit, rng_note, step_note = what
    if cut is not None:
        origin, normal, up, note = cut
        clip_note = f"clip: {note}, normal ({', '.join(f'{v:.3g}' for v in normal)})"
    else:
        c, lam, n, _, _ = contact_zone_3d(h5, step)
        pick = lam > 0.0 if np.any(lam > 0.0) else np.ones(lam.size, dtype=bool)
        origin = c[pick].mean(axis=0)
        order = [int(i) for i in np.argsort(-np.abs(n), kind="stable")]
        if on_lines:               # the contact surfaces seen along their normal
            normal, up = np.sign(n[order[0]] or 1.0) * np.eye(3)[order[0]], order[1]
            clip_note = "the contact surfaces alone, seen along their mean normal"
        else:                      # --cut none: the whole bodies, from the side of the first axis across
            normal, up = np.eye(3)[[i for i in range(3) if i != order[0]][0]], order[0]
            clip_note = "no clip"
    view.CameraParallelProjection = 1
    view.CameraFocalPoint = [float(v) for v in origin]
    view.CameraPosition = [float(v) for v in origin - normal]
    view.CameraViewUp = [float(v) for v in np.eye(3)[up]]
    view.ResetCamera()
    zoom_note = ""
    if a.zoom == "contact":
        try:
            focal, hw, hh = zoom_box_3d(h5, scale, step, np.asarray(origin, dtype=float), normal, up)
        except (ValueError, OSError, KeyError) as e:
            return fail(f"--zoom contact: {e}")
        dist = float(np.linalg.norm(np.asarray(view.CameraPosition) - np.asarray(view.CameraFocalPoint)))
        view.CameraFocalPoint = [float(v) for v in focal]
        view.CameraPosition = [float(v) for v in focal - dist * normal]
        view.CameraParallelScale = max(hh, hw / (w / h))
        zoom_note = f", zoom on the contact zone ({2 * hw:.4g} x {2 * hh:.4g})"
    out = os.path.abspath(a.output)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    pvs.SaveScreenshot(out, view, ImageResolution=[w, h])
    if not os.path.isfile(out):
        return fail(f"ParaView wrote no {out}")
    print(f"{TOOL}: wrote {a.output} ({label}, {assoc.lower()[:-1]} data, colour {lo:.4g} to {hi:.4g}"
          f"{' ' + unit if unit else ''}, {rng_note}, magnification {scale:g}, {clip_note}{zoom_note}{step_note})")
    return 0


if __name__ == "__main__":
    try:
        status = main()
    except SystemExit as e:
        status = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    except Exception as e:  # noqa: BLE001 - report every failure with a message
        status = fail(f"error: {type(e).__name__}: {e}")
    # os._exit: skip ParaView's teardown, which under xvfb-run can end in an X error
    # (GLXBadContext) and exit status 1 after the picture was written.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)
