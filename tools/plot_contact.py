#!/usr/bin/python3
"""Normal contact pressure and gap along the contact line of robin_contact runs, several
runs overlaid, optionally with the Hertz line-contact pressure of a parabolic-gap scene; for
solid (3D) results a pressure map of each contact surface and the pressure along a line
through it, optionally with Hertz's point contact (the end of this text).

Usage: tools/plot_contact.py FILE.h5 [FILE.h5 ...] [--hertz] [--mindlin] [--radius R] [--pair K]
       [-o contact.png] [--title TEXT]
       solid results also [--line x|y|z|DX,DY,DZ] [--centre X,Y,Z] [--force P] [--csv FILE]

Top panel: /contact/pressure (nodal force / tributary length) against the arc length s along
the contact curve (/contact/s). The legend gives each run's contact force per unit thickness:
the resultant vector on body 1 (/contact/resultant_body1, two components) when the result
file has it, else the sum of the nodal normal forces (sum of
/contact/normal_force; a scalar, not a resultant: the normals vary along a curved contact);
the same is printed, one line per run ('plot_contact: NAME: ...'). Dotted vertical lines
mark the edges of each run's contact zone (the zero of p^2 extrapolated from the two
outermost active nodes, rc_results.contact_edges).
A run of several contact pairs (root attribute `pairs` > 1) gives one curve per pair, from
/contact/pair_<k>, labelled 'pair k (bodies A,B)', its force the resultant on the pair's
first body (/contact/pair_<k>/resultant_on_first_body).
With friction (the line has /contact/shear, or /contact/pair_<k>/shear), a panel under the
pressure shows the shear traction /contact/shear (tangential force / tributary length, signed
along the slave tangent) of each frictional line, the stick zone shaded in the curve's colour
(each run of neighbouring stick nodes, /contact/state = 1, spanning half a node spacing beyond
its end nodes); the tangential resultant and the stick and slip counts are printed
('plot_contact: NAME: tangential resultant Q = ..., stick n, slip n').
Next panel: the gap /contact/gap = B1u1 + B2u2 - g0 (<= 0; < 0 where the bodies are apart).
Units from the result file (root attributes unit_length/unit_force/unit_stress and the
datasets' `units` attributes; SI m, N, Pa when absent), values scaled to an SI prefix
(MPa, µm, MN/m) written in the axis labels: no matplotlib offset text; numbers in the
legends are written with their unit ('3000 N/mm', '32 MPa', never a power of ten beside them).
With --hertz, for each run with a parabolic initial gap g0 = (x - xc)^2 / (2 R):
  P  = sum of /contact/normal_force             (total force per unit thickness)
  R, xc from the root attributes gap_radius/gap_center if present, else from the
        effective input deck text (/input_deck dataset; as a last resort the deck file
        named by the root attribute 'deck')
  1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2  (plane strain; 1/E1 + 1/E2 in plane stress),
        E, nu from the young/poisson attributes of /body1 and /body2
  a  = sqrt(4 P R / (pi E*)),  p0 = 2 P / (pi a),  p(x) = p0 sqrt(1 - (x - xc)^2 / a^2)
the Hertz curve is added to the top panel and a bottom panel shows p/p0 against (s - xc)/a
(zoomed on the contact zone, |s - xc| <= 1.6 a) with sqrt(1 - t^2); the errors against
Hertz are printed (stdout line 'plot_contact: Hertz for NAME: ... err_a=... err_p0=...
err_L2=...') and written in that panel's legend:
  err_a   |a_num - a| / a, a_num half the distance between the contact-zone edges
  err_p0  |max p - p0| / p0
  err_L2  sqrt(sum w (p - p_H)^2 / sum w p_H^2) over the nodes where p_H > 0 or lam > 0,
          w the tributary lengths (/contact/tributary_length)
Hertz assumes two half-spaces: with finite bodies and a coarse mesh expect agreement
only when the contact width 2a is small against the bodies and spans several elements.
A run of several pairs gets a Hertz curve on pair K only with --pair K (P: that pair's normal
forces, E*: its two bodies; the other pairs' curves are drawn without one); without --pair it
gets none, and the note on stderr names the option. A run without a parabolic gap
(gap_radius = 0) gets no Hertz curve (a note on stderr), unless --radius R gives the relative radius of curvature of a gap that is
the geometry's (a disc on a flat block: the disc's radius); xc is then the middle of the
run's contact zone (its edges as above).
Runs that are identical for Hertz (same P, R, xc, E*) share one curve.
With --mindlin (implies --hertz), for each Hertzian run with Coulomb friction (friction =
'coulomb' and mu > 0 in the input deck), Cattaneo-Mindlin's shear of a tangential load Q < mu P
applied at constant P over the Hertz contact (a, p0 as above; bodies of one material, or
at least of equal Dundurs' beta, so that the normal and the tangential problems uncouple):
  Q  = sum of /contact/tangential_force (the tangential resultant)
  c  = a sqrt(1 - |Q| / (mu P))        (half-width of the stick zone; 0 when |Q| >= mu P)
  q(x) = sign(Q) mu p0 (sqrt(1 - x^2/a^2) - (c/a) sqrt(1 - x^2/c^2)),  x = s - xc
(the second term only for |x| < c) is added to the shear panel and, as q / (mu p0), to the zoom
panel; printed: 'plot_contact: Mindlin for NAME: mu=... Q=... c=... c_num=... err_c=...
err_q=...' with c_num half the width of the stick zone, err_c = |c_num - c| / a and
err_q = sqrt(sum w (q - q_M)^2 / sum w q_M^2) over the Hertz zone. A run without Coulomb
friction or without a Hertz curve gets no Mindlin curve (a note on stderr).
Solid results (3D; root attribute dimension = 3, every file of the run solid): per contact
surface (/contact, or each /contact/pair_<k>) a pressure map over the surface's two
coordinates across its normal (the axis closest to the mean normal, weighted by the normal
forces, is left out: x, z for a normal along y), drawn on its faces (/contact/.../faces,
quadrilaterals split in two), the first 4 surfaces side by side; below, the pressure and the
gap along a line through the contact centre, linearly interpolated on those faces, against
the signed distance t from the centre, the nodes within half a median face edge of the line
as dots. The contact centre is the normal-force weighted mean of the active nodes, moved onto
each symmetry plane: a plane of the model's bounding box across the surface on which the
active zone ends on one side only (a half or quarter model, as inputs/sphere_block.nml).
  --line x|y|z|DX,DY,DZ  the line's direction (default: the map's first axis); its component
                         along the normal axis is dropped
  --centre X,Y,Z         the line's point instead of the contact centre
  --csv FILE             the line's samples: curve, t, x, y, z (on the faces), pressure, gap,
                         hertz_pressure (empty without a Hertz curve)
  --hertz --radius R     Hertz's point contact: a = (3 P R / (4 E*))^(1/3), p0 = 3 P / (2 pi a^2),
                         p(r) = p0 sqrt(1 - r^2/a^2), R the relative radius of curvature (a
                         sphere of radius R on a flat: R), 1/E* = sum (1 - nu^2)/E of the two
                         bodies, P the resultant's component along the normal axis
                         (/contact/resultant_body1, a pair's resultant_on_first_body) times 2 per
                         symmetry plane, or --force P. The curve against |t| on the line, the
                         circle r = a on the map; printed ('plot_contact: Hertz for NAME: P=...
                         a=... p0=... a_fit=... p0_fit=... err_a=... err_p0=... err_L2=...'):
                         the Hertz shape fitted to the nodal pressures (p^2 linear in r^2, least
                         squares over the nodes with p > 0, r the distance from the centre across
                         the normal), err_a = |a_fit - a| / a, err_p0 = |max p - p0| / p0,
                         err_L2 weighted by the tributary areas. Several pairs: on --pair K only.
Printed per surface: its nodes, faces, map axes, centre, symmetry planes, largest pressure and
active nodes; per line its direction, samples and largest interpolated pressure. With friction
each surface also gets a map of the shear's length (/contact/.../shear_magnitude) with the stick
nodes (state 1) marked, and its tangential resultant (x, y, z) and stick and slip counts are
printed ('plot_contact: NAME: tangential resultant (...), stick n, slip n'). No Mindlin curve
(tools/cattaneo3d_study.py compares a sphere's with Mindlin's).
Exit 0 on success, 1 (with a message) on a missing or unreadable file or any other failure.
Run with /usr/bin/python3 (numpy, h5py and matplotlib come from Debian packages).
"""
import os
import re
import sys

