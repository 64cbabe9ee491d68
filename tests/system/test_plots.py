#!/usr/bin/python3
"""The plot tools on a large result within a memory budget (run by `make check`).

Solves the default scene at 512x256 cells per body (about 263k DOFs per body, ~10 s) and
the Hertz deck (inputs/hard/hertz.nml), then runs tools/plot_history.py,
plot_contact.py (also --hertz) and plot_solution.py (von Mises and sxy) on them, each as a
child process under an address-space cap (RLIMIT_AS, CAP_MB) so that a runaway fails
instead of swamping the machine, and checks:
  - exit 0 and peak resident memory (os.wait4 of that child) below BUDGET_MB;
  - the PNG is a picture, not almost uniform or almost black (the 1024x512 failure: a
    million element edges): grey-level spread over the image, and for plot_solution the
    fraction of dark pixels in the plot area below 30%;
  - plot_solution says that its colour scale is clipped and that edges are not drawn;
  - plot_contact --hertz prints the errors against Hertz (err_a, err_p0, err_L2);
  - friction: on a Hertz scene with Coulomb friction and a tangential displacement (Q about
    0.76 mu P), plot_contact adds the shear panel (a taller picture) and prints the
    tangential resultant and the stick and slip counts of the file's /contact/state;
    --mindlin adds Cattaneo-Mindlin's shear: its stick half-width c computed here from the
    file (Hertz's a from P, R, E*; Q, mu P) is the one printed, and the solution agrees
    with it (stick half-width within 5% of a, shear L2 error below 8%); on a frictionless
    result --mindlin says why there is no Mindlin curve and draws the picture --hertz draws,
    pixel for pixel;
  - failures end with a message and exit 1: a result without /body2, a file that is not
    HDF5, and running out of memory (--pixels 8000 under the cap);
  - rc_results' and rc_figures' unit helpers (SI defaults, stored units, SI-prefix scaling, labels,
    numbers with units);
  - plot_contact names the force it shows: the sum of the nodal normal forces as one number
    with its unit ('1.579e9 N/mm', not '1.579 1e9 N/mm'), or the resultant vector when the
    result file stores one;
  - a solid result (Hertz's sphere on a block, the quarter model inputs/sphere_block.nml on
    the coarse mesh): plot_contact --hertz --radius 1 --csv maps the contact surface and
    writes the pressure along the line through the contact centre: the Hertz P, a and p0 it
    prints are those computed here (P four times the resultant's y component of the quarter
    model, E* from the deck's E and nu); every sample of the CSV lies on the line (along x
    from the centre on the symmetry planes, t = x, z = 0), its pressure, gap and y equal the
    linear interpolation on the file's /contact/faces computed here (barycentric coordinates
    of the face that holds the sample), its Hertz column p0 sqrt(1 - t^2/a^2); the samples
    span the surface along the line; a diagonal line (--line 1,5,1: the component along the
    normal dropped) gives t = (x + z)/sqrt(2), x = z; plane and solid results together: exit
    1 with a message.
Wall times are printed (TIME lines), never asserted.
"""
import os
import re
import resource
import shutil
import subprocess
import sys
import time

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_figures import axis_label, format_quantity, si_scale  # noqa: E402
from rc_results import result_units  # noqa: E402
from rc_run import run_solver  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", "bin/robin_contact"))
PYTHON = os.environ.get("PYTHON", "/usr/bin/python3")
OUT = os.path.abspath(os.path.join(os.environ.get("BUILD", "build/release"), "test-out", "plots"))
BUDGET_MB = 600          # peak RSS of one plot tool on the 512x256 result
CAP_MB = 1500            # address-space cap of each tool run (a runaway fails fast)
NX, NY = int(os.environ.get("PLOT_TEST_NX", 512)), int(os.environ.get("PLOT_TEST_NY", 256))
check = Checks()
shutil.rmtree(OUT, ignore_errors=True)
os.makedirs(OUT)


