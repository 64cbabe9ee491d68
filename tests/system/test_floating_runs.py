#!/usr/bin/python3
"""Bodies held only by contact, whole program (run by `make check`; doc/method.md, "Bodies held only
by contact"):

(a) force-controlled Hertz (inputs/hertz_force.nml on the h = 0.01 mesh): the vertical
    contact force sum(-lam n_y) equals the applied P = 2 to 1e-10, Robin and monolithic;
    Robin = monolithic to 1e-8; half-width a and peak pressure p0 within 3% of Hertz's
    formulas (the loads, not the solver, fix P: an independent reason);
(b) equivalence: the force-controlled run's vertical displacement at the disc centre (0, 2)
    prescribed there (the disc is then supported, not floating) gives the same contact forces
    (1e-8) and displacements;
(c) the paper's scene with body 1's clamp replaced by a roller (ux = 0 on its left side):
    body 1 floats vertically; Robin (harmonic) = monolithic to 1e-6; the vertical contact
    force equals the applied -11.5e6 N/m to 1e-10; the floating line and the result file
    name the free motion; the rigid amplitude is the displacement at the fixing DOF;
(c2) the same with ux = 0 on body 1's top instead: two free motions (vertical translation,
    rotation about a point of the top line); force and moment of the contact balance the
    load's (from the deck's tractions) to 1e-10; Robin = monolithic to 1e-6;
(d) a run stopped at max_outer with a checkpoint and restarted ends bitwise identical to an
    uninterrupted run;
(e) 1 and 2 OpenMP threads give identical contact forces;
(f) the 'steklov' and 'constant' Robin operators on that scene: the converged runs equal
    the monolithic forces to 1e-6, a run that does not converge exits 2 and says so (its
    outer counts are printed as INFO lines);
(g) with bin/robin_contact_mpi and mpirun: factorization='mumps' on np 1 and 2 gives the
    CHOLMOD forces to 1e-10.
"""
import math
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tools"))
from rc_checks import Checks  # noqa: E402
from rc_results import rel_err, text_attr  # noqa: E402
from plane_decks import PAPER_ROLLER  # noqa: E402
from rc_run import result_fields, run_solver, solver_env  # noqa: E402
from hertz_study import hertz_fit  # noqa: E402

BIN = os.environ.get("BIN", "bin/robin_contact")
MPI_BIN = os.environ.get("MPI_BIN", "bin/robin_contact_mpi")
OUT = os.path.join(os.environ.get("BUILD", "build/release"), "test-out", "floating_runs")
shutil.rmtree(OUT, ignore_errors=True)
os.makedirs(OUT)
check = Checks()
ENV = solver_env(2)

HERTZ = "inputs/hertz_force.nml"
H = "0.01"
HMESH = [f"&body id=1, mesh='gmsh/hertz_force_h{H}.msh' /", f"&body id=2, mesh='gmsh/hertz_force_h{H}.msh' /"]
P_HERTZ = 2.0           # pressure 1.0 on the flat side of length 2R = 2 (per unit thickness)
R_DISC = 1.0

ROLLER = os.path.join(OUT, "paper_roller.nml")
with open(ROLLER, "w") as f:
    f.write(PAPER_ROLLER)
# the same, ux = 0 on body 1's top instead: free are the vertical translation and a rotation
# about a point of the top line (two equilibrium rows: force and moment)
ROLLER_TOP = os.path.join(OUT, "paper_roller_top.nml")
with open(ROLLER_TOP, "w") as f:
    f.write(open(ROLLER).read().replace("group='left', ux=0.0 /\n&boundary body=2", "group='top', ux=0.0 /\n&boundary body=2"))
# applied vertical load on body 1: top -(3e6 + 1e6 x) over x in (0, 3) = -13.5e6, right side +2e6 over 1
LOAD_Y = -(3.0e6 * 3.0 + 1.0e6 * 4.5) + 2.0e6 * 1.0
# its moment about (1.5, 2): top -int_0^3 (x - 1.5)(3e6 + 1e6 x) dx = -2.25e6, right side 1.5 * 2e6
MOMENT_TOP = -2.25e6 + 3.0e6


