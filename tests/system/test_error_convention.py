#!/usr/bin/python3
"""One error convention below the driver (run by `make check`; doc/developing.md, "How
errors travel").

  - `fatal` (the exit with a message) is called only under src/driver/: every other module
    reports a failure through `type(error_t), intent(out) :: err`;
  - no procedure a module exports (in its `public` list, bound to a public type, or the
    interface of a deferred binding) has a status out-argument (integer, logical or text)
    named info, stat, istat, ierr, ok, why, msg, emsg or message, LAPACK's own wrappers
    (src/linalg/lapack.f90) and the driver excepted;
  - no NaN is made in src/ (a failure is an error_t, never a NaN in the result);
  - `stop` only in the driver and in the serial MPI stand-in's abort.
Each check is also run on a made-up source that must make it fail.
"""
import glob
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_checks import Checks  # noqa: E402

check = Checks()
STATUS = {"info", "stat", "istat", "ierr", "ok", "why", "msg", "emsg", "message"}
EXEMPT = {"src/linalg/lapack.f90"}           # LAPACK's own interfaces keep LAPACK's INFO
STOP_ALLOWED = {"src/parallel/mpi_env_serial.f90"}


def logical_lines(text):
    """The source's statements: comments dropped, continuation lines joined, lower case."""
    out, cur = [], ""
    for ln in text.splitlines():
        code, quote = [], None
        for ch in ln:
            if quote:
                quote = None if ch == quote else quote
            elif ch in "'\"":
                quote = ch
            elif ch == "!":
                break
            code.append(ch)
        s = "".join(code).strip()
        if not s:
            continue
        if s.startswith("&"):
            s = s[1:].lstrip()
        if s.endswith("&"):
            cur += s[:-1] + " "
            continue
        out.append((cur + s).lower())
        cur = ""
    return out


HEAD = re.compile(r"^(?:(?:pure|elemental|recursive|impure|module)\s+)*(?:(?:integer|logical|real|character|"
                  r"complex|type|class)\b[^!]*?\s+)?(subroutine|function)\s+(\w+)\s*(\(([^)]*)\))?")
END = re.compile(r"^end\s*(subroutine|function)\b")


def exported_status_args(text):
    """[(procedure, argument)] of status out-arguments in what the module exports."""
    lines = logical_lines(text)
    public, default_private, bound, deferred_ifaces = set(), False, set(), set()
    public_types, type_name = set(), None
    for s in lines:
        if s == "private":
            default_private = True
        m = re.match(r"^public\s*(?:::)?\s*(.*)$", s)
        if m and m.group(1):
            public.update(n.strip() for n in m.group(1).split(","))
        m = re.match(r"^type\s*,([^:]*)::\s*(\w+)", s)
        if m:
            type_name = m.group(2)
            if "public" in m.group(1) or not default_private:
                public_types.add(type_name)
            continue
        if re.match(r"^type\s*::\s*(\w+)", s):
            type_name = re.match(r"^type\s*::\s*(\w+)", s).group(1)
            continue
        if re.match(r"^end\s*type\b", s):
            type_name = None
            continue
        if type_name:
            m = re.match(r"^(?:generic|procedure)\s*(\((\w+)\))?[^:]*::\s*(.*)$", s)
            if m:
                bind = (type_name, m.group(2), m.group(3))
                bound.add(bind)
    exported = {n for n in public}
    for tname, iface, rest in bound:
        if tname in public_types or tname in public or not default_private:
            if iface:
                deferred_ifaces.add(iface)
            for item in rest.split(","):
                exported.add(item.split("=>")[-1].strip())
    exported |= deferred_ifaces
    out, depth, name, args, decls = [], 0, None, set(), []
    for s in lines:
        m = HEAD.match(s)
        if m and not s.startswith("end"):
            depth += 1
            if depth == 1:
                name = m.group(2)
                args = {a.strip() for a in (m.group(4) or "").split(",") if a.strip()}
                decls = []
            continue
        if END.match(s):
            if depth == 1 and (name in exported or not default_private):
                for d in decls:
                    if re.search(r"intent\s*\(\s*(in)?out\s*\)", d) and re.match(r"^(integer|logical|character)\b", d):
                        for v in re.findall(r"(\w+)\s*(?:\([^)]*\))?\s*(?:=[^,]*)?(?:,|$)", d.split("::", 1)[-1]):
                            if v in STATUS and v in args:
                                out.append((name, v))
            depth = max(0, depth - 1)
            continue
        if depth == 1 and "::" in s:
            decls.append(s)
    return out


def fatal_calls(text):
    return [s for s in logical_lines(text) if re.search(r"\bcall\s+fatal\s*\(", s)]


def stops(text):
    """The stop statements, alone or as the action of a one-line if."""
    return [s for s in logical_lines(text) if re.search(r"(^|\)\s*)(error\s+)?stop\b", s)]


files = sorted(os.path.relpath(f, ROOT) for f in glob.glob(os.path.join(ROOT, "src", "**", "*.f90"), recursive=True))
below = [f for f in files if not f.startswith("src/driver/")]

bad = [f"{f}: {len(fatal_calls(open(os.path.join(ROOT, f)).read()))}" for f in below
       if fatal_calls(open(os.path.join(ROOT, f)).read())]
check(files and not bad, "fatal is called only under src/driver/", "; ".join(bad[:6]))
check(fatal_calls("subroutine s()\n  call fatal(EXIT_INPUT, 'x')\nend subroutine s\n"),
      "the fatal check finds a call")

bad = []
for f in below:
    if f in EXEMPT:
        continue
    bad += [f"{f}: {p}({a})" for p, a in exported_status_args(open(os.path.join(ROOT, f)).read())]
check(not bad, "no exported procedure below the driver has an info/stat/ok/why/msg out-argument "
      "(LAPACK's wrappers excepted)", "; ".join(bad[:8]) + (f" (+{len(bad) - 8} more)" if len(bad) > 8 else ""))
made_up = """module m
  implicit none (type, external)
  private
  public :: good, bad_one
  type, public :: t
  contains
    procedure :: run => t_run
  end type t
contains
  subroutine good(x, err)
    real, intent(in) :: x
    type(error_t), intent(out) :: err
  end subroutine good
  subroutine bad_one(x, &
      info)
    real, intent(in) :: x
    integer, intent(out) :: info  ! a status
  end subroutine bad_one
  subroutine t_run(self, ok, why)
    class(t), intent(inout) :: self
    logical, intent(out) :: ok
    character(len=*), intent(out) :: why
  end subroutine t_run
  subroutine hidden(info)
    integer, intent(out) :: info
  end subroutine hidden
end module m
"""
found = sorted(exported_status_args(made_up))
check(found == [("bad_one", "info"), ("t_run", "ok"), ("t_run", "why")],
      "the status check finds a public procedure's info and a bound procedure's ok and why, and not a private "
      "helper's",
      str(found))

nan = [f for f in files if re.search(r"ieee_quiet_nan|ieee_signaling_nan", open(os.path.join(ROOT, f)).read(), re.I)]
check(not nan, "no NaN is made in src/", ", ".join(nan))

bad = [f for f in below if f not in STOP_ALLOWED and stops(open(os.path.join(ROOT, f)).read())]
check(not bad, "stop only in the driver and the serial MPI stand-in", ", ".join(bad))
check(stops("  if (x) error stop 'no'\n") and stops("  stop 3\n") and not stops("  call stop_now()\n"),
      "the stop check finds a stop statement and a one-line if's stop")

print(f"{'FAILED: ' + str(len(check.failed)) if check.failed else 'all checks passed'}")
sys.exit(1 if check.failed else 0)