import numpy as np
import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from rc_figures import (axis_label, format_quantity, plain_axis, plot_parser, run_label,  # noqa: E402
                        save_figure, si_scale, tool_main)
from rc_results import (contact_edges, dataset_unit, hertz_pressure, hertz_zone, num_attr,  # noqa: E402
                        result_units, text_attr, text_dataset)
from rc_run import strip_comments  # noqa: E402

NUM = r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?)"


def deck_value(text, name):
    """Last assignment `name = number` in namelist text (case-insensitive), or None."""
    hits = re.findall(r"(?<![\w%])" + name + r"\s*=\s*" + NUM, text, flags=re.I)
    if not hits:
        return None
    return float(hits[-1].replace("d", "e").replace("D", "e"))


def plane_stress(text):
    hits = re.findall(r"(?<![\w%])plane\s*=\s*['\"]?\s*(\w+)", text or "", flags=re.I)
    return bool(hits) and hits[-1].lower() == "stress"


def deck_text(f, path):
    """(the effective deck text without comments, where-from) of a result file: /input_deck,
    else the deck file named by the root attribute 'deck'; ('', 'input_deck') when neither is there."""
    text = text_dataset(f, "input_deck")
    src = "input_deck"
    if text is None:
        deck = text_attr(f, "deck")
        cand = [deck, os.path.join(os.path.dirname(path), deck)] if deck else []
        for c in cand:
            if c and os.path.isfile(c):
                with open(c, encoding="utf-8", errors="replace") as fh:
                    text = fh.read()
                src = f"deck file {c} (overrides not seen)"
                break
    return (strip_comments(text) if text else ""), src


def friction_of(text):
    """(friction law, mu) of the deck text: the last `friction = '...'` ('none' when absent)
    and the last `mu = number` (0 when absent)."""
    hits = re.findall(r"(?<![\w%])friction\s*=\s*['\"]\s*(\w+)", text, flags=re.I)
    mu = deck_value(text, "mu")
    return (hits[-1].lower() if hits else "none"), (0.0 if mu is None else mu)


def gap_parameters(f, path):
    """(R, xc, plane_stress, where-from) of a result file."""
    R = num_attr(f, "gap_radius")
    xc = num_attr(f, "gap_center")
    text, src = deck_text(f, path)
    if R is None:
        R = deck_value(text, "gap_radius")
    else:
        src = "attributes"
    if xc is None:
        xc = deck_value(text, "gap_center")
    if xc is None:
        xc = 0.0                      # the deck default (config.f90)
    return R, xc, plane_stress(text), src


def hertz(f, path, radius=None, edges=None, lam=None, bodies=(1, 2)):
    """Hertz curve data of one run, or (None, reason); radius and edges: the relative radius and
    the contact zone of a run whose gap is its geometry's (used when it has no gap_radius);
    lam, bodies: the normal forces and the two bodies of the pair (default /contact, 1 and 2)."""
    R, xc, pstress, src = gap_parameters(f, path)
    if radius is not None and not (R is not None and R > 0.0):
        if edges is None:
            return None, "no contact zone (no active node) to centre the --radius curve on"
        R, xc, src = radius, 0.5 * (edges[0] + edges[1]), "--radius, centred on the contact zone"
    if R is None:
        return None, "no gap_radius in the attributes or the input deck"
    if not R > 0.0:
        return None, "gap_radius = 0 (no parabolic gap)"
    P = float(np.sum(np.array(f["/contact/normal_force"]) if lam is None else lam))
    if not P > 0.0:
        return None, f"total normal force P = {P:g} <= 0"
    inv = 0.0
    for b in (f"body{k}" for k in bodies):
        E = num_attr(f[b], "young")
        nu = num_attr(f[b], "poisson")
        if E is None or nu is None:
            return None, f"/{b} has no young/poisson attributes"
        inv += (1.0 if pstress else 1.0 - nu * nu) / E
    Es = 1.0 / inv
    a, p0 = hertz_zone(P, R, Es)
    return dict(P=P, R=R, xc=xc, Es=Es, a=a, p0=p0, src=src, pstress=pstress), None


def mindlin(r, h, law, mu):
    """Cattaneo-Mindlin data of one frictional Hertzian run (see the docstring), or (None, reason)."""
    if law != "coulomb" or not mu > 0.0:
        return None, f"friction = '{law}'" + (f", mu = {mu:g}" if law == "coulomb" else "") + " (Coulomb with mu > 0 needed)"
    Q = float(np.sum(r["tforce"]))
    ratio = min(abs(Q) / (mu * h["P"]), 1.0)
    return dict(mu=mu, Q=Q, P=h["P"], c=h["a"] * np.sqrt(1.0 - ratio), sign=1.0 if Q >= 0.0 else -1.0), None


def mindlin_shear(x, h, m):
    """Cattaneo-Mindlin shear q at x: sign(Q) mu p0 (sqrt(1 - t^2) - (c/a) sqrt(1 - (x-xc)^2/c^2))."""
    q = hertz_pressure(x, h["xc"], h["a"], h["p0"])
    if m["c"] > 0.0:
        q = q - (m["c"] / h["a"]) * hertz_pressure(x, h["xc"], m["c"], h["p0"])
    return m["sign"] * m["mu"] * q


def stick_spans(x, state):
    """The stick zone of a line sorted by x: (lo, hi) of each run of neighbouring stick nodes
    (state 1), extended by half the spacing to the next node outward (to the line's end at an
    end node)."""
    spans = []
    st = np.asarray(state) == 1
    k = 0
    n = len(x)
    while k < n:
        if not st[k]:
            k += 1
            continue
        j = k
        while j + 1 < n and st[j + 1]:
            j += 1
        lo = 0.5 * (x[k - 1] + x[k]) if k > 0 else x[k]
        hi = 0.5 * (x[j] + x[j + 1]) if j < n - 1 else x[j]
        spans.append((float(lo), float(hi)))
        k = j + 1
    return spans