def info(what):
    print("INFO  " + what, flush=True)


def out(name):
    return os.path.join(OUT, name + ".h5")


def run(deck, *over, name, env=None, extra=()):
    """Run deck with overrides into OUT/name.h5: (process, result fields, file)."""
    path = out(name)
    p, res = run_solver(BIN, deck, *over, f"&output file='{path}' /", *extra, env=env or ENV)
    return p, res, path


def contact(path):
    with h5py.File(path, "r") as f:
        return np.array(f["/contact/normal_force"]), np.array(f["/contact/normal"])


def vertical_force(path):
    """The vertical force the contact exerts on body 1: sum(-lam n_y), n the contact normal."""
    lam, n = contact(path)
    return float(-np.sum(lam * n[1, :]))


def ok_run(p, res, what):
    good = p.returncode == 0 and res is not None and res["status"] == "converged"
    return check(good, f"{what}: converged", "" if good else f"exit {p.returncode}, {p.stderr.strip()[-200:]}")


def both_methods(deck, *over, name, what):
    """Run deck with the Robin and with the monolithic method into OUT/<name>_<method>.h5:
    yields (method, process, result fields, file) of each run that converged (checked)."""
    for method in ("robin", "monolithic"):
        p, res, path = run(deck, *over, f"&solver method='{method}' /", name=f"{name}_{method}")
        if ok_run(p, res, f"{what} {method}"):
            yield method, p, res, path


# ---- (a) force-controlled Hertz ---------------------------------------------------------------
hz = {}
for method, p, res, path in both_methods(HERTZ, *HMESH, name="hertz", what=f"Hertz force-controlled h={H}"):
    hz[method] = path
    P = vertical_force(path)
    check(abs(P - P_HERTZ) <= 1e-10 * P_HERTZ, f"Hertz {method}: vertical contact force = P = 2 (1e-10 rel)",
          f"{abs(P - P_HERTZ) / P_HERTZ:.2e}")
    check("translation along y" in "".join(ln for ln in p.stdout.splitlines() if ln.startswith("floating:")),
          f"Hertz {method}: the floating line names the translation along y")
    info(f"Hertz {method}: outer {res['outer']} inner {res['inner']} wall {res['wall_s']} s")
if len(hz) == 2:
    lr, _ = contact(hz["robin"])
    lm, _ = contact(hz["monolithic"])
    e = rel_err(lr, lm)
    check(e is not None and e <= 1e-8, "Hertz: Robin = monolithic contact forces (1e-8)", f"{e:.2e}")
    with h5py.File(hz["robin"], "r") as f:
        x = np.array(f["/contact/x"], dtype=float)
        pr = np.array(f["/contact/pressure"], dtype=float)
        E = float(f["/body1"].attrs["young"])
        nu = float(f["/body1"].attrs["poisson"])
    estar = E / (2.0 * (1.0 - nu ** 2))
    a_h = math.sqrt(4.0 * P_HERTZ * R_DISC / (math.pi * estar))
    p0_h = 2.0 * P_HERTZ / (math.pi * a_h)
    a, p0, xc = hertz_fit(x, pr)
    check(abs(a / a_h - 1.0) <= 0.03, "Hertz: half-width a within 3% of Hertz", f"a={a:.5f}, Hertz {a_h:.5f}, "
          f"{a / a_h - 1.0:+.2%}")
    check(abs(p0 / p0_h - 1.0) <= 0.03, "Hertz: peak pressure p0 within 3% of Hertz",
          f"p0={p0:.4f}, Hertz {p0_h:.4f}, {p0 / p0_h - 1.0:+.2%}")

# ---- (b) equivalence with the displacement-controlled run ----------------------------------------
CENTRE = np.array([0.0, 2.0])