def tool(name, *args, cap_mb=CAP_MB):
    """Run tools/<name> args; returns (exit status, stdout+stderr, wall s, peak RSS MB)."""
    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (cap_mb << 20, cap_mb << 20))
    t0 = time.monotonic()
    p = subprocess.Popen([PYTHON, os.path.join(ROOT, "tools", name), *args], stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True, preexec_fn=limit)
    out = p.stdout.read()
    _, status, ru = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)
    wall = time.monotonic() - t0
    return p.returncode, out, wall, ru.ru_maxrss / 1024.0


def picture(path, what, plot_area=False):
    import matplotlib.image as mpimg
    if not check(os.path.isfile(path), f"{what}: {os.path.basename(path)} written"):
        return
    img = mpimg.imread(path)
    grey = img[..., :3].mean(axis=2) if img.ndim == 3 else img
    spread = float(np.percentile(grey, 99) - np.percentile(grey, 1))
    check(grey.std() > 0.05 and spread > 0.3, f"{what}: not almost uniform",
          f"grey std {grey.std():.3f}, 1-99 percentile spread {spread:.2f}")
    if plot_area:
        h, w = grey.shape
        area = grey[int(0.15 * h):int(0.85 * h), int(0.10 * w):int(0.75 * w)]
        dark = float(np.mean(area < 0.2))
        check(dark < 0.3, f"{what}: plot area not almost black", f"{100 * dark:.1f}% dark pixels < 30%")


def budget(name, rc, out, wall, mb, what):
    print(f"TIME  {what}: {wall:.2f} s wall, peak RSS {mb:.0f} MB")
    check(rc == 0, f"{what}: exit 0", f"exit {rc}" + ("" if rc == 0 else ": " + out.strip()[-400:]))
    check(mb < BUDGET_MB, f"{what}: peak RSS {mb:.0f} MB < {BUDGET_MB} MB")


# ---- results -------------------------------------------------------------------------
big = f"{OUT}/big.h5"
t0 = time.monotonic()
p, res = run_solver(BIN, os.path.join(ROOT, "inputs/default.nml"), f"&body id=1, nx={NX}, ny={NY} /",
                    f"&body id=2, nx={NX}, ny={NY} /", f"&output file='{big}' /")
print(f"TIME  robin_contact default deck {NX}x{NY} per body: {time.monotonic() - t0:.1f} s")
if not check(p.returncode == 0 and os.path.isfile(big), f"default deck at {NX}x{NY} per body solved",
             f"exit {p.returncode}"):
    sys.exit(1)
hz = f"{OUT}/hertz.h5"
p, _ = run_solver(BIN, os.path.join(ROOT, "inputs/hard/hertz.nml"), f"&output file='{hz}' /")
check(p.returncode == 0, "Hertz deck solved", f"exit {p.returncode}")

# ---- the tools on the big result ------------------------------------------------------
rc, out, wall, mb = tool("plot_history.py", big, "-o", f"{OUT}/history.png")
budget("plot_history.py", rc, out, wall, mb, f"plot_history.py {NX}x{NY}")
picture(f"{OUT}/history.png", "history.png")

rc, out, wall, mb = tool("plot_contact.py", big, "--hertz", "-o", f"{OUT}/contact.png")
budget("plot_contact.py", rc, out, wall, mb, f"plot_contact.py --hertz {NX}x{NY}")
picture(f"{OUT}/contact.png", "contact.png")
check("no Hertz curve: gap_radius = 0" in out, "plot_contact --hertz on a flat gap says why there is no Hertz curve")

rc, out, wall, mb = tool("plot_solution.py", big, "-o", f"{OUT}/solution.png")
budget("plot_solution.py", rc, out, wall, mb, f"plot_solution.py {NX}x{NY}")
picture(f"{OUT}/solution.png", "solution.png", plot_area=True)
check("clipped above the 99.5th percentile" in out, "plot_solution: colour scale clipped, and says so", out.strip())

