#!/usr/bin/python3
"""A new result replaces every file of an earlier, larger one at the same name (run by
`make check`; decks written by the test in a temporary folder).

(1) an 8-body stack (7 pairs) into r.h5, then a 3-body stack (2 pairs) into the same name:
    r_body4..8.xdmf and r_contact3..7.xdmf of the earlier result are removed (the run says
    "removed 10 stale files of an earlier result"), r_body1..3.xdmf, r_contact1..2.xdmf and
    r_contact.xdmf are the new run's (its run_id), and files that only look alike
    (r_body9x.xdmf, r_body4.xdmf.keep, rr_body5.xdmf, r_body04.xdmf) are left alone;
(2) a failing 3-body run over the 8-body result (its r_body1.xdmf is a folder: exit 3)
    removes nothing: every file of the earlier result is still there, byte for byte;
(3) a 2-body run (one pair) over the 3-body result removes r_body3.xdmf, r_contact1.xdmf and
    r_contact2.xdmf (a one-pair result has r_contact.xdmf only);
(4) `&output xdmf`: a 70-body stack with the default ('auto', above 64 bodies) writes the
    collection alone (r.xdmf with all 70 bodies and 69 lines, r_contact.xdmf) and removes
    every per-body and per-pair file of the earlier result; xdmf='per_body' writes them all
    (70 + 69 more files, each one grid); xdmf='collection' on 3 bodies writes the two
    collection files only; an unknown value is exit 1 naming the group, variable and value.
"""
import filecmp
import os
import re
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import run_solver, solver_env  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", os.path.join(ROOT, "bin/robin_contact")))
ENV = solver_env(1)
check = Checks()


def stack(n):
    """n blocks stacked downwards, body n clamped below, the others clamped on their left sides."""
    lines = [f"&body id={k}, x0=0.0, y0={float(n - k)}, width=1.0, height=1.0, nx=2, ny=2"
             + (", bottom='clamped'" if k == n else ", left='clamped'") + " /" for k in range(1, n + 1)]
    lines.append("&traction body=1, side='top', t0=0.0, -1.0e6 /")
    lines.append("&solver method='monolithic' /")   # one QP: every stack converges
    if n == 2:
        lines += ["&contact bodies=1,2, groups='bottom','top' /"]
    else:
        lines += [f"&contact bodies={k},{k + 1}, groups='bottom','top' /" for k in range(1, n)]
    return "\n".join(lines) + "\n"


def run(work, n, xdmf_mode=None):
    deck = os.path.join(work, f"stack{n}.nml")
    with open(deck, "w") as f:
        f.write(stack(n))
    over = "&output file='r.h5' /" if xdmf_mode is None else f"&output file='r.h5', xdmf='{xdmf_mode}' /"
    p, _ = run_solver(BIN, deck, over, cwd=work, env=ENV, timeout=300)
    return p.returncode, p.stdout + p.stderr


def run_id(path):
    m = re.search(r"run_id (\S+) -->", open(path, encoding="utf-8").read()) if os.path.isfile(path) else None
    return m.group(1) if m else None


def xdmf(work):
    return sorted(f for f in os.listdir(work) if f.endswith(".xdmf"))


