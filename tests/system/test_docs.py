#!/usr/bin/python3
"""The user documentation holds together (run by `make check`).

  - README.md has at most MAX_README_LINES lines;
  - every relative link and image of README.md and doc/*.md points to an existing file;
  - the module graph of doc/developing.md is what tools/module_graph.py derives from src/;
  - doc/developing.md's Layout names every source file of src/ in its own folder and every
    header of include/, and names no file that is not there; every procedure or type it names
    (a name with an underscore that src/ defines) is defined in the file it is named under, or
    in the module that qualifies it ("assembly's nodal_stress");
  - doc/developing.md's extension guides ("How to extend" and the "Adding ..." sections) name
    files that exist, quote no underscored name the code does not have, and define each
    `module::name` they quote in that module's file;
  - no issue numbers in README.md or doc/ (CHANGELOG.md holds the history);
  - doc/geometry.md's "Shipped scenes" names every inputs/*.nml and the Cattaneo-Mindlin study;
  - the effective deck of README.md's annotated run is the one bin/robin_contact prints for
    inputs/default.nml;
  - doc/running.md's h5py recipe for a body's contact resultant, run on inputs/stack3.nml's
    result, gives the loads statics fixes (body 1 held up by 6e5, body 2 balanced, body 3 6e5
    down) and doc/running.md's numbers.
Each check is also run once on a made-up input that must make it fail, so that a check that
cannot fail is itself a failure.
"""
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402

PYTHON = os.environ.get("PYTHON", "/usr/bin/python3")
BIN = os.path.abspath(os.path.join(ROOT, os.environ.get("BIN", "bin/robin_contact")))
MAX_README_LINES = 210
MAY_BE_MISSING = set()
ISSUE_RE = re.compile(r"issue ?#?[0-9]+", re.I)
LINK_RE = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")

check = Checks()


def too_long(text):
    n = len(text.splitlines())
    return n > MAX_README_LINES, n


def broken_links(path, text, may_be_missing=MAY_BE_MISSING):
    """Relative link targets of a Markdown text (code spans and fenced blocks left out) that
    do not exist, resolved against the folder of path."""
    text = re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)
    text = re.sub(r"`[^`\n]*`", "", text)
    bad = []
    for target in LINK_RE.findall(text):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I) or target.startswith("#"):
            continue  # http:, https:, mailto: ... and anchors in the same page
        file = os.path.normpath(os.path.join(os.path.dirname(path), target.split("#", 1)[0]))
        if not os.path.exists(file) and file not in may_be_missing:
            bad.append(target)
    return bad


def issue_numbers(text):
    return ISSUE_RE.findall(text)


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


docs = [os.path.join(ROOT, "README.md")] + sorted(glob.glob(os.path.join(ROOT, "doc", "*.md")))

# README length
long_, n = too_long(read(docs[0]))
check(not long_, f"README.md has at most {MAX_README_LINES} lines", f"{n} lines")
check(too_long("line\n" * (MAX_README_LINES + 1))[0], "the length check refuses a README one line too long")

# relative links
for path in docs:
    bad = broken_links(path, read(path))
    check(not bad, f"{os.path.relpath(path, ROOT)}: relative links point to existing files",
          "missing: " + ", ".join(bad) if bad else "")
probe = os.path.join(ROOT, "README.md")
bad = broken_links(probe, "[a](doc/running.md) [b](doc/no-such-page.md) ![c](doc/no-such.png) "
                          "[d](doc/tutorial.md) [e](https://example.org/x) [f](#top) `[g](nowhere.md)`")
check(bad == ["doc/no-such-page.md", "doc/no-such.png"],
      "the link check finds made-up broken links and skips web links, anchors and code",
      f"found {bad}")
check(broken_links(probe, "[x](doc/not-there.md)", may_be_missing=set()) == ["doc/not-there.md"],
      "a missing page outside the two exceptions is a broken link")

# issue numbers
for path in docs:
    found = issue_numbers(read(path))
    check(not found, f"{os.path.relpath(path, ROOT)}: no issue numbers", ", ".join(found))
made_up = "fixed by " + "Issue" + " #14 and " + "issue" + " 3"     # split: this file is grepped too
check(issue_numbers(made_up) == ["Issue" + " #14", "issue" + " 3"],
      "the issue-number check finds made-up issue numbers")

