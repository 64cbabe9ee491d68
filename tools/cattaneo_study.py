#!/usr/bin/python3
"""Cattaneo-Mindlin: a cylinder pressed on a body of the same material by a normal force P, then
sheared by a tangential force Q < mu P (Coulomb). The contact keeps Hertz's pressure; a central
stick zone |x| < c = a sqrt(1 - Q/(mu P)) and two slip zones carry the shear
q(x) = mu p0 (sqrt(1 - x^2/a^2) - (c/a) sqrt(1 - x^2/c^2)) (the second term only for |x| < c).

The scene: two blocks W x H of the same material (E = 1000, nu = 0.3, plane strain), the upper
one's bottom and the lower one's top in contact with the parabolic initial gap x^2/(2R) of a
cylinder of radius R = 1 (`gap_radius`, so both bodies are flat, mirror images, and their
contact is Hertz's between two equal half-spaces as far as the blocks, 40 half-widths wide, are
half-spaces); the lower block clamped below, the upper one pressed by a displacement -d of its
top (its rotation held there) and free along x, so that only friction holds it against Q:
  - `force`: Q as a shear traction Q/W on its top;
  - `displacement`: its top moved by ux = the force run's mean top displacement (Q measured);
  - `stages`: P in a first load stage, Q in a second (with the load history, Coulomb's slip is
    on each step's increment; for equal materials P alone makes no slip, so the answer is the
    same).
Theory with the computed P and Q: a = sqrt(4 P R / (pi E*)), E* = E / (2 (1 - nu^2)),
p0 = 2 P / (pi a), c as above. Measured: a and p0 by the Hertz fit of the pressure
(hertz_study.hertz_fit), c as the least-squares fit of the shear to the formula (one unknown),
the L2 error of the shear against the formula away from the zone edges (|x| < 0.9 a and
||x| - c| > 0.1 a).

`--scene disc`: a half-disc of radius R = 1 (centre (0,1), flat side up) on a
block 8 x 4 of the same material (inputs/gmsh/cattaneo_disc.geo), the block clamped below, the
disc pressed by uy = -d on its flat side (d set by a first run so that a = ac) in load stage 1 and
sheared in stage 2:
  - `force`: Q as a shear traction Q/(2R) on the flat side, the disc held along x by friction alone
    (its flat side's uy holds its rotation);
  - `displacement`: the flat side moved by ux = the force run's mean ux of it (held at 0 in stage 1).
A finite disc is not a half-space: under P alone its surface slides against the block's (the
relative slip over the contact is about 0.4 (a/R) p0 a/E* and odd in x), friction resists it, and
that odd shear stays in the stick zone after Q; relative to the Cattaneo-Mindlin shear (scale
mu p0) it is about (a/R)/mu, so the scene has a/R = ac/R = 0.005. The table splits the shear's
L2 error into its parts even and odd in x (the odd one is that effect; the even one the mesh's).
Meshes: quadrangles, a structured patch of squares h = ac/n under the contact in each body
(|x| < 1.5 ac), coarser away; --n gives the values of a/h (default 8,16,32):
inputs/gmsh/cattaneo_disc_a<n>.msh when shipped, else written by gmsh into --out. `--ar 0.07,0.02,0.005` (one --n) measures the finite-size effect:
for each a/R the relative slip under P alone without friction (the disc held at its flat side's
middle) and the Cattaneo-Mindlin errors with friction. `--block L,D`: the block (-L,L) x (-D,0).

usage: cattaneo_study.py [--scene blocks|disc] [--bin BIN] [--n 100,200,400]
       [--mode force|displacement|stages] [--method monolithic|robin] [--out DIR]
       [--ar LIST] [--mu MU] [--block L,D] [--gmsh GMSH]
Prints one row per mesh and the observed orders of the c and shear errors.
"""
import argparse
import math
import os
import subprocess
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from hertz_study import hertz_fit  # noqa: E402

