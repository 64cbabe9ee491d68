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

usage: cattaneo_study.py [--bin BIN] [--n 100,200,400] [--mode force|displacement|stages]
       [--method monolithic|robin] [--out DIR]
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


def deck(n, method):
    ny = n * int(H * 1000) // int(W * 1000)
    return f"""&scene title='Cattaneo-Mindlin, two equal blocks', units='custom' /
&body id=1, x0={-W / 2}, y0=0.0, width={W}, height={H}, nx={n}, ny={ny}, young={E}, poisson={NU}, bottom='contact' /
&body id=2, x0={-W / 2}, y0={-H}, width={W}, height={H}, nx={n}, ny={ny}, young={E}, poisson={NU}, top='contact',
      bottom='clamped' /
&contact friction='coulomb', mu={MU}, gap_radius={R}, gap_center=0.0 /
&solver method='{method}', stop='residual', tol=1.0e-10 /
"""


def run(binary, n, mode, method, out, extra=()):
    """One run; returns (its measured quantities, console text)."""
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
    p = solve(binary, path, h5, [top], None)
    P = p["P"]
    loads = [top, f"&traction body=1, side='top', t0={QFRAC * MU * P / W}, 0.0 /"]
    if mode == "force":
        r = solve(binary, path, h5, loads, extra)
        r["Q_applied"] = QFRAC * MU * P
        return r
    f = solve(binary, path, h5, loads, None)
    with h5py.File(h5, "r") as g:
        xy = np.array(g["body1/coordinates"])
        u = np.array(g["body1/displacement"])
    if xy.shape[0] == 2:
        xy, u = xy.T, u.T
    ux = float(np.mean(u[np.abs(xy[:, 1] - H) < 1e-12, 0]))
    r = solve(binary, path, h5, [f"&boundary body=1, group='top', ux={ux!r}, uy={-D} /"], extra)
    r["Q_force"] = f["Q"]
    return r


def solve(binary, path, h5, loads, extra):
    cmd = [binary, path, *loads, f"&output file='{h5}' /", *(extra or ())]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=1200)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {p.returncode}: {(p.stdout + p.stderr).strip()[-400:]}")
    return measure(h5, p.stdout)


def measure(h5, text):
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
    es = E / (2.0 * (1.0 - NU ** 2))
    a = math.sqrt(4.0 * P * R / (math.pi * es))
    p0 = 2.0 * P / (math.pi * a)
    out = dict(P=P, Q=Q, a=a, p0=p0, lam=lam[o], lt=lt[o], text=text)
    if Q == 0.0:
        return out
    c_th = a * math.sqrt(1.0 - Q / (MU * P))
    af, p0f, _ = hertz_fit(x, p)
    qs = np.sign(np.sum(q)) * q

    def cm(cc):
        return MU * p0 * (np.sqrt(np.clip(1.0 - x ** 2 / a ** 2, 0.0, None))
                          - (cc / a) * np.sqrt(np.clip(1.0 - x ** 2 / cc ** 2, 0.0, None)))
    inside = np.abs(x) < a
    cs = np.linspace(0.5 * c_th, 1.5 * c_th, 4001)
    c_fit = cs[int(np.argmin([np.linalg.norm((qs - cm(cc))[inside]) for cc in cs]))]
    away = inside & (np.abs(np.abs(x) - c_th) > 0.1 * a) & (np.abs(x) < 0.9 * a)
    l2 = float(np.linalg.norm((qs - cm(c_th))[away]) / np.linalg.norm(cm(c_th)[away]))
    stick = x[st == 1]
    out.update(c=c_th, c_fit=c_fit, c_err=c_fit / c_th - 1.0, l2=l2, a_err=af / a - 1.0, p0_err=p0f / p0 - 1.0,
               stick_half=float((stick.max() - stick.min()) / 2.0) if stick.size else 0.0)
    return out


def orders(hs, errs):
    return [math.log(abs(errs[k - 1]) / abs(errs[k])) / math.log(hs[k - 1] / hs[k])
            if errs[k] != 0.0 and errs[k - 1] != 0.0 else float("nan") for k in range(1, len(hs))]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(os.path.dirname(HERE), "bin/robin_contact"))
    ap.add_argument("--n", default="100,200,400")
    ap.add_argument("--mode", default="force", choices=("force", "displacement", "stages"))
    ap.add_argument("--method", default="monolithic", choices=("monolithic", "robin"))
    ap.add_argument("--out", default="results/cattaneo")
    args = ap.parse_args()
    ns = [int(v) for v in args.n.split(",")]
    rows = []
    print("| cells per block | h | a/h | P | Q/(mu P) | a err | p0 err | c err | shear L2 err | outer |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for n in ns:
        r = run(args.bin, n, args.mode, args.method, args.out)
        h = W / n
        outer = next((t.split("=")[1] for t in r["text"].split() if t.startswith("outer=")), "")
        rows.append((h, r))
        print(f"| {n} x {n // 2} | {h:.4g} | {r['a'] / h:.1f} | {r['P']:.6g} | {r['Q'] / (MU * r['P']):.4f} | "
              f"{r['a_err']:+.2%} | {r['p0_err']:+.2%} | {r['c_err']:+.2%} | {r['l2']:.2%} | {outer} |")
    if len(rows) > 1:
        hs = [h for h, _ in rows]
        print("observed orders, c:", ", ".join(f"{v:.2f}" for v in orders(hs, [r["c_err"] for _, r in rows])),
              "; shear L2:", ", ".join(f"{v:.2f}" for v in orders(hs, [r["l2"] for _, r in rows])))


if __name__ == "__main__":
    main()
