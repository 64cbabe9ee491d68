#!/usr/bin/python3
"""Load steps and stages (&solver load_steps, stage= of the load groups), whole program.

1. Hertz, force-controlled (the disc held only by contact), load_steps=4: step k's
   contact resultant on the disc is k/4 of the applied load P = 2 (equilibrium, 1e-9);
   the last step equals the one-step run (1e-10 relative: only the warm start differs);
   /steps/step_<k> has stage 1, load_factor k/4, converged; the step: lines say the same.
   The patch test's prescribed displacement, ramped: step k's pressure is k/4 of the exact.
2. The XDMF files are a time series: every DataItem names a dataset of the HDF5 file with
   the shape it states; meshio's TimeSeriesReader reads every step with its time.
3. Two stages: a normal pressure (stage 1, 2 steps), then a tangential traction held by a
   roller (stage 2, 3 steps). In stage 2 the normal load stays whole (resultant = p w,
   1e-9); the block's mean x displacement grows linearly with the stage-2 factor; the last
   step equals the one-step run with both loads at once (1e-10).
4. A step that does not converge stops the run: exit 2, the steps before it written
   (converged) and it marked (status max_outer): stage 1 lifts the block off (contact
   open, a few outer iterations), stage 2 presses it (more than max_outer = 100).
5. Bad input, exit 1, one message naming the variable and value, nothing written: stage=0,
   load_steps=0 and 10001, more load_steps values than stages, a stage without a load.
6. SIGTERM in the middle of the history (after the second step: line): exit 4, a checkpoint
   at step 3 holding two steps (the checkpoint of a history with two steps done once
   crashed); --restart continues at step 3 and ends bitwise as the uninterrupted run.
"""
import os
import shutil
import signal
import subprocess
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import run_solver, solver_env  # noqa: E402

BIN = os.environ.get("BIN", "bin/robin_contact")
OUT = os.path.abspath(os.path.join(os.environ.get("BUILD", "build/release"), "test-out", "load_steps"))
shutil.rmtree(OUT, ignore_errors=True)
os.makedirs(OUT)
check = Checks()
env = solver_env(2)


def out(name):
    return f"&output file='{OUT}/{name}.h5' /"


def run(*args):
    p, _ = run_solver(BIN, *args, env=env)
    return p


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300))


def step_lines(text):
    return [dict(kv.split("=", 1) for kv in ln.split()[1:]) for ln in text.splitlines() if ln.startswith("step: ")]


# ---- 1. Hertz, force-controlled, four steps ------------------------------------------------
HERTZ = "inputs/hertz_force.nml"
P = 2.0
one = run(HERTZ, out("hertz1"))
four = run(HERTZ, "&solver load_steps=4 /", out("hertz4"))
check(one.returncode == 0 and four.returncode == 0, "hertz: the one-step and the four-step runs converge",
      f"exit {one.returncode}, {four.returncode}")
lines = step_lines(four.stdout)
check(len(lines) == 4 and [ln["step"] for ln in lines] == ["1", "2", "3", "4"], "hertz: one step: line per step",
      str(lines))
check(not step_lines(one.stdout), "hertz: a one-step run prints no step: line")
if four.returncode == 0:
    with h5py.File(f"{OUT}/hertz4.h5", "r") as f, h5py.File(f"{OUT}/hertz1.h5", "r") as g:
        steps = f["steps"]
        check(sorted(steps) == [f"step_{k}" for k in range(1, 5)], "hertz: /steps holds step_1 .. step_4",
              str(list(steps)))
        for k in range(1, 5):
            s = steps[f"step_{k}"]
            a = s.attrs
            check(int(a["stage"]) == 1 and abs(float(a["load_factor"]) - k / 4) < 1e-15 and
                  a["status"] in ("converged", b"converged"), f"hertz: step {k}: stage 1, load factor {k}/4, converged",
                  str(dict(a)))
            fy = float(s["contact/resultant_body1"][1])
            check(abs(fy - k / 4 * P) <= 1e-9 * P, f"hertz: step {k}: contact resultant on the disc = {k}/4 P (1e-9)",
                  f"{fy!r}")
            check(lines[k - 1]["stage"] == "1" and lines[k - 1]["status"] == "converged" and
                  int(lines[k - 1]["outer"]) == int(a["outer"]), f"hertz: step {k}: its step: line", str(lines[k - 1]))
        for name in ["contact/normal_force", "body1/displacement", "body2/displacement", "body1/von_mises"]:
            e = rel(f[name], g[name])
            check(e <= 1e-10, f"hertz: last step = one-step run: /{name} (1e-10)", f"{e:.2e}")
            e = rel(f["steps/step_4/" + name], f[name])
            check(e == 0.0, f"hertz: /steps/step_4/{name} is the last result's")
        check(f.attrs["outer_iterations"] == steps["step_4"].attrs["outer"], "hertz: the root holds the last step")
        check("steps" not in g, "hertz: a one-step run has no /steps")