E, NU, R, MU = 1000.0, 0.3, 1.0, 0.3
W, H, D = 2.0, 1.0, 0.008          # blocks, the top's displacement
QFRAC = 0.5                        # Q = QFRAC mu P
ROOT = os.path.dirname(HERE)
GEO = os.path.join(ROOT, "inputs", "gmsh", "cattaneo_disc.geo")
AC = 0.005                         # disc scene: the contact half-width aimed at (a/R)
BLOCK = (4.0, 4.0)                 # disc scene: the block's half-width and depth
D0 = 1.0e-4                        # disc scene: the flat side's displacement for a of about 0.0055


def deck(n, method):
    ny = n * int(H * 1000) // int(W * 1000)
    return f"""&scene title='Cattaneo-Mindlin, two equal blocks', units='custom' /
&body id=1, x0={-W / 2}, y0=0.0, width={W}, height={H}, nx={n}, ny={ny}, young={E}, poisson={NU}, bottom='contact' /
&body id=2, x0={-W / 2}, y0={-H}, width={W}, height={H}, nx={n}, ny={ny}, young={E}, poisson={NU}, top='contact',
      bottom='clamped' /
&contact friction='coulomb', mu={MU}, gap_radius={R}, gap_center=0.0 /
&solver method='{method}', stop='residual', tol=1.0e-10 /
"""


def run(binary, n, mode, method, out, extra=(), force_h5=None):
    """One run; returns its measured quantities (the console text among them). force_h5, mode
    'displacement': the result file of the force run on this mesh (same method), whose mean top
    displacement is prescribed, instead of running it again."""
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, f"cm_{mode}_{method}_{n}.nml")
    with open(path, "w") as f:
        f.write(deck(n, method))
    h5 = os.path.join(out, f"cm_{mode}_{method}_{n}.h5")
    top = f"&boundary body=1, group='top', uy={-D} /"
    if mode == "stages":
        p = solve(binary, path, h5, [f"&boundary body=1, group='top', uy={-D}, stage=1 /"], None)
        P = p["P"]
        loads = [f"&boundary body=1, group='top', uy={-D}, stage=1 /",
                 f"&traction body=1, side='top', t0={QFRAC * MU * P / W}, 0.0, stage=2 /"]
        return solve(binary, path, h5, loads, extra)
    if mode == "displacement" and force_h5 is not None:
        f = measure(force_h5, "")
        ux = mean_ux(force_h5, H)
        r = solve(binary, path, h5, [f"&boundary body=1, group='top', ux={ux!r}, uy={-D} /"], extra)
        r["Q_force"] = f["Q"]
        return r
    p = solve(binary, path, h5, [top], None)
    P = p["P"]
    loads = [top, f"&traction body=1, side='top', t0={QFRAC * MU * P / W}, 0.0 /"]
    if mode == "force":
        r = solve(binary, path, h5, loads, extra)
        r["Q_applied"] = QFRAC * MU * P
        return r
    f = solve(binary, path, h5, loads, None)
    ux = mean_ux(h5, H)
    r = solve(binary, path, h5, [f"&boundary body=1, group='top', ux={ux!r}, uy={-D} /"], extra)
    r["Q_force"] = f["Q"]
    return r


def mean_ux(h5, y):
    """The mean x displacement of body 1's nodes on the line y (its loaded side) in a result."""
    with h5py.File(h5, "r") as g:
        xy = np.array(g["body1/coordinates"])
        u = np.array(g["body1/displacement"])
    if xy.shape[0] == 2:
        xy, u = xy.T, u.T
    return float(np.mean(u[np.abs(xy[:, 1] - y) < 1e-12, 0]))


def solve(binary, path, h5, loads, extra, mu=None):
    cmd = [binary, path, *loads, f"&output file='{h5}' /", *(extra or ())]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=1200)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {p.returncode}: {(p.stdout + p.stderr).strip()[-400:]}")
    return measure(h5, p.stdout, mu)


def disc_mesh(n, out, ac=AC, gmsh="gmsh", block=BLOCK):
    """The disc scene's mesh with a/h = n: the shipped one for the default ac and block, else gmsh's."""
    shipped = os.path.join(ROOT, "inputs", "gmsh", f"cattaneo_disc_a{n}.msh")
    if ac == AC and tuple(block) == BLOCK and os.path.exists(shipped):
        return shipped
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, f"cattaneo_disc_ac{ac:g}_a{n}_L{block[0]:g}_D{block[1]:g}.msh")
    cmd = [gmsh, "-2", "-format", "msh41", "-setnumber", "ac", repr(ac), "-setnumber", "n", str(n),
           "-setnumber", "L", repr(block[0]), "-setnumber", "D", repr(block[1]), GEO, "-o", path]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if p.returncode != 0 or not os.path.exists(path):
        raise RuntimeError(f"{' '.join(cmd)}: exit {p.returncode}: {(p.stdout + p.stderr).strip()[-400:]}")
    return path