def centre_node(f):
    xy = np.array(f["/body1/coordinates"])
    k = int(np.argmin(np.hypot(xy[0] - CENTRE[0], xy[1] - CENTRE[1])))
    return k, float(np.hypot(*(xy[:, k] - CENTRE)))


for method in ("robin", "monolithic"):
    if method not in hz:
        continue
    with h5py.File(hz[method], "r") as f:
        k, dist = centre_node(f)
        uy = float(np.array(f["/body1/displacement"])[1, k])
        u1 = np.array(f["/body1/displacement"])
        u2 = np.array(f["/body2/displacement"])
    check(dist <= 1e-12, f"equivalence {method}: a node at the disc centre (0, 2)", f"distance {dist:.1e}")
    p, res, path = run(HERTZ, *HMESH, f"&boundary body=1, group='disc_centre', uy={uy!r} /",
                       f"&solver method='{method}' /", name=f"hertz_disp_{method}")
    if not ok_run(p, res, f"equivalence {method}: displacement-controlled run (uy={uy:.6e} at the centre)"):
        continue
    check(not any(ln.startswith("floating:") for ln in p.stdout.splitlines()),
          f"equivalence {method}: with uy prescribed at the centre the disc is not floating")
    lf, _ = contact(hz[method])
    ld, _ = contact(path)
    e = rel_err(ld, lf)
    check(e is not None and e <= 1e-8, f"equivalence {method}: same contact forces (1e-8)", f"{e:.2e}")
    with h5py.File(path, "r") as f:
        e1 = rel_err(np.array(f["/body1/displacement"]), u1)
        e2 = rel_err(np.array(f["/body2/displacement"]), u2)
    check(e1 is not None and e1 <= 1e-8 and e2 is not None and e2 <= 1e-8,
          f"equivalence {method}: same displacements (1e-8)", f"body 1 {e1:.2e}, body 2 {e2:.2e}")

# ---- (c) the paper's scene with body 1 on a roller --------------------------------------------
pr_ = {}
for method, p, res, path in both_methods(ROLLER, name="roller", what="paper roller"):
    pr_[method] = path
    info(f"paper roller {method}: outer {res['outer']} inner {res['inner']} wall {res['wall_s']} s")
    fl = [ln for ln in p.stdout.splitlines() if ln.startswith("floating:")]
    check(len(fl) == 1 and "body 1" in fl[0] and "translation along y" in fl[0],
          f"paper roller {method}: one floating line, body 1, 'translation along y'", fl[0][:120] if fl else "none")
    Fy = vertical_force(path)
    check(abs(Fy + LOAD_Y) <= 1e-10 * abs(LOAD_Y), f"paper roller {method}: vertical contact force = 11.5e6 (1e-10 rel)",
          f"{abs(Fy + LOAD_Y) / abs(LOAD_Y):.2e}")
    with h5py.File(path, "r") as f:
        b1 = f["/body1"]
        check(int(np.asarray(b1.attrs.get("free_rigid_motions", -1)).reshape(-1)[0]) == 1
              and text_attr(b1, "rigid_motions") == "translation along y",
              f"paper roller {method}: /body1 records one free motion, translation along y",
              text_attr(b1, "rigid_motions"))
        ok = all(k in b1 for k in ("rigid_amplitude", "rigid_basis", "fixing_dofs"))
        check(ok, f"paper roller {method}: /body1 has rigid_amplitude, rigid_basis, fixing_dofs")
        check("free_rigid_motions" not in f["/body2"].attrs or
              int(np.asarray(f["/body2"].attrs["free_rigid_motions"]).reshape(-1)[0]) == 0,
              f"paper roller {method}: body 2 (clamped) records no free motion")
        if ok:
            amp = np.array(b1["rigid_amplitude"]).reshape(-1)
            basis = np.array(b1["rigid_basis"]).reshape(-1, 3)
            fix = np.array(b1["fixing_dofs"]).reshape(-1)
            u = np.array(b1["displacement"])
            # K^+ is zero at the fixing DOF: the displacement there is the rigid part alone,
            # amp * (basis translation (0, 1) at that DOF)
            node, comp = int(fix[0]) // 2, int(fix[0]) % 2
            check(amp.size == 1 and np.allclose(basis[0], [0.0, 1.0, 0.0]) and comp == 1
                  and abs(u[comp, node] - amp[0]) <= 1e-12 * abs(amp[0]),
                  f"paper roller {method}: the displacement at the fixing DOF is the rigid amplitude",
                  f"amp {amp[0]:.6e}, u {u[comp, node]:.6e}")
            # the rigid translation moves the body down onto the support
            check(amp[0] < 0.0, f"paper roller {method}: body 1 moves down (amplitude < 0)", f"{amp[0]:.3e}")
