#!/usr/bin/python3
"""The result files of a run of several bodies and contact pairs (run by `make check`), on a
stack of 3 unit blocks (body 1 on top, loaded by a uniform traction; body 3 clamped below;
pairs (1,2) and (2,3)) and on a two-body deck (inputs/table1/q1_6x2.nml):

1. HDF5: root attributes `bodies` and `pairs`; `/contact/pair_<k>` for every pair with the
   ids of its bodies, its slave body, its rows (segments 0-based within the pair, never one
   joining two pairs in /contact either). Independent checks: per pair, the sum of the nodal
   normal forces and the resultant on its first body equal the applied load (the traction
   times the block width); the pair groups' rows concatenated are /contact's rows.
   A two-body file has exactly the datasets it always had, plus /contact/pair_1.
2. XDMF: <stem>.xdmf one spatial collection of body1..bodyN and one contact line per pair
   (two bodies: body1, body2, contact); <stem>_body<a>.xdmf for every body, _contact.xdmf
   and, for several pairs, _contact<k>.xdmf; every HDF DataItem names a dataset of that
   shape; meshio reads each single-grid file back to the HDF5 data; ParaView's Xdmf3ReaderT
   reads the collection when pvpython is installed (otherwise SKIP).
   Files are committed together: a final name that is a folder (_contact2.xdmf, a file only
   a 3-body run writes) fails the run (exit 3) and leaves the earlier result byte for byte.
3. tools/plot_solution.py draws every body (its cell count), tools/plot_contact.py one curve
   per pair, labelled 'pair k (bodies A,B)'; on the two-body file no pair label.
4. Restart: the 3-body run stopped by SIGTERM during the outer iteration and restarted from
   its checkpoint ends bitwise equal to the uninterrupted run; so does one restarted from a
   periodic checkpoint (checkpoint_every) of a run stopped by max_outer.
"""
import filecmp
import os
import re
import shutil
import signal
import subprocess
import sys
import xml.etree.ElementTree as ET

import h5py
import meshio
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_results import text_attr  # noqa: E402
from rc_run import run_solver, solver_env  # noqa: E402

check = Checks()
BIN = os.path.abspath(os.path.join(ROOT, os.environ.get("BIN", "bin/robin_contact")))
PY = "/usr/bin/python3"
OUT = os.path.abspath(os.path.join(ROOT, os.environ.get("BUILD", "build/release"), "test-out", "nbody_output"))
shutil.rmtree(OUT, ignore_errors=True)
os.makedirs(OUT)
env = solver_env(1)

LOAD = 1.0e6          # traction on body 1's top [Pa] times the block width 1 m: force per thickness
NB, NX = 3, 16        # bodies of the stack, elements per block side


def stack(n=NB, nx=NX):
    """Deck lines of n unit blocks stacked downwards, body 1 loaded, body n clamped."""
    lines = [f"&body id={k}, x0=0.0, y0={float(n - k)}, width=1.0, height=1.0, nx={nx}, ny={nx}"
             + (", bottom='clamped'" if k == n else ", left='roller'") + " /" for k in range(1, n + 1)]
    lines.append(f"&traction body=1, side='top', t0=0.0, {-LOAD} /")
    lines += [f"&contact bodies={k},{k + 1}, groups='bottom','top' /" for k in range(1, n)]
    return lines


def write_deck(name, lines):
    path = os.path.join(OUT, name + ".nml")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path


def out(stem):
    return f"&output file='{OUT}/{stem}.h5' /"


def datasets(f):
    names = []
    f.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
    return names


# the datasets of a two-body result as they were before the pair groups (two-body files
# keep exactly these)
TWO_BODY = ["input_deck"] + [f"history/{k}" for k in ("active", "criterion", "inner", "residual", "wall_s")] + [
    f"contact/{k}" for k in ("active", "coordinates", "g0", "gap", "geometry_xyz", "normal",
                             "normal_displacement_body1", "normal_displacement_body2", "normal_force",
                             "normal_force_body1", "normal_force_body2", "obstacle_body1", "obstacle_body2",
                             "pressure", "resultant_body1", "s", "segments", "tributary_length", "x", "y")] + [
    f"body{b}/{k}" for b in (1, 2) for k in ("body_id", "cells", "contact_pressure", "coordinates", "displacement",
                                             "displacement_xyz", "geometry_xyz", "reaction", "reaction_xyz",
                                             "stress", "sxx", "sxy", "syy", "szz", "von_mises")]