rc, out, wall, mb = tool("plot_solution.py", big, "--field", "sxy", "-o", f"{OUT}/solution_sxy.png")
budget("plot_solution.py", rc, out, wall, mb, f"plot_solution.py --field sxy {NX}x{NY}")
picture(f"{OUT}/solution_sxy.png", "solution_sxy.png", plot_area=True)

# ---- Hertz ---------------------------------------------------------------------------------
rc, out, wall, mb = tool("plot_contact.py", hz, "--hertz", "-o", f"{OUT}/hertz.png")
check(rc == 0 and "1 Hertz curves" in out, "plot_contact --hertz on the Hertz deck: one Hertz curve", f"exit {rc}")
line = [ln for ln in out.splitlines() if ln.startswith("plot_contact: Hertz for hertz:")]
ok = bool(line) and all(k in line[0] for k in ("err_a=", "err_p0=", "err_L2=", " a=", " p0="))
check(ok, "plot_contact --hertz prints a, p0 and the errors against Hertz", line[0] if line else out.strip())
if line:
    err = {k: float(v) for k, v in (w.split("=") for w in line[0].split() if w.startswith("err_"))}
    check(err["err_p0"] < 0.05 and err["err_L2"] < 0.05, "Hertz deck (80x40): p0 and L2 errors below 5%", str(err))
picture(f"{OUT}/hertz.png", "hertz.png")

# ---- a solid result: the pressure map and the pressure along a line ------------------------
def line_check(csv_path, h5, direction, hertz=None):
    """The CSV of plot_contact on a solid result against the file: the samples on the line
    through the centre (0, ., 0) along direction (in x, z), and their pressure, gap and y the
    linear interpolation on /contact/faces (computed here); returns the samples' t and x."""
    import csv
    with h5py.File(h5, "r") as f:
        xyz = np.stack([f["contact/x"][()], f["contact/y"][()], f["contact/z"][()]], axis=1)
        pres, gap = f["contact/pressure"][()], f["contact/gap"][()]
        faces = f["contact/faces"][()]
    with open(csv_path) as fh:
        rows = list(csv.DictReader(fh))
    t = np.array([float(r["t"]) for r in rows])
    q = np.array([[float(r[k]) for k in ("x", "y", "z")] for r in rows])
    pc, gc = np.array([float(r["pressure"]) for r in rows]), np.array([float(r["gap"]) for r in rows])
    d = np.asarray(direction, dtype=float) / np.hypot(*direction)
    on_line = len(rows) > 0 and max(np.abs(q[:, 0] - t * d[0]).max(), np.abs(q[:, 2] - t * d[1]).max()) <= 1e-12
    worst, missing = 0.0, 0
    a, b, c = (xyz[faces[:, k]][:, [0, 2]] for k in range(3))
    for k in range(len(rows)):
        pt = q[k, [0, 2]]
        den = (b[:, 1] - c[:, 1]) * (a[:, 0] - c[:, 0]) + (c[:, 0] - b[:, 0]) * (a[:, 1] - c[:, 1])
        l1 = ((b[:, 1] - c[:, 1]) * (pt[0] - c[:, 0]) + (c[:, 0] - b[:, 0]) * (pt[1] - c[:, 1])) / den
        l2 = ((c[:, 1] - a[:, 1]) * (pt[0] - c[:, 0]) + (a[:, 0] - c[:, 0]) * (pt[1] - c[:, 1])) / den
        lam = np.stack([l1, l2, 1.0 - l1 - l2], axis=1)
        hold = np.nonzero(lam.min(axis=1) >= -1e-9)[0]
        if not hold.size:
            missing += 1
            continue
        e, w = hold[0], lam[hold[0]]
        worst = max(worst, abs(w @ pres[faces[e]] - pc[k]) / pres.max(),
                    abs(w @ gap[faces[e]] - gc[k]) / np.abs(gap).max(),
                    abs(w @ xyz[faces[e], 1] - q[k, 1]) / np.abs(xyz).max())
    check(len(rows) >= 300 and on_line, f"plot_contact --csv (line {direction}): {len(rows)} samples, all on the line "
          "through the centre", f"{len(rows)} rows, on the line: {on_line}")
    check(missing == 0 and worst <= 1e-12, f"plot_contact --csv (line {direction}): pressure, gap and y are the linear "
          "interpolation on the file's faces", f"largest relative difference {worst:.1e}, {missing} samples on no face")
    if hertz is not None:
        hz_col = np.array([float(r["hertz_pressure"]) for r in rows])
        p0_, a_ = hertz
        ref = p0_ * np.sqrt(np.clip(1.0 - (t / a_) ** 2, 0.0, None))
        check(np.abs(hz_col - ref).max() <= 1e-9 * p0_, "plot_contact --csv: the Hertz column is p0 sqrt(1 - t^2/a^2)",
              f"max difference {np.abs(hz_col - ref).max():.2e}")
    return t, q[:, 0]