with tempfile.TemporaryDirectory() as work:
    rc, text = run(work, 8)
    old = xdmf(work)
    check(rc == 0 and "r_body8.xdmf" in old and "r_contact7.xdmf" in old, "8 bodies: exit 0, r_body8, r_contact7",
          f"exit {rc}: {old}")
    alike = ["r_body9x.xdmf", "r_body4.xdmf.keep", "rr_body5.xdmf", "r_body04.xdmf"]
    for f in alike:
        shutil.copy(os.path.join(work, "r_body4.xdmf"), os.path.join(work, f))

    # (2) a failing run over it removes nothing
    snap = os.path.join(work, "snap")
    os.mkdir(snap)
    for f in os.listdir(work):
        if f.startswith("r") and os.path.isfile(os.path.join(work, f)):
            shutil.copy(os.path.join(work, f), snap)
    os.rename(os.path.join(work, "r_body1.xdmf"), os.path.join(snap, "moved_body1"))
    os.mkdir(os.path.join(work, "r_body1.xdmf"))
    rc, text = run(work, 3)
    check(rc == 3 and "removed" not in text, "a failing 3-body run over the 8-body result: exit 3, nothing removed",
          f"exit {rc}: {text.strip()[-300:]}")
    same = all(filecmp.cmp(os.path.join(snap, f), os.path.join(work, f), shallow=False)
               for f in os.listdir(snap) if f not in ("moved_body1", "r_body1.xdmf"))
    check(same, "a failing run: every file of the earlier result byte for byte as it was")
    os.rmdir(os.path.join(work, "r_body1.xdmf"))
    os.rename(os.path.join(snap, "moved_body1"), os.path.join(work, "r_body1.xdmf"))

    # (1) a smaller result in its place
    rc, text = run(work, 3)
    now = xdmf(work)
    gone = [f"r_body{k}.xdmf" for k in range(4, 9)] + [f"r_contact{k}.xdmf" for k in range(3, 8)]
    check(rc == 0 and not any(f in now for f in gone), "3 bodies over 8: r_body4..8, r_contact3..7 removed",
          f"exit {rc}: left {[f for f in gone if f in now]}")
    check("removed 10 stale files of an earlier result" in text, "the run says it removed 10 stale files",
          "\n".join(ln for ln in text.splitlines() if "stale" in ln))
    ids = {run_id(os.path.join(work, f)) for f in ["r.xdmf", "r_contact.xdmf", "r_body1.xdmf", "r_body2.xdmf",
                                                    "r_body3.xdmf", "r_contact1.xdmf", "r_contact2.xdmf"]}
    check(len(ids) == 1 and None not in ids, "the 3-body result's files all carry its run_id", str(ids))
    check(all(os.path.isfile(os.path.join(work, f)) for f in alike), "files that only look alike are left alone",
          str([f for f in alike if not os.path.isfile(os.path.join(work, f))]))

    # (3) one pair after two: the numbered contact files go
    rc, text = run(work, 2)
    now = xdmf(work)
    check(rc == 0 and all(f not in now for f in ("r_body3.xdmf", "r_contact1.xdmf", "r_contact2.xdmf"))
          and "r_contact.xdmf" in now and "removed 3 stale files" in text,
          "2 bodies over 3: r_body3, r_contact1, r_contact2 removed, r_contact.xdmf kept", f"exit {rc}: {now}")

    # (4) which XDMF files: the collection alone above 64 bodies, or asked for (the look-alike
    # files of (1) stay; only the result's own names count)
    def xdmf(work):
        return sorted(f for f in os.listdir(work) if re.fullmatch(r"r(_body\d+|_contact\d*)?\.xdmf", f)
                      and f != "r_body04.xdmf")

    rc, text = run(work, 70, "per_body")
    now = xdmf(work)
    check(rc == 0 and len(now) == 2 + 70 + 69 and "r_body70.xdmf" in now and "r_contact69.xdmf" in now,
          "70 bodies, xdmf='per_body': r.xdmf, r_contact.xdmf, 70 body and 69 pair files", f"exit {rc}: {len(now)} files")
    rc, text = run(work, 70)
    now = xdmf(work)
    check(rc == 0 and now == ["r.xdmf", "r_contact.xdmf"] and "removed 139 stale files" in text,
          "70 bodies, default xdmf: the two collection files, the 139 per-body and per-pair ones removed",
          f"exit {rc}: {now[:5]} ... {len(now)} files; " + " ".join(ln for ln in text.splitlines() if "stale" in ln))
    body_grids = set(re.findall(r'<Grid Name="(body\d+)"', open(os.path.join(work, "r.xdmf")).read()))
    line_grids = set(re.findall(r'<Grid Name="(contact_pair\d+)"', open(os.path.join(work, "r.xdmf")).read()))
    check(body_grids == {f"body{k}" for k in range(1, 71)} and len(line_grids) == 69,
          "r.xdmf holds every body and every pair's line", f"{len(body_grids)} bodies, {len(line_grids)} lines")
    rc, text = run(work, 3, "collection")
    now = xdmf(work)
    check(rc == 0 and now == ["r.xdmf", "r_contact.xdmf"], "3 bodies, xdmf='collection': the two collection files only",
          f"exit {rc}: {now}")
    rc, text = run(work, 3, "none")
    check(rc == 1 and "xdmf" in text and "'none'" in text and "&output" in text and "Traceback" not in text,
          "xdmf='none': exit 1 naming &output, xdmf and the value", f"exit {rc}: {text.strip()[-300:]}")

sys.exit(1 if check.failed else 0)