PAIR = ["x", "y", "s", "normal", "normal_force", "normal_force_side1", "normal_force_side2", "pressure", "gap",
        "active", "normal_displacement_side1", "normal_displacement_side2", "geometry_xyz", "segments",
        "resultant_on_first_body"]
# /contact's datasets over all rows and the pair groups' datasets they stack
STACKED = {"x": "x", "y": "y", "s": "s", "normal": "normal", "normal_force": "normal_force",
           "normal_force_body1": "normal_force_side1", "normal_force_body2": "normal_force_side2",
           "pressure": "pressure", "gap": "gap", "active": "active", "g0": "g0",
           "tributary_length": "tributary_length", "normal_displacement_body1": "normal_displacement_side1",
           "normal_displacement_body2": "normal_displacement_side2", "geometry_xyz": "geometry_xyz"}


# ---- 1. HDF5 -----------------------------------------------------------------------------
def check_pairs(h5, tag, npair, bodies):
    """The pair groups of a result against /contact and the applied load."""
    with h5py.File(h5, "r") as f:
        nbody = max(max(b) for b in bodies)
        check(int(f.attrs.get("bodies", -1)) == nbody, f"{tag}: root attribute bodies = {nbody}",
              str(f.attrs.get("bodies")))
        check(int(f.attrs.get("pairs", -1)) == npair, f"{tag}: root attribute pairs = {npair}",
              str(f.attrs.get("pairs")))
        c = f["contact"]
        groups = sorted(k for k in c if isinstance(c[k], h5py.Group))
        if not check(groups == [f"pair_{k}" for k in range(1, npair + 1)],
                     f"{tag}: /contact has pair_1 .. pair_{npair}", str(groups)):
            return
        rows = 0
        for k in range(1, npair + 1):
            g = c.get(f"pair_{k}")
            if g is None:
                continue
            missing = [d for d in PAIR if d not in g]
            check(not missing, f"{tag}: pair_{k} has its datasets", f"missing {missing}")
            got = [int(v) for v in np.asarray(g.attrs.get("bodies", [])).reshape(-1)]
            check(got == list(bodies[k - 1]), f"{tag}: pair_{k} attribute bodies = {list(bodies[k - 1])}", str(got))
            check(int(g.attrs.get("slave_body", -1)) in bodies[k - 1], f"{tag}: pair_{k} slave_body is one of its bodies",
                  str(g.attrs.get("slave_body")))
            if missing:
                continue
            lam = np.array(g["normal_force"])
            n = lam.size
            seg = np.array(g["segments"])
            check(seg.shape == (n - 1, 2) and np.array_equal(seg, np.column_stack([np.arange(n - 1), np.arange(1, n)])),
                  f"{tag}: pair_{k} segments: {n - 1} segments 0-based within the pair", str(seg.shape))
            s = float(lam.sum())
            check(abs(s - LOAD) <= 1e-6 * LOAD, f"{tag}: pair_{k}: sum of normal_force = the applied load {LOAD:g}",
                  f"{s:.10g}")
            r = np.array(g["resultant_on_first_body"]).reshape(-1)
            check(r.size == 2 and abs(r[0]) <= 1e-6 * LOAD and abs(r[1] - LOAD) <= 1e-6 * LOAD,
                  f"{tag}: pair_{k}: resultant on body {bodies[k - 1][0]} = (0, {LOAD:g}) (holds the load up)",
                  str(r))
            rows += n
        check(rows == c["normal_force"].shape[0] == int(f.attrs["contact_nodes"]),
              f"{tag}: the pairs' rows add up to /contact's rows", f"{rows} vs {c['normal_force'].shape[0]}")
        bad = []
        for whole, part in STACKED.items():
            pieces = [np.array(c[f"pair_{k}/{part}"]) for k in range(1, npair + 1) if f"pair_{k}/{part}" in c]
            if len(pieces) != npair:
                bad.append(f"{part} missing")
                continue
            axis = 1 if whole == "normal" else 0         # normal: h5py shape (2, rows)
            if not np.array_equal(np.concatenate(pieces, axis=axis), np.array(c[whole])):
                bad.append(whole)
        check(not bad, f"{tag}: the pair groups' rows concatenated equal /contact's rows", str(bad))
        # /contact's segments: every one joins two neighbouring rows of the same pair
        first = np.cumsum([0] + [c[f"pair_{k}/normal_force"].shape[0] for k in range(1, npair + 1)])
        pair_of = np.searchsorted(first, np.arange(first[-1]), side="right")
        seg = np.array(c["segments"])
        ok = seg.ndim == 2 and seg.shape[1] == 2 and np.all(seg[:, 1] == seg[:, 0] + 1) \
            and np.all(pair_of[seg[:, 0]] == pair_of[seg[:, 1]])
        check(ok and seg.shape[0] == first[-1] - npair, f"{tag}: /contact/segments join rows of one pair only",
              str(seg.shape))


