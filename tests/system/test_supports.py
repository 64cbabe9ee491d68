#!/usr/bin/python3
"""Support checks that decide by the scene, not by its scale (run by `make check`). The meshes
are written by the test (tests/system/msh_blocks.py), no gmsh needed.

(a) Two strips 5e4 long and 1 high, each clamped on its short left side, the upper one pressed
    by a traction: neither is held only by contact (no 'floating:' line; a thin clamp at
    aspect 5e4 is a clamp), and the monolithic solve converges; the same scene shrunk by 1e-3
    (50 x 1e-3) is decided the same way. With only ux = 0 on its left side the upper strip is
    free to translate vertically and to nothing else: one free motion, a translation. (The
    forces themselves are not compared: a 5e4:1 cantilever's bending flexibility is beyond
    double precision, cond(F1 + F2) ~ 6e9, and the two scales differ by 3% in the resultant.)
(b) A rocker pinned at the middle of its top, pressed into a clamped base by a prescribed
    displacement of the pin (uy = -1e-3, no load at all): held by contact on both sides of
    the pin, it solves by Robin and by monolithic, the two agree to 1e-8; the contact forces
    are mirror-symmetric about the pin (to 1e-8 of the largest); twice the displacement
    gives twice the forces (g0 = 0 and no load: the problem is positively homogeneous), to
    1e-8. Pulled up (uy = +1e-3) or not displaced, nothing presses it: exit 1 naming the
    body and its free motion, and no result file.
(c) A contact group that is also clamped (a foundation drawn as a body): every Robin operator
    and the monolithic solve converge; the vertical resultant on the upper body equals its
    load, 2 (a traction of 1 on a top of length 2; its support, ux = 0, carries no vertical
    force), to 1e-9. Clamped at two of its contact nodes only (F_2 singular, not zero): the
    default operator converges to the monolithic forces; 'steklov' and 'constant' either do
    too or stop with exit 2, never with other forces.
"""
import os
import shutil
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, HERE)
from rc_checks import Checks  # noqa: E402
from rc_run import line_fields, result_fields, run_solver  # noqa: E402
from msh_blocks import block, write_msh  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
MONO = "&solver method='monolithic' /"
check = Checks()


def run(tmp, name, deck_text, *over):
    """Write and run a deck; returns (exit code, stdout+stderr, contact forces or None, h5 path)."""
    deck = os.path.join(tmp, name + ".nml")
    out = os.path.join(tmp, name + ".h5")
    with open(deck, "w") as f:
        f.write(deck_text)
    p, _ = run_solver(BIN, deck, *over, f"&output file='{out}' /", cwd=tmp, timeout=300)
    text = p.stdout + p.stderr
    lam = None
    if p.returncode == 0:
        with h5py.File(out, "r") as f:
            lam = np.array(f["/contact/normal_force"], dtype=float)
    return p.returncode, text, lam, out


def strips(length, height, nx, upper_left):
    return f"""&scene title='strips', plane='strain' /
&body id=1, x0=0, y0={height}, width={length}, height={height}, nx={nx}, ny=2, young=2.1e11, poisson=0.3,
      left='{upper_left}', bottom='contact' /
&body id=2, x0=0, y0=0, width={length}, height={height}, nx={nx}, ny=2, young=2.1e11, poisson=0.3,
      left='clamped', top='contact' /
&traction body=1, side='top', t0=0,-1e3 /
"""


ROCKER = """&scene title='rocker' /
&body id=1, mesh='rocker.msh', region='rocker', young=1e3, poisson=0.3 /
&body id=2, mesh='rocker.msh', region='base', young=1e3, poisson=0.3 /
&boundary body=1, group='pin', ux=0, uy={uy} /
&boundary body=2, group='base_bottom', ux=0, uy=0 /
&contact body1_group='rocker_bottom', body2_group='base_top' /
"""

FOUNDATION = """&scene title='foundation' /
&body id=1, mesh='rocker.msh', region='rocker', young=1e3, poisson=0.3 /
&body id=2, mesh='rocker.msh', region='base', young=1e3, poisson=0.3 /
&boundary body=1, group='rocker_left', ux=0 /
&traction body=1, group='rocker_top', t0=0,-1 /
&boundary body=2, group='base_bottom', ux=0, uy=0 /
&boundary body=2, group='base_top', ux=0, uy=0 /
&contact body1_group='rocker_bottom', body2_group='base_top' /
"""

