#!/usr/bin/python3
"""Cattaneo-Mindlin in 3D: the scene of inputs/cattaneo_sphere.nml (a sphere R = 1 pressed on a
block of the same material, P, then pulled sideways, Q ~ 0.5 mu P, Coulomb mu = 0.3, a half
model) with a contact radius a ~ 0.02 R (the top pushed down by --push): a finite sphere's own
lateral expansion under P makes a shear that Mindlin's half-spaces do not have, of relative
size about 0.4 (a/R)/mu (measured in 2D: doc/verification.md), so a small a/R. Meshed here with
gmsh (inputs/gmsh/cattaneo_sphere.geo, hc = --hc within rc = 0.06 of the contact point; three
meshes, a/h about 6, 8 and 11; the contact group only the sphere's cap of radius --cap = 0.04,
twice a, where gmsh meshes the surface in nearly equilateral triangles and the rows are a
quarter of the whole half sphere's). Two ways of pulling: 'force' (a traction on the sphere's top,
0.5 mu P over its area, P from a first run of the normal load alone on the first mesh; the
sphere held along x by the contact alone) and 'displacement' (the top moved along x by
--shift instead, its uy held).

Measured from each result (the pair's nodes, r their distance from the y axis):
  P, Q        2 x the contact's resultant on the sphere along y and x (half model)
  a           Hertz's contact radius (3 P R / (4 E*))^(1/3), E* = E / (2 (1 - nu^2))
  c (fit)     the stick radius that fits Mindlin's shear best to the shear averaged over
              rings a/16 wide (as the 2D study fits c to the computed shear)
  c (area)    the stick zone's radius from its area: sqrt(2 A_stick / pi), A_stick the
              tributary areas of the nodes in state stick (half model: half a disc); the
              scatter of the nodal shear (below) takes edge nodes over mu p: it runs small
  c_theory    Mindlin: a (1 - Q / (mu P))^(1/3)
  shear       the shear along x against Mindlin's
              q(r) = mu p0 sqrt(1 - r^2/a^2) - [r < c] mu p0 (c/a) sqrt(1 - r^2/c^2),
              p0 = 3 P / (2 pi a^2), its relative L2 error (tributary-area weighted) away
              from the stick edge, where q has a kink, and from the contact's edge: 'rings',
              both averaged over rings a/8 wide (the force of a ring's nodes over their area;
              the rings with their middle below 0.9 a and more than 0.15 a from c), and
              'nodal', node by node (r < 0.9 a, |r - c| > 0.15 a): in the stick zone the
              nodal shear of these unstructured tetrahedra scatters about its local mean
and the observed orders of the errors of c and of the shear between successive meshes.
Prints a Markdown table; with --check, exits 1 unless on the finest mesh |c (fit) / c_theory - 1|
<= 3% and the ring-averaged shear error <= 5% for both ways of pulling. --keep DIR keeps the
meshes and result files there; --from DIR measures the result files such a run left there
(no runs; no DOFs, times or memory).

usage: tools/cattaneo3d_study.py [--bin bin/robin_contact] [--hc 0.0033,0.0025,0.0018] [--cap 0.04] [--method monolithic]
                                 [--check] [--keep DIR | --from DIR]
"""
import argparse
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
E, NU, R, MU = 1000.0, 0.3, 1.0, 0.3
DECK = """&scene title = 'Cattaneo-Mindlin: a sphere on a block, half model', dimension = 3 /
&body id = 1, mesh = '{msh}', region = 'sphere', young = 1000.0, poisson = 0.3 /
&body id = 2, mesh = '{msh}', region = 'block', young = 1000.0, poisson = 0.3 /
&boundary body = 1, group = 'sphere_top', uy = {push}, stage = 1 /
&boundary body = 1, group = 'sphere_z0', uz = 0.0 /
&boundary body = 2, group = 'block_bottom', ux = 0.0, uy = 0.0, uz = 0.0 /
&boundary body = 2, group = 'block_z0', uz = 0.0 /
&contact body1_group = 'sphere_arc', body2_group = 'block_top', friction = 'coulomb', mu = 0.3 /
&solver method = '{method}' /
&output file = '{h5}' /
"""


def mindlin_shear(r, a, p0, c):
    """Mindlin's shear along the pull at the distances r from the centre."""
    q = MU * p0 * np.sqrt(np.clip(1.0 - (r / a) ** 2, 0.0, None))
    return q - np.where(r < c, MU * p0 * (c / a) * np.sqrt(np.clip(1.0 - (r / c) ** 2, 0.0, None)), 0.0)