# module graph
tool = os.path.join(ROOT, "tools", "module_graph.py")
r = subprocess.run([PYTHON, tool, "--check"], capture_output=True, text=True)
check(r.returncode == 0, "tools/module_graph.py --check: doc/developing.md has the current module graph",
      (r.stdout + r.stderr).strip()[-2000:])
with tempfile.TemporaryDirectory() as tmp:
    doc = os.path.join(tmp, "developing.md")
    shutil.copy(os.path.join(ROOT, "doc", "developing.md"), doc)
    text = read(doc)
    with open(doc, "w", encoding="utf-8") as f:
        f.write(text.replace("<!-- module-graph:end -->", "  m_x --> m_y\n<!-- module-graph:end -->", 1))
    r = subprocess.run([PYTHON, tool, "--check", "--doc", doc], capture_output=True, text=True)
    check(r.returncode == 1 and "m_x --> m_y" in r.stdout,
          "module_graph --check exits 1 and shows the diff when the graph in the file was changed",
          f"exit {r.returncode}")
    r = subprocess.run([PYTHON, tool, "--write", "--doc", doc], capture_output=True, text=True)
    r2 = subprocess.run([PYTHON, tool, "--check", "--doc", doc], capture_output=True, text=True)
    check(r.returncode == 0 and r2.returncode == 0 and read(doc) == text,
          "module_graph --write restores it (then --check passes)", f"exit {r.returncode}, {r2.returncode}")
    with open(doc, "w", encoding="utf-8") as f:
        f.write("no markers here\n")
    r = subprocess.run([PYTHON, tool, "--check", "--doc", doc], capture_output=True, text=True)
    check(r.returncode == 1 and "marker" in r.stderr, "module_graph refuses a file without the markers",
          r.stderr.strip())

    # the graph comes from the sources: a made-up source tree
    src = os.path.join(tmp, "src")
    os.makedirs(os.path.join(src, "one"))
    os.makedirs(os.path.join(src, "two"))
    with open(os.path.join(src, "one", "alpha.f90"), "w") as f:
        f.write("module alpha\n  use, intrinsic :: iso_c_binding\n  use hdf5\n  use :: beta, only: b\n"
                "  use omp_lib ! threads\n  implicit none\ncontains\n  module procedure p\nend module alpha\n")
    with open(os.path.join(src, "two", "beta.f90"), "w") as f:
        f.write("module beta\n  ! use alpha (a comment, not a use)\n  implicit none\nend module beta\n")
    with open(os.path.join(src, "main.f90"), "w") as f:
        f.write("program main\n  use alpha\n  use, non_intrinsic :: beta\nend program main\n")
    r = subprocess.run([PYTHON, tool, "--src", src], capture_output=True, text=True)
    edges = sorted(re.findall(r"^  (m_\w+ --> m_\w+)$", r.stdout, re.M))
    check(r.returncode == 0 and edges == ["m_alpha --> m_beta", "m_main --> m_alpha", "m_main --> m_beta"],
          "module_graph derives the edges from the use statements (library modules and comments left out)",
          f"edges {edges}")
    check('subgraph g_src_one ["src/one"]' in r.stdout and 'subgraph g_src_two ["src/two"]' in r.stdout,
          "module_graph groups the modules by source folder")

# the shipped scenes
def unnamed_scenes(text, decks):
    """The decks (inputs/*.nml file names) and study the "Shipped scenes" section of a
    geometry.md text does not name."""
    m = re.search(r"^## Shipped scenes\n(.*?)(?=^## |\Z)", text, re.S | re.M)
    section = m.group(1) if m else ""
    missing = [d for d in decks if f"inputs/{d}" not in section]
    return missing + ([] if "cattaneo_study.py" in section else ["Cattaneo-Mindlin (tools/cattaneo_study.py)"])


decks = sorted(os.path.basename(p) for p in glob.glob(os.path.join(ROOT, "inputs", "*.nml")))
geometry = read(os.path.join(ROOT, "doc", "geometry.md"))
missing = unnamed_scenes(geometry, decks)
check(not missing, f"doc/geometry.md, Shipped scenes: names the {len(decks)} decks of inputs/ and the Cattaneo-Mindlin study",
      "missing: " + ", ".join(missing) if missing else "")