def mindlin_errors(r, h, m):
    """c_num (half the width of the stick zone around xc: the span holding xc, else the
    widest), err_c = |c_num - c| / a and err_q (weighted L2 over the Hertz zone)."""
    e = {"c_num": 0.0, "err_c": float("nan"), "err_q": float("nan")}
    spans = r["stick"]
    if spans:
        hold = [sp for sp in spans if sp[0] <= h["xc"] <= sp[1]]
        lo, hi = hold[0] if hold else max(spans, key=lambda sp: sp[1] - sp[0])
        e["c_num"] = 0.5 * (hi - lo)
    e["err_c"] = abs(e["c_num"] - m["c"]) / h["a"]
    x, w = r["x"], r["trib"]
    if w.shape != x.shape:
        w = np.gradient(x) if x.size > 1 else np.ones_like(x)
    qm = mindlin_shear(x, h, m)
    zone = hertz_pressure(x, h["xc"], h["a"], h["p0"]) > 0.0
    den = float(np.sum(w[zone] * qm[zone] ** 2))
    if den > 0.0:
        e["err_q"] = float(np.sqrt(np.sum(w[zone] * (r["shear"][zone] - qm[zone]) ** 2) / den))
    return e


def hertz_curve(h, xmin, xmax, n=401):
    lo, hi = min(xmin, h["xc"] - h["a"]), max(xmax, h["xc"] + h["a"])
    x = np.linspace(lo, hi, n)
    x = np.union1d(x, [h["xc"] - h["a"], h["xc"] + h["a"]])
    return x, hertz_pressure(x, h["xc"], h["a"], h["p0"])


def hertz_errors(r, h):
    """err_a, err_p0, err_L2 of one run against its Hertz solution h (see the docstring)."""
    x, p, lam, w = r["x"], r["p"], r["lam"], r["trib"]
    ph = hertz_pressure(x, h["xc"], h["a"], h["p0"])
    e = {"err_a": float("nan"), "err_p0": abs(float(p.max(initial=0.0)) - h["p0"]) / h["p0"],
         "err_L2": float("nan"), "a_num": float("nan")}
    if r["edges"] is not None:
        e["a_num"] = 0.5 * (r["edges"][1] - r["edges"][0])
        e["err_a"] = abs(e["a_num"] - h["a"]) / h["a"]
    zone = (ph > 0.0) | (lam > 0.0)
    if w.shape != x.shape:
        w = np.gradient(x) if x.size > 1 else np.ones_like(x)
    den = float(np.sum(w[zone] * ph[zone] ** 2))
    if den > 0.0:
        e["err_L2"] = float(np.sqrt(np.sum(w[zone] * (p[zone] - ph[zone]) ** 2) / den))
    return e


def read_line(f, g, u, resultant_name):
    """The curve of one contact line (HDF5 group g: /contact or /contact/pair_<k>)."""
    # position along the contact curve: s (arc length along the slave's curve; in older
    # files the coordinate along a rectangle's side); the oldest have only x
    sname = "s" if "s" in g else "x"
    x = np.array(g[sname], dtype=float)
    resultant = None
    if resultant_name in g:
        resultant = np.asarray(g[resultant_name], dtype=float).reshape(-1)[:2]
    order = np.argsort(x, kind="stable")
    lam = np.array(g["normal_force"], dtype=float)
    r = dict(x=x[order], p=np.array(g["pressure"], dtype=float)[order], lam=lam[order],
             gap=np.array(g["gap"], dtype=float)[order] if "gap" in g else None,
             trib=np.array(g["tributary_length"], dtype=float)[order]
             if "tributary_length" in g else np.zeros(0),
             method=text_attr(f, "method", "?"), status=text_attr(f, "status", "?"),
             delta=num_attr(f, "delta", float("nan")), resultant=resultant, sname=sname,
             ux=dataset_unit(g[sname], u["length"]),
             up=dataset_unit(g["pressure"], u["stress"]),
             uf=dataset_unit(g["normal_force"], u["line_force"]),
             ug=dataset_unit(g["gap"], u["length"]) if "gap" in g else u["length"])
    r["P"] = float(np.sum(lam))
    r["edges"] = contact_edges(r["x"], r["p"], r["lam"])
    r["friction"] = "shear" in g
    if r["friction"]:
        r["shear"] = np.array(g["shear"], dtype=float)[order]
        r["tforce"] = np.array(g["tangential_force"], dtype=float)[order]
        r["state"] = np.array(g["state"], dtype=int)[order] if "state" in g else np.full(x.size, -1)
        r["us"] = dataset_unit(g["shear"], u["stress"])
        r["stick"] = stick_spans(r["x"], r["state"])
    return r


def read_run(path, want_hertz, want_mindlin=False, radius=None, pair=None):
    """The curves of one result file: one (/contact), or one per pair when it has several
    (pair: the one that gets the Hertz and Mindlin curves)."""
    with h5py.File(path, "r") as f:
        u = result_units(f)
        npair = int(f.attrs.get("pairs", 1))
        if npair <= 1:
            r = read_line(f, f["contact"], u, "resultant_body1")
            r["h"], r["why"] = hertz(f, path, radius, r["edges"]) if want_hertz else (None, None)
            r["pair"] = ""
            r["m"], r["mwhy"] = None, None
            if want_mindlin:
                if r["h"] is None:
                    r["mwhy"] = f"no Hertz curve ({r['why']})"
                elif not r["friction"]:
                    r["mwhy"] = "no friction (no /contact/shear)"
                else:
                    r["m"], r["mwhy"] = mindlin(r, r["h"], *friction_of(deck_text(f, path)[0]))
            return [r]
        if pair is not None and not 1 <= pair <= npair:
            raise ValueError(f"--pair {pair}: the file has {npair} contact pairs (1 to {npair})")
        runs = []
        for k in range(1, npair + 1):
            g = f[f"contact/pair_{k}"]
            r = read_line(f, g, u, "resultant_on_first_body")
            a, b = (int(v) for v in np.asarray(g.attrs["bodies"]).reshape(-1)[:2])
            r["pair"] = f"pair {k} (bodies {a},{b})"
            why = f"{npair} contact pairs" + (f", --pair {pair} chosen" if pair else
                                              f": pick the pair with --pair K (1 to {npair})")
            r["h"], r["why"] = (None, why) if want_hertz else (None, None)
            r["m"], r["mwhy"] = (None, f"no Hertz curve ({why})") if want_mindlin else (None, None)
            if k == pair and want_hertz:
                r["h"], r["why"] = hertz(f, path, radius, r["edges"], r["lam"], (a, b))
                if want_mindlin:
                    if r["h"] is None:
                        r["mwhy"] = f"no Hertz curve ({r['why']})"
                    elif not r["friction"]:
                        r["mwhy"] = f"no friction (no /contact/pair_{k}/shear)"
                    else:
                        r["m"], r["mwhy"] = mindlin(r, r["h"], *friction_of(deck_text(f, path)[0]))
            runs.append(r)
        return runs


# ---- solid (3D) results: a pressure map of each contact surface and the pressure along a line --
AXES = "xyz"


def is_solid(path):
    """Whether a result file is of solid bodies (its root attribute `dimension` is 3)."""
    with h5py.File(path, "r") as f:
        return int(np.asarray(f.attrs.get("dimension", 2)).reshape(-1)[0]) == 3


def parse_vector(text, what):
    """Three numbers 'X,Y,Z' (ValueError naming the option otherwise)."""
    try:
        v = np.array([float(t) for t in text.split(",")])
    except ValueError:
        v = np.zeros(0)
    if v.size != 3:
        raise ValueError(f"{what} takes three numbers X,Y,Z, not {text!r}")
    return v


def model_box(f):
    """(lo, hi) of every body's nodes of a result file."""
    xs = [np.asarray(f[f"body{b}/coordinates"][()], dtype=float) for b in range(1, int(f.attrs.get("bodies", 2)) + 1)]
    return np.min([x.min(axis=1) for x in xs], axis=0), np.max([x.max(axis=1) for x in xs], axis=0)