def measure(h5):
    """P, Q, a, c, c_theory and the shear's relative L2 errors (nodal, rings) of a result file."""
    with h5py.File(h5, "r") as f:
        g = f["/contact/pair_1"]
        x, z = g["x"][()], g["z"][()]
        area = g["tributary_area"][()]
        state = g["state"][()]
        lam = g["normal_force"][()]
        fx = g["tangential_force_xyz"][()][:, 0]
        res = g["resultant_on_first_body"][()]
    P, Q = 2.0 * abs(res[1]), 2.0 * abs(res[0])
    estar = E / (2.0 * (1.0 - NU * NU))
    a = (3.0 * P * R / (4.0 * estar)) ** (1.0 / 3.0)
    p0 = 3.0 * P / (2.0 * math.pi * a * a)
    c = math.sqrt(2.0 * np.sum(area[state == 1]) / math.pi)
    ct = a * (1.0 - Q / (MU * P)) ** (1.0 / 3.0)
    r = np.hypot(x, z)
    fx = fx * np.sign(np.sum(fx))
    q = np.where(area > 0, fx / np.where(area > 0, area, 1.0), 0.0)
    qt = mindlin_shear(r, a, p0, ct)
    w = (r < 0.9 * a) & (np.abs(r - ct) > 0.15 * a)
    nodal = math.sqrt(np.sum(area[w] * (q[w] - qt[w]) ** 2) / np.sum(area[w] * qt[w] ** 2))
    return dict(P=P, Q=Q, a=a, c=c, ct=ct, cfit=fit_c(r, fx, area, a, p0), nodal=nodal,
                shear=ring_error(r, fx, area, a, ct, qt), active=int(np.count_nonzero(lam > 0)))


def ring_error(r, force, area, a, ct, qt):
    """The relative L2 error of the shear averaged over rings a/8 wide (the force of a ring's
    nodes over their area) against Mindlin's qt averaged alike, over the rings whose middle is
    below 0.9 a and more than 0.15 a from the stick edge ct."""
    num = den = 0.0
    for lo in np.arange(8) * a / 8.0:
        k = (r >= lo) & (r < lo + a / 8.0)
        mid = lo + a / 16.0
        if not k.any() or mid > 0.9 * a or abs(mid - ct) <= 0.15 * a:
            continue
        qm, qa = np.sum(force[k]) / np.sum(area[k]), np.sum(qt[k] * area[k]) / np.sum(area[k])
        num += np.sum(area[k]) * (qm - qa) ** 2
        den += np.sum(area[k]) * qa ** 2
    return math.sqrt(num / den)


def fit_c(r, fx, area, a, p0, rings=16):
    """The stick radius c that fits Mindlin's shear best to the shear averaged over rings a/16
    wide (up to 0.95 a; least squares weighted by the rings' areas; golden-section search)."""
    k = [(r >= lo) & (r < lo + a / rings) for lo in np.arange(rings) * a / rings if lo + a / (2 * rings) <= 0.95 * a]
    k = [m for m in k if m.any()]
    qm = [np.sum(fx[m]) / np.sum(area[m]) for m in k]

    def cost(c):
        return sum(np.sum(area[m]) * (q - np.sum(mindlin_shear(r[m], a, p0, c) * area[m]) / np.sum(area[m])) ** 2
                   for m, q in zip(k, qm))
    lo, hi = 0.3 * a, a
    g = (math.sqrt(5.0) - 1.0) / 2.0
    x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
    f1, f2 = cost(x1), cost(x2)
    while hi - lo > 1e-6 * a:
        if f1 < f2:
            hi, x2, f2 = x2, x1, f1
            x1 = hi - g * (hi - lo)
            f1 = cost(x1)
        else:
            lo, x1, f1 = x1, x2, f2
            x2 = lo + g * (hi - lo)
            f2 = cost(x2)
    return 0.5 * (lo + hi)


def mesh(hc, work, gmsh, cap):
    out = os.path.join(work, f"cattaneo_sphere_h{hc}.msh")
    subprocess.run([gmsh, "-3", "-format", "msh41", "-v", "2", "-setnumber", "hc", hc, "-setnumber", "rc", "0.06",
                    "-setnumber", "cap", repr(cap), os.path.join(ROOT, "inputs", "gmsh", "cattaneo_sphere.geo"), "-o", out], capture_output=True, check=True)
    return out


