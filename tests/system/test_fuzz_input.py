#!/usr/bin/env python3
"""Fuzz test of the Gmsh reader and the deck reader, run by `make check`.

The readers promise: bad input ends with exit 1 and a clear message naming the file, with no
Fortran runtime error, no backtrace, no signal, no hang and nothing written (no result, no
checkpoint); valid input runs. This script mutates shipped inputs with a fixed seed and checks
that promise on every case:
- meshes (inputs/gmsh/paper.msh, patch_mixed.msh, pin_hole.msh, each with a deck that reads it):
  truncation at a byte, a line deleted, duplicated or swapped, a number replaced by a huge,
  negative, zero, NaN, fractional or text value, a byte changed, a section header or footer
  removed, a blank or garbage line inserted;
- decks (the small shipped decks): a line dropped or duplicated, a value replaced by a wrong
  type or an extreme number, a quote cut, a group's '/' deleted, a byte changed;
- fixed cases: the unmutated inputs (exit 0) and reproducers of failures the fuzzing found.
A case passes when it exits 0 or 1 (2, not converged, only for a deck mutation: a changed
setting, load or material may stop the iteration, which must say why; 3 only with an error
message), within 20 s, with no runtime error text on stderr, and, on exit 1, with an error
message naming the file and nothing written.
A summary table of the cases by mutation kind and outcome ends the output.
Environment: BIN (the program), FUZZ_SEED (default 20261125), FUZZ_JOBS (parallel runs, 2),
FUZZ_SCALE (a factor on the number of mutated cases, 1), FUZZ_VERBOSE=1 (print every case's exit
code and last line of stderr).
"""
import concurrent.futures
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import solver_env  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", "bin/robin_contact"))
ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
INPUTS = os.path.join(ROOT, "inputs")
SEED = int(os.environ.get("FUZZ_SEED", "20261125"))
JOBS = int(os.environ.get("FUZZ_JOBS", "2"))
SCALE = float(os.environ.get("FUZZ_SCALE", "1"))
VERBOSE = os.environ.get("FUZZ_VERBOSE", "") not in ("", "0")
TIMEOUT = 20                         # seconds per run; a timeout is a failure
OUTPUT = "&output file='out.h5' /"   # every run writes (if at all) into its own folder
# the mesh cases solve with the default Robin operator, which converges on any valid mesh
# (the paper's 'steklov' at delta 0.95 of gmsh_paper.nml may not on a changed one)
ROBUST = "&solver robin_operator='harmonic', delta=0.5 /"
RUNTIME_TEXT = ("Fortran runtime", "Backtrace", "Error termination", "SIGSEGV", "SIGFPE",
                "SIGBUS", "SIGABRT", "Segmentation fault", "Program received signal")
check = Checks()
TMP = tempfile.mkdtemp(prefix="rc_fuzz_")


def read(path):
    with open(path, "rb") as f:
        return f.read()


# ---- the inputs that are mutated ----------------------------------------------------------
# mesh bases: (name, mesh file, deck, the deck's mesh path, cases)
MESH_BASES = [
    ("paper", "gmsh/paper.msh", "gmsh_paper.nml", "gmsh/paper.msh", 240),
    ("patch_mixed", "gmsh/patch_mixed.msh", "patch.nml", "gmsh/patch.msh", 180),
    ("pin_hole", "gmsh/pin_hole.msh", "pin_hole.nml", "gmsh/pin_hole.msh", 80),
]
# deck bases: (deck, cases); their meshes are reached through a link 'gmsh' in each case folder
DECK_BASES = [("default.nml", 60), ("gmsh_paper.nml", 50), ("patch.nml", 50),
              ("paper_roller.nml", 40), ("pin_hole.nml", 40)]

NUMBER = re.compile(rb"(?<![\w.+\-\"])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.\"])")
BAD_NUMBERS = [b"2147483648", b"9223372036854775808", b"99999999999999999999999", b"1e308",
               b"1e400", b"-1", b"-2147483648", b"0", b"-0", b"nan", b"NaN", b"inf", b"-Infinity",
               b"1.5", b"0.5e-300", b"abc", b"1x", b"0x10", b"", b"1e", b"+", b"-", b".", b"1-2", b"+e5"]