def disc_deck(msh, method, mu):
    fric = f", friction='coulomb', mu={mu}" if mu > 0.0 else ""
    return f"""&scene title='Cattaneo-Mindlin, a half-disc on a block', units='custom' /
&body id=1, mesh='{os.path.abspath(msh)}', region='disc', young={E}, poisson={NU} /
&body id=2, mesh='{os.path.abspath(msh)}', region='block', young={E}, poisson={NU} /
&boundary body=2, group='block_bottom', ux=0.0, uy=0.0 /
&contact body1_group='disc_contact', body2_group='block_contact'{fric} /
&solver method='{method}', stop='residual', tol=1.0e-10 /
"""


def disc_press(binary, msh, out, tag, ac, mu, method="monolithic"):
    """P alone (the flat side's uy = -d, d set by a first run so that a = ac): (d, the measured run,
    its deck's path, its result file)."""
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, f"{tag}.nml")
    with open(path, "w") as f:
        f.write(disc_deck(msh, method, mu))
    h5 = os.path.join(out, f"{tag}.h5")
    hold = [] if mu > 0.0 else ["&boundary body=1, group='disc_centre', ux=0.0 /"]
    d = D0 * (ac / 0.0055) ** 2
    a = solve(binary, path, h5, [f"&boundary body=1, group='disc_top', uy={-d!r} /", *hold], None, mu)["a"]
    d *= (ac / a) ** 2
    return d, solve(binary, path, h5, [f"&boundary body=1, group='disc_top', uy={-d!r} /", *hold], None, mu), path, h5


def run_disc(binary, n, mode, method, out, extra=(), ac=AC, mu=MU, gmsh="gmsh", block=BLOCK):
    """The disc scene on the mesh a/h = n, P then Q in two load stages; returns the measured run."""
    if mode not in ("force", "displacement"):
        raise ValueError(f"the disc scene has the modes force and displacement, not {mode}")
    msh = disc_mesh(n, out, ac, gmsh, block)
    tag = f"cmd_{mode}_{method}_{n}"
    d, p, path, h5 = disc_press(binary, msh, out, tag, ac, mu, method)
    q = QFRAC * mu * p["P"]
    press = f"&boundary body=1, group='disc_top', uy={-d!r}, stage=1 /"
    loads = [press, f"&traction body=1, group='disc_top', t0={q / (2.0 * R)!r}, 0.0, stage=2 /"]
    if mode == "force":
        r = solve(binary, path, h5, loads, extra, mu)
        r.update(Q_applied=q, d=d)
        return r
    f = solve(binary, path, h5, loads, None, mu)
    ux = mean_ux(h5, R)
    r = solve(binary, path, h5, [press, f"&boundary body=1, group='disc_top', ux={ux!r}, stage=2 /"], extra, mu)
    r.update(Q_force=f["Q"], d=d, ux=ux)
    return r


def disc_slip(h5, r):
    """Relative tangential displacement of the disc's surface against the block's over |x| < a
    (frictionless, P alone): its largest value and its slope, in units of p0 a/E* and p0/E*."""
    with h5py.File(h5, "r") as f:
        sides = []
        for k in (1, 2):
            xy = np.array(f[f"body{k}/coordinates"])
            u = np.array(f[f"body{k}/displacement"])
            sides.append((xy.T, u.T) if xy.shape[0] == 2 else (xy, u))
    (x1, u1), (x2, u2) = sides
    a, es = r["a"], E / (2.0 * (1.0 - NU ** 2))
    arc = R - np.sqrt(np.clip(R ** 2 - x1[:, 0] ** 2, 0.0, None))
    on1 = (np.abs(x1[:, 0]) < 1.2 * a) & (np.abs(x1[:, 1] - arc) < 1e-9 * R)
    on2 = (np.abs(x2[:, 0]) < a) & (np.abs(x2[:, 1]) < 1e-12)
    o = np.argsort(x1[on1, 0])
    xb = x2[on2, 0]
    s = np.interp(xb, x1[on1, 0][o], u1[on1, 0][o]) - u2[on2, 0]
    return float(np.max(np.abs(s))) / (r["p0"] * a / es), float(np.polyfit(xb, s, 1)[0]) / (r["p0"] / es)