def surface_frame(xyz, normal, lam, box, centre=None):
    """The frame of one contact surface: the axis k closest to its mean normal (weighted by the
    normal forces; all nodes alike when none is positive), the two other axes (i, j) in order
    (the map's coordinates), the contact centre and the symmetry planes. The centre is the
    normal-force weighted mean of the active nodes (all when none is active), or `centre`;
    a symmetry plane is the plane of the model's bounding box normal to i or j on which the
    active zone ends on one side only (a half or quarter model: the zone is part of a whole
    one); the centre lies on it."""
    act = lam > 0.0
    w = np.where(act, lam, 0.0) if act.any() else np.ones(lam.size)
    n = (w[:, None] * normal).sum(axis=0)
    k = int(np.argmax(np.abs(n)))
    i, j = (a for a in range(3) if a != k)
    pick = act if act.any() else np.ones(lam.size, dtype=bool)
    c = (w[pick, None] * xyz[pick]).sum(axis=0) / w[pick].sum()
    lo, hi = box
    tol = 1e-9 * float(np.max(hi - lo))
    sym = []
    for a in (i, j):
        ends = [float(v) for v in (lo[a], hi[a]) if np.any(np.abs(xyz[pick, a] - v) <= tol)]
        if len(ends) == 1:
            sym.append((a, ends[0]))
            c[a] = ends[0]
    if centre is not None:
        c = np.asarray(centre, dtype=float)
    return k, (i, j), c, sym


def read_surface(f, g, u, resultant_name, box, centre=None):
    """One contact surface of a solid result (HDF5 group g: /contact or /contact/pair_<k>):
    its nodes, fields, faces (the file's `faces`: triangles, quadrilaterals split in two; a
    Delaunay triangulation of the map's coordinates without them) and frame (surface_frame)."""
    xyz = np.stack([np.asarray(g[c], dtype=float) for c in ("x", "y", "z")], axis=1)
    normal = np.asarray(g["normal"][()], dtype=float).T
    lam = np.asarray(g["normal_force"][()], dtype=float)
    r = dict(xyz=xyz, lam=lam, p=np.asarray(g["pressure"][()], dtype=float),
             gap=np.asarray(g["gap"][()], dtype=float),
             area=np.asarray(g["tributary_area"][()], dtype=float) if "tributary_area" in g else np.ones(lam.size),
             method=text_attr(f, "method", "?"), status=text_attr(f, "status", "?"),
             delta=num_attr(f, "delta", float("nan")),
             resultant=np.asarray(g[resultant_name][()], dtype=float).reshape(-1) if resultant_name in g else None,
             ux=dataset_unit(g["x"], u["length"]), up=dataset_unit(g["pressure"], u["stress"]),
             uf=dataset_unit(g["normal_force"], u["force"]), ug=dataset_unit(g["gap"], u["length"]))
    r["k"], r["ij"], r["c"], r["sym"] = surface_frame(xyz, normal, lam, box, centre)
    # friction: the shear's length, the state (1 stick, 2 slip), the tangential force vectors
    if "shear_magnitude" in g:
        r["shear"] = np.asarray(g["shear_magnitude"][()], dtype=float)
        r["state"] = np.asarray(g["state"][()], dtype=int)
        r["tforce"] = np.asarray(g["tangential_force_xyz"][()], dtype=float)
        r["us"] = dataset_unit(g["shear_magnitude"], u["stress"])
    tris = []
    if "faces" in g:
        for fc in np.asarray(g["faces"][()], dtype=int).reshape(len(g["faces"]), -1):
            v = fc[fc >= 0]
            tris += [v[[0, 1, 2]]] + ([v[[0, 2, 3]]] if v.size == 4 else [])
    r["tris"] = np.array(tris, dtype=int).reshape(-1, 3)
    r["nfaces"] = len(g["faces"]) if "faces" in g else 0
    return r


def surface_triangulation(r):
    """The matplotlib triangulation of a surface in its map's coordinates."""
    import matplotlib.tri as mtri
    i, j = r["ij"]
    x, y = r["xyz"][:, i], r["xyz"][:, j]
    return mtri.Triangulation(x, y, r["tris"]) if len(r["tris"]) else mtri.Triangulation(x, y)


def line_direction(spec, r):
    """The unit direction of the line through a surface's centre: an axis name or DX,DY,DZ
    (default: the map's first axis), its component along the surface's normal axis dropped."""
    if spec is None:
        d = np.eye(3)[r["ij"][0]]
    elif spec.strip().lower() in ("x", "y", "z"):
        d = np.eye(3)[AXES.index(spec.strip().lower())]
    else:
        d = parse_vector(spec, "--line")
    d = np.array(d, dtype=float)
    d[r["k"]] = 0.0
    if not np.linalg.norm(d) > 0.0:
        raise ValueError(f"--line {spec}: along the contact normal ({AXES[r['k']]}), not across the surface")
    return d / np.linalg.norm(d)


def sample_line(r, d, n=401):
    """The pressure and gap along the line through the centre c with direction d, linearly
    interpolated on the surface's triangles (in the map's coordinates), at n points evenly
    spaced over the nodes' extent along d (and t = 0): the samples inside the surface, as
    (t, points (n, 3), pressure, gap), t the signed distance from c, the points on the
    triangles (their coordinate along the normal axis interpolated too); and the nodes within
    half a median face edge of the line (t, pressure)."""
    import matplotlib.tri as mtri
    i, j = r["ij"]
    tri = surface_triangulation(r)
    q = r["xyz"][:, [i, j]] - r["c"][[i, j]]
    d2 = d[[i, j]]
    t_nodes = q @ d2
    t = np.linspace(t_nodes.min(), t_nodes.max(), n)
    t = np.union1d(t, [0.0]) if t_nodes.min() < 0.0 < t_nodes.max() else t
    px, py = r["c"][i] + t * d2[0], r["c"][j] + t * d2[1]
    pres = mtri.LinearTriInterpolator(tri, r["p"])(px, py)
    gap = mtri.LinearTriInterpolator(tri, r["gap"])(px, py)
    inside = ~np.ma.getmaskarray(pres)
    pts = np.zeros((t.size, 3))
    pts[:, i], pts[:, j] = px, py
    pts[:, r["k"]] = np.ma.filled(mtri.LinearTriInterpolator(tri, r["xyz"][:, r["k"]])(px, py), np.nan)
    edges = np.concatenate([tri.x[tri.edges[:, 0]] - tri.x[tri.edges[:, 1]],
                            tri.y[tri.edges[:, 0]] - tri.y[tri.edges[:, 1]]]).reshape(2, -1)
    h = float(np.median(np.hypot(*edges))) if edges.size else 0.0
    off = np.abs(q @ np.array([-d2[1], d2[0]]))
    near = off <= 0.5 * h
    return dict(t=t[inside], xyz=pts[inside], p=np.asarray(pres)[inside], gap=np.asarray(gap)[inside],
                t_nodes=t_nodes[near], p_nodes=r["p"][near], h=h)


def hertz_point(P, R, Es):
    """Radius a = (3 P R / (4 E*))^(1/3) and peak pressure p0 = 3 P / (2 pi a^2) of Hertz's
    point contact: total force P, relative radius R, contact modulus E*."""
    a = (3.0 * P * R / (4.0 * Es)) ** (1.0 / 3.0)
    return a, 3.0 * P / (2.0 * np.pi * a * a)


