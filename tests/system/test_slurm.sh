#!/bin/bash
# test_slurm.sh: tools/slurm/run_deck.sbatch picks up its own checkpoint when resubmitted.
# The script is called as Slurm would run it: bash with SLURM_JOB_ID, SLURM_SUBMIT_DIR,
# SLURM_CPUS_PER_TASK set, from another folder (the batch spool), and a fake `srun` first
# on PATH (it drops srun's options and runs the command, as a job step would).
#   1. submission 1 (max_outer=1500, checkpoint_every=500) stops: exit 2, checkpoint left;
#   2. submission 2, no --restart, max_outer raised: finds the checkpoint, the solver prints
#      'resuming after outer iteration 1500', converges (exit 0), checkpoint deleted;
#   3. the same command again: no checkpoint any more, starts from iteration 1;
#   4. SIGTERM to the job step (what --signal=TERM@120 does before the time limit): exit 4
#      with a checkpoint; the identical command resubmitted resumes from it and converges;
#   5. --fresh ignores an existing checkpoint;
#   6. submitted from another folder: exit 1, 'submit from the repository root';
#   7. tools/rc_run.py result-file: deck &output, override, default results/<deck>.h5.
# Prints PASS/FAIL lines; exits 1 if any check failed.
set -u
cd "$(dirname "$0")/../.." || exit 1
ROOT=$PWD
PYTHON=${PYTHON:-/usr/bin/python3}
BIN=${BIN:-bin/robin_contact}
case "$BIN" in /*) ;; *) BIN=$ROOT/$BIN ;; esac
. tests/system/checks.sh test_slurm

# fake srun: drop the options, run the command (exec: the signal reaches the solver)
mkdir -p "$tmp/bin" "$tmp/spool"
cat > "$tmp/bin/srun" <<'SH'
#!/bin/bash
while [ $# -gt 0 ] && [ "${1#-}" != "$1" ]; do shift; done
exec "$@"
SH
chmod +x "$tmp/bin/srun"
cp tools/slurm/run_deck.sbatch "$tmp/spool/slurm_script"     # Slurm runs a copy from its spool

DECK=inputs/table1/q1_16x8.nml
MESH=("&body id=1, nx=256, ny=8 /" "&body id=2, nx=256, ny=8 /")
SLOW="&solver delta=0.998 /"                 # about 4900 outer iterations, about 5 s
res=$tmp/run.h5
OUTPUT="&output file='$res', checkpoint_every=500 /"
job() {   # log, args...: one "submission" of run_deck.sbatch; sets rc
  local log=$1; shift
  (cd "$tmp/spool" && env PATH="$tmp/bin:$PATH" BIN="$BIN" PYTHON="$PYTHON" SLURM_JOB_ID=$RANDOM \
     SLURM_SUBMIT_DIR="$ROOT" SLURM_CPUS_PER_TASK=2 bash ./slurm_script "$@") >"$log" 2>&1
  rc=$?
}

# 1. first submission stops at max_outer with a checkpoint
job "$tmp/1.log" "$DECK" "${MESH[@]}" "$SLOW" "&solver max_outer=1500 /" "$OUTPUT"
check "submission 1 (max_outer=1500): exit 2 (exit $rc)" [ $rc -eq 2 ]
check "submission 1: checkpoint $(basename "$res").ckpt.h5 written" [ -f "$res.ckpt.h5" ]
check "submission 1: run_deck names the result file" grep -q "^run_deck: job .* result $res" "$tmp/1.log"
if grep -q "resuming" "$tmp/1.log"; then fail "submission 1 does not resume"; else pass "submission 1 does not resume"; fi
# 2. resubmitted without --restart: resumes from the checkpoint
job "$tmp/2.log" "$DECK" "${MESH[@]}" "$SLOW" "&solver max_outer=40000 /" "$OUTPUT"
check "submission 2 (no --restart, max_outer raised): exit 0 (exit $rc)" [ $rc -eq 0 ]
check "submission 2: run_deck found the checkpoint" grep -q "found the checkpoint $res.ckpt.h5" "$tmp/2.log"
check "submission 2: solver says 'resuming after outer iteration 1500'" \
  grep -q "resuming after outer iteration 1500" "$tmp/2.log"
check "submission 2: converged" grep -q "^result: status=converged" "$tmp/2.log"
check "submission 2: checkpoint deleted after convergence" [ ! -f "$res.ckpt.h5" ]
# 3. the same command once more: nothing to resume
job "$tmp/3.log" "$DECK" "&output file='$tmp/small.h5' /"
check "a run without checkpoint starts from scratch (exit $rc)" [ $rc -eq 0 ]
if grep -q "resuming" "$tmp/3.log"; then fail "no checkpoint: no resuming"; else pass "no checkpoint: no resuming"; fi

# 4. SIGTERM to the job step, then the identical command resubmitted
res4=$tmp/sig.h5
CMD=("$DECK" "${MESH[@]}" "$SLOW" "&solver max_outer=40000 /" "&output file='$res4' /")
(cd "$tmp/spool" && exec env PATH="$tmp/bin:$PATH" BIN="$BIN" PYTHON="$PYTHON" SLURM_JOB_ID=1 \
   SLURM_SUBMIT_DIR="$ROOT" SLURM_CPUS_PER_TASK=2 bash ./slurm_script "${CMD[@]}") >"$tmp/4.log" 2>&1 &
shell=$!
step=""
for _ in $(seq 100); do                       # wait for the solver (the step) to start iterating
  step=$(pgrep -P "$shell" -f "^$BIN " || true)   # the binary by its path (robin_contact_debug too)
  [ -n "$step" ] && break
  sleep 0.05
done
sleep 0.8                                     # into the outer iteration (as in test_restart.py)
if [ -n "$step" ]; then
  kill -TERM "$step"
  wait "$shell"; rc=$?
  check "SIGTERM to the job step: exit 4 (exit $rc)" [ $rc -eq 4 ]
  check "SIGTERM: checkpoint written" [ -f "$res4.ckpt.h5" ]
  check "SIGTERM: run_deck says to resubmit" grep -q "resubmit the same command" "$tmp/4.log"
  job "$tmp/5.log" "${CMD[@]}"
  check "identical command resubmitted: exit 0 (exit $rc)" [ $rc -eq 0 ]
  check "identical command resubmitted: 'resuming after outer iteration N'" \
    grep -q "resuming after outer iteration [1-9]" "$tmp/5.log"
else
  wait "$shell"
  fail "SIGTERM case: the solver step was not found running"
fi

# 5. --fresh ignores a checkpoint
job "$tmp/6.log" "$DECK" "${MESH[@]}" "$SLOW" "&solver max_outer=600 /" "$OUTPUT"
job "$tmp/7.log" --fresh "$DECK" "${MESH[@]}" "$SLOW" "&solver max_outer=600 /" "$OUTPUT"
check "--fresh: exit 2 again at max_outer (exit $rc)" [ $rc -eq 2 ]
check "--fresh: says it ignores the checkpoint" grep -q "fresh: ignoring the checkpoint" "$tmp/7.log"
if grep -q "resuming" "$tmp/7.log"; then fail "--fresh: no resuming"; else pass "--fresh: no resuming"; fi

# 6. submitted from another folder
(cd "$tmp/spool" && env PATH="$tmp/bin:$PATH" SLURM_JOB_ID=7 SLURM_SUBMIT_DIR="$tmp" bash ./slurm_script "$DECK") \
  >"$tmp/8.log" 2>&1
rc=$?
check "submitted from another folder: exit 1 (exit $rc)" [ $rc -eq 1 ]
check "submitted from another folder: 'submit from the repository root'" \
  grep -q "submit from the repository root" "$tmp/8.log"
(cd "$tmp/spool" && env PATH="$tmp/bin:$PATH" SLURM_ARRAY_TASK_ID=0 SLURM_SUBMIT_DIR="$tmp" \
   bash "$ROOT/tools/slurm/sweep_table1.sbatch") >"$tmp/9.log" 2>&1
rc=$?
check "sweep_table1 submitted from another folder: exit 1, 'submit from the repository root' (exit $rc)" \
  grep -q "submit from the repository root" "$tmp/9.log"

# 7. the result file run_deck derives
rf() { "$PYTHON" tools/rc_run.py result-file "$@"; }
check "result-file: the deck's &output file" [ "$(rf inputs/table1/q1_3x1.nml)" = results/table1/q1_3x1.h5 ]
check "result-file: the last &output override (quotes, '/' in the path)" \
  [ "$(rf inputs/table1/q1_3x1.nml "&output file='a/b.h5' /" '&OUTPUT checkpoint_every=5, FILE="c/d.h5" /')" = c/d.h5 ]
grep -v -i "^ *&output" inputs/table1/q1_3x1.nml > "$tmp/noout.nml"
check "result-file: default results/<deck name>.h5" [ "$(rf "$tmp/noout.nml")" = results/noout.h5 ]
check "git ignores slurm-*.out in the repository root" git check-ignore -q slurm-robin_contact-123.out

echo "test_slurm: $fails failed check(s)"
[ $fails -eq 0 ]
