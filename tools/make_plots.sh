#!/bin/bash
# make_plots.sh: what `make plots` does: solve the default deck, then draw
#   results/history.png   (tools/plot_history.py: criterion and residual per outer iteration)
#   results/contact.png   (tools/plot_contact.py --hertz: contact pressure and gap; the Hertz
#                          curve and p/p0 panel are added only when the deck has a parabolic gap)
#   results/solution.png  (tools/plot_solution.py: deformed bodies coloured by von Mises,
#                          rasterised, colour scale clipped at the 99.5th percentile)
#
# Usage: tools/make_plots.sh            (from the repository root; make plots calls it as
#                                        BIN=$(PROG) PYTHON=$(PYTHON) bash tools/make_plots.sh)
# Environment: BIN (default bin/robin_contact), PYTHON (default /usr/bin/python3),
#   DECK (default inputs/default.nml), RESULT (default results/default.h5: the run's
#   result file, set with an &output override), OMP_NUM_THREADS (default 2).
# Exit: 0 when the three plots were written (also when the run did not converge, exit 2:
# the plots then show the unconverged state, with a warning); 1 when the run failed
# without a result (bad input 1, numerical failure 3, ...) or a plot tool failed.
set -u
BIN=${BIN:-bin/robin_contact}
PYTHON=${PYTHON:-/usr/bin/python3}
DECK=${DECK:-inputs/default.nml}
RESULT=${RESULT:-results/default.h5}
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2}
out=$(dirname "$RESULT")

[ -x "$BIN" ] || { echo "make_plots: no executable $BIN (run make first)" >&2; exit 1; }
[ -f "$DECK" ] || { echo "make_plots: no deck $DECK" >&2; exit 1; }
mkdir -p results "$out" || exit 1
rm -f "$RESULT"          # never plot a stale result of an earlier run
"$BIN" "$DECK" "&output file='$RESULT' /"
rc=$?
case $rc in
  0) ;;
  2|4) echo "make_plots: warning: $DECK did not converge (exit $rc); plotting its last state" >&2 ;;
  *) echo "make_plots: $BIN $DECK failed (exit $rc)" >&2; exit 1 ;;
esac
[ -f "$RESULT" ] || { echo "make_plots: no result file $RESULT" >&2; exit 1; }
plot() {   # tool args...: run a plot tool; a failure is said, also a death by a signal
  "$PYTHON" "tools/$1" "${@:2}"
  local rc=$?
  if [ $rc -gt 128 ]; then
    echo "make_plots: tools/$1 killed by signal $((rc - 128)) (out of memory? see dmesg)" >&2
  elif [ $rc -ne 0 ]; then
    echo "make_plots: tools/$1 failed (exit $rc)" >&2
  fi
  return $rc
}
plot plot_history.py "$RESULT" -o results/history.png || exit 1
plot plot_contact.py "$RESULT" --hertz -o results/contact.png || exit 1
plot plot_solution.py "$RESULT" -o results/solution.png || exit 1
echo "make_plots: results/history.png results/contact.png results/solution.png"
