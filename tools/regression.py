#!/usr/bin/env python3
"""Same results as a stored reference: every shipped deck's contact forces and outer count.

  tools/regression.py --store  [--bin bin/robin_contact] [--ref tests/data/regression.json]
  tools/regression.py [--bin bin/robin_contact] [--ref ...] [--only SUBSTRING] [--quick]

--store runs every deck of inputs/, inputs/hard/, inputs/table1/ and tests/data/decks/ with its own
settings, again with method='monolithic' and with the harmonic operator at delta 0.5, and stores, per deck: the exit code, the status, the outer iteration count and the
nodal contact forces (/contact/normal_force). Without --store it runs them again and compares:
same exit code, status and outer count, and max |f - f_ref| <= 1e-12 max |f_ref| (scale-aware;
exactly 0 = 0 for a deck without contact), and, for a converged run, every body in equilibrium
(each `reaction:` line's balance below 1e-9, or below ten times its own rounding level); with --loose (a build that rounds differently, such as
`make DEBUG=1`) the forces within ten times each run's own a posteriori bound and no outer counts.
A store recorded on another kind of processor (its vendor, model and vector units, the kernels
OpenBLAS picks) is compared the loose way too, and the run says so: the same binary rounds
differently there. --quick takes the decks that run in under a second.
Exit 0 when every deck agrees, 1 otherwise (each difference printed). Runs with
OMP_NUM_THREADS=2 unless set; results go to a temporary folder, nothing in the tree is written
but the reference file (--store).
"""
import argparse
import glob
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DECK_DIRS = ("inputs", "inputs/hard", "inputs/table1", "tests/data/decks")
RTOL = 1.0e-12


MONO = "&solver method='monolithic' /"
HARMONIC = "&solver method='robin', robin_operator='harmonic', delta=0.5 /"


def decks():
    """(key, deck, overrides): every shipped deck with its own settings, its monolithic
    reference (key suffix ' monolithic') and the harmonic operator at delta 0.5 (' harmonic')."""
    out = []
    for d in DECK_DIRS:
        for p in sorted(glob.glob(os.path.join(ROOT, d, "*.nml"))):
            deck = os.path.relpath(p, ROOT)
            out += [(deck, deck, []), (deck + " monolithic", deck, [MONO]),
                    (deck + " harmonic", deck, [HARMONIC])]
    return out


def machine():
    """The kind of processor, as far as it decides how a run rounds: its vendor, family,
    model and name, and the vector units OpenBLAS chooses its kernels by."""
    info, flags = {}, set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                k, _, v = line.partition(":")
                k, v = k.strip(), v.strip()
                if k in ("vendor_id", "cpu family", "model", "model name") and k not in info:
                    info[k] = v
                elif k == "flags" and not flags:
                    flags = set(v.split())
    except OSError:
        return "unknown"
    units = [u for u in ("avx", "avx2", "fma", "avx512f", "avx512vl") if u in flags]
    return " / ".join([info.get(k, "?") for k in ("vendor_id", "cpu family", "model", "model name")]
                      + [" ".join(units), os.environ.get("OPENBLAS_CORETYPE", "")])


BALANCE_MAX = 1e-9   # a converged run's bodies balance to rounding (measured: 4e-12 at worst where
                     # K u's terms do not cancel; contrast_1e6's stiff body 1.4e-8, its rounding 3e-7)


def run_deck(binary, key, deck, overrides, tmp):
    h5 = os.path.join(tmp, key.replace("/", "_").replace(" ", "_") + ".h5")
    env = dict(os.environ)
    env.setdefault("OMP_NUM_THREADS", "2")
    t0 = time.time()
    p = subprocess.run([binary, deck, *overrides, f"&output file='{h5}' /"], cwd=ROOT, capture_output=True,
                       text=True, env=env, timeout=1800)
    wall = time.time() - t0
    rec = {"exit": p.returncode, "wall_s": round(wall, 3)}
    if os.path.exists(h5):
        with h5py.File(h5, "r") as f:
            rec["status"] = f.attrs["status"].decode() if isinstance(f.attrs["status"], bytes) \
                else str(f.attrs["status"])
            rec["outer"] = int(f.attrs["outer_iterations"])
            rec["force"] = [float(x) for x in f["contact/normal_force"][()]]
            rec["error_bound"] = float(f.attrs["error_bound"])
        os.remove(h5)
    return rec, p


