#!/usr/bin/env bash
# Bad input decks must be rejected cleanly.
#
# For every tests/data/bad_input/*.nml, run the program (default bin/robin_contact; set BIN to
# use another binary) in a fresh empty directory and check:
#   - the exit code is 1 (bad input);
#   - every "! expect: <text>" line of the deck occurs in stdout+stderr (fixed string);
#   - there is no 'Fortran runtime error', 'Error termination' or 'Backtrace' text;
#   - no file was created (no result file, no partial output).
# A deck normally is the only argument. A line "! args: ..." replaces the arguments
# (shell words; @deck is the deck's absolute path, @dir its directory; "(none)": no
# argument at all), for the missing-file, no-argument and bad-override cases.
# Prints "PASS  <deck>" or "FAIL  <deck>: <why>" per deck, then a summary line, and exits
# non-zero if any deck failed.
#
# Usage: bash tests/system/test_bad_input.sh            (from the repository root)
#        BIN=bin/robin_contact_debug bash tests/system/test_bad_input.sh
set -u
decks=$(cd "$(dirname "${BASH_SOURCE[0]}")/../data/bad_input" && pwd)
BIN=${BIN:-bin/robin_contact}
if [ -e "$BIN" ]; then
  BIN=$(cd "$(dirname "$BIN")" && pwd)/$(basename "$BIN")
fi
if [ ! -x "$BIN" ]; then
  echo "FAIL  setup: binary '$BIN' not found or not executable (build it, or set BIN)"
  exit 2
fi

npass=0
nfail=0
for deck in "$decks"/*.nml; do
  name=bad_input/$(basename "$deck")
  args_line=$(sed -n 's/^! args:[[:space:]]*//p' "$deck" | head -n 1 | sed 's/[[:space:]]*$//')
  if [ -z "$args_line" ]; then
    set -- "$deck"
  elif [ "$args_line" = "(none)" ]; then
    set --
  else
    args_line=${args_line//@deck/$deck}
    args_line=${args_line//@dir/$decks}
    eval "set -- $args_line"
  fi

  work=$(mktemp -d)
  out=$(cd "$work" && OMP_NUM_THREADS=1 timeout 120 "$BIN" "$@" 2>&1)
  rc=$?
  why=""
  add() { why="${why:+$why; }$1"; }

  [ "$rc" -eq 1 ] || add "exit code $rc, expected 1"
  nexp=0
  while IFS= read -r e; do
    [ -n "$e" ] || continue
    nexp=$((nexp + 1))
    grep -qF -- "$e" <<<"$out" || add "message lacks '$e'"
  done < <(sed -n 's/^! expect:[[:space:]]*//p' "$deck" | sed 's/[[:space:]]*$//')
  [ "$nexp" -gt 0 ] || add "the deck has no '! expect:' line"
  for bad in 'Fortran runtime error' 'Error termination' 'Backtrace'; do
    grep -qF -- "$bad" <<<"$out" && add "output contains '$bad'"
  done
  created=$(cd "$work" && find . -mindepth 1 | head -n 3 | tr '\n' ' ')
  [ -z "$created" ] || add "files were created: $created"
  rm -rf "$work"

  if [ -z "$why" ]; then
    echo "PASS  $name"
    npass=$((npass + 1))
  else
    echo "FAIL  $name: $why"
    sed 's/^/        | /' <<<"$out" | head -n 8
    nfail=$((nfail + 1))
  fi
done
echo "test_bad_input: $npass passed, $nfail failed"
[ "$nfail" -eq 0 ]