# ---- 2. XDMF -----------------------------------------------------------------------------
def grids(path):
    """(collection?, [(name, grid element)]) of an XDMF file."""
    dom = ET.parse(path).getroot().find("Domain")
    top = dom.findall("Grid")
    if len(top) == 1 and top[0].get("GridType") == "Collection":
        return True, [(g.get("Name"), g) for g in top[0].findall("Grid")]
    return False, [(g.get("Name"), g) for g in top]


def check_dataitems(path, h5, tag):
    """Every HDF DataItem of an XDMF file names a dataset of the result with its dimensions."""
    bad = []
    with h5py.File(h5, "r") as f:
        for it in ET.parse(path).getroot().iter("DataItem"):
            fname, _, ds = it.text.strip().partition(":")
            dims = tuple(int(v) for v in it.get("Dimensions").split())
            if fname != os.path.basename(h5) or ds not in f:
                bad.append(it.text.strip())
            elif int(np.prod(f[ds].shape)) != int(np.prod(dims)) or (len(dims) > 1 and f[ds].shape != dims):
                bad.append(f"{ds} {f[ds].shape} vs {dims}")
    check(not bad, f"{tag}: {os.path.basename(path)}: every DataItem names a dataset of its shape", str(bad[:3]))


def check_xdmf(stem, tag, nbody, npair):
    h5 = f"{OUT}/{stem}.h5"
    want = {f"{stem}.h5", f"{stem}.xdmf", f"{stem}_contact.xdmf"} | {f"{stem}_body{a}.xdmf" for a in range(1, nbody + 1)}
    if npair > 1:
        want |= {f"{stem}_contact{k}.xdmf" for k in range(1, npair + 1)}
    have = {n for n in os.listdir(OUT) if re.fullmatch(re.escape(stem) + r"(\.h5|(_\w+)?\.xdmf)", n)}
    if not check(have == want, f"{tag}: the files are {sorted(want)}", str(sorted(have))):
        return
    coll, g = grids(f"{OUT}/{stem}.xdmf")
    names = [n for n, _ in g]
    lines = ["contact"] if npair == 1 else [f"contact_pair{k}" for k in range(1, npair + 1)]
    check(coll and names == [f"body{a}" for a in range(1, nbody + 1)] + lines,
          f"{tag}: {stem}.xdmf is one spatial collection of the bodies and contact lines", str(names))
    for path in sorted(want - {f"{stem}.h5"}):
        check_dataitems(f"{OUT}/{path}", h5, tag)
    with h5py.File(h5, "r") as f:
        for a in range(1, nbody + 1):
            p = f"{OUT}/{stem}_body{a}.xdmf"
            c, gg = grids(p)
            check(not c and [n for n, _ in gg] == [f"body{a}"], f"{tag}: {stem}_body{a}.xdmf is the uniform grid body{a}")
            m = meshio.read(p)
            ok = np.array_equal(m.points[:, :2], np.array(f[f"body{a}/coordinates"]).T) \
                and np.array_equal(m.point_data["von_mises"], np.array(f[f"body{a}/von_mises"])) \
                and sum(len(cb.data) for cb in m.cells) == f[f"body{a}/cells"].shape[0]
            check(ok, f"{tag}: meshio reads {stem}_body{a}.xdmf back to /body{a}")
        files = [(f"{stem}_contact.xdmf", "contact", "body")]
        if npair > 1:
            files += [(f"{stem}_contact{k}.xdmf", f"contact/pair_{k}", "side") for k in range(1, npair + 1)]
        for name, grp, side in files:
            m = meshio.read(f"{OUT}/{name}")
            n = f[f"{grp}/normal_force"].shape[0]
            nseg = f[f"{grp}/segments"].shape[0]
            ok = np.array_equal(m.points[:, :2], np.column_stack([f[f"{grp}/x"], f[f"{grp}/y"]])) \
                and np.array_equal(m.point_data["pressure"], np.array(f[f"{grp}/pressure"])) \
                and np.array_equal(m.point_data[f"normal_displacement_{side}2"],
                                   np.array(f[f"{grp}/normal_displacement_{side}2"])) \
                and [cb.type for cb in m.cells] == ["line"] and len(m.cells[0].data) == nseg
            check(ok, f"{tag}: meshio reads {name} back to /{grp} ({n} nodes, {nseg} segments)")
    PARAVIEW.append((stem, tag, nbody + len(lines)))