if len(pr_) == 2:
    lr, _ = contact(pr_["robin"])
    lm, _ = contact(pr_["monolithic"])
    e = rel_err(lr, lm)
    check(e is not None and e <= 1e-6, "paper roller: Robin = monolithic contact forces (1e-6)", f"{e:.2e}")
    with h5py.File(pr_["robin"], "r") as fr, h5py.File(pr_["monolithic"], "r") as fm:
        ea = rel_err(np.array(fr["/body1/rigid_amplitude"]), np.array(fm["/body1/rigid_amplitude"]))
        eu = rel_err(np.array(fr["/body1/displacement"]), np.array(fm["/body1/displacement"]))
    check(ea is not None and ea <= 1e-6 and eu is not None and eu <= 1e-6,
          "paper roller: Robin = monolithic rigid amplitude and body 1 displacement (1e-6)", f"{ea:.2e}, {eu:.2e}")

# ---- (c2) body 1 held by ux = 0 on its top: two free motions ---------------------------------
pt = {}
for method, p, res, path in both_methods(ROLLER_TOP, name="roller_top", what="ux=0 on body 1's top,"):
    pt[method] = path
    info(f"ux=0 on body 1's top, {method}: outer {res['outer']} inner {res['inner']}")
    fl = "".join(ln for ln in p.stdout.splitlines() if ln.startswith("floating:"))
    check("translation along y" in fl and "rotation about" in fl and "2.0000" in fl,
          f"ux=0 on body 1's top, {method}: free translation along y and a rotation about a point of y = 2", fl[:160])
    lam, n = contact(path)
    with h5py.File(path, "r") as f:
        x = np.array(f["/contact/x"])
        y = np.array(f["/contact/y"])
        nfree = int(np.asarray(f["/body1"].attrs.get("free_rigid_motions", -1)).reshape(-1)[0])
    fx, fy = -lam * n[0, :], -lam * n[1, :]   # the contact's force on body 1 at each node
    mom = float(np.sum((x - 1.5) * fy - (y - 2.0) * fx))
    check(nfree == 2, f"ux=0 on body 1's top, {method}: /body1 records 2 free motions", str(nfree))
    check(abs(np.sum(fy) + LOAD_Y) <= 1e-10 * abs(LOAD_Y),
          f"ux=0 on body 1's top, {method}: vertical contact force = 11.5e6 (1e-10 rel)",
          f"{abs(np.sum(fy) + LOAD_Y) / abs(LOAD_Y):.2e}")
    check(abs(mom + MOMENT_TOP) <= 1e-10 * abs(LOAD_Y) * 1.5,
          f"ux=0 on body 1's top, {method}: contact moment about (1.5, 2) balances the load's 0.75e6",
          f"{mom:.6e}, rel {abs(mom + MOMENT_TOP) / (abs(LOAD_Y) * 1.5):.2e}")
if len(pt) == 2:
    e = rel_err(contact(pt["robin"])[0], contact(pt["monolithic"])[0])
    check(e is not None and e <= 1e-6, "ux=0 on body 1's top: Robin = monolithic contact forces (1e-6)", f"{e:.2e}")

