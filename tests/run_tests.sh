#!/usr/bin/env bash
# Runs every test of `make check`: the Fortran unit test programs built from
# tests/unit/test_*.f90 into $BUILD/tests, then the whole-program tests tests/system/test_*.sh
# and tests/system/test_*.py (tests/test_*.sh and tests/test_*.py too, for a test not yet
# sorted into a folder). Each is one test; it passes when it exits 0. Logs go to
# $BUILD/test-logs/unit/<test>.log and $BUILD/test-logs/system/<test>.log (a unit test and a
# system test may share a name: test_supports). Last line: N passed, M failed.
set -u
BUILD=${BUILD:-build/release}
PYTHON=${PYTHON:-/usr/bin/python3}
export BIN=${BIN:-bin/robin_contact}
export PYTHON BUILD
logs=$BUILD/test-logs
mkdir -p "$logs/unit" "$logs/system"
pass=0; fail=0; failed=""
run_one() {   # kind (unit or system: the log's folder), name, command...
  local kind=$1 name=$2; shift 2
  local log=$logs/$kind/$name.log
  local t0=$(date +%s%N)
  if timeout 900 "$@" >"$log" 2>&1; then
    status=PASS; pass=$((pass+1))
  else
    status=FAIL; fail=$((fail+1)); failed="$failed $name"
  fi
  local t1=$(date +%s%N)
  local checks=$(grep -c '^PASS' "$log" || true)
  local bad=$(grep -c '^FAIL' "$log" || true)
  local ms=$(( (t1 - t0) / 1000000 ))
  printf '%-4s %-28s %4s checks passed, %s failed  (%d.%03d s)\n' "$status" "$name" "$checks" "$bad" \
    $((ms / 1000)) $((ms % 1000))
  if [ $status = FAIL ]; then
    echo "---- last lines of $log"; tail -n 25 "$log"; echo "----"
  fi
}
for t in "$BUILD"/tests/test_*; do
  case "$t" in *.o|*.log) continue;; esac
  [ -x "$t" ] || continue
  run_one unit "$(basename "$t")" "$t"
done
for t in tests/system/test_*.sh tests/test_*.sh; do
  [ -f "$t" ] || continue
  run_one system "$(basename "$t" .sh)" bash "$t"
done
# the MPI binary, built beside the tests so far (make check): wait for it before the Python
# tests, some of which run it when it exists
if [ -n "${MPI_BUILD_STATUS:-}" ]; then
  waited=0
  while [ ! -f "$MPI_BUILD_STATUS" ] && [ $waited -lt 1800 ]; do sleep 1; waited=$((waited + 1)); done
  if [ "$(cat "$MPI_BUILD_STATUS" 2>/dev/null)" != 0 ]; then
    fail=$((fail+1)); failed="$failed mpi_build"
    echo "FAIL mpi_build (the MPI binary did not build; last lines of ${MPI_BUILD_STATUS%.status}.log)"
    tail -n 25 "${MPI_BUILD_STATUS%.status}.log" 2>/dev/null
  fi
fi
for t in tests/system/test_*.py tests/test_*.py; do
  [ -f "$t" ] || continue
  run_one system "$(basename "$t" .py)" "$PYTHON" "$t"
done
[ -n "$failed" ] && echo "failed:$failed"
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
