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
    result file stores one.
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
