#!/usr/bin/python3
"""The user documentation holds together (run by `make check`).

  - README.md has at most MAX_README_LINES lines;
  - every relative link and image of README.md and doc/*.md points to an existing file;
  - the module graph of doc/developing.md is what tools/module_graph.py derives from src/;
  - no issue numbers in README.md or doc/ (CHANGELOG.md holds the history).
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

print(f"{'FAILED: ' + str(len(check.failed)) if check.failed else 'all checks passed'}")
sys.exit(1 if check.failed else 0)