E3, NU3, R3 = 1000.0, 0.3, 1.0          # inputs/sphere_block.nml
sb = f"{OUT}/sphere.h5"
coarse = os.path.join(ROOT, "inputs/gmsh/sphere_block_h0.02.msh")
p, _ = run_solver(BIN, os.path.join(ROOT, "inputs/sphere_block.nml"), f"&body id=1, mesh='{coarse}' /",
                  f"&body id=2, mesh='{coarse}' /", f"&output file='{sb}' /")
if check(p.returncode == 0, "Hertz 3D (quarter model, coarse mesh) solved", f"exit {p.returncode}"):
    with h5py.File(sb, "r") as f:
        P3 = 4.0 * float(f["contact/resultant_body1"][1])
        xz = np.stack([f["contact/x"][()], f["contact/z"][()]], axis=1)
    a3 = (3.0 * P3 * R3 / (4.0 * E3 / (2.0 * (1.0 - NU3 ** 2)))) ** (1.0 / 3.0)
    p03 = 3.0 * P3 / (2.0 * np.pi * a3 ** 2)
    rc, out, wall, mb = tool("plot_contact.py", sb, "--hertz", "--radius", "1", "--csv", f"{OUT}/line.csv",
                             "-o", f"{OUT}/sphere.png")
    print(f"TIME  plot_contact.py --hertz on a solid result: {wall:.2f} s wall, peak RSS {mb:.0f} MB")
    check(rc == 0 and "1 Hertz curves" in out, "plot_contact --hertz --radius 1 on a solid result: exit 0, "
          "one Hertz curve", f"exit {rc} {out.strip()[-300:]}")
    picture(f"{OUT}/sphere.png", "sphere.png (pressure map and line)")
    line = [ln for ln in out.splitlines() if ln.startswith("plot_contact: Hertz for sphere:")]
    vals = {k: float(v) for k, v in (w.split("=") for w in line[0].split() if w.count("=") == 1
                                     and w.split("=")[0] in ("P", "a", "p0", "a_fit"))} if line else {}
    check(bool(vals) and abs(vals["P"] / P3 - 1) < 1e-5 and abs(vals["a"] / a3 - 1) < 1e-5
          and abs(vals["p0"] / p03 - 1) < 1e-5 and "symmetry planes x = 0, z = 0" in line[0],
          "plot_contact --hertz on the quarter model: P = 4 x the resultant, a and p0 of Hertz's point contact",
          f"{line} against P={P3:.6g} a={a3:.6g} p0={p03:.6g}")
    check(bool(vals) and abs(vals["a_fit"] / a3 - 1) < 0.05, "the Hertz shape fitted to the pressures: a within 5%",
          f"{vals}")
    t, x = line_check(f"{OUT}/line.csv", sb, (1.0, 0.0), hertz=(p03, a3))
    xmax = float(xz[xz[:, 1] == 0.0, 0].max())
    check(t.size and t.min() == 0.0 and xmax - t.max() < 0.01 * xmax,
          "the samples span the surface along the line (from the centre to the last node on z = 0)",
          f"t from {t.min() if t.size else None} to {t.max() if t.size else None}, last node at x = {xmax:.6g}")
    rc, out, _, _ = tool("plot_contact.py", sb, "--line", "1,5,1", "--csv", f"{OUT}/diag.csv", "-o", f"{OUT}/diag.png")
    check(rc == 0 and "along (0.7071, 0, 0.7071)" in out, "plot_contact --line 1,5,1: the line along (1, 0, 1)/sqrt(2)",
          f"exit {rc} {out.strip()[-300:]}")
    if rc == 0:
        line_check(f"{OUT}/diag.csv", sb, (1.0, 1.0))
    rc, out, _, _ = tool("plot_contact.py", sb, hz, "-o", f"{OUT}/both.png")
    check(rc == 1 and "cannot draw plane and solid results together" in out and "Traceback" not in out
          and not os.path.exists(f"{OUT}/both.png"),
          "plot_contact on a plane and a solid result: exit 1 with a message", out.strip()[-300:])