def compare(ref, new, loose=False):
    """The differences between two records, as a list of sentences. loose: a build that
    rounds differently (the checked -O0 build): forces within ten times the run's own a
    posteriori bound, outer counts not compared."""
    diffs = []
    for key in ("exit", "status") + (() if loose else ("outer",)):
        if ref.get(key) != new.get(key):
            diffs.append(f"{key} {ref.get(key)} -> {new.get(key)}")
    if ("force" in ref) != ("force" in new):
        diffs.append("result file " + ("missing" if "force" in ref else "new"))
    elif "force" in ref:
        fr, fn = np.array(ref["force"]), np.array(new["force"])
        if fr.shape != fn.shape:
            diffs.append(f"contact nodes {fr.size} -> {fn.size}")
        else:
            scale = np.max(np.abs(fr)) if fr.size else 0.0
            err = np.max(np.abs(fn - fr)) if fr.size else 0.0
            rtol = max(RTOL, 10.0 * new.get("error_bound", 0.0)) if loose else RTOL
            if err > rtol * scale or (scale == 0.0 and err > RTOL):
                diffs.append(f"contact forces differ: max |df| = {err:.3e} = {err / max(scale, 1e-300):.3e} relative "
                             f"(the run's own a posteriori bound {new.get('error_bound', float('nan')):.1e})")
    return diffs


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="bin/robin_contact")
    ap.add_argument("--ref", default="tests/data/regression.json")
    ap.add_argument("--store", action="store_true")
    ap.add_argument("--only", default="")
    ap.add_argument("--verbose", action="store_true", help="print the end of a differing run's output")
    ap.add_argument("--loose", action="store_true",
                    help="for a build that rounds differently: forces within 10x each run's a posteriori "
                         "bound, outer counts not compared")
    ap.add_argument("--quick", action="store_true", help="only the decks that ran in under 1 s")
    a = ap.parse_args()
    binary = os.path.abspath(os.path.join(ROOT, a.bin)) if not os.path.isabs(a.bin) else a.bin
    ref_path = os.path.join(ROOT, a.ref)
    ref = {}
    here = machine()
    loose = a.loose
    if not a.store:
        with open(ref_path) as f:
            stored = json.load(f)
        ref = stored["decks"]
        if stored.get("machine") != here and not loose:
            loose = True
            print(f"INFO the store was recorded on another kind of processor ({stored.get('machine')}); "
                  f"this one ({here}) rounds differently: forces compared within 10x each run's "
                  "a posteriori bound, outer counts not compared")
    todo = [t for t in decks() if a.only in t[0]]
    if a.quick:
        todo = [t for t in todo if t[0] in ref and ref[t[0]]["wall_s"] < 1.0]
    out, bad = {}, 0
    with tempfile.TemporaryDirectory() as tmp:
        for deck, path, overrides in todo:
            rec, p = run_deck(binary, deck, path, overrides, tmp)
            out[deck] = rec
            if a.store:
                print(f"{deck:56s} exit={rec['exit']} status={rec.get('status')} outer={rec.get('outer')} "
                      f"m={len(rec.get('force', []))} {rec['wall_s']:.2f} s")
                continue
            if deck not in ref:
                print(f"NEW  {deck}: not in the reference (store it)")
                bad += 1
                continue
            diffs = compare(ref[deck], rec, loose)
            # every converged run is in equilibrium body by body: each `reaction:` line's
            # balance (supports + loads + contact forces over the sum of their magnitudes)
            # (or to its own rounding level, where K u's terms cancel far below the forces)
            for b, lvl in re.findall(r"^reaction: body=.* balance=(\S+) \(rounding (\S+)\)", p.stdout, re.M):
                if rec["exit"] == 0 and float(b) > max(BALANCE_MAX, 10.0 * float(lvl)):
                    diffs.append(f"a body out of equilibrium: reaction balance {b} > {BALANCE_MAX:.0e} and > 10 x "
                                 f"its rounding level {lvl}")
                    break
            print(("FAIL " if diffs else "PASS ") + f"{deck} outer={rec.get('outer')} "
                  + "; ".join(diffs))
            if diffs:
                bad += 1
                if a.verbose:
                    print(p.stdout[-2000:] + p.stderr[-2000:])
    if a.store:
        with open(ref_path, "w") as f:
            json.dump({"note": "contact forces and outer counts of every shipped deck, stored by "
                               "tools/regression.py --store", "machine": here, "decks": out}, f, indent=0)
        print(f"stored {len(out)} decks in {a.ref}")
        return 0
    missing = [d for d in ref if d not in out and a.only in d and not a.quick]
    for d in missing:
        print(f"FAIL {d}: in the reference but no longer shipped")
    bad += len(missing)
    print(f"{len(out) - bad + len(missing)} passed, {bad} failed")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