PARAVIEW = []     # (stem, tag, its number of blocks): the files check_paraview has ParaView read


def check_paraview():
    """ParaView's Xdmf3ReaderT reads each collection of PARAVIEW into its number of blocks (the
    bodies and contact lines), all of them in one pvpython (its start-up takes seconds)."""
    pv = shutil.which("pvpython")
    if not PARAVIEW:
        return
    if not pv:
        for stem, tag, _ in PARAVIEW:
            print(f"SKIP  {tag}: pvpython not found: ParaView's reading of {stem}.xdmf not tested")
        return
    script = "from paraview import simple as s\n" + "".join(
        f"r = s.Xdmf3ReaderT(FileName=[{os.path.abspath(f'{OUT}/{stem}.xdmf')!r}])\n"
        f"r.UpdatePipeline()\nd = s.servermanager.Fetch(r)\nprint('BLOCKS', {stem!r}, d.GetNumberOfBlocks())\n"
        for stem, _, _ in PARAVIEW)
    cmd = [pv, "-c", script] if os.environ.get("DISPLAY") or not shutil.which("xvfb-run") \
        else ["xvfb-run", "-a", pv, "-c", script]
    q = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    for stem, tag, blocks in PARAVIEW:
        got = re.findall(rf"^BLOCKS {re.escape(stem)} (\d+)$", q.stdout, re.M)
        check(got and int(got[-1]) == blocks, f"{tag}: ParaView reads {stem}.xdmf: {blocks} blocks",
              f"BLOCKS {got[-1]}" if got else (q.stdout + q.stderr).strip()[-300:])


# ---- 3. plot tools ---------------------------------------------------------------------------
def check_plots(stem, tag, npair, bodies, ncell):
    h5 = f"{OUT}/{stem}.h5"
    q = subprocess.run([PY, os.path.join(ROOT, "tools", "plot_solution.py"), h5, "-o", f"{OUT}/{stem}_solution.png"],
                       capture_output=True, text=True, timeout=300)
    check(q.returncode == 0 and f", {ncell} cells)" in q.stdout and os.path.isfile(f"{OUT}/{stem}_solution.png"),
          f"{tag}: plot_solution draws every body ({ncell} cells)", (q.stdout + q.stderr).strip()[-300:])
    q = subprocess.run([PY, os.path.join(ROOT, "tools", "plot_contact.py"), h5, "-o", f"{OUT}/{stem}_contact.png"],
                       capture_output=True, text=True, timeout=300)
    labels = re.findall(r"pair (\d+) \(bodies (\d+),(\d+)\)", q.stdout)
    want = [(str(k), str(a), str(b)) for k, (a, b) in enumerate(bodies, start=1)] if npair > 1 else []
    check(q.returncode == 0 and labels == want and os.path.isfile(f"{OUT}/{stem}_contact.png"),
          f"{tag}: plot_contact draws " + ("one curve per pair, labelled 'pair k (bodies A,B)'" if npair > 1
                                           else "one curve, no pair label"), (q.stdout + q.stderr).strip()[-300:])