# ---- 1b. a prescribed displacement ramped: the patch test's uniform pressure ---------------
# (inputs/patch.nml: the top pressed down by uy = -1e-3 through &boundary; uniaxial strain, so
# p = delta / (h1/M1 + h2/M2) exactly, M = E(1-nu)/((1+nu)(1-2nu)); step k: k/4 of it)
p = run("inputs/patch.nml", "&solver load_steps=4 /", out("patch4"))
check(p.returncode == 0, "patch: load_steps=4 converges", f"exit {p.returncode}")
if p.returncode == 0:
    m1, m2 = 200.0 * 0.7 / (1.3 * 0.4), 100.0 * 0.75 / (1.25 * 0.5)
    p_exact = 1.0e-3 / (0.5 / m1 + 1.0 / m2)
    with h5py.File(f"{OUT}/patch4.h5", "r") as f:
        for k in range(1, 5):
            pr = np.array(f[f"steps/step_{k}/contact/pressure"])
            e = float(np.max(np.abs(pr / (k / 4 * p_exact) - 1.0)))
            check(e <= 1e-8, f"patch: step {k}: uniform pressure {k}/4 of the exact one (1e-8)", f"{e:.2e}")

# ---- 2. the XDMF time series ------------------------------------------------------------
def xdmf_items(path):
    """(HDF5 file, dataset path, dims) of every DataItem, and the Time values of the file."""
    root = ET.parse(path).getroot()
    items = []
    for d in root.iter("DataItem"):
        h5, ds = d.text.strip().split(":", 1)
        items.append((os.path.join(os.path.dirname(path), h5), ds, tuple(int(x) for x in d.get("Dimensions").split())))
    times = [float(t.get("Value")) for t in root.iter("Time")]
    return root, items, times


for name in ["hertz4.xdmf", "hertz4_body1.xdmf", "hertz4_body2.xdmf", "hertz4_contact.xdmf"]:
    path = f"{OUT}/{name}"
    if not os.path.exists(path):
        check(False, f"xdmf: {name} written")
        continue
    root, items, times = xdmf_items(path)
    top = root.find("Domain/Grid")
    check(top is not None and top.get("CollectionType") == "Temporal" and len(list(top)) == 4,
          f"xdmf: {name}: a temporal collection of 4 steps")
    check(times == [0.25, 0.5, 0.75, 1.0], f"xdmf: {name}: times 0.25 .. 1 (cumulative load factor)", str(times))
    bad = []
    with h5py.File(items[0][0], "r") as f:
        for _, ds, dims in items:
            if ds not in f or tuple(f[ds].shape) != dims:
                bad.append((ds, dims, f[ds].shape if ds in f else None))
    check(not bad, f"xdmf: {name}: every DataItem is a dataset of the stated shape", str(bad[:3]))
    check(any("/steps/step_3/" in ds for _, ds, _ in items), f"xdmf: {name}: step 3's fields from /steps/step_3")
try:
    import meshio
    with meshio.xdmf.TimeSeriesReader(f"{OUT}/hertz4_body1.xdmf") as r:
        pts, cells = r.read_points_cells()
        got = [r.read_data(k) for k in range(r.num_steps)]
    with h5py.File(f"{OUT}/hertz4.h5", "r") as f:
        u2 = np.array(f["steps/step_2/body1/displacement_xyz"])
    check(len(got) == 4 and [t for t, _, _ in got] == [0.25, 0.5, 0.75, 1.0],
          "meshio: the body's time series has the 4 steps and their times")
    check(np.array_equal(got[1][1]["displacement"], u2), "meshio: step 2's displacement is /steps/step_2's")
except ImportError:
    check(False, "meshio is importable")