GARBAGE = [b"", b" ", b"\t", b"garbage line", b"1 2 3 4 5 6 7 8 9", b"$Nodes", b"$EndElements",
           b"\x00\x01\x02", b"\xff\xfe", b"-1 -1 -1", b"\"unterminated", b"0"]


def lines_of(data):
    return data.split(b"\n")


def join(lines):
    return b"\n".join(lines)


def mutate_mesh(rng, data):
    """One random mutation of the mesh bytes: (kind, detail, mutated bytes)."""
    kind = rng.choice(["truncate", "delete_line", "duplicate_line", "swap_lines", "number",
                       "number", "number", "flip_byte", "drop_header", "insert_line"])
    ls = lines_of(data)
    if kind == "truncate":
        k = rng.randrange(len(data))
        return kind, f"at byte {k}", data[:k]
    if kind in ("delete_line", "duplicate_line"):
        k = rng.randrange(len(ls))
        new = ls[:k] + ls[k + 1:] if kind == "delete_line" else ls[:k + 1] + ls[k:]
        return kind, f"line {k + 1}", join(new)
    if kind == "swap_lines":
        a, b = rng.randrange(len(ls)), rng.randrange(len(ls))
        ls[a], ls[b] = ls[b], ls[a]
        return kind, f"lines {a + 1} and {b + 1}", join(ls)
    if kind == "number":
        spans = [m.span() for m in NUMBER.finditer(data)]
        s, e = rng.choice(spans)
        v = rng.choice(BAD_NUMBERS + [b"-" + data[s:e].lstrip(b"-+")])
        line = data.count(b"\n", 0, s) + 1
        return kind, f"line {line}: {data[s:e].decode()} -> {v.decode()}", data[:s] + v + data[e:]
    if kind == "flip_byte":
        k = rng.randrange(len(data))
        v = rng.randrange(256)
        return kind, f"byte {k}: {data[k]} -> {v}", data[:k] + bytes([v]) + data[k + 1:]
    if kind == "drop_header":
        marks = [i for i, ln in enumerate(ls) if ln.startswith(b"$")]
        k = rng.choice(marks)
        return kind, ls[k].decode(), join(ls[:k] + ls[k + 1:])
    k = rng.randrange(len(ls) + 1)                       # insert_line
    g = rng.choice(GARBAGE)
    return kind, f"before line {k + 1}: {g!r}", join(ls[:k] + [g] + ls[k:])


# ---- decks ----------------------------------------------------------------------------
def code_spans(text):
    """(start, end) of the parts of namelist text outside '!' comments, line by line."""
    out, pos = [], 0
    for ln in text.split("\n"):
        q, cut = None, len(ln)
        for i, c in enumerate(ln):
            if q:
                if c == q:
                    q = None
            elif c in "'\"":
                q = c
            elif c == "!":
                cut = i
                break
        out.append((pos, pos + cut))
        pos += len(ln) + 1
    return out


VALUE = re.compile(r"'[^'\n]*'|\"[^\"\n]*\"|\.(?:true|false)\.|[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?",
                   re.I)
BAD_VALUES = ["'text'", "abc", ".true.", "1.5", "-1", "0", "-0.0", "1e308", "-1e308", "1e-308",
              "1e999", "NaN", "Inf", "-Inf", "2147483648", "-2147483649", "99999999999",
              "1.0d400", "''", "'" + "x" * 5000 + "'", "3*", "1,2,3", "&", "/", "%", "1 2"]