# ---- the runs --------------------------------------------------------------------------------
PAIRS3 = [(1, 2), (2, 3)]
deck3 = write_deck("stack3", stack())
p, r = run_solver(BIN, deck3, out("s3"), env=env, timeout=600)
check(p.returncode == 0, "3-body stack: the run converges", f"exit {p.returncode} {p.stderr.strip()[-300:]}")
if p.returncode == 0:
    check_pairs(f"{OUT}/s3.h5", "3 bodies", 2, PAIRS3)
    check_xdmf("s3", "3 bodies", 3, 2)
    check_plots("s3", "3 bodies", 2, PAIRS3, 3 * NX * NX)

two = os.path.join(ROOT, "inputs", "table1", "q1_6x2.nml")
p, r = run_solver(BIN, two, out("two"), env=env, timeout=600)
check(p.returncode == 0, "2 bodies: the run converges", f"exit {p.returncode}")
if p.returncode == 0:
    with h5py.File(f"{OUT}/two.h5", "r") as f:
        got = datasets(f)
    extra = sorted(set(got) - set(TWO_BODY))
    check(set(TWO_BODY) <= set(got) and extra and all(n.startswith("contact/pair_1/") for n in extra),
          "2 bodies: the datasets of a two-body result, plus /contact/pair_1 only",
          f"missing {sorted(set(TWO_BODY) - set(got))}, extra outside pair_1 "
          f"{[n for n in extra if not n.startswith('contact/pair_1/')]}")
    with h5py.File(f"{OUT}/two.h5", "r") as f:
        m = f["contact/normal_force"].shape[0]
        has = "contact/pair_1" in f
        check(has and all(f"contact/pair_1/{p_}" in f and np.array_equal(np.array(f[f"contact/{w}"]),
                                                                          np.array(f[f"contact/pair_1/{p_}"]))
                          for w, p_ in list(STACKED.items()) + [("segments", "segments")]),
              f"2 bodies: /contact/pair_1 is /contact ({m} rows)")
        check(has and list(np.asarray(f["contact/pair_1"].attrs.get("bodies", []))) == [1, 2],
              "2 bodies: pair_1 bodies = [1, 2]")
    check_xdmf("two", "2 bodies", 2, 1)
    with h5py.File(f"{OUT}/two.h5", "r") as f:
        ncell = f["body1/cells"].shape[0] + f["body2/cells"].shape[0]
    check_plots("two", "2 bodies", 1, [(1, 2)], ncell)
check_paraview()

# the files of a 3-body result are committed together: a folder at a name only it writes
if os.path.isfile(f"{OUT}/s3.h5"):
    keep = f"{OUT}/keep"
    os.makedirs(keep)
    names = sorted(n for n in os.listdir(OUT) if re.fullmatch(r"s3(\.h5|(_\w+)?\.xdmf)", n))
    for n in names:
        shutil.copy2(f"{OUT}/{n}", f"{keep}/{n}")
    if os.path.isfile(f"{OUT}/s3_contact2.xdmf"):
        os.remove(f"{OUT}/s3_contact2.xdmf")
    os.mkdir(f"{OUT}/s3_contact2.xdmf")
    p, _ = run_solver(BIN, deck3, out("s3"), "&traction body=1, side='top', t0=0.0, -2.0e6 /", env=env, timeout=600)
    same = all(filecmp.cmp(f"{OUT}/{n}", f"{keep}/{n}", shallow=False) for n in names if n != "s3_contact2.xdmf")
    left = [n for n in os.listdir(OUT) if n.endswith((".tmp", ".bak")) or ".tmp" in n]
    check(p.returncode == 3 and "s3_contact2.xdmf" in p.stderr + p.stdout,
          "3 bodies: a folder at <stem>_contact2.xdmf: exit 3, named", f"exit {p.returncode} {p.stderr.strip()[-200:]}")
    check(same and not left, "3 bodies: the earlier result is byte for byte as it was, no temporary left",
          f"left {left}")
    os.rmdir(f"{OUT}/s3_contact2.xdmf")