def finite_size(binary, ars, n, mu, out, gmsh="gmsh", block=BLOCK):
    """For each a/R: the relative slip under P alone (frictionless) and the Cattaneo-Mindlin errors."""
    print("| a/R | mu | (a/R)/mu | slip max / (p0 a/E*) | slip slope / (p0/E*) | shear after P / (mu p0) "
          "| c err | shear L2 err | its odd part |")
    print("| --- " * 9 + "|")
    for ar in ars:
        ac = ar * R
        msh = disc_mesh(n, out, ac, gmsh, block)
        _, r0, _, h5 = disc_press(binary, msh, out, f"slip_{ar:g}", ac, 0.0)
        smax, slope = disc_slip(h5, r0)
        _, r1, _, _ = disc_press(binary, msh, out, f"press_{ar:g}", ac, mu)
        with h5py.File(os.path.join(out, f"press_{ar:g}.h5"), "r") as f:
            x, q = np.array(f["contact/x"]), np.array(f["contact/shear"])
        q1 = float(np.sqrt(np.mean(q[np.abs(x) < 0.9 * r1["a"]] ** 2))) / (mu * r1["p0"])
        r = run_disc(binary, n, "force", "monolithic", out, ac=ac, mu=mu, gmsh=gmsh, block=block)
        print(f"| {r['a'] / R:.4f} | {mu:g} | {r['a'] / R / mu:.3f} | {smax:.4f} | {slope:.4f} | {q1:.4f} | "
              f"{r['c_err']:+.2%} | {r['l2']:.2%} | {r['l2_odd']:.2%} |", flush=True)


def measure(h5, text, mu=None):
    with h5py.File(h5, "r") as f:
        c = f["contact"]
        x = np.array(c["x"])
        p = np.array(c["pressure"])
        q = np.array(c["shear"]) if "shear" in c else np.zeros_like(x)
        st = np.array(c["state"]) if "state" in c else np.zeros(x.shape, int)
        lam = np.array(c["normal_force"])
        lt = np.array(c["tangential_force"]) if "tangential_force" in c else np.zeros_like(x)
    o = np.argsort(x)
    x, p, q, st = x[o], p[o], q[o], st[o]
    P, Q = float(np.sum(lam)), abs(float(np.sum(lt)))
    mu = MU if mu is None else mu
    es = E / (2.0 * (1.0 - NU ** 2))
    a = math.sqrt(4.0 * P * R / (math.pi * es))
    p0 = 2.0 * P / (math.pi * a)
    out = dict(P=P, Q=Q, a=a, p0=p0, lam=lam[o], lt=lt[o], text=text)
    if Q == 0.0:
        return out
    c_th = a * math.sqrt(1.0 - Q / (mu * P))
    af, p0f, _ = hertz_fit(x, p)
    qs = np.sign(np.sum(q)) * q

    def cm(cc):
        return mu * p0 * (np.sqrt(np.clip(1.0 - x ** 2 / a ** 2, 0.0, None))
                          - (cc / a) * np.sqrt(np.clip(1.0 - x ** 2 / cc ** 2, 0.0, None)))
    inside = np.abs(x) < a
    cs = np.linspace(0.5 * c_th, 1.5 * c_th, 4001)
    xi, cc = x[inside], cs[:, None]            # cm(cc) on |x| < a for every cc at once, a row each
    shapes = mu * p0 * (np.sqrt(np.clip(1.0 - xi ** 2 / a ** 2, 0.0, None))
                        - (cc / a) * np.sqrt(np.clip(1.0 - xi ** 2 / cc ** 2, 0.0, None)))
    c_fit = cs[int(np.argmin([np.linalg.norm(qs[inside] - row) for row in shapes]))]
    away = inside & (np.abs(np.abs(x) - c_th) > 0.1 * a) & (np.abs(x) < 0.9 * a)
    l2 = float(np.linalg.norm((qs - cm(c_th))[away]) / np.linalg.norm(cm(c_th)[away]))
    err = qs - cm(c_th)                # its parts even and odd in x (the mirror by interpolation)
    mirror = np.interp(-x, x, err)
    l2_even, l2_odd = (float(np.linalg.norm((0.5 * (err + sg * mirror))[away]) / np.linalg.norm(cm(c_th)[away]))
                       for sg in (1.0, -1.0))
    stick = x[st == 1]
    out.update(mu=mu, x=x, q=qs, c=c_th, l2_even=l2_even, l2_odd=l2_odd, c_fit=c_fit, c_err=c_fit / c_th - 1.0, l2=l2, a_err=af / a - 1.0, p0_err=p0f / p0 - 1.0,
               stick_half=float((stick.max() - stick.min()) / 2.0) if stick.size else 0.0)
    return out