# ---- (c3) the lower body floating, softer than the upper one ------------------------------------
# body 2 (E = 1e10, 21x softer) on rollers on both vertical sides, pushed up by 4e6 on its bottom
# against body 1 clamped on its top: the floating body is body 2 (its rows enter G with body 2's
# normal), vertical force 12e6. Once, the harmonic inner tolerance asked the floating body's
# SMALBE solves for a gradient below the rounding of its augmented Hessian and MPRGP spun to
# inner_max_it (1.2 M products for m = 25): the product count is bounded here.
LOWER = os.path.join(OUT, "lower_floating.nml")
with open(LOWER, "w") as f:
    f.write("""&body id=1, x0=0.0, y0=1.0, width=3.0, height=1.0, nx=24, ny=16, young=2.1e11, poisson=0.277 /
&body id=2, x0=0.0, y0=0.0, width=3.0, height=1.0, nx=24, ny=16, young=1.0e10, poisson=0.3 /
&boundary body=1, group='top', ux=0.0, uy=0.0 /
&boundary body=2, group='left', ux=0.0 /
&boundary body=2, group='right', ux=0.0 /
&traction body=2, side='bottom', t0=0.0, 4.0e6 /
&contact body1_group='bottom', body2_group='top' /
&solver robin_operator='harmonic', delta=0.5, tol=1e-10 /
""")
lres = {}
for method, p, res, path in both_methods(LOWER, name="lower", what="lower body floating,"):
    lres[method] = path
    check("floating: body 2 is held only by contact (free: translation along y)" in p.stdout,
          f"lower body floating, {method}: body 2 named floating along y")
    fy = vertical_force(path)
    check(abs(fy / 12.0e6 - 1.0) <= 1e-10, f"lower body floating, {method}: contact force = the load 12e6 "
          "(1e-10)", f"{abs(fy / 12.0e6 - 1.0):.2e}")
    check(int(res["inner"]) <= 5000, f"lower body floating, {method}: at most 5000 products", res["inner"])
if len(lres) == 2:
    e = rel_err(contact(lres["robin"])[0], contact(lres["monolithic"])[0])
    check(e is not None and e <= 1e-8, "lower body floating: Robin = monolithic (1e-8)", f"{e:.2e}")

# ---- (d) checkpoint and restart ------------------------------------------------------------------
if "robin" in pr_:
    # checkpoint_every lives in &output: the output group whole
    p, res = run_solver(BIN, ROLLER, "&solver max_outer=10 /",
                        f"&output file='{out('roller_part')}', checkpoint_every=5 /", env=ENV)
    ck = out("roller_part") + ".ckpt.h5"
    check(p.returncode == 2 and os.path.exists(ck), "restart: a run stopped at max_outer=10 exits 2 with a checkpoint",
          f"exit {p.returncode}")
    if os.path.exists(ck):
        p, res = run_solver(BIN, ROLLER, f"&output file='{out('roller_restart')}' /", "--restart", ck, env=ENV)
        if ok_run(p, res, "restart from the checkpoint"):
            lr, _ = contact(pr_["robin"])
            lx, _ = contact(out("roller_restart"))
            d = float(np.max(np.abs(lx - lr)) / np.max(np.abs(lr)))
            check(np.array_equal(lx, lr), "restart: contact forces bitwise identical to the uninterrupted run",
                  f"max diff {d:.2e}")
            with h5py.File(out("roller_restart"), "r") as fx, h5py.File(pr_["robin"], "r") as fr:
                same = all(np.array_equal(np.array(fx[k]), np.array(fr[k]))
                           for k in ("/body1/displacement", "/body1/rigid_amplitude", "/history/residual"))
                n1, n2 = int(fx.attrs["outer_iterations"]), int(fr.attrs["outer_iterations"])
            check(same and n1 == n2, "restart: displacements, rigid amplitude, history and outer count identical",
                  f"outer {n1} vs {n2}")