# ---- friction: the shear panel and Cattaneo-Mindlin ---------------------------------------
E, NU, R_GAP, MU = 2.1e11, 0.3, 100.0, 0.3
cm = f"{OUT}/mindlin.h5"
cm_deck = f"{OUT}/mindlin.nml"
with open(cm_deck, "w") as fh:
    fh.write(f"""&scene title='Hertz line contact with Coulomb friction, sheared', plane='strain' /
&body id=1, x0=0.0, y0=6.0, width=12.0, height=6.0, nx=240, ny=120, young={E}, poisson={NU},
      left='free', right='free', top='displacement', bottom='contact' /
&body id=2, x0=0.0, y0=0.0, width=12.0, height=6.0, nx=240, ny=120, young={E}, poisson={NU},
      left='free', right='free', top='contact', bottom='clamped' /
&displacement body=1, side='top', u=0.004, -0.01 /
&contact gap_radius={R_GAP}, gap_center=6.0, friction='coulomb', mu={MU} /
&solver method='robin', robin_operator='harmonic', delta=0.5, tol=1e-8 /
&output file='{cm}' /
""")
p, _ = run_solver(BIN, cm_deck)
if check(p.returncode == 0 and os.path.isfile(cm), "sheared Hertz deck with Coulomb friction solved", f"exit {p.returncode}"):
    with h5py.File(cm, "r") as f:
        lam = f["contact/normal_force"][()]
        tf = f["contact/tangential_force"][()]
        state = f["contact/state"][()]
    P, Q = float(lam.sum()), float(tf.sum())
    a_h = np.sqrt(4.0 * P * R_GAP / (np.pi * E / (2.0 * (1.0 - NU * NU))))
    c_h = a_h * np.sqrt(1.0 - abs(Q) / (MU * P))
    nstick, nslip = int(np.sum(state == 1)), int(np.sum(state == 2))
    check(nstick > 3 and nslip > 3 and 0.5 < abs(Q) / (MU * P) < 0.95,
          "sheared Hertz deck: partial slip (stick and slip nodes, Q below mu P)",
          f"stick {nstick}, slip {nslip}, Q/(mu P) {abs(Q) / (MU * P):.3f}")

    rc, out, _, _ = tool("plot_contact.py", cm, "-o", f"{OUT}/friction.png")
    check(rc == 0 and os.path.getsize(f"{OUT}/friction.png") > 0, "plot_contact on a frictional result: exit 0, picture written",
          f"exit {rc} {out.strip()[-300:]}")
    picture(f"{OUT}/friction.png", "friction.png")
    m = re.search(r"tangential resultant Q = .*, stick (\d+), slip (\d+),", out)
    check(m is not None and (int(m.group(1)), int(m.group(2))) == (nstick, nslip),
          "plot_contact: the tangential resultant and the file's stick and slip counts printed",
          f"{m.group(0) if m else out.strip()[-300:]} against stick {nstick}, slip {nslip}")

    rc, out, _, _ = tool("plot_contact.py", cm, "--mindlin", "-o", f"{OUT}/mindlin.png")
    check(rc == 0 and "1 Mindlin curves" in out, "plot_contact --mindlin on the sheared Hertz deck: one Mindlin curve",
          f"exit {rc} {out.strip()[-300:]}")
    picture(f"{OUT}/mindlin.png", "mindlin.png")
    line = [ln for ln in out.splitlines() if ln.startswith("plot_contact: Mindlin for mindlin:")]
    vals = {k: float(v) for k, v in (w.split("=") for w in line[0].split() if "=" in w)} if line else {}
    check(bool(vals) and abs(vals["c"] / c_h - 1.0) < 1e-4 and abs(vals["mu"] - MU) < 1e-12,
          "plot_contact --mindlin: c = a sqrt(1 - Q/(mu P)) from the file's forces and the deck's mu",
          f"{line} against c = {c_h:.6g}")
    check(bool(vals) and vals["err_c"] < 0.05 and vals["err_q"] < 0.08,
          "sheared Hertz deck: stick zone and shear agree with Cattaneo-Mindlin (err_c < 5%, err_q < 8%)", str(vals))
    import matplotlib.image as mpimg
    if os.path.isfile(f"{OUT}/friction.png") and os.path.isfile(f"{OUT}/contact.png"):
        tall, plain = mpimg.imread(f"{OUT}/friction.png").shape, mpimg.imread(f"{OUT}/contact.png").shape
        check(tall[0] > plain[0], "plot_contact with friction: taller than without (the shear panel)", f"{tall} {plain}")