def orders(hs, errs):
    return [math.log(abs(errs[k - 1]) / abs(errs[k])) / math.log(hs[k - 1] / hs[k])
            if errs[k] != 0.0 and errs[k - 1] != 0.0 else float("nan") for k in range(1, len(hs))]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default="blocks", choices=("blocks", "disc"))
    ap.add_argument("--bin", default=os.path.join(ROOT, "bin/robin_contact"))
    ap.add_argument("--n", default=None, help="cells per block along x (blocks; 100,200,400) or a/h (disc; 8,16,32)")
    ap.add_argument("--mode", default="force", choices=("force", "displacement", "stages"))
    ap.add_argument("--method", default="monolithic", choices=("monolithic", "robin"))
    ap.add_argument("--out", default="results/cattaneo")
    ap.add_argument("--ar", default=None, help="disc: the a/R values of the finite-size study (one --n)")
    ap.add_argument("--mu", type=float, default=MU, help="disc: the friction coefficient")
    ap.add_argument("--gmsh", default="gmsh")
    ap.add_argument("--block", default="4,4", help="disc: the block's half-width and depth")
    args = ap.parse_args()
    disc = args.scene == "disc"
    block = tuple(float(v) for v in args.block.split(","))
    ns = [int(v) for v in (args.n or ("8,16,32" if disc else "100,200,400")).split(",")]
    if disc and args.ar:
        finite_size(args.bin, [float(v) for v in args.ar.split(",")], ns[0], args.mu, args.out, args.gmsh, block)
        return
    rows = []
    first = "| a/h | h | a/R" if disc else "| cells per block | h | a/h"
    print(f"{first} | P | Q/(mu P) | a err | p0 err | c err | shear L2 err |" + (" even, odd |" if disc else "")
          + " outer |")
    print("| --- " * (11 if disc else 10) + "|")
    for n in ns:
        if disc:
            r = run_disc(args.bin, n, args.mode, args.method, args.out, mu=args.mu, gmsh=args.gmsh, block=block)
            h = AC / n
            lead = f"| {n} | {h:.4g} | {r['a'] / R:.4f}"
            parts = f" {r['l2_even']:.2%}, {r['l2_odd']:.2%} |"
        else:
            r = run(args.bin, n, args.mode, args.method, args.out)
            h = W / n
            lead = f"| {n} x {n // 2} | {h:.4g} | {r['a'] / h:.1f}"
            parts = ""
        outer = next((t.split("=")[1] for t in r["text"].split() if t.startswith("outer=")), "")
        rows.append((h, r))
        print(f"{lead} | {r['P']:.6g} | {r['Q'] / (r['mu'] * r['P']):.4f} | "
              f"{r['a_err']:+.2%} | {r['p0_err']:+.2%} | {r['c_err']:+.2%} | {r['l2']:.2%} |{parts} {outer} |", flush=True)
    if len(rows) > 1:
        hs = [h for h, _ in rows]
        print("observed orders, c:", ", ".join(f"{v:.2f}" for v in orders(hs, [r["c_err"] for _, r in rows])),
              "; shear L2:", ", ".join(f"{v:.2f}" for v in orders(hs, [r["l2"] for _, r in rows])))


if __name__ == "__main__":
    main()
