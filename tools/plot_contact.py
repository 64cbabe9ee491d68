#!/usr/bin/python3
"""Normal contact pressure along the contact line of robin_contact runs, several runs
overlaid, optionally with the Hertz line-contact pressure of a parabolic-gap scene.

Usage: tools/plot_contact.py FILE.h5 [FILE.h5 ...] [--hertz] [-o contact.png] [--title TEXT]

Plots /contact/pressure (nodal force / tributary length [stress]) against /contact/x.
With --hertz, for each run with a parabolic initial gap g0 = (x - xc)^2 / (2 R):
  P  = sum of /contact/normal_force             (total force per unit thickness)
  R, xc from the root attributes gap_radius/gap_center if present, else from the
        effective input deck text (/input_deck dataset; as a last resort the deck file
        named by the root attribute 'deck')
  1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2  (plane strain; 1/E1 + 1/E2 in plane stress),
        E, nu from the young/poisson attributes of /body1 and /body2
  a  = sqrt(4 P R / (pi E*)),  p0 = 2 P / (pi a),  p(x) = p0 sqrt(1 - (x - xc)^2 / a^2)
Hertz assumes two half-spaces: with finite bodies and a coarse mesh expect agreement
only when the contact width 2a is small against the bodies and spans several elements.
A run without a parabolic gap (gap_radius = 0) gets no Hertz curve (a note on stderr).
Runs that are identical for Hertz (same P, R, xc, E*) share one curve.
Exit 0 on success, 1 on a missing or unreadable file.
Run with /usr/bin/python3 (numpy, h5py and matplotlib come from Debian packages).
"""
import argparse
import os
import re
import sys

import numpy as np
import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from rc_common import finish_plot, hertz_pressure, hertz_zone, num_attr, run_label, \
    text_attr, text_dataset  # noqa: E402

NUM = r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?)"


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


def deck_value(text, name):
    """Last assignment `name = number` in namelist text (case-insensitive), or None."""
    hits = re.findall(r"(?<![\w%])" + name + r"\s*=\s*" + NUM, text, flags=re.I)
    if not hits:
        return None
    return float(hits[-1].replace("d", "e").replace("D", "e"))


def plane_stress(text):
    hits = re.findall(r"(?<![\w%])plane\s*=\s*['\"]?\s*(\w+)", text or "", flags=re.I)
    return bool(hits) and hits[-1].lower() == "stress"


def gap_parameters(f, path):
    """(R, xc, plane_stress, where-from) of a result file."""
    R = num_attr(f, "gap_radius")
    xc = num_attr(f, "gap_center")
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
    text = strip_comments(text) if text else ""
    if R is None:
        R = deck_value(text, "gap_radius")
    else:
        src = "attributes"
    if xc is None:
        xc = deck_value(text, "gap_center")
    if xc is None:
        xc = 0.0                      # the deck default (config.f90)
    return R, xc, plane_stress(text), src


def hertz(f, path):
    """Hertz curve data of one run, or (None, reason)."""
    R, xc, pstress, src = gap_parameters(f, path)
    if R is None:
        return None, "no gap_radius in the attributes or the input deck"
    if not R > 0.0:
        return None, "gap_radius = 0 (no parabolic gap)"
    P = float(np.sum(np.array(f["/contact/normal_force"])))
    if not P > 0.0:
        return None, f"total normal force P = {P:g} <= 0"
    inv = 0.0
    for b in ("body1", "body2"):
        E = num_attr(f[b], "young")
        nu = num_attr(f[b], "poisson")
        if E is None or nu is None:
            return None, f"/{b} has no young/poisson attributes"
        inv += (1.0 if pstress else 1.0 - nu * nu) / E
    Es = 1.0 / inv
    a, p0 = hertz_zone(P, R, Es)
    return dict(P=P, R=R, xc=xc, Es=Es, a=a, p0=p0, src=src, pstress=pstress), None


def hertz_curve(h, xmin, xmax, n=401):
    lo, hi = min(xmin, h["xc"] - h["a"]), max(xmax, h["xc"] + h["a"])
    x = np.linspace(lo, hi, n)
    x = np.union1d(x, [h["xc"] - h["a"], h["xc"] + h["a"]])
    return x, hertz_pressure(x, h["xc"], h["a"], h["p0"])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="+", metavar="FILE.h5", help="robin_contact result files")
    ap.add_argument("--hertz", action="store_true", help="add the Hertz line-contact pressure")
    ap.add_argument("-o", "--output", default="contact.png", help="output image (default contact.png)")
    ap.add_argument("--title", default=None, help="figure title")
    a = ap.parse_args(argv)

    fig, ax = plt.subplots(figsize=(8.0, 5.0), dpi=120)
    colours = plt.rcParams["axes.prop_cycle"].by_key().get("color", ["C0"])
    seen = []
    xmin, xmax = np.inf, -np.inf
    runs = []
    for k, path in enumerate(a.files):
        try:
            with h5py.File(path, "r") as f:
                x = np.array(f["/contact/x"], dtype=float)
                p = np.array(f["/contact/pressure"], dtype=float)
                method = text_attr(f, "method", "?")
                status = text_attr(f, "status", "?")
                delta = num_attr(f, "delta", float("nan"))
                h, why = hertz(f, path) if a.hertz else (None, None)
        except (OSError, KeyError) as e:
            print(f"plot_contact: cannot read {path}: {e}", file=sys.stderr)
            return 1
        name, label = run_label(path, method, status, delta)
        order = np.argsort(x, kind="stable")
        c = colours[k % len(colours)]
        ax.plot(x[order], p[order], "o-", color=c, ms=3.5, lw=1.3, label=label)
        if x.size:
            xmin, xmax = min(xmin, x.min()), max(xmax, x.max())
        runs.append((name, c, h, why))

    if a.hertz:
        for name, c, h, why in runs:
            if h is None:
                print(f"plot_contact: {name}: no Hertz curve: {why}", file=sys.stderr)
                continue
            key = tuple(float(f"{h[q]:.6g}") for q in ("P", "R", "xc", "Es"))
            if key in seen:
                continue
            seen.append(key)
            hx, hp = hertz_curve(h, xmin if np.isfinite(xmin) else h["xc"] - h["a"],
                                 xmax if np.isfinite(xmax) else h["xc"] + h["a"])
            ax.plot(hx, hp, "--", color=c if len(runs) > 1 else "k", lw=1.4,
                    label=f"Hertz for {name}: P={h['P']:.4g}, R={h['R']:.4g}, "
                          f"a={h['a']:.4g}, p0={h['p0']:.4g}")
            print(f"plot_contact: Hertz for {name}: P={h['P']:.6g} R={h['R']:.6g} xc={h['xc']:.6g} "
                  f"E*={h['Es']:.6g}{' (plane stress)' if h['pstress'] else ''} a={h['a']:.6g} "
                  f"p0={h['p0']:.6g} (R, xc from {h['src']})")
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.grid(True, alpha=0.4)
    return finish_plot(fig, ax, a.output, "plot_contact", f"{len(runs)} runs, {len(seen)} Hertz curves",
                       "x along the contact line", "normal contact pressure",
                       a.title or "contact pressure" + (" and Hertz line contact" if seen else ""))


if __name__ == "__main__":
    sys.exit(main())
