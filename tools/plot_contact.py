#!/usr/bin/python3
"""Normal contact pressure and gap along the contact line of robin_contact runs, several
runs overlaid, optionally with the Hertz line-contact pressure of a parabolic-gap scene.

Usage: tools/plot_contact.py FILE.h5 [FILE.h5 ...] [--hertz] [--mindlin] [--radius R] [--pair K]
       [-o contact.png] [--title TEXT]

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


def main(argv=None):
    ap = plot_parser(__doc__, "contact.png")
    ap.add_argument("--hertz", action="store_true", help="add the Hertz line-contact pressure and p/p0 panel")
    ap.add_argument("--mindlin", action="store_true",
                    help="add Cattaneo-Mindlin's shear to the shear panel (Coulomb friction; implies --hertz)")
    ap.add_argument("--radius", type=float, default=None,
                    help="Hertz's relative radius for a run whose gap is its geometry's (no gap_radius)")
    ap.add_argument("--pair", type=int, default=None, metavar="K",
                    help="with several contact pairs: the pair that gets the Hertz (and Mindlin) curve")
    a = ap.parse_args(argv)
    a.hertz = a.hertz or a.mindlin

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