# a frictionless result: --mindlin says why not and changes nothing in the picture
rc, out, _, _ = tool("plot_contact.py", hz, "--mindlin", "-o", f"{OUT}/hertz_mindlin.png")
check(rc == 0 and "no Mindlin curve: no friction" in out and "0 Mindlin curves" in out
      and "tangential resultant" not in out,
      "plot_contact --mindlin on a frictionless result: exit 0, says why there is no Mindlin curve",
      f"exit {rc} {out.strip()[-300:]}")
if os.path.isfile(f"{OUT}/hertz_mindlin.png") and os.path.isfile(f"{OUT}/hertz.png"):
    import matplotlib.image as mpimg
    same = np.array_equal(mpimg.imread(f"{OUT}/hertz_mindlin.png"), mpimg.imread(f"{OUT}/hertz.png"))
    check(same, "plot_contact on a frictionless result: --mindlin draws the picture --hertz draws, pixel for pixel")

# ---- failures end with a message -------------------------------------------------------------
bad = f"{OUT}/nobody2.h5"
shutil.copy(hz, bad)
with h5py.File(bad, "a") as f:
    del f["body2"]
rc, out, _, _ = tool("plot_solution.py", bad, "-o", f"{OUT}/bad.png")
check(rc == 1 and "plot_solution: cannot read" in out and "Traceback" not in out,
      "plot_solution on a result without /body2: exit 1 with a message", out.strip())
with open(f"{OUT}/not.h5", "w") as f:
    f.write("not an HDF5 file\n")
for name in ("plot_solution.py", "plot_contact.py", "plot_history.py"):
    rc, out, _, _ = tool(name, f"{OUT}/not.h5", "-o", f"{OUT}/bad.png")
    check(rc == 1 and "cannot read" in out and "Traceback" not in out, f"{name} on a non-HDF5 file: exit 1 with a message",
          out.strip()[-200:])
rc, out, _, _ = tool("plot_solution.py", big, "--pixels", "8000", "-o", f"{OUT}/oom.png", cap_mb=1000)
check(rc == 1 and "out of memory" in out and "Traceback" not in out,
      "plot_solution out of memory (--pixels 8000 under a 1000 MB cap): exit 1 with a message", out.strip()[-200:])