def hertz_3d(f, r, radius, force, bodies):
    """Hertz's point contact for one surface, or (None, reason): R = --radius; E* from the
    young/poisson attributes of its two bodies (1/E* = sum (1 - nu^2)/E); P = --force, else
    the resultant's component along the surface's normal axis times 2 per symmetry plane."""
    if radius is None:
        return None, "a solid result needs --radius R (the relative radius of curvature)"
    if not radius > 0.0:
        return None, f"--radius {radius:g} <= 0"
    inv = 0.0
    for b in (f"body{k}" for k in bodies):
        E, nu = num_attr(f[b], "young"), num_attr(f[b], "poisson")
        if E is None or nu is None:
            return None, f"/{b} has no young/poisson attributes"
        inv += (1.0 - nu * nu) / E
    nsym = len(r["sym"])
    if force is not None:
        P, src = force, "--force"
    else:
        if r["resultant"] is None:
            return None, "no contact resultant in the file (give --force P)"
        part = abs(float(r["resultant"][r["k"]]))
        P = part * 2 ** nsym
        src = "resultant" if not nsym else (f"{2 ** nsym} x the resultant {part:.6g} (symmetry planes "
                                           + ", ".join(f"{AXES[a]} = {v:g}" for a, v in r["sym"]) + ")")
    if not P > 0.0:
        return None, f"total normal force P = {P:g} <= 0"
    a, p0 = hertz_point(P, radius, 1.0 / inv)
    return dict(P=P, R=radius, Es=1.0 / inv, a=a, p0=p0, src=src), None


def hertz_3d_errors(r, h):
    """The Hertz shape fitted to the nodal pressures (p^2 = p0^2 (1 - rho^2/a^2), linear least
    squares over the nodes with p > 0, rho the distance from the centre in the map's plane),
    err_a, err_p0 (|max p - p0| / p0) and err_L2 (weighted by the tributary areas, over the
    nodes where Hertz's pressure or the normal force is positive)."""
    i, j = r["ij"]
    rho = np.hypot(r["xyz"][:, i] - r["c"][i], r["xyz"][:, j] - r["c"][j])
    p = r["p"]
    e = {"a_fit": float("nan"), "p0_fit": float("nan"), "err_a": float("nan"), "err_L2": float("nan"),
         "err_p0": abs(float(p.max(initial=0.0)) - h["p0"]) / h["p0"]}
    m = p > 0.0
    if m.sum() >= 2:
        c, *_ = np.linalg.lstsq(np.c_[np.ones(m.sum()), -rho[m] ** 2], p[m] ** 2, rcond=None)
        if c[0] > 0.0 and c[1] > 0.0:
            e["p0_fit"], e["a_fit"] = float(np.sqrt(c[0])), float(np.sqrt(c[0] / c[1]))
            e["err_a"] = abs(e["a_fit"] - h["a"]) / h["a"]
    ph = h["p0"] * np.sqrt(np.clip(1.0 - (rho / h["a"]) ** 2, 0.0, None))
    zone = (ph > 0.0) | (r["lam"] > 0.0)
    den = float(np.sum(r["area"][zone] * ph[zone] ** 2))
    if den > 0.0:
        e["err_L2"] = float(np.sqrt(np.sum(r["area"][zone] * (p[zone] - ph[zone]) ** 2) / den))
    return e


def read_run_3d(path, a):
    """The contact surfaces of one solid result: one (/contact), or one per pair (the Hertz
    curve on --pair K's only)."""
    centre = parse_vector(a.centre, "--centre") if a.centre else None
    with h5py.File(path, "r") as f:
        u = result_units(f)
        box = model_box(f)
        npair = int(f.attrs.get("pairs", 1))
        if a.pair is not None and not 1 <= a.pair <= npair:
            raise ValueError(f"--pair {a.pair}: the file has {npair} contact pairs (1 to {npair})")
        out = []
        for k in ([None] if npair <= 1 else range(1, npair + 1)):
            g = f["contact"] if k is None else f[f"contact/pair_{k}"]
            r = read_surface(f, g, u, "resultant_body1" if k is None else "resultant_on_first_body", box, centre)
            bodies = (1, 2) if k is None else tuple(int(v) for v in np.asarray(g.attrs["bodies"]).reshape(-1)[:2])
            r["pair"] = "" if k is None else f"pair {k} (bodies {bodies[0]},{bodies[1]})"
            r["h"], r["why"] = None, None
            if a.hertz:
                if k is None or k == a.pair:
                    r["h"], r["why"] = hertz_3d(f, r, a.radius, a.force, bodies)
                else:
                    r["why"] = f"{npair} contact pairs" + (f", --pair {a.pair} chosen" if a.pair else
                                                           f": pick the pair with --pair K (1 to {npair})")
            out.append(r)
        return out


def shear_map(fig, ax, r, tri, fx, lx):
    """The shear's length on a solid result's contact surface, the stick nodes marked."""
    fs, ls = si_scale(r["shear"], r["us"])
    pc = ax.tripcolor(tri, r["shear"] / fs, shading="gouraud", cmap="magma", vmin=0.0,
                      vmax=max(r["shear"].max(initial=0.0) / fs, 1e-300))
    fig.colorbar(pc, ax=ax, label=axis_label("shear |t|", ls), shrink=0.85)
    st = r["state"] == 1
    i, j = r["ij"]
    ax.plot(r["xyz"][st, i] / fx, r["xyz"][st, j] / fx, "c.", ms=3.0, label=f"stick ({int(st.sum())} nodes)")
    finish_map(ax, r, tri, lx, "shear, the stick zone marked")


def finish_map(ax, r, tri, lx, what):
    """A surface map's frame: equal axes over the surface, their labels, the title, the legend."""
    i, j = r["ij"]
    ax.set_aspect("equal")
    ax.set_xlim(tri.x.min(), tri.x.max())
    ax.set_ylim(tri.y.min(), tri.y.max())
    ax.set_xlabel(axis_label(AXES[i], lx))
    ax.set_ylabel(axis_label(AXES[j], lx))
    ax.set_title(f"{r['name']}: {what}", fontsize=8)
    ax.legend(fontsize=6, loc="upper right", framealpha=0.6)
    plain_axis(ax)