made_up = "## Shipped scenes\n`inputs/a.nml`, tools/cattaneo_study.py\n## Next\n`inputs/b.nml`\n"
check(unnamed_scenes(made_up, ["a.nml", "b.nml"]) == ["b.nml"]
      and unnamed_scenes("## Shipped scenes\n", ["a.nml"]) == ["a.nml", "Cattaneo-Mindlin (tools/cattaneo_study.py)"],
      "the scene check finds a deck and the study left out")


# doc/developing.md's Layout against the tree
def layout_paths(text):
    """The src/ files the Layout block names, as paths (folders by indentation), and the
    include/ line's headers."""
    block = text.split("## Layout", 1)[1].split("```", 2)[1] if "## Layout" in text else ""
    stack, paths, headers = [], set(), set()
    for ln in block.splitlines():
        m = re.match(r"^( *)(\S+)(\s|$)", ln)
        if not m:
            continue
        indent, name = len(m.group(1)), m.group(2)
        while stack and stack[-1][0] >= indent:
            stack.pop()
        if name.endswith("/"):
            stack.append((indent, name[:-1]))
            if name == "include/":
                headers = set(re.findall(r"([A-Za-z0-9_]+\.h)\b", ln))
        elif re.fullmatch(r"[A-Za-z0-9_]+\.(f90|c)", name) and stack and stack[0][1] == "src":
            paths.add("/".join([d for _, d in stack] + [name]))
    return paths, headers


def layout_mismatch(text):
    paths, headers = layout_paths(text)
    tree = {os.path.relpath(f, ROOT) for ext in ("f90", "c")
            for f in glob.glob(os.path.join(ROOT, "src", "**", "*." + ext), recursive=True)}
    heads = {os.path.basename(f) for f in glob.glob(os.path.join(ROOT, "include", "*.h"))}
    return sorted(tree - paths), sorted(paths - tree), sorted(heads - headers), sorted(headers - heads)


dev = read(os.path.join(ROOT, "doc", "developing.md"))
missing, extra, hmissing, hextra = layout_mismatch(dev)
check(not (missing or extra or hmissing or hextra),
      "doc/developing.md's Layout names every src/ file in its folder and every include/ header, and nothing else",
      f"not named: {missing + hmissing}; named but absent: {extra + hextra}")
moved = dev.replace("    blas_tiles.c", "    blas_tile.c", 1).replace("\n    digest.f90", "\n  digest.f90", 1)
m2, e2, _, _ = layout_mismatch(moved)
check("src/linalg/blas_tiles.c" in m2 and "src/linalg/blas_tile.c" in e2 and "src/base/digest.f90" in m2,
      "the layout check finds a renamed file and a file put in the wrong folder", f"{m2} / {e2}")


# the procedures and types the Layout names against where src/ defines them
def layout_entries(text):
    """{src path: its description} of the Layout block (an entry's continuation lines joined)."""
    block = text.split("## Layout", 1)[1].split("```", 2)[1] if "## Layout" in text else ""
    stack, entries, cur = [], {}, None
    for ln in block.splitlines():
        m = re.match(r"^( *)(\S+)(\s|$)", ln)
        if not m:
            continue
        indent, name = len(m.group(1)), m.group(2)
        if re.fullmatch(r"[A-Za-z0-9_]+\.(f90|c)", name) or name.endswith("/"):
            while stack and stack[-1][0] >= indent:
                stack.pop()
            cur = None
            if name.endswith("/"):
                stack.append((indent, name[:-1]))
            elif stack and stack[0][1] == "src":
                cur = "/".join([d for _, d in stack] + [name])
                entries[cur] = ln[m.end(2):]
        elif cur is not None:
            entries[cur] += " " + ln.strip()
    return entries


DEF_F90 = [re.compile(r"^\s*(?:(?:pure|elemental|recursive|impure|module)\s+)*(?:(?:integer|logical|real|character|"
                      r"complex|type|class)\b[^!\n]*?\s+)?(?:subroutine|function)\s+(\w+)", re.I | re.M),
           re.compile(r"^\s*type\s*(?:,[^:!\n]*)?::\s*(\w+)", re.I | re.M),
           re.compile(r"^\s*procedure\s*(?:\([^)]*\))?\s*(?:,[^:!\n]*)?::\s*(\w+)", re.I | re.M)]
DEF_C = re.compile(r"^(?:static\s+)?(?:const\s+)?(?:struct\s+)?\w+[\s*]+\**(\w+)\s*\([^;]*$", re.M)