# ---- (e) OpenMP threads -------------------------------------------------------------------------
lt = {}
for t in (1, 2):
    p, res, path = run(ROLLER, name=f"roller_omp{t}", env=solver_env(t))
    if ok_run(p, res, f"paper roller OMP_NUM_THREADS={t}"):
        lt[t] = contact(path)[0]
if len(lt) == 2:
    check(np.array_equal(lt[1], lt[2]), "OMP_NUM_THREADS=1 and 2: identical contact forces",
          f"max diff {np.max(np.abs(lt[1] - lt[2])):.2e}")

# ---- (f) the other Robin operators -----------------------------------------------------------------
if "monolithic" in pr_:
    lm, _ = contact(pr_["monolithic"])
    for op, extra, deltas in (("steklov", "", (0.3, 0.5, 0.7)),
                              ("constant", ", alpha=1e-13", (0.5, 0.9)),
                              ("constant", ", alpha=1e-12", (0.5, 0.7))):
        for d in deltas:
            tag = f"{op}{extra.replace(', ', ' ')} delta={d}"
            p, res, path = run(ROLLER, f"&solver robin_operator='{op}'{extra}, delta={d}, max_outer=300 /",
                               name=f"roller_{op}{extra[8:]}_{d}")
            if res is None:
                check(False, f"{tag}: a result line", f"exit {p.returncode}, {p.stderr.strip()[-200:]}")
                continue
            info(f"{tag}: exit {p.returncode} status {res['status']} outer {res['outer']} inner {res['inner']}")
            if p.returncode == 0:
                e = rel_err(contact(path)[0], lm)
                check(res["status"] == "converged" and e is not None and e <= 1e-6,
                      f"{tag}: converged, forces = monolithic (1e-6)", f"{e:.2e}")
            else:
                st = ""
                if os.path.exists(path):
                    with h5py.File(path, "r") as f:
                        st = text_attr(f, "status")
                check(p.returncode == 2 and res["status"] in ("max_outer", "diverged") and st in ("", res["status"]),
                      f"{tag}: not converged: exit 2, status max_outer or diverged (result line and file)",
                      f"exit {p.returncode}, {res['status']}, file '{st}'")

# ---- (g) MUMPS under MPI ----------------------------------------------------------------------------
if not (os.path.exists(MPI_BIN) and shutil.which("mpirun")):
    print(f"SKIP  {MPI_BIN} or mpirun absent: no MUMPS runs")
elif pr_:
    env = solver_env(1)
    env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_mpi_yield_when_idle="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    for method, ref in pr_.items():
        lref, _ = contact(ref)
        for np_ in (1, 2):
            path = out(f"roller_mumps_{method}_np{np_}")
            cmd = ["mpirun", "--oversubscribe", "-np", str(np_), MPI_BIN, ROLLER,
                   f"&solver factorization='mumps', method='{method}' /", f"&output file='{path}' /"]
            try:
                p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=120)
            except subprocess.TimeoutExpired:
                check(False, f"MUMPS {method} np={np_}: finished within 120 s")
                continue
            res = result_fields(p.stdout)
            if not ok_run(p, res, f"MUMPS {method} np={np_}"):
                continue
            info(f"MUMPS {method} np={np_}: outer {res['outer']} inner {res['inner']}")
            e = rel_err(contact(path)[0], lref)
            check(e is not None and e <= 1e-10, f"MUMPS {method} np={np_}: CHOLMOD's contact forces (1e-10)",
                  f"{e:.2e}")
            # the same iteration as CHOLMOD's (its data agree to rounding): rank 0 must have
            # every body's condensed data, the kernel of body 2's singular F included (once,
            # with one rank per body, it lacked it and took 3x the products)
            with h5py.File(ref, "r") as f:
                inner_ref = int(f.attrs["inner_iterations"])
            check(int(res["inner"]) <= 1.2 * inner_ref + 10,
                  f"MUMPS {method} np={np_}: inner products as CHOLMOD's (<= 1.2x {inner_ref} + 10)", res["inner"])

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