# ---- 3. two stages -----------------------------------------------------------------------
TWO = f"""&scene title='normal pressure, then a tangential traction' /
&body id=1, x0=0, y0=1, width=1, height=0.5, nx=8, ny=4, young=1e9, poisson=0.3, bottom='contact',
      left='roller' /
&body id=2, x0=0, y0=0, width=1, height=1, nx=8, ny=8, young=1e9, poisson=0.3, top='contact',
      bottom='clamped' /
&traction body=1, side='top', t0=0.0,-1.0e6 /
&traction body=1, side='top', t0=2.0e5,0.0, stage=2 /
&solver tol=1e-11, load_steps=2,3 /
"""
with open(f"{OUT}/two.nml", "w") as fh:
    fh.write(TWO)
two = run(f"{OUT}/two.nml", out("two"))
with open(f"{OUT}/two_once.nml", "w") as fh:
    fh.write(TWO.replace(", stage=2", "").replace("load_steps=2,3", "load_steps=1"))
ref = run(f"{OUT}/two_once.nml", out("two_ref"))
check(two.returncode == 0 and ref.returncode == 0, "two stages: the stepped and the one-step runs converge",
      f"exit {two.returncode}, {ref.returncode}")
lines = step_lines(two.stdout)
check([(ln["stage"], ln["load_factor"]) for ln in lines] ==
      [("1", "0.5"), ("1", "1"), ("2", "0.333333"), ("2", "0.666667"), ("2", "1")],
      "two stages: 5 steps, stage 1 in 2, stage 2 in 3", str(lines))
if two.returncode == 0 and ref.returncode == 0:
    with h5py.File(f"{OUT}/two.h5", "r") as f, h5py.File(f"{OUT}/two_ref.h5", "r") as g:
        pw = 1.0e6 * 1.0
        fac = [0.5, 1.0, 1.0, 1.0, 1.0]
        for k in range(1, 6):
            fy = float(f[f"steps/step_{k}/contact/resultant_body1"][1])
            check(abs(fy - fac[k - 1] * pw) <= 1e-9 * pw,
                  f"two stages: step {k}: normal resultant {fac[k - 1]} p w (stage 1 {'ramped' if k < 2 else 'held'})",
                  f"{fy!r}")
        ux = [float(np.mean(f[f"steps/step_{k}/body1/displacement"][0])) for k in range(2, 6)]
        t = [0.0, 1 / 3, 2 / 3, 1.0]
        lin = [ux[0] + tt * (ux[3] - ux[0]) for tt in t]
        check(abs(ux[3] - ux[0]) > 1e-6 and max(abs(a - b) for a, b in zip(ux, lin)) <= 1e-8 * abs(ux[3] - ux[0]),
              "two stages: the mean x displacement grows linearly over stage 2", str(ux))
        for name in ["contact/normal_force", "body1/displacement", "body2/displacement"]:
            e = rel(f[name], g[name])
            check(e <= 1e-10, f"two stages: last step = both loads at once: /{name} (1e-10)", f"{e:.2e}")

# ---- 4. a step that does not converge stops the run ----------------------------------------
STOP = """&body id=1, x0=0.0, y0=1.0, width=3.0, height=1.0, nx=16, ny=8, young=2.1e11, poisson=0.277,
      left='clamped', right='free', top='free', bottom='contact' /
&body id=2, x0=0.0, y0=0.0, width=3.0, height=1.0, nx=16, ny=8, young=2.1e11, poisson=0.277,
      left='clamped', right='free', top='contact', bottom='free' /
&traction body=1, side='top', t0=0.0,1.0e5 /
&traction body=1, side='top', t0=0.0,-3.0e6, t1=0.0,-1.0e6, stage=2 /
&solver robin_operator='steklov', delta=0.95, stop='increment', max_outer=100, load_steps=1,1 /
"""
with open(f"{OUT}/stop.nml", "w") as fh:
    fh.write(STOP)
p = run(f"{OUT}/stop.nml", out("stop"))
lines = step_lines(p.stdout)
check(p.returncode == 2, "a step that does not converge: exit 2", f"exit {p.returncode}")
check(len(lines) == 2 and lines[0]["status"] == "converged" and lines[1]["status"] == "max_outer",
      "the run stops at the step that did not converge, the earlier ones converged",
      str([(ln["step"], ln["status"]) for ln in lines]))