def mutate_deck(rng, text):
    """One random mutation of the deck: (kind, detail, mutated text)."""
    kind = rng.choice(["drop_line", "duplicate_line", "value", "value", "value", "cut_quote",
                       "drop_slash", "flip_byte"])
    spans = code_spans(text)
    code = [(s, e) for s, e in spans if text[s:e].strip()]
    if kind in ("drop_line", "duplicate_line"):
        s, e = rng.choice(code)
        ln = text[s:e + 1]
        new = text[:s] + text[e + 1:] if kind == "drop_line" else text[:s] + ln + text[s:]
        return kind, ln.strip()[:60], new
    if kind == "value":
        cands = [m.span() for s, e in code for m in VALUE.finditer(text, s, e)]
        s, e = rng.choice(cands)
        v = rng.choice(BAD_VALUES)
        return kind, f"{text[s:e][:40]} -> {v[:40]}", text[:s] + v + text[e:]
    if kind == "cut_quote":
        cands = [i for s, e in code for i in range(s, e) if text[i] in "'\""]
        k = rng.choice(cands)
        return kind, f"quote at {k}", text[:k] + text[k + 1:]
    if kind == "drop_slash":
        cands = []
        for s, e in code:
            q = None
            for i in range(s, e):
                c = text[i]
                if q:
                    q = None if c == q else q
                elif c in "'\"":
                    q = c
                elif c == "/":
                    cands.append(i)
        k = rng.choice(cands)
        return kind, f"'/' at {k}", text[:k] + text[k + 1:]
    raw = text.encode("latin-1")                         # flip_byte
    k = rng.randrange(len(raw))
    v = rng.randrange(256)
    new = (raw[:k] + bytes([v]) + raw[k + 1:]).decode("latin-1")
    return kind, f"byte {k}: {raw[k]} -> {v}", new


# ---- running a case -----------------------------------------------------------------------
class Case:
    """One run: files written into its folder, the program run there with the deck d.nml."""

    def __init__(self, group, kind, detail, files, mesh_file=None, allow2=False, overrides=()):
        self.group, self.kind, self.detail = group, kind, detail
        self.files = files                  # name -> bytes
        self.mesh_file = mesh_file          # the file the message must name (or the deck)
        self.allow2 = allow2
        self.overrides = list(overrides)
        self.name = None