# ---- 4. restart --------------------------------------------------------------------------
def differences(a, b):
    """The datasets of every body and pair, the history and the counts that differ between
    two result files (bitwise)."""
    diff = []
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        for k in datasets(fa):
            if k.startswith(("contact/", "body")) or k in ("history/criterion", "history/residual",
                                                              "history/inner", "history/active"):
                if k not in fb or not np.array_equal(np.array(fa[k]), np.array(fb[k])):
                    diff.append(k)
        for k in ("outer_iterations", "inner_iterations", "status"):
            if text_attr(fa, k) != text_attr(fb, k):
                diff.append(k)
    return diff


# a slow relaxation: some 450 outer iterations, long enough to be stopped part-way
SLOW = "&solver delta=0.02, acceleration='none' /"
deckr = write_deck("stack3_slow", stack(nx=32))
p, _ = run_solver(BIN, deckr, SLOW, out("full"), env=env, timeout=900)
check(p.returncode == 0, "3 bodies, slow: the uninterrupted run converges", f"exit {p.returncode}")
proc = subprocess.Popen([BIN, deckr, SLOW, out("sig")], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                        text=True, env=env)
sent = False
for ln in proc.stdout:
    w = ln.split()
    # a progress line of the outer iteration: its number first
    if not sent and w and w[0].isdigit() and int(w[0]) >= 5:
        proc.send_signal(signal.SIGTERM)
        sent = True
proc.wait(timeout=300)
check(sent and proc.returncode == 4, "3 bodies: SIGTERM during the outer iteration exits 4", f"exit {proc.returncode}")
ck = f"{OUT}/sig.h5.ckpt.h5"
check(os.path.isfile(ck), "3 bodies: SIGTERM: checkpoint written")
if os.path.isfile(ck) and os.path.isfile(f"{OUT}/full.h5"):
    with h5py.File(f"{OUT}/sig.h5", "r") as f, h5py.File(f"{OUT}/full.h5", "r") as g:
        n, nfull = int(f.attrs["outer_iterations"]), int(g.attrs["outer_iterations"])
    check(0 < n < nfull, "3 bodies: SIGTERM: stopped part-way", f"outer {n} of {nfull}")
    p, _ = run_solver(BIN, deckr, SLOW, out("restart"), "--restart", ck, env=env, timeout=900)
    check(p.returncode == 0, "3 bodies: the restart converges", f"exit {p.returncode} {p.stderr.strip()[-300:]}")
    if p.returncode == 0:
        diff = differences(f"{OUT}/full.h5", f"{OUT}/restart.h5")
        check(not diff, "3 bodies: the restart ends bitwise equal to the uninterrupted run "
              "(every body, every pair, the history)", str(diff[:5]))

# periodic checkpoints: stopped by max_outer, resumed without that limit
p, _ = run_solver(BIN, deckr, "&solver delta=0.02, acceleration='none', max_outer=200 /",
                  out("part").replace(" /", ", checkpoint_every=100 /"), env=env, timeout=900)
ck2 = f"{OUT}/part.h5.ckpt.h5"
check(p.returncode == 2 and os.path.isfile(ck2), "3 bodies: max_outer=200 exits 2 with a periodic checkpoint",
      f"exit {p.returncode}")
if os.path.isfile(ck2) and os.path.isfile(f"{OUT}/full.h5"):
    p, _ = run_solver(BIN, deckr, SLOW, out("part_restart"), "--restart", ck2, env=env, timeout=900)
    diff = differences(f"{OUT}/full.h5", f"{OUT}/part_restart.h5") if p.returncode == 0 else ["exit"]
    check(not diff, "3 bodies: the restart from the periodic checkpoint ends bitwise equal to the uninterrupted run",
          f"exit {p.returncode} {diff[:5]}")

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