def main_3d(a):
    """plot_contact.py on solid results (see the docstring's last part)."""
    runs = []
    for path in a.files:
        try:
            surfaces = read_run_3d(path, a)
        except (OSError, KeyError, ValueError) as e:
            print(f"plot_contact: cannot read {path}: {e}", file=sys.stderr)
            return 1
        for r in surfaces:
            r["name"], r["label"] = run_label(path, r["method"], r["status"], r["delta"])
            if r["pair"]:
                r["name"] += f" {r['pair']}"
                r["label"] = f"{r['pair']}, {r['label']}"
            runs.append(r)
    if a.mindlin:
        print("plot_contact: no Mindlin curve for solid results (tools/cattaneo3d_study.py compares a sphere's "
              "with Mindlin's)", file=sys.stderr)
    for r in runs:
        if "shear" in r:
            q = np.sum(r["tforce"], axis=0)
            print(f"plot_contact: {r['name']}: tangential resultant ({', '.join(f'{v:.6g}' for v in q)}), "
                  f"stick {int(np.sum(r['state'] == 1))}, slip {int(np.sum(r['state'] == 2))}")
    ux, up, ug = runs[0]["ux"], runs[0]["up"], runs[0]["ug"]
    rows = []
    nhertz = 0
    for r in runs:
        try:
            d = line_direction(a.line, r)
        except ValueError as e:
            print(f"plot_contact: {e}", file=sys.stderr)
            return 1
        r["d"], r["line"] = d, sample_line(r, d)
        i, j = r["ij"]
        sym = ", ".join(f"{AXES[s]} = {v:g}" for s, v in r["sym"]) or "none"
        print(f"plot_contact: {r['name']}: contact surface of {len(r['p'])} nodes, {r['nfaces']} faces, map in "
              f"{AXES[i]}, {AXES[j]} (normal along {AXES[r['k']]}), centre ({', '.join(f'{v:.6g}' for v in r['c'])}), "
              f"symmetry planes {sym}, max pressure {format_quantity(r['p'].max(initial=0.0), up)}, "
              f"{int(np.sum(r['lam'] > 0))} active nodes")
        ln = r["line"]
        at = float(ln["t"][np.argmax(ln["p"])]) if ln["p"].size else float("nan")
        print(f"plot_contact: {r['name']}: line through the centre along ({', '.join(f'{v:.4g}' for v in d)}): "
              f"{ln['t'].size} samples, max pressure {ln['p'].max(initial=0.0):.6g} at t={at:.6g}")
        h = r["h"]
        if a.hertz and h is None:
            print(f"plot_contact: {r['name']}: no Hertz curve: {r['why']}", file=sys.stderr)
        if h is not None:
            nhertz += 1
            r["err"] = e = hertz_3d_errors(r, h)
            print(f"plot_contact: Hertz for {r['name']}: P={h['P']:.6g} R={h['R']:.6g} E*={h['Es']:.6g} a={h['a']:.6g} "
                  f"p0={h['p0']:.6g} (P from {h['src']}) a_fit={e['a_fit']:.6g} p0_fit={e['p0_fit']:.6g} "
                  f"err_a={e['err_a']:.3g} err_p0={e['err_p0']:.3g} err_L2={e['err_L2']:.3g}")
        for t, q, p, g_ in zip(ln["t"], ln["xyz"], ln["p"], ln["gap"]):
            ph = h["p0"] * np.sqrt(max(1.0 - (t / h["a"]) ** 2, 0.0)) if h else None
            rows.append((r["name"], t, *q, p, g_, ph))
    if a.csv:
        import csv
        folder = os.path.dirname(a.csv)
        if folder:
            os.makedirs(folder, exist_ok=True)
        with open(a.csv, "w", newline="") as fh:
            wr = csv.writer(fh)
            wr.writerow(["curve", "t", "x", "y", "z", "pressure", "gap", "hertz_pressure"])
            for row in rows:
                wr.writerow([row[0]] + [repr(float(v)) if np.isfinite(v) else "" for v in row[1:7]]
                            + ["" if row[7] is None else repr(float(row[7]))])
        print(f"plot_contact: wrote {a.csv} ({len(rows)} samples along the line)")

    # panels: one pressure map per surface (at most 4), the pressure and the gap along the line
    maps = runs[:4]
    if len(runs) > 4:
        print(f"plot_contact: note: {len(runs)} contact surfaces, the first 4 mapped", file=sys.stderr)
    shear = any("shear" in r for r in maps)
    fig = plt.figure(figsize=(max(8.0, 4.2 * len(maps)), 15.0 if shear else 11.0), dpi=120)
    gs = fig.add_gridspec(4 if shear else 3, len(maps), height_ratios=[2.4, 2.4, 2.0, 1.0] if shear else [2.4, 2.0, 1.0])
    below = 2 if shear else 1
    fx, lx = si_scale(np.concatenate([r["xyz"].reshape(-1) for r in runs]), ux)
    fp, lp = si_scale(np.concatenate([r["p"] for r in runs] + [[r["h"]["p0"]] for r in runs if r["h"]]), up)
    fg, lg = si_scale(np.concatenate([r["line"]["gap"] for r in runs]), ug)
    for col, r in enumerate(maps):
        ax = fig.add_subplot(gs[0, col])
        i, j = r["ij"]
        tri = surface_triangulation(r)
        tri.x, tri.y = tri.x / fx, tri.y / fx
        # the colour scale from 0 (a uniform pressure shows as one colour, not as rounding)
        pc = ax.tripcolor(tri, r["p"] / fp, shading="gouraud", cmap="viridis",
                          vmin=min(0.0, r["p"].min(initial=0.0) / fp), vmax=max(r["p"].max(initial=0.0) / fp, 1e-300))
        if len(r["tris"]) <= 5000:
            ax.triplot(tri, color="0.85", lw=0.3)
        cb = fig.colorbar(pc, ax=ax, label=axis_label("contact pressure p", lp), shrink=0.85)
        cb.formatter.set_useOffset(False)
        cb.update_ticks()
        ln = r["line"]
        cx, cy = r["c"][i], r["c"][j]
        ax.plot((cx + ln["t"] * r["d"][i]) / fx, (cy + ln["t"] * r["d"][j]) / fx, "k--", lw=1.0, label="the line")
        ax.plot([cx / fx], [cy / fx], "k+", ms=9, label="contact centre")
        if r["h"]:
            th = np.linspace(0.0, 2.0 * np.pi, 361)
            ax.plot((cx + r["h"]["a"] * np.cos(th)) / fx, (cy + r["h"]["a"] * np.sin(th)) / fx, "w:", lw=1.3,
                    label=f"Hertz a = {format_quantity(r['h']['a'], ux)}")
        finish_map(ax, r, tri, lx, "contact pressure")
        if "shear" in r:
            shear_map(fig, fig.add_subplot(gs[1, col]), r, tri, fx, lx)
    ax = fig.add_subplot(gs[below, :])
    axg = fig.add_subplot(gs[below + 1, :], sharex=ax)
    colours = plt.rcParams["axes.prop_cycle"].by_key().get("color", ["C0"])
    for n, r in enumerate(runs):
        c = colours[n % len(colours)]
        ln = r["line"]
        dtext = ", ".join(f"{v:.3g}" for v in r["d"])
        ax.plot(ln["t"] / fx, ln["p"] / fp, "-", color=c, lw=1.3, label=f"{r['label']}, along ({dtext})")
        ax.plot(ln["t_nodes"] / fx, ln["p_nodes"] / fp, "o", color=c, ms=3.0, alpha=0.7,
                label=f"{r['name']}: nodes within half an edge of the line")
        axg.plot(ln["t"] / fx, ln["gap"] / fg, "-", color=c, lw=1.1)
        h = r["h"]
        if h:
            tt = np.linspace(min(ln["t"].min(initial=0.0), -1.2 * h["a"] if ln["t"].min(initial=0.0) < 0 else 0.0),
                             max(ln["t"].max(initial=0.0), 1.2 * h["a"]), 801)
            e = r["err"]
            ax.plot(tt / fx, h["p0"] * np.sqrt(np.clip(1.0 - (tt / h["a"]) ** 2, 0.0, None)) / fp, "--",
                    color="k" if len(runs) == 1 else c, lw=1.3,
                    label=f"Hertz p0 sqrt(1 - r²/a²): P = {format_quantity(h['P'], r['uf'])}, "
                          f"R = {format_quantity(h['R'], ux)}, a = {format_quantity(h['a'], ux)}, "
                          f"p0 = {format_quantity(h['p0'], up)}; err_a = {e['err_a']:.2g}, err_p0 = {e['err_p0']:.2g}")
    for axx in (ax, axg):
        axx.axhline(0.0, color="0.5", lw=0.6)
        axx.axvline(0.0, color="0.5", lw=0.6, ls=":")
        axx.grid(True, alpha=0.4)
        plain_axis(axx)
    ax.set_ylabel(axis_label("contact pressure p", lp))
    axg.set_ylabel(axis_label("gap", lg))
    axg.set_xlabel(axis_label("distance t from the contact centre along the line", lx))
    ax.tick_params(labelbottom=False)
    ax.set_title(a.title or "contact pressure along the line through the contact centre (dots: the nodes on it)"
                 + (", Hertz point contact" if nhertz else ""), fontsize=9)
    ax.legend(fontsize=7, loc="best")
    save_figure(fig, a.output)
    print(f"plot_contact: wrote {a.output} ({len(a.files)} runs, {len(runs)} contact surfaces, {nhertz} Hertz curves)")
    return 0