def run_case(case):
    """Run the case; returns (outcome, problems, the last line of stderr): outcome the exit
    code as text or 'timeout'."""
    folder = os.path.join(TMP, case.name)
    os.makedirs(folder)
    for name, data in case.files.items():
        with open(os.path.join(folder, name), "wb") as f:
            f.write(data)
    os.symlink(os.path.join(INPUTS, "gmsh"), os.path.join(folder, "gmsh"))
    inputs = set(os.listdir(folder))
    try:
        p = subprocess.run([BIN, "d.nml", *case.overrides, OUTPUT], capture_output=True, cwd=folder,
                           env=solver_env("1"), timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        return "timeout", [f"no exit within {TIMEOUT} s"], ""
    err = p.stderr.decode("utf-8", "replace")
    rc = p.returncode
    problems = []
    if rc < 0 or rc >= 128:
        problems.append(f"killed by a signal (exit {rc})")
    for t in RUNTIME_TEXT:
        if t in err:
            problems.append(f"stderr has '{t}'")
    allowed = {0, 1, 3} | ({2} if case.allow2 else set())
    if rc not in allowed and not (rc < 0 or rc >= 128):
        problems.append(f"exit {rc}")
    if rc in (1, 3) and not re.search(r"^robin_contact: (error|failed): ", err, re.M):
        problems.append("no error message")
    if rc == 2 and not re.search(r"^robin_contact: \w+: ", err, re.M):
        problems.append("no error message")
    if rc == 1:
        names = ["d.nml", "override"] + ([case.mesh_file] if case.mesh_file else [])
        if not any(n in err for n in names):
            problems.append("the message names no input file")
        left = []
        for dirpath, _, filenames in os.walk(folder):
            left += [os.path.relpath(os.path.join(dirpath, f), folder) for f in filenames
                     if dirpath != folder or f not in inputs]
        if left:
            problems.append(f"files written: {sorted(left)[:4]}")
    if problems:
        problems.append("stderr: " + err.strip()[-300:])
    else:
        shutil.rmtree(folder, ignore_errors=True)
    last = (err.strip().splitlines() or [""])[-1]
    if VERBOSE:
        print(f"{case.name} [{case.detail}] exit {rc}: {last[:300]}", flush=True)
    return str(rc), problems, last


# ---- the cases ------------------------------------------------------------------------
def mesh_case(base, kind, detail, mesh):
    name, _, deck, deck_mesh, _ = base
    deck_text = read(os.path.join(INPUTS, deck)).replace(deck_mesh.encode(), b"m.msh")
    return Case("mesh " + name, kind, detail, {"d.nml": deck_text, "m.msh": mesh}, mesh_file="m.msh",
                overrides=[ROBUST])


def fixed_cases():
    """The unmutated inputs (must run) and reproducers of failures found by fuzzing:
    (case, expected exit code, regular expression the last line of stderr must match)."""
    out = []
    for base in MESH_BASES:
        out.append((mesh_case(base, "unmutated", base[1], read(os.path.join(INPUTS, base[1]))), "0", ""))
    for deck, _ in DECK_BASES:
        out.append((Case("deck " + deck, "unmutated", deck, {"d.nml": read(os.path.join(INPUTS, deck))}),
                    "0", ""))
    paper = read(os.path.join(INPUTS, "gmsh/paper.msh"))
    out.append((mesh_case(MESH_BASES[0], "fixed", "empty mesh file", b""), "1", r"m\.msh.*empty"))
    out.append((mesh_case(MESH_BASES[0], "fixed", "no $EndMeshFormat",
                          paper.replace(b"$EndMeshFormat\n", b"", 1)), "1", r"m\.msh"))
    # two nodes of the plate swap their coordinates: the cells around them fold over their
    # neighbours (each counter-clockwise once turned); the run used to solve this mesh
    pin = lines_of(read(os.path.join(INPUTS, "gmsh/pin_hole.msh")))
    pin[2738], pin[2933] = pin[2933], pin[2738]
    out.append((mesh_case(MESH_BASES[2], "fixed", "two nodes' coordinates swapped", join(pin)), "1",
                r"m\.msh.*elements \d+ and \d+ overlap"))
    # a coordinate '+' or '.' (no digit): the reader took it for 0
    mixed = lines_of(read(os.path.join(INPUTS, "gmsh/patch_mixed.msh")))
    for token in (b"+", b"."):
        bad_z = mixed[:137] + [b"0 0.400000000001665 " + token] + mixed[138:]
        out.append((mesh_case(MESH_BASES[1], "fixed", f"z = {token.decode()}", join(bad_z)), "1",
                    r"m\.msh', line 138: expected a node z coordinate \(a finite real\) in \$Nodes, found '"
                    + re.escape(token.decode()) + "'"))
    # a prescribed displacement of -1e308 on a group: its loads K u overflow (the checked
    # build trapped in the assembly; the run's message blamed the stiffness)
    patch = read(os.path.join(INPUTS, "patch.nml"))
    out.append((Case("deck patch.nml", "fixed", "ux = -1e308 on a group", {"d.nml": patch.replace(
        b"group = 'top_left', ux = 0.0", b"group = 'top_left', ux = -1e308")}), "1",
        r"d\.nml: &boundary 2 \(body 1, group 'top_left'\) prescribes 1\.000E\+308"))
    # a rectangle's corner at -1e308: its extent overflows (the checked build trapped; the
    # message named a traction)
    default = read(os.path.join(INPUTS, "default.nml"))
    out.append((Case("deck default.nml", "fixed", "x0 = -1e308", {"d.nml": default.replace(
        b"x0 = 0.0, y0 = 1.0", b"x0 = -1e308, y0 = 1.0", 1)}), "1",
        r"d\.nml: body 1: its rectangle reaches a coordinate of magnitude 1\.000E\+308"))
    # a rectangle 1e-308 wide: its cells' stiffness overflows (the checked build trapped)
    out.append((Case("deck default.nml", "fixed", "width = 1e-308", {"d.nml": default.replace(
        b"width = 3.0", b"width = 1e-308", 1)}), "1",
        r"d\.nml: body 1: its cells of 4\.167E-310 x 6\.250E-02 \[length\]"))
    # young = 1e-308: its flexibility overflows (the checked build trapped in the condensation);
    # refused where it is read (the last line echoes the deck's line)
    out.append((Case("deck default.nml", "fixed", "young = 1e-308", {"d.nml": default.replace(
        b"young = 2.1e11", b"young = 1e-308", 1)}), "1",
        r"^ *\d+ \| +young = 1e-308,"))
    # a pressure of 1e308 on a group (the checked build trapped), a displacement of 1e250
    # (the squares of its loads overflow in the solver: the checked build trapped), and one
    # of 1e130, within the bound, which runs
    gp = read(os.path.join(INPUTS, "gmsh_paper.nml"))
    out.append((Case("deck gmsh_paper.nml", "fixed", "pressure = 1e308", {"d.nml": gp.replace(
        b"group = 'upper_right', t0 = 0.0, 2.0e6", b"group = 'upper_right', pressure = 1e308")}), "1",
        r"d\.nml: &traction 2 \(body 1\) reaches 1\.000E\+308"))
    out.append((Case("deck gmsh_paper.nml", "fixed", "ux = 1e250 on a group", {"d.nml": gp.replace(
        b"group = 'lower_left', ux = 0.0", b"group = 'lower_left', ux = 1e250")}), "1",
        r"d\.nml: &boundary 2 \(body 2, group 'lower_left'\) prescribes 1\.000E\+250"))
    out.append((Case("deck gmsh_paper.nml", "fixed", "ux = 1e130 on a group", {"d.nml": gp.replace(
        b"group = 'lower_left', ux = 0.0", b"group = 'lower_left', ux = 1e130")}), "0", ""))
    return out


def random_cases(rng):
    cases = []
    for base in MESH_BASES:
        data = read(os.path.join(INPUTS, base[1]))
        for _ in range(round(SCALE * base[4])):
            cases.append(mesh_case(base, *mutate_mesh(rng, data)))
    for deck, n in DECK_BASES:
        text = read(os.path.join(INPUTS, deck)).decode("latin-1")
        for _ in range(round(SCALE * n)):
            kind, detail, new = mutate_deck(rng, text)
            cases.append(Case("deck " + deck, kind, detail, {"d.nml": new.encode("latin-1")}, allow2=True))
    return cases


def main():
    rng = random.Random(SEED)
    fixed = fixed_cases()
    cases = [c for c, _, _ in fixed] + random_cases(rng)
    expect = {id(c): (e, pat) for c, e, pat in fixed}
    for i, c in enumerate(cases):
        c.name = f"{i:04d}_{re.sub(r'[^A-Za-z0-9_]+', '_', c.group)}_{c.kind}"
    print(f"test_fuzz_input: {len(cases)} cases, seed {SEED}, {JOBS} parallel runs, binary {BIN}")
    t0 = time.time()
    with concurrent.futures.ThreadPoolExecutor(max_workers=JOBS) as pool:
        results = list(pool.map(run_case, cases))
    wall = time.time() - t0
    table = {}
    for c, (outcome, problems, last) in zip(cases, results):
        want, pattern = expect.get(id(c), (None, ""))
        if want is not None and outcome != want:
            problems = [f"exit {outcome}, expected {want}"] + problems
        if pattern and not re.search(pattern, last):
            problems = [f"the message does not match /{pattern}/: {last[-300:]}"] + problems
        key = (c.group.split()[0], c.kind)
        row = table.setdefault(key, {})
        col = "FAIL" if problems else f"exit {outcome}"
        row[col] = row.get(col, 0) + 1
        if want is not None or problems:
            check(not problems, f"{c.name}: {c.group}, {c.kind} ({c.detail})", "; ".join(problems))
    cols = ["exit 0", "exit 1", "exit 2", "exit 3", "FAIL"]
    print(f"\n{'input':6} {'mutation':16}" + "".join(f"{k:>8}" for k in cols) + f"{'cases':>8}")
    for (grp, kind), row in sorted(table.items()):
        print(f"{grp:6} {kind:16}" + "".join(f"{row.get(k, 0):>8}" for k in cols)
              + f"{sum(row.values()):>8}")
    total = {k: sum(r.get(k, 0) for r in table.values()) for k in cols}
    print(f"{'all':23}" + "".join(f"{total[k]:>8}" for k in cols) + f"{len(cases):>8}")
    print(f"wall time {wall:.1f} s")
    check(total["FAIL"] == 0, f"all {len(cases)} fuzz cases keep the promise", f"{total['FAIL']} failed")
    if not check.failed:
        shutil.rmtree(TMP, ignore_errors=True)
    else:
        print(f"failed cases' folders kept in {TMP}")
        print(f"test_fuzz_input: {len(check.failed)} failed check(s)")
        sys.exit(1)
    print("test_fuzz_input: 0 failed check(s)")


if __name__ == "__main__":
    main()