if os.path.exists(f"{OUT}/stop.h5"):
    with h5py.File(f"{OUT}/stop.h5", "r") as f:
        st = [f["steps"][f"step_{k}"].attrs["status"] for k in range(1, len(f["steps"]) + 1)]
        st = [s.decode() if isinstance(s, bytes) else s for s in st]
        check(len(st) == len(lines) and st[-1] == "max_outer" and all(s == "converged" for s in st[:-1]),
              "the result file holds the steps solved, the last one marked max_outer", str(st))
else:
    check(False, "a run stopped at a step writes its result file")

# ---- 5. bad input ------------------------------------------------------------------------
BAD = [("stage=0", "&traction body=1, side='top', t0=0.0,-1.0e6, stage=0 /", ["stage", "0"]),
       ("load_steps=0", "&solver load_steps=0 /", ["load_steps", "0"]),
       ("load_steps=10001", "&solver load_steps=10001 /", ["load_steps", "10001", "10000"]),
       ("more load_steps values than stages", "&solver load_steps=2,3,4 /", ["load_steps", "2,3,4", "stages"]),
       ("a stage without a load", "&traction body=1, side='top', t0=0.0,-1.0e6, stage=4 /", ["stage = 3", "no load"]),
       ("fewer load_steps values than stages (but more than one)",
        "&traction body=1, side='top', t0=0.0,-1.0e6, stage=3 /", ["load_steps", "2,3", "stages"])]
for what, override, words in BAD:
    name = "bad_" + what.split()[0].replace("=", "")
    p = run(f"{OUT}/two.nml", override, out(name))
    msg = p.stderr.strip()
    check(p.returncode == 1 and len(msg.splitlines()) <= 2 and all(w in msg for w in words) and
          "Fortran runtime" not in msg, f"bad input: {what}: exit 1, the message names {words}",
          f"exit {p.returncode}: {msg[-300:]}")
    check(not os.path.exists(f"{OUT}/{name}.h5") and not os.path.exists(f"{OUT}/{name}.xdmf"),
          f"bad input: {what}: nothing written")

# ---- 6. SIGTERM in the middle of the history, restart -------------------------------------
# about 4700 outer iterations per step, half a second: the signal sent at step 2's line lands in step 3
DECK = "inputs/table1/q1_16x8.nml"
SLOW = ["&body id=1, nx=32, ny=8 /", "&body id=2, nx=32, ny=8 /", "&solver delta=0.998, max_outer=40000, load_steps=4 /"]
full = run(DECK, *SLOW, out("full"))
check(full.returncode == 0, "slow history: the uninterrupted run converges", f"exit {full.returncode}")
proc = subprocess.Popen([BIN, DECK, *SLOW, out("sig")], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                        env=env)
for ln in proc.stdout:
    if ln.startswith("step: step=2 "):
        proc.send_signal(signal.SIGTERM)
        break
so, se = proc.communicate(timeout=600)
check(proc.returncode == 4, "SIGTERM in step 3: exit 4", f"exit {proc.returncode}: {se[-300:]}")
ck = f"{OUT}/sig.h5.ckpt.h5"
if os.path.exists(ck):
    with h5py.File(ck, "r") as c:
        at = int(c["load_history"].attrs["step"]) if "load_history" in c else 0
    check(at == 3, "the checkpoint is at step 3, with the results of steps 1 and 2", f"step {at}")
    re_ = run(DECK, *SLOW, out("re"), "--restart", ck)
    check(re_.returncode == 0, "the restart converges", f"exit {re_.returncode}: {re_.stderr[-300:]}")
    check("resuming after outer iteration" in re_.stdout and len(step_lines(re_.stdout)) == 4,
          "the restart resumes step 3 (steps 1 and 2 replayed), one step: line per step")
    if re_.returncode == 0 and full.returncode == 0:
        with h5py.File(f"{OUT}/full.h5", "r") as a, h5py.File(f"{OUT}/re.h5", "r") as b:
            names = []
            a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
            diff = [n for n in names if n not in ("input_deck", "history/wall_s") and
                    (n not in b or not np.array_equal(np.array(a[n]), np.array(b[n])))]
            check(not diff and any(n.startswith("steps/step_1/") for n in names),
                  "the restarted history is bitwise the uninterrupted one (every dataset, /steps included)",
                  str(diff[:5]))
            for k in ["outer_iterations", "inner_iterations", "status"]:
                check(a.attrs[k] == b.attrs[k], f"restart: root attribute {k} as uninterrupted")
else:
    check(False, "SIGTERM in step 3: checkpoint written")

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