check(not os.path.exists(f"{OUT}/oom.png"), "out of memory: no picture written")

# ---- units ---------------------------------------------------------------------------------
with h5py.File(hz, "r") as f:
    u = result_units(f)
check(u["length"] == "m" and u["stress"] == "Pa" and u["line_force"] == "N/m",
      "result_units: SI defaults when the file has no unit attributes", str(u))
withu = f"{OUT}/units.h5"
shutil.copy(hz, withu)
with h5py.File(withu, "a") as f:
    f.attrs["unit_length"], f.attrs["unit_force"], f.attrs["unit_stress"] = np.bytes_("mm"), np.bytes_("N"), np.bytes_("MPa")
    f["contact/pressure"].attrs["units"] = np.bytes_("MPa")
    f["contact/normal_force"].attrs["units"] = np.bytes_("N/mm")
    u = result_units(f)
check(u["length"] == "mm" and u["stress"] == "MPa" and u["line_force"] == "N/mm" and u["from_file"],
      "result_units: stored units read", str(u))
check(si_scale([3.2e7], "Pa") == (1e6, "MPa") and si_scale([-1.5e-6], "m") == (1e-6, "µm")
      and si_scale([2e3], "m") == (1.0, "m") and si_scale([5.1e6], "N/m") == (1e6, "MN/m")
      and si_scale([2e4], "MPa") == (1e3, "1e3 MPa") and si_scale([0.0], "Pa") == (1.0, "Pa"),
      "si_scale: SI prefixes, explicit power of ten for other units")
check(axis_label("x", "m") == "x [m]" and axis_label("p/p0", "") == "p/p0 [-]", "axis_label")
check(format_quantity(3000.0, "N/mm") == "3000 N/mm" and format_quantity(3.2e7, "Pa") == "32 MPa"
      and format_quantity(1.23456e5, "N/mm") == "1.235e5 N/mm" and format_quantity([1.5e3, -2e3], "N/m")
      == "(1.5, -2) kN/m" and format_quantity(2.5e-5, "m") == "25 µm",
      "format_quantity: one number (or vector) and its unit, SI prefix or plain number")
force_line = {}
for name, args in (("plot_contact.py", ["--hertz"]), ("plot_solution.py", []), ("plot_history.py", [])):
    rc, out, _, _ = tool(name, withu, *args, "-o", f"{OUT}/units_{name[:-3]}.png")
    check(rc == 0, f"{name} on a result with stored units (mm, MPa): exit 0", f"exit {rc} {out.strip()[-200:]}")
    if name == "plot_contact.py":
        force_line = [ln for ln in out.splitlines() if ln.startswith("plot_contact: units: ")]
with h5py.File(withu, "r") as f:
    total = float(np.sum(f["contact/normal_force"][()]))
    stored = np.array(f["contact/resultant_body1"][()], dtype=float)
m = re.search(r": resultant = \((\S+), (\S+)\) N/mm$", force_line[0]) if force_line else None
check(m is not None and abs(float(m.group(2)) - stored[1]) <= 1e-3 * abs(stored[1]),
      "plot_contact: the stored resultant on body 1 (/contact/resultant_body1) in N/mm",
      f"{force_line} against {stored}")
sum_file = f"{OUT}/no_resultant.h5"
shutil.copy(withu, sum_file)
with h5py.File(sum_file, "a") as f:
    del f["contact/resultant_body1"]
rc, out, _, _ = tool("plot_contact.py", sum_file, "-o", f"{OUT}/no_resultant.png")
m = re.search(r": sum of nodal normal forces = (\S+) N/mm$", out, re.M)
check(rc == 0 and m is not None and abs(float(m.group(1)) / total - 1.0) < 1e-3 and "resultant =" not in out,
      "plot_contact: without a stored resultant, the sum of the nodal normal forces, named so",
      out.strip()[-300:])

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