def run(binary, work, name, text, *extra):
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write(text + "".join(e + "\n" for e in extra))
    t0 = time.time()
    p = subprocess.run([binary, deck], capture_output=True, text=True)
    return p, time.time() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin", "robin_contact"))
    ap.add_argument("--hc", default="0.0033,0.0025,0.0018")
    ap.add_argument("--push", type=float, default=-4.0e-4, help="the top's displacement along y (stage 1)")
    ap.add_argument("--shift", type=float, default=5.0e-5, help="the top's displacement along x ('displacement')")
    ap.add_argument("--method", default="monolithic")
    ap.add_argument("--cap", type=float, default=0.04,
                    help="the contact group is the sphere's cap of this radius (0: its whole lower half)")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--keep", default=None, metavar="DIR")
    ap.add_argument("--from", dest="source", default=None, metavar="DIR")
    a = ap.parse_args()
    gmsh = shutil.which("gmsh")
    if not gmsh and not a.source:
        print("cattaneo3d_study: gmsh is needed to mesh the sphere (apt-get install gmsh)")
        return 1
    if a.keep:
        os.makedirs(a.keep, exist_ok=True)
    work = os.path.abspath(a.source or a.keep) if (a.source or a.keep) else tempfile.mkdtemp(prefix="rc_cattaneo3d_")
    failed = False
    try:
        if a.source:
            meshes = {hc: None for hc in a.hc.split(",")}
        else:
            meshes = {hc: mesh(hc, work, gmsh, a.cap) for hc in a.hc.split(",")}
            traction = normal_load(a, work, next(iter(meshes.values())))
            if traction is None:
                return 1
        print("| pull | hc | DOFs | contact nodes | Q / (mu P) | a | a / h | c (Mindlin) | c (fit) | error | order "
              "| c (area) | error | shear error (rings) | order | (nodal) | outer | wall s | peak MiB |")
        print("| --- " * 19 + "|")
        for pull in ("force", "displacement"):
            last = None
            for hc, msh in meshes.items():
                h5 = os.path.join(work, f"{pull}_{hc}.h5")
                res, wall, peak = {}, float("nan"), "?"
                if not a.source:
                    text = DECK.format(msh=msh, push=a.push, method=a.method, h5=h5)
                    if pull == "force":
                        extra = f"&traction body=1, group='sphere_top', t0={traction!r}, 0.0, 0.0, stage=2 /"
                    else:
                        extra = f"&boundary body=1, group='sphere_top', ux={a.shift!r}, stage=2 /"
                    p, wall = run(a.bin, work, f"{pull}_{hc}", text, extra)
                    if p.returncode != 0:
                        print(f"| {pull} | {hc} | run failed (exit {p.returncode}): {p.stderr.strip()[-200:]} |")
                        failed = True
                        continue
                    res = dict(w.split("=", 1) for w in p.stdout.splitlines()[-1].split()[1:] if "=" in w)
                    peak = next((w.split("=")[1] for w in p.stdout.split() if w.startswith("peak_mb=")), "?")
                m = measure(h5)
                ef, ea = m["cfit"] / m["ct"] - 1.0, m["c"] / m["ct"] - 1.0
                of = os_ = ""
                if last is not None:
                    lh = math.log(float(last[0]) / float(hc))
                    if ef != 0 and last[1] != 0:
                        of = f"{math.log(abs(last[1] / ef)) / lh:.2f}"
                    os_ = f"{math.log(last[2] / m['shear']) / lh:.2f}"
                print(f"| {pull} | {hc} | {res.get('dofs', '?')} | {m['active']} | {m['Q'] / (MU * m['P']):.4f} "
                      f"| {m['a']:.5f} | {m['a'] / float(hc):.1f} | {m['ct']:.5f} | {m['cfit']:.5f} | {100 * ef:+.2f}% | {of} "
                      f"| {m['c']:.5f} | {100 * ea:+.2f}% | {100 * m['shear']:.2f}% | {os_} | {100 * m['nodal']:.1f}% "
                      f"| {res.get('outer', '?')} | {wall:.1f} | {peak} |", flush=True)
                last = (hc, ef, m["shear"])
            if a.check and last is not None and (abs(last[1]) > 0.03 or last[2] > 0.05):
                print(f"check: {pull}: on the finest mesh c (fit) is off by {100 * last[1]:+.2f}% (3% allowed) and the "
                      f"shear by {100 * last[2]:.2f}% (5% allowed)")
                failed = True
    finally:
        if not (a.keep or a.source):
            shutil.rmtree(work, ignore_errors=True)
    return 1 if (a.check and failed) else 0


def normal_load(a, work, first):
    """The pull's traction: 0.5 mu P over the top's area, P from the normal load alone on the
    first mesh (printed); None when that run fails."""
    h5 = os.path.join(work, "normal.h5")
    p, _ = run(a.bin, work, "normal", DECK.format(msh=first, push=a.push, method=a.method, h5=h5))
    if p.returncode != 0:
        print(f"the normal load alone failed (exit {p.returncode}): {p.stderr.strip()[-300:]}")
        return None
    with h5py.File(h5, "r") as f:
        p_half = abs(f["/contact/pair_1/resultant_on_first_body"][1])
    traction = 0.5 * MU * p_half / (math.pi / 2.0)
    print(f"P (half model, normal load alone, first mesh) = {p_half:.6e}; the pull's traction {traction:.6e}\n")
    return traction


if __name__ == "__main__":
    sys.exit(main())