def src_definitions(root):
    """{name: the src files that define it}: Fortran procedures (interface bodies too), types
    and type-bound names; C functions (a trailing underscore, the Fortran binding, dropped)."""
    defs = {}
    for f in glob.glob(os.path.join(root, "src", "**", "*.*"), recursive=True):
        rel = os.path.relpath(f, root)
        if not f.endswith((".f90", ".c")):
            continue
        text = read(f)
        for pat in (DEF_F90 if f.endswith(".f90") else [DEF_C]):
            for name in pat.findall(text):
                defs.setdefault(name.lower().rstrip("_"), set()).add(rel)
    return defs


def misplaced_names(text, defs):
    """Names with an underscore in a Layout entry that src/ defines, but not in that entry's
    file; a name after "<module>'s " or "<module>' " is looked for in that module's file."""
    stems = {os.path.splitext(os.path.basename(p))[0]: p for ps in defs.values() for p in ps}
    out = []
    for path, desc in layout_entries(text).items():
        for m in re.finditer(r"\b[a-z][a-z0-9]*_[a-z0-9_]*\b", desc):
            where = defs.get(m.group(0))
            if not where:
                continue
            q = re.search(r"(\w+)'s?\s+$", desc[:m.start()])
            want = stems.get(q.group(1), path) if q else path
            if want not in where:
                out.append(f"{m.group(0)} (under {path}) is defined in {', '.join(sorted(where))}")
    return sorted(set(out))


defs = src_definitions(ROOT)
bad = misplaced_names(dev, defs)
check(defs and not bad, "every procedure and type doc/developing.md's Layout names is defined in the file it is named "
      "under (or in the module it is qualified by)", "; ".join(bad[:4]))
wrong = dev.replace("(build_interface: two groups per pair", "(two groups per pair", 1).replace(
    "    condense.f90        a body on its contact rows B_a:", "    condense.f90        a body on its contact rows B_a (build_interface):", 1)
bad2 = misplaced_names(wrong, defs)
check(any(b.startswith("build_interface (under src/contact/condense.f90)") for b in bad2),
      "the name check finds a procedure named under the wrong file", "; ".join(bad2[:2]))



# the extension guides (How to extend, Adding ...): the files they name exist, the names they
# quote occur in the code, and a qualified name module::name is defined in that module's file
def guide_text(text):
    """doc/developing.md from '## How to extend' to the end (the extension guides)."""
    return text.split("## How to extend", 1)[1] if "## How to extend" in text else ""