def main(argv=None):
    ap = plot_parser(__doc__, "contact.png")
    ap.add_argument("--hertz", action="store_true",
                    help="add the Hertz line-contact pressure and p/p0 panel (solid results: point contact)")
    ap.add_argument("--mindlin", action="store_true",
                    help="add Cattaneo-Mindlin's shear to the shear panel (Coulomb friction; implies --hertz)")
    ap.add_argument("--radius", type=float, default=None,
                    help="Hertz's relative radius for a run whose gap is its geometry's (no gap_radius)")
    ap.add_argument("--pair", type=int, default=None, metavar="K",
                    help="with several contact pairs: the pair that gets the Hertz (and Mindlin) curve")
    ap.add_argument("--line", default=None, metavar="x|y|z|DX,DY,DZ",
                    help="solid results: the direction of the line through the contact centre")
    ap.add_argument("--centre", default=None, metavar="X,Y,Z", help="solid results: the line's point")
    ap.add_argument("--force", type=float, default=None, metavar="P",
                    help="solid results: Hertz's total normal force (default: from the file)")
    ap.add_argument("--csv", default=None, metavar="FILE", help="solid results: write the line's samples")
    a = ap.parse_args(argv)
    a.hertz = a.hertz or a.mindlin
    solid = []
    for path in a.files:
        try:
            solid.append(is_solid(path))
        except OSError as e:
            print(f"plot_contact: cannot read {path}: {e}", file=sys.stderr)
            return 1
    if any(solid):
        if not all(solid):
            print("plot_contact: cannot draw plane and solid results together (solid: "
                  + ", ".join(p for p, s in zip(a.files, solid) if s) + "; plane: "
                  + ", ".join(p for p, s in zip(a.files, solid) if not s) + ")", file=sys.stderr)
            return 1
        return main_3d(a)

    runs = []
    for path in a.files:
        try:
            curves = read_run(path, a.hertz, a.mindlin, a.radius, a.pair)
        except (OSError, KeyError, ValueError) as e:
            print(f"plot_contact: cannot read {path}: {e}", file=sys.stderr)
            return 1
        for r in curves:
            r["name"], r["label"] = run_label(path, r["method"], r["status"], r["delta"])
            if r["pair"]:
                r["name"] += f" {r['pair']}"
                r["label"] = f"{r['pair']}, {r['label']}"
            runs.append(r)
    ux, up, uf, ug = (runs[0][k] for k in ("ux", "up", "uf", "ug"))
    for r in runs[1:]:
        if (r["ux"], r["up"], r["uf"], r["ug"]) != (ux, up, uf, ug):
            print(f"plot_contact: warning: {r['name']} has other units ({r['ux']}, {r['up']}, {r['uf']}, "
                  f"{r['ug']}) than {runs[0]['name']}; drawn in {ux}, {up}", file=sys.stderr)

    # Hertz solutions (one curve per distinct P, R, xc, E*)
    seen = []
    if a.hertz:
        for r in runs:
            h = r["h"]
            if h is None:
                print(f"plot_contact: {r['name']}: no Hertz curve: {r['why']}", file=sys.stderr)
                continue
            r["err"] = hertz_errors(r, h)
            key = tuple(float(f"{h[q]:.6g}") for q in ("P", "R", "xc", "Es"))
            r["new_curve"] = key not in seen
            if r["new_curve"]:
                seen.append(key)
            e = r["err"]
            print(f"plot_contact: Hertz for {r['name']}: P={h['P']:.6g} R={h['R']:.6g} xc={h['xc']:.6g} "
                  f"E*={h['Es']:.6g}{' (plane stress)' if h['pstress'] else ''} a={h['a']:.6g} "
                  f"p0={h['p0']:.6g} (R, xc from {h['src']}) a_num={e['a_num']:.6g} err_a={e['err_a']:.3g} "
                  f"err_p0={e['err_p0']:.3g} err_L2={e['err_L2']:.3g}")
    with_hertz = bool(seen)
    nmindlin = 0
    for r in runs:
        if not a.mindlin:
            break
        m = r["m"]
        if m is None:
            print(f"plot_contact: {r['name']}: no Mindlin curve: {r['mwhy']}", file=sys.stderr)
            continue
        nmindlin += 1
        r["merr"] = e = mindlin_errors(r, r["h"], m)
        print(f"plot_contact: Mindlin for {r['name']}: mu={m['mu']:.6g} Q={m['Q']:.6g} P={m['P']:.6g} "
              f"Q/(mu P)={abs(m['Q']) / (m['mu'] * m['P']):.4g} a={r['h']['a']:.6g} c={m['c']:.6g} "
              f"c_num={e['c_num']:.6g} err_c={e['err_c']:.3g} err_q={e['err_q']:.3g}")
    fric = [r for r in runs if r["friction"]]
    for r in fric:
        r["Q"] = float(np.sum(r["tforce"]))
        zone = ", ".join(format_quantity(list(sp), ux) for sp in r["stick"]) or "none"
        print(f"plot_contact: {r['name']}: tangential resultant Q = {format_quantity(r['Q'], uf)}, "
              f"stick {int(np.sum(r['state'] == 1))}, slip {int(np.sum(r['state'] == 2))}, stick zone {zone}")
    for r in runs:
        if r["resultant"] is not None:
            r["force_text"] = f"resultant = {format_quantity(r['resultant'], uf)}"
        else:
            r["force_text"] = f"sum of nodal normal forces = {format_quantity(r['P'], uf)}"
        print(f"plot_contact: {r['name']}: {r['force_text']}")
    sn = runs[0]["sname"]

    # panels: pressure, [shear], gap, [Hertz zoom]
    ratios = [2.2] + ([1.6] if fric else []) + [1.0] + ([2.0] if with_hertz else [])
    fig = plt.figure(figsize=(8.0, 7.0 + (2.5 if with_hertz else 0.0) + (2.0 if fric else 0.0)), dpi=120)
    gs = fig.add_gridspec(len(ratios), 1, height_ratios=ratios)
    ax = fig.add_subplot(gs[0])
    axs = fig.add_subplot(gs[1], sharex=ax) if fric else None
    axg = fig.add_subplot(gs[2 if fric else 1], sharex=ax)
    colours = plt.rcParams["axes.prop_cycle"].by_key().get("color", ["C0"])
    fx, lx = si_scale(np.concatenate([r["x"] for r in runs]), ux)
    fp, lp = si_scale(np.concatenate([r["p"] for r in runs] + [[r["h"]["p0"]] for r in runs if r.get("h")]), up)
    gaps = [r["gap"] for r in runs if r["gap"] is not None]
    fg, lg = si_scale(np.concatenate(gaps) if gaps else np.zeros(0), ug)
    xmin = min((r["x"].min() for r in runs if r["x"].size), default=0.0)
    xmax = max((r["x"].max() for r in runs if r["x"].size), default=1.0)
    for k, r in enumerate(runs):
        c = r["colour"] = colours[k % len(colours)]
        mk = "o-" if r["x"].size <= 150 else "-"
        ax.plot(r["x"] / fx, r["p"] / fp, mk, color=c, ms=3.0, lw=1.3, label=f"{r['label']}: {r['force_text']}")
        if r["gap"] is not None:
            axg.plot(r["x"] / fx, r["gap"] / fg, mk, color=c, ms=2.5, lw=1.1)
        if r["edges"] is not None:
            xl, xr = r["edges"]
            for i, xe in enumerate((xl, xr)):
                for axx in (ax, axg):
                    axx.axvline(xe / fx, color=c, ls=":", lw=1.0,
                                label=(f"contact zone edges {sn} = {format_quantity([xl, xr], ux)}"
                                       if i == 0 and axx is ax else None))
        h = r.get("h")
        if h is not None and r.get("new_curve"):
            hx, hp = hertz_curve(h, xmin, xmax, 801)
            ax.plot(hx / fx, hp / fp, "--",
                    color=c if len(runs) > 1 else "k", lw=1.3,
                    label=f"Hertz for {r['name']}: P = {format_quantity(h['P'], uf)}, "
                          f"R = {format_quantity(h['R'], ux)}, a = {format_quantity(h['a'], ux)}, "
                          f"p0 = {format_quantity(h['p0'], up)}")
    if fric:
        us = fric[0]["us"]
        fs, ls = si_scale(np.concatenate([r["shear"] for r in fric]
                                         + [[r["m"]["mu"] * r["h"]["p0"]] for r in fric if r.get("m")]), us)
        for r in fric:
            c = r["colour"]
            mk = "o-" if r["x"].size <= 150 else "-"
            axs.plot(r["x"] / fx, r["shear"] / fs, mk, color=c, ms=3.0, lw=1.3,
                     label=f"{r['name']}: Q = {format_quantity(r['Q'], uf)}, stick {int(np.sum(r['state'] == 1))}, "
                           f"slip {int(np.sum(r['state'] == 2))}")
            for i, (lo, hi) in enumerate(r["stick"]):
                axs.axvspan(lo / fx, hi / fx, color=c, alpha=0.15, lw=0,
                            label=f"stick zone of {r['name']}" if i == 0 else None)
            m = r.get("m")
            if m is not None:
                h = r["h"]
                mx = np.union1d(np.linspace(h["xc"] - 1.2 * h["a"], h["xc"] + 1.2 * h["a"], 801),
                                [h["xc"] - m["c"], h["xc"] + m["c"]])
                axs.plot(mx / fx, mindlin_shear(mx, h, m) / fs, "--", color=c if len(runs) > 1 else "k", lw=1.3,
                         label=f"Cattaneo-Mindlin for {r['name']}: mu = {m['mu']:g}, c = {format_quantity(m['c'], ux)}, "
                               f"err_q = {r['merr']['err_q']:.2g}")
        axs.axhline(0.0, color="0.5", lw=0.6)
        axs.grid(True, alpha=0.4)
        axs.set_ylabel(axis_label("shear traction", ls))
        axs.tick_params(labelbottom=False)
        axs.legend(fontsize=7, loc="best")
        plain_axis(axs)
    ax.axhline(0.0, color="0.5", lw=0.6)
    axg.axhline(0.0, color="0.5", lw=0.6)
    ax.grid(True, alpha=0.4)
    axg.grid(True, alpha=0.4)
    ax.set_ylabel(axis_label("contact pressure p", lp))
    axg.set_ylabel(axis_label("gap", lg))
    axg.set_xlabel(axis_label("arc length s along the contact curve" if sn == "s" else "x", lx))
    ax.tick_params(labelbottom=False)
    ax.set_title(a.title or "contact pressure (top)" + (", shear traction (shaded: stick)" if fric else "")
                 + " and gap (below; < 0: apart)"
                 + (", Hertz line contact" if with_hertz else ""), fontsize=10)
    ax.legend(fontsize=7, loc="best")
    plain_axis(ax)
    plain_axis(axg)

    if with_hertz:
        axh = fig.add_subplot(gs[len(ratios) - 1])
        s = np.linspace(-1.6, 1.6, 641)
        axh.plot(s, np.sqrt(np.clip(1.0 - s * s, 0.0, None)), "k--", lw=1.3, label="Hertz sqrt(1 - t²)")
        for r in runs:
            h = r.get("h")
            if h is None:
                continue
            sr = (r["x"] - h["xc"]) / h["a"]
            sel = np.abs(sr) <= 1.6
            e = r["err"]
            axh.plot(sr[sel], r["p"][sel] / h["p0"], "o-" if sel.sum() <= 150 else "-", color=r["colour"],
                     ms=3.0, lw=1.2,
                     label=f"{r['name']}: err_a = {e['err_a']:.2g}, err_p0 = {e['err_p0']:.2g}, "
                           f"err_L2 = {e['err_L2']:.2g} ({int(np.sum(r['lam'] > 0))} active nodes)")
            if r["edges"] is not None:
                for xe in r["edges"]:
                    axh.axvline((xe - h["xc"]) / h["a"], color=r["colour"], ls=":", lw=1.0)
            m = r.get("m")
            if m is not None:
                axh.plot(sr[sel], r["shear"][sel] / (m["mu"] * h["p0"]), "s-" if sel.sum() <= 150 else "-",
                         color=r["colour"], ms=2.5, lw=1.0, alpha=0.7, label=f"{r['name']}: q / (mu p0)")
                axh.plot(s, mindlin_shear(h["xc"] + s * h["a"], h, m) / (m["mu"] * h["p0"]), ":",
                         color="k" if len(runs) == 1 else r["colour"], lw=1.3,
                         label=f"Cattaneo-Mindlin q / (mu p0), c/a = {m['c'] / h['a']:.3g}")
        axh.set_xlim(-1.6, 1.6)
        axh.set_ylim(-1.45 if any(r.get("m") and r["m"]["sign"] < 0 for r in runs) else -0.05, 1.45)
        axh.axhline(0.0, color="0.5", lw=0.6)
        axh.grid(True, alpha=0.4)
        axh.set_xlabel(f"t = ({sn} - xc) / a  [-]  (a: Hertz half-width)")
        axh.set_ylabel("p / p0" + (", q / (mu p0)" if nmindlin else "") + " [-]")
        axh.set_title("zoom on the contact zone, normalised by Hertz (dotted: contact-zone edges; "
                      "errors against Hertz in the legend)",
                      fontsize=9)
        axh.legend(fontsize=7, loc="upper right")
        plain_axis(axh)
    save_figure(fig, a.output)
    curves = f", {len(runs)} curves" if len(runs) != len(a.files) else ""
    extra = f", {nmindlin} Mindlin curves" if a.mindlin else ""
    print(f"plot_contact: wrote {a.output} ({len(a.files)} runs{curves}, {len(seen)} Hertz curves{extra})")
    return 0


if __name__ == "__main__":
    tool_main(main, "plot_contact")
