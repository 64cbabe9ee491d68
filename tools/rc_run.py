"""Running robin_contact and reading its console output.

The program's console output ends with key=value lines (see doc/running.md, "What a run prints"):
  result: status=converged method=robin outer=189 inner=2491 n1=816 n2=816 m=24 delta=0.5 residual=... wall_s=0.036 bodies=2 pairs=1 dofs=1632
  time: assemble=... factor=... condense=... iterate=... output=... total=... peak_mb=... factor_mb=...
  contact: total normal force= ...
This module parses them (result_fields, time_fields, line_fields, contact_force), runs the
program (solver_env, run_solver) and tells which result file a run writes
(deck_result_file; also from the shell: `rc_run.py result-file DECK [OVERRIDE ...]`).
Imports the standard library only.
"""
import os
import re
import subprocess

# ---- the program's output lines -------------------------------------------------------
RESULT_KEYS = ("status", "method", "outer", "inner", "n1", "n2", "m", "delta", "residual", "wall_s", "bodies", "pairs",
               "dofs")
# the documented shape of the result and time lines, checked to the letter by tests/system/test_runs.py
RESULT_LINE = re.compile(r"^result: status=(\w+) method=(\w+) outer=(\d+) inner=(\d+) n1=(\d+) n2=(\d+) "
                         r"m=(\d+) delta=([0-9.eE+-]+) residual=([0-9.eE+-]+) wall_s=([0-9.eE+-]+) "
                         r"bodies=(\d+) pairs=(\d+) dofs=(\d+)$", re.M)
TIME_LINE = re.compile(r"^time: assemble=[0-9.]+ factor=[0-9.]+ condense=[0-9.]+ iterate=[0-9.]+ output=[0-9.]+ "
                       r"total=[0-9.]+", re.M)
FORCE_RE = re.compile(r"^contact: total normal force=\s*(\S+)", re.M)


def line_fields(text, tag):
    """The key=value fields (strings) of the last line `<tag>: ...` of the output text, as a
    dict in line order, or None when there is no such line. Words without '=' are skipped."""
    lines = re.findall(r"^" + re.escape(tag) + r": (.*)$", text, re.M)
    if not lines:
        return None
    return dict(kv.split("=", 1) for kv in lines[-1].split() if "=" in kv)


def result_fields(text):
    """Fields of the last `result:` line (status, method, outer, inner, ... as strings), or None."""
    return line_fields(text, "result")


def time_fields(text):
    """Fields of the last `time:` line (assemble, factor, ..., total, peak_mb, factor_mb), or None."""
    return line_fields(text, "time")


def contact_force(text):
    """The total normal force of the last `contact:` line, as a string, or None."""
    m = FORCE_RE.findall(text)
    return m[-1] if m else None


# ---- running the program ----------------------------------------------------------------
def solver_env(threads=None, base=None):
    """A copy of the environment (base, default os.environ) for a run: OMP_NUM_THREADS =
    threads if given, else the inherited value, else 2."""
    env = dict(os.environ if base is None else base)
    if threads is None:
        env.setdefault("OMP_NUM_THREADS", "2")
    else:
        env["OMP_NUM_THREADS"] = str(threads)
    return env


def run_solver(binary, *args, env=None, **kwargs):
    """Run `binary args...` with its output captured as text (env: default solver_env()).
    Extra keyword arguments go to subprocess.run (cwd, timeout, ...).
    Returns (CompletedProcess, result_fields(stdout))."""
    p = subprocess.run([binary, *args], capture_output=True, text=True,
                       env=solver_env() if env is None else env, **kwargs)
    return p, result_fields(p.stdout)


def run_text(binary, work, name, text, *over, env=None, timeout=300):
    """Write the deck `text` to work/name.nml and run it there with the overrides `over` and
    its result in work/name.h5. Returns (exit code, stdout + stderr, the result's path)."""
    deck = os.path.join(work, name + ".nml")
    with open(deck, "w") as f:
        f.write(text)
    p, _ = run_solver(binary, deck, *over, f"&output file='{name}.h5' /", cwd=work, env=env, timeout=timeout)
    return p.returncode, p.stdout + p.stderr, os.path.join(work, name + ".h5")


def tool_parser(doc, binary="bin/robin_contact"):
    """The argument parser of a tool that runs the program: the tool's docstring as its help
    (line breaks kept) and --bin, the program to run (default `binary`)."""
    import argparse
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=binary, help=f"the robin_contact binary (default {binary})")
    return ap


# ---- decks: where a run writes its result ------------------------------------------------
def find_unquoted(text, ch, start=0):
    """Index of the first ch in text[start:] outside '...' and "..." strings, or -1."""
    q = None
    for i in range(start, len(text)):
        c = text[i]
        if q:
            if c == q:
                q = None
        elif c in "'\"":
            q = c
        elif c == ch:
            return i
    return -1


def strip_comments(text):
    """Drop Fortran '!' comments (outside quotes) from namelist text."""
    out = []
    for line in text.splitlines():
        i = find_unquoted(line, "!")
        out.append(line if i < 0 else line[:i])
    return "\n".join(out)


def namelist_groups(text, group):
    """The bodies of every `&group ... /` in namelist text (comments dropped; a '/' inside a
    quoted string does not end the group), in order."""
    text = strip_comments(text)
    out = []
    for m in re.finditer(r"&" + re.escape(group) + r"\b", text, flags=re.I):
        i = find_unquoted(text, "/", m.end())
        if i >= 0:
            out.append(text[m.end():i])
    return out


def deck_result_file(deck, overrides=()):
    """The result file a run of `robin_contact deck overrides...` writes: the last
    `file = '...'` of the &output groups of the deck, then of the overrides; by default
    results/<deck name without .nml>.h5 (deck.f90). Relative to the working directory."""
    with open(deck, encoding="utf-8", errors="replace") as fh:
        texts = [fh.read(), *overrides]
    result = None
    for t in texts:
        for body in namelist_groups(t, "output"):
            for m in re.finditer(r"(?<![\w%])file\s*=\s*(?:'([^']*)'|\"([^\"]*)\")", body, flags=re.I):
                result = (m.group(1) if m.group(1) is not None else m.group(2)).strip()
    if not result:
        base = os.path.basename(deck)
        result = "results/" + (base[:-4] if base.lower().endswith(".nml") else base) + ".h5"
    return result


if __name__ == "__main__":
    # command-line use by the shell tools: rc_run.py result-file DECK [OVERRIDE ...]
    import sys
    if len(sys.argv) >= 3 and sys.argv[1] == "result-file":
        try:
            print(deck_result_file(sys.argv[2], sys.argv[3:]))
        except OSError as e:
            print(f"rc_run: cannot read deck {sys.argv[2]}: {e}", file=sys.stderr)
            sys.exit(1)
        sys.exit(0)
    print("usage: rc_run.py result-file DECK.nml [OVERRIDE ...]", file=sys.stderr)
    sys.exit(1)