def code_words(root):
    """Every identifier of src/, tests/, tools/, the Makefile and include/ (a set)."""
    words = set()
    files = glob.glob(os.path.join(root, "src", "**", "*.*"), recursive=True)
    for sub in ("tests", "tools", "include"):
        files += glob.glob(os.path.join(root, sub, "**", "*.*"), recursive=True)
    for f in files + [os.path.join(root, "Makefile")]:
        if os.path.basename(f) == "test_docs.py":     # this test's own made-up names
            continue
        if f.endswith((".f90", ".c", ".h", ".py", ".sh")) or f.endswith("Makefile"):
            words.update(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", read(f)))
        words.add(os.path.splitext(os.path.basename(f))[0])     # a test or module by its file's name
    return words


def guide_mismatch(text, defs, words):
    """What the guides quote that is not in the tree: paths, underscored names, module::name."""
    out = []
    stems = {os.path.splitext(os.path.basename(p))[0]: p for ps in defs.values() for p in ps}
    for q in re.findall(r"`([^`\n]+)`", guide_text(text)):
        for tok in q.split():
            tok = tok.strip("(),;.")
            if re.fullmatch(r"(src|tests|tools|include|doc|inputs|bench)/[\w./-]+", tok):
                if "test_x." not in tok and not os.path.exists(os.path.join(ROOT, tok)):
                    out.append(f"no file {tok}")
            elif "::" in tok and re.fullmatch(r"\w+::\w+", tok):
                mod, name = tok.split("::")
                if stems.get(mod) not in defs.get(name.lower(), set()):
                    out.append(f"{name} is not defined in module {mod}")
            elif re.fullmatch(r"[A-Za-z][A-Za-z0-9]*_[A-Za-z0-9_]*", tok) and tok not in words:
                out.append(f"{tok} occurs nowhere in the code")
    return sorted(set(out))


words = code_words(ROOT)
gbad = guide_mismatch(dev, defs, words)
check(guide_text(dev) and not gbad, "doc/developing.md's extension guides name files that exist and names the code has",
      "; ".join(gbad[:4]))
gwrong = dev.replace("`new_robin_operator`", "`new_robin_op`").replace(
    "`tests/unit/test_qp_newton.f90`", "`tests/unit/test_newton.f90`", 1)
gbad2 = guide_mismatch(gwrong, defs, words)
check("new_robin_op occurs nowhere in the code" in gbad2 and "no file tests/unit/test_newton.f90" in gbad2,
      "the guide check finds a renamed procedure and a missing file", "; ".join(gbad2[:4]))

# the README's effective deck against the program's
def echo_of(text):
    """The effective-deck lines of a run's output: from its first line to the &output group."""
    lines = text.splitlines()
    first = next((i for i, ln in enumerate(lines) if ln.startswith("robin_contact ") and "effective input" in ln), None)
    if first is None:
        return []
    last = next((i for i in range(first, len(lines)) if lines[i].startswith("&output")), len(lines) - 1)
    while last + 1 < len(lines) and lines[last + 1].startswith("      "):   # the group's wrapped lines
        last += 1
    # one logical line per group: where a line wraps depends on the length of the paths in it
    out = []
    for ln in lines[first:last + 1]:
        if ln.startswith("      ") and out:
            out[-1] += " " + ln.strip()
        else:
            out.append(ln)
    return out


with tempfile.TemporaryDirectory(prefix="rc_docs_") as tmp:
    h5 = os.path.join(tmp, "default.h5")
    r = subprocess.run([BIN, os.path.join("inputs", "default.nml"), f"&output file='{h5}' /"], cwd=ROOT,
                       capture_output=True, text=True, timeout=300)
    program = [ln.replace(h5, "results/default.h5") for ln in echo_of(r.stdout)]

    def echo_mismatch(text):
        """How the effective deck of a README text differs from the program's ([] when it does not)."""
        readme = echo_of(text)
        diff = [f"README: {a!r} / program: {b!r}" for a, b in zip(readme, program) if a != b]
        return diff + ([f"{len(readme)} lines against {len(program)}"] if len(readme) != len(program) else [])

    diff = echo_mismatch(read(docs[0]))
    check(r.returncode == 0 and program and not diff,
          "README.md's annotated run shows the effective deck the program prints for inputs/default.nml",
          f"exit {r.returncode}; " + "; ".join(diff[:3]) if diff or r.returncode else "")
    half = len(program) // 2
    made_up = "\n".join(program[:half] + program[half + 1:])    # one line of the program's echo left out
    check(program and echo_mismatch(made_up), "the echo check finds a line left out")

    # doc/running.md's resultant recipe on the three-block stack
    running = read(os.path.join(ROOT, "doc", "running.md"))
    code = next((b for b in re.findall(r"^```python\n(.*?)^```", running, re.S | re.M) if "def contact_resultant" in b), "")
    h5 = os.path.join(tmp, "stack3.h5")
    r = subprocess.run([BIN, os.path.join("inputs", "stack3.nml"), f"&output file='{h5}' /"], cwd=ROOT,
                       capture_output=True, text=True, timeout=300)
    prog = code.split("\nprint(", 1)[0] + "\n" + "\n".join(
        f"print(*contact_resultant({h5!r}, {b}))" for b in (1, 2, 3))
    q = subprocess.run([PYTHON, "-c", prog], capture_output=True, text=True, timeout=300)
    try:
        got = [[float(v) for v in ln.split()] for ln in q.stdout.splitlines()]
    except ValueError:
        got = []
    want = [[0.0, 6.0e5], [0.0, 0.0], [0.0, -6.0e5]]
    ok = len(got) == 3 and all(abs(g - w) <= 1e-6 * 6.0e5 for gs, ws in zip(got, want) for g, w in zip(gs, ws))
    check(bool(code) and r.returncode == 0 and q.returncode == 0 and ok,
          "doc/running.md's contact_resultant recipe on inputs/stack3.nml: (0, 6e5) on body 1, 0 on body 2, "
          "(0, -6e5) on body 3", f"exit {r.returncode}/{q.returncode}: {got} {q.stderr.strip()[-300:]}")
    check("[0, 6e5]" in code and "[0, 0]" in code, "doc/running.md's recipe shows those numbers")

print(f"{'FAILED: ' + str(len(check.failed)) if check.failed else 'all checks passed'}")
sys.exit(1 if check.failed else 0)
