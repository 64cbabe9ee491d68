#!/bin/bash
# test_tools.sh: the post-processing and batch tools work on real solver output.
#   - bash -n on tools/sweep.sh, tools/make_plots.sh and every tools/slurm/*.sbatch;
#   - runs $BIN (default bin/robin_contact) on inputs/table1/q1_16x8.nml into a temporary
#     folder, runs tools/plot_history.py, plot_contact.py (also with --hertz) and
#     plot_solution.py on the result and checks each PNG exists and is > 10 kB;
#   - if tests/data/decks/gap.nml exists: runs it and checks plot_contact.py --hertz draws
#     the Hertz curve of that parabolic-gap scene;
#   - runs tools/sweep.sh on q1_3x1 with delta = 0.5, 1 and checks the CSV: header from
#     the result-line keys plus the override column, 2 data rows, statuses converged and
#     max_outer/diverged (exit codes 0 and 2).
# Prints PASS/FAIL lines; exits 1 if any check failed. Python: $PYTHON (default
# /usr/bin/python3). Run from anywhere (it works in the repository root).
set -u
cd "$(dirname "$0")/../.." || exit 1
PYTHON=${PYTHON:-/usr/bin/python3}
BIN=${BIN:-bin/robin_contact}
case "$BIN" in /*) ;; *) BIN=$PWD/$BIN ;; esac
export BIN PYTHON
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2}
. tests/system/checks.sh test_tools
min_png=10240
png_ok() {   # name file
  local n=0
  [ -f "$2" ] && n=$(stat -c %s "$2")
  if [ -f "$2" ] && [ "$n" -gt $min_png ] && [ "$(head -c 4 "$2" | od -An -c | tr -d ' ')" = "211PNG" ]; then
    pass "$1: $(basename "$2") is a PNG of $n bytes (> $min_png)"
  else
    fail "$1: $(basename "$2") missing, not a PNG or too small ($n bytes)"
  fi
}

solve() {   # deck out.h5 log: run $BIN on deck into out.h5; true when it exits 0 (in rc) with out.h5 written
  "$BIN" "$1" "&output file='$2' /" >"$3" 2>&1
  rc=$?
  [ $rc -eq 0 ] && [ -f "$2" ]
}

plot_case() {   # tool out.png args...
  local tool=$1 out=$2; shift 2
  local what="$tool $(basename "${1:-}")${2:+ ${*:2}} -o $(basename "$out")"
  if "$PYTHON" "tools/$tool" "$@" -o "$out" >"$tmp/plot.log" 2>&1; then
    png_ok "$what" "$out"
  else
    fail "$what exited non-zero"; tail -n 5 "$tmp/plot.log"
  fi
}

# ---- syntax of the shell tools --------------------------------------------------------
for f in tools/sweep.sh tools/make_plots.sh tools/slurm/*.sbatch; do
  [ -f "$f" ] || { fail "bash -n $f: no such file"; continue; }
  check "bash -n $f" bash -n "$f"
done

# ---- plots on a real result -------------------------------------------------------------
if [ ! -x "$BIN" ]; then
  fail "no executable $BIN (build with make, or set BIN)"
  echo "test_tools: $fails failed check(s)"; exit 1
fi
h5=$tmp/a.h5
if solve inputs/table1/q1_16x8.nml "$h5" "$tmp/run.log"; then
  pass "robin_contact inputs/table1/q1_16x8.nml -> $(basename "$h5") (exit 0)"
  plot_case plot_history.py "$tmp/history.png" "$h5"
  plot_case plot_contact.py "$tmp/contact.png" "$h5"
  plot_case plot_contact.py "$tmp/contact_hertz.png" "$h5" --hertz
  plot_case plot_solution.py "$tmp/solution.png" "$h5"
  plot_case plot_solution.py "$tmp/solution_s.png" "$h5" --scale 1000
  if "$PYTHON" tools/plot_history.py "$h5" "$tmp/none.h5" -o "$tmp/x.png" >/dev/null 2>&1; then
    fail "plot_history.py with a missing file exits non-zero"
  else
    pass "plot_history.py with a missing file exits non-zero"
  fi
else
  fail "robin_contact inputs/table1/q1_16x8.nml (exit $rc)"; tail -n 15 "$tmp/run.log"
fi

if [ -f tests/data/decks/gap.nml ]; then
  g=$tmp/gap.h5
  if solve tests/data/decks/gap.nml "$g" "$tmp/gap.log"; then
    "$PYTHON" tools/plot_contact.py "$g" "$h5" --hertz -o "$tmp/gap.png" >"$tmp/gapplot.log" 2>&1
    rc=$?
    if [ $rc -eq 0 ] && grep -q "^plot_contact: Hertz for gap: P=.* R=2000 xc=1.5 " "$tmp/gapplot.log" \
       && grep -q "1 Hertz curves" "$tmp/gapplot.log"; then
      pass "plot_contact.py --hertz on the parabolic-gap deck: R, xc read from the deck, one Hertz curve"
      png_ok "plot_contact.py gap.h5 a.h5 --hertz" "$tmp/gap.png"
    else
      fail "plot_contact.py --hertz on the parabolic-gap deck (exit $rc)"; cat "$tmp/gapplot.log"
    fi
  else
    fail "robin_contact tests/data/decks/gap.nml (exit $rc)"; tail -n 15 "$tmp/gap.log"
  fi
fi

# ---- sweep ---------------------------------------------------------------------------------
sw=$tmp/sweep
bash tools/sweep.sh inputs/table1/q1_3x1.nml "$sw" 'solver:delta=0.5,1' >"$tmp/sweep.log" 2>&1
rc=$?
check "sweep.sh q1_3x1 'solver:delta=0.5,1' exits 0 (exit $rc)" [ $rc -eq 0 ]
csv=$sw/sweep.csv
if [ -f "$csv" ]; then
  header=$(head -n 1 "$csv")
  check "CSV header: $header" [ "$header" = "status,method,outer,inner,n1,n2,m,delta,residual,wall_s,solver.delta,exit,file" ]
  rows=$(tail -n +2 "$csv" | grep -c .)
  check "CSV has 2 data rows ($rows)" [ "$rows" -eq 2 ]
  r1=$(sed -n 2p "$csv"); r2=$(sed -n 3p "$csv")
  s1=${r1%%,*}; s2=${r2%%,*}
  if [ "$s1" = converged ] && [[ "$r1" == *,0.5,0,* ]]; then
    pass "row 1: delta 0.5 converged, exit 0 ($r1)"
  else
    fail "row 1: delta 0.5 converged, exit 0 ($r1)"
  fi
  if [[ ( "$s2" = max_outer || "$s2" = diverged ) && "$r2" == *,1,2,* ]]; then
    pass "row 2: delta 1 max_outer or diverged, exit 2 ($r2)"
  else
    fail "row 2: delta 1 max_outer or diverged, exit 2 ($r2)"
  fi
  d1=$(echo "$r1" | cut -d, -f8)
  check "row 1: result-line delta column is 0.5 ($d1)" [ "$d1" = 0.5 ]
else
  fail "sweep.sh wrote no $csv"; tail -n 15 "$tmp/sweep.log"
fi

echo "test_tools: $fails failed check(s)"
[ $fails -eq 0 ]