with tempfile.TemporaryDirectory() as tmp:
    # (a) strips
    rc, text, lam_big, _ = run(tmp, "strips", strips(5e4, 1.0, 200, "clamped"), MONO)
    check(rc == 0, "strips 5e4:1, clamped: the monolithic solve converges", f"exit {rc}: {text[-400:]}")
    check("floating:" not in text and "kernel fails" not in text,
          "strips 5e4:1, clamped: no body is taken as held only by contact")
    rc2, text2, lam_small, _ = run(tmp, "strips_small", strips(50.0, 1e-3, 200, "clamped"), MONO)
    check(rc2 == 0, "strips shrunk by 1e-3: the monolithic solve converges", f"exit {rc2}")
    check("floating:" not in text2 and "kernel fails" not in text2,
          "strips shrunk by 1e-3: no body is taken as held only by contact")
    rc3, text3, _, _ = run(tmp, "strips_roller", strips(5e4, 1.0, 200, "roller"), MONO)
    fl = [ln for ln in text3.splitlines() if ln.startswith("floating:")]
    check(len(fl) == 1 and "free: translation" in fl[0] and "rotation" not in fl[0],
          "strips 5e4:1, upper on a roller: one free motion, a vertical translation", fl[0] if fl else text3[-300:])
    check(rc3 == 0, "strips 5e4:1, upper on a roller: converges", f"exit {rc3}")

    # (b) rocker
    write_msh(os.path.join(tmp, "rocker.msh"),
              [block("rocker", 0.0, 1.0, 2.0, 0.5, 20, 5, [("pin", 10, 5)]), block("base", 0.0, 0.0, 2.0, 1.0, 20, 10)])
    rc_r, text_r, lam_r, _ = run(tmp, "rocker", ROCKER.format(uy=-1e-3))
    rc_m, _, lam_m, _ = run(tmp, "rocker_mono", ROCKER.format(uy=-1e-3), MONO)
    check(rc_r == 0 and rc_m == 0, "rocker pressed by its pin's displacement: Robin and monolithic converge",
          f"exit {rc_r}, {rc_m}: {text_r[-400:]}")
    if lam_r is not None and lam_m is not None:
        err = np.abs(lam_r - lam_m).max() / np.abs(lam_m).max()
        check(err <= 1e-8, "rocker: Robin = monolithic", f"{err:.2e}")
        check(np.abs(lam_m).max() > 0, "rocker: the contact carries a force", f"{np.abs(lam_m).max():.3e}")
        with h5py.File(os.path.join(tmp, "rocker_mono.h5"), "r") as f:
            x = np.array(f["/contact/x"], dtype=float)
        order = np.argsort(x)
        mirror = np.argsort(2.0 - x)
        err = np.abs(lam_m[order] - lam_m[mirror]).max() / np.abs(lam_m).max()
        check(err <= 1e-8, "rocker: forces mirror-symmetric about the pin", f"{err:.2e}")
        rc2, _, lam2, _ = run(tmp, "rocker2", ROCKER.format(uy=-2e-3), MONO)
        if lam2 is not None:
            err = np.abs(lam2 - 2.0 * lam_m).max() / np.abs(2.0 * lam_m).max()
            check(err <= 1e-8, "rocker: twice the displacement, twice the forces", f"{err:.2e}")
        else:
            check(False, "rocker: twice the displacement solves", f"exit {rc2}")
    for uy in ("1e-3", "0"):
        rc_u, text_u, _, out = run(tmp, f"rocker_up{uy}", ROCKER.format(uy=uy))
        check(rc_u == 1 and "body 1 is held only by contact" in text_u and "no load presses it" in text_u
              and "rotation about" in text_u, f"rocker with uy = {uy}: exit 1, no load presses it",
              f"exit {rc_u}: {text_u[-300:]}")
        check(not os.path.exists(out), f"rocker with uy = {uy}: no result file")
        check("Traceback" not in text_u and "Error termination" not in text_u, f"rocker with uy = {uy}: no backtrace")

    # the same refusal under MPI: every rank decides and all stop together (a rank that waits
    # for the others is a hang, which the timeout turns into a failure)
    mpi_bin = os.path.join(ROOT, "bin", "robin_contact_mpi")
    if os.path.exists(mpi_bin) and shutil.which("mpirun"):
        deck = os.path.join(tmp, "rocker_up_mpi.nml")
        out = os.path.join(tmp, "rocker_up_mpi.h5")
        with open(deck, "w") as f:
            f.write(ROCKER.format(uy="1e-3"))
        env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                   OMPI_MCA_mpi_yield_when_idle="1", OMP_NUM_THREADS="1")
        try:
            p = subprocess.run(["mpirun", "--oversubscribe", "-np", "3", mpi_bin, deck,
                                "&solver factorization='mumps' /", f"&output file='{out}' /"],
                               capture_output=True, text=True, cwd=tmp, env=env, timeout=120)
            check(p.returncode == 1 and "no load presses it" in p.stderr and not os.path.exists(out),
                  "rocker pulled up, mpirun -np 3: exit 1 on every rank, nothing written",
                  f"exit {p.returncode}: {p.stderr[-300:]}")
        except subprocess.TimeoutExpired:
            check(False, "rocker pulled up, mpirun -np 3: exit 1 on every rank", "timed out (a rank waited)")
    else:
        print("SKIP  rocker under MPI: no MPI binary or mpirun")

    # (c) foundation
    rc_m, _, lam_m, _ = run(tmp, "found_mono", FOUNDATION, MONO)
    check(rc_m == 0, "foundation: monolithic converges", f"exit {rc_m}")
    for op in ("'harmonic'", "'steklov'", "'constant', alpha=1e-3"):
        rc_f, text_f, lam_f, _ = run(tmp, "found", FOUNDATION, f"&solver robin_operator={op} /")
        check(rc_f == 0, f"foundation, robin_operator={op}: converges", f"exit {rc_f}: {text_f[-400:]}")
        if rc_f == 0:
            fy = float(line_fields(text_f, "contact")["resultant_on_body1"].split(",")[1])
            check(abs(fy - 2.0) <= 1e-9 * 2.0, f"foundation, {op}: vertical resultant = the load 2", f"{fy!r}")
            if lam_m is not None:
                err = np.abs(lam_f - lam_m).max() / np.abs(lam_m).max()
                check(err <= 1e-10, f"foundation, {op}: = monolithic", f"{err:.2e}")
            check(result_fields(text_f)["status"] == "converged", f"foundation, {op}: status converged")

    # (d) the same foundation clamped at two of its contact nodes only: F_2 singular, not zero
    write_msh(os.path.join(tmp, "part.msh"),
              [block("rocker", 0.0, 1.0, 2.0, 0.5, 20, 5),
               block("base", 0.0, 0.0, 2.0, 1.0, 20, 10, [("mid", 10, 10), ("q", 5, 10)])])
    part = FOUNDATION.replace("rocker.msh", "part.msh").replace(
        "&boundary body=2, group='base_top', ux=0, uy=0 /",
        "&boundary body=2, group='mid', ux=0, uy=0 /\n&boundary body=2, group='q', ux=0, uy=0 /")
    rc_m, _, lam_m, _ = run(tmp, "part_mono", part, MONO)
    check(rc_m == 0, "foundation clamped at two contact nodes: monolithic converges", f"exit {rc_m}")
    rc_h, text_h, lam_h, _ = run(tmp, "part_harmonic", part)
    check(rc_h == 0, "foundation clamped at two contact nodes: the default (harmonic) converges", f"exit {rc_h}")
    if rc_h == 0 and lam_m is not None:
        fy = float(line_fields(text_h, "contact")["resultant_on_body1"].split(",")[1])
        check(abs(fy - 2.0) <= 1e-9 * 2.0, "foundation clamped at two nodes: vertical resultant = the load 2", f"{fy!r}")
        err = np.abs(lam_h - lam_m).max() / np.abs(lam_m).max()
        check(err <= 1e-8, "foundation clamped at two nodes, harmonic: = monolithic", f"{err:.2e}")
    for op in ("'steklov'", "'constant', alpha=1e-3"):
        rc_o, _, lam_o, _ = run(tmp, "part_other", part, f"&solver robin_operator={op} /")
        agree = rc_o == 2 or (rc_o == 0 and lam_m is not None and
                              np.abs(lam_o - lam_m).max() <= 1e-8 * np.abs(lam_m).max())
        check(agree, f"foundation clamped at two nodes, {op}: converged to the monolithic forces or exit 2",
              f"exit {rc_o}")

print(f"{len(check.failed)} failed" if check.failed else "all passed")
sys.exit(1 if check.failed else 0)
