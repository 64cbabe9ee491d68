#!/bin/bash
# sweep.sh: run robin_contact locally on a grid of namelist overrides and collect the
# `result:` lines of all runs into one CSV.
#
# Usage: tools/sweep.sh [--csv FILE] DECK OUTDIR SPEC [SPEC ...] ['&group var=value /' ...]
#
#   SPEC  GROUP:VAR=V1,V2,...            one variable, its values separated by commas
#         GROUP:VAR1/VAR2=A1/B1,A2/B2    linked variables, varied together (one value per
#                                        variable, separated by '/'), e.g. meshes nx/ny
#         GROUP is a namelist group (solver, contact, scene, ...). GROUP 'body' sets the
#         variables on both bodies (&body id=1 ... / and &body id=2 ... /); 'body1' or
#         'body2' sets them on one body only. Values are namelist values as written in a
#         deck (strings quoted: solver:method="'robin','monolithic'"); they cannot contain
#         commas or '/'.
#   '&...' arguments are fixed overrides passed to every run (before the grid's).
#   The grid is the cartesian product of all SPECs (the first SPEC varies slowest).
#
# Examples:
#   tools/sweep.sh inputs/table1/q1_16x8.nml results/sweep 'solver:delta=0.1,0.5,0.95' 'body:nx=8,16'
#   tools/sweep.sh inputs/table1/q1_3x1.nml /tmp/sw 'body:nx/ny=3/1,6/2,16/8,24/16' \
#                  'solver:delta=0.1,0.5,0.7,0.95,1' '&solver max_outer=400 /'
#
# Each run writes OUTDIR/<deck name>_<tag>.h5 (the &output file override is always
# added last) and its console output to OUTDIR/<deck name>_<tag>.log, where <tag> is
# built from the override values (e.g. q1_16x8_delta0.5_nx8.h5).
# The CSV (default OUTDIR/sweep.csv, rewritten at the start, one row appended per run)
# has the columns
#   status,method,outer,inner,n1,n2,m,delta,residual,wall_s   (keys of the result line)
#   GROUP.VAR ...                                             (one per swept variable)
#   exit,file                                                 (exit code, result file)
# A run without a result line gets its status from the exit code (bad_input, failed,
# interrupted, exit<N>) and empty result columns.
# Exit codes of robin_contact: 0 converged, 1 bad input, 2 not converged, 3 numerical
# failure, 4 interrupted. The sweep records 2, 3, 4 (and crashes) and goes on; it stops
# at the first 1 (bad input: the rest of the grid would fail the same way).
# Environment: BIN (default bin/robin_contact), OMP_NUM_THREADS (default 2).
# Exit status: 0 when the whole grid ran (whatever the runs' statuses), 1 on bad usage
# or a run with bad input, 4 when the sweep itself was interrupted (SIGINT/SIGTERM: the
# running solver checkpoints and stops, its row is written, then the sweep stops).
set -u

die() { echo "sweep: $*" >&2; exit 1; }
usage() { sed -n '2,/^set -u/p' "$0" | sed '$d;s/^# \{0,1\}//'; }   # the comment above

BIN=${BIN:-bin/robin_contact}
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2}
csv=""
while [ $# -gt 0 ]; do
  case "$1" in
    --csv) [ $# -ge 2 ] || die "--csv needs a file"; csv=$2; shift 2 ;;
    --csv=*) csv=${1#--csv=}; shift ;;
    -h|--help) usage; exit 0 ;;
    --) shift; break ;;
    -*) die "unknown option $1 (see --help)" ;;
    *) break ;;
  esac
done
[ $# -ge 2 ] || { usage >&2; exit 1; }
deck=$1; outdir=$2; shift 2
[ -f "$deck" ] || die "no deck file '$deck'"
[ -x "$BIN" ] || die "no executable '$BIN' (build it with make, or set BIN)"
mkdir -p "$outdir" || die "cannot create '$outdir'"
[ -n "$csv" ] || csv=$outdir/sweep.csv
stem=$(basename "$deck"); stem=${stem%.nml}

# ---- parse the grid specification ---------------------------------------------------
fixed=()            # fixed overrides
spec_group=()       # per SPEC: group
spec_vars=()        # per SPEC: variables separated by spaces
spec_vals=()        # per SPEC: values separated by spaces (each value a/b/... for linked vars)
columns=()          # CSV override columns GROUP.VAR
for arg in "$@"; do
  case "$arg" in
    '&'*) fixed+=("$arg"); continue ;;
  esac
  [[ "$arg" =~ ^([A-Za-z][A-Za-z0-9_]*):([A-Za-z][A-Za-z0-9_/]*)=(.+)$ ]] \
    || die "bad SPEC '$arg' (expected GROUP:VAR=V1,V2 or GROUP:VAR1/VAR2=A1/B1,A2/B2)"
  g=${BASH_REMATCH[1],,}; vs=${BASH_REMATCH[2]}; vals=${BASH_REMATCH[3]}
  IFS=/ read -r -a va <<<"$vs"
  IFS=, read -r -a vl <<<"$vals"
  [ ${#vl[@]} -gt 0 ] || die "SPEC '$arg' has no values"
  for v in "${vl[@]}"; do
    [ -n "$v" ] || die "SPEC '$arg' has an empty value"
    case "$v" in *' '*) die "SPEC '$arg': values cannot contain blanks" ;; esac
    IFS=/ read -r -a parts <<<"$v"
    [ ${#parts[@]} -eq ${#va[@]} ] || die "SPEC '$arg': value '$v' does not give one value per variable (${vs})"
  done
  spec_group+=("$g"); spec_vars+=("${va[*]}"); spec_vals+=("${vl[*]}")
  for v in "${va[@]}"; do columns+=("$g.$v"); done
done
nspec=${#spec_group[@]}
total=1
for ((s = 0; s < nspec; s++)); do read -r -a vl <<<"${spec_vals[s]}"; total=$((total * ${#vl[@]})); done

keys=(status method outer inner n1 n2 m delta residual wall_s)
csv_field() {       # quote a CSV field when needed
  local v=$1
  if [[ "$v" == *[,\"]* || "$v" == *$'\n'* ]]; then v=${v//\"/\"\"}; printf '"%s"' "$v"; else printf '%s' "$v"; fi
}
{
  line=""
  for k in "${keys[@]}" "${columns[@]}" exit file; do line+="${line:+,}$(csv_field "$k")"; done
  echo "$line"
} >"$csv" || die "cannot write '$csv'"

stop=0
trap 'stop=1' INT TERM
run=0

# ---- one run: $1.. = index of the value of each SPEC -------------------------------------
run_one() {
  local -a idx=("$@") ov=() cols=() order=()
  local -A asg=()
  local tag="" s k v t key
  for ((s = 0; s < nspec; s++)); do
    local -a vars vals parts
    read -r -a vars <<<"${spec_vars[s]}"
    read -r -a vals <<<"${spec_vals[s]}"
    IFS=/ read -r -a parts <<<"${vals[idx[s]]}"
    local g=${spec_group[s]} targets
    case "$g" in
      body) targets="body#1 body#2" ;;
      body1|body2) targets="body#${g#body}" ;;
      *) targets=$g ;;
    esac
    for ((k = 0; k < ${#vars[@]}; k++)); do
      v=${parts[k]}
      cols+=("$v")
      t=$(printf '%s' "${vars[k]}${v}" | tr -d "'\"" | tr -c 'A-Za-z0-9.+-' '_')
      tag+="_$t"
      for key in $targets; do
        [ -n "${asg[$key]+x}" ] || order+=("$key")
        asg[$key]+="${asg[$key]:+, }${vars[k]}=$v"
      done
    done
  done
  for key in "${order[@]}"; do
    case "$key" in
      body#*) ov+=("&body id=${key#body#}, ${asg[$key]} /") ;;
      *) ov+=("&$key ${asg[$key]} /") ;;
    esac
  done
  local file=$outdir/$stem$tag.h5 log=$outdir/$stem$tag.log
  run=$((run + 1))
  printf 'sweep: [%d/%d] %s\n' "$run" "$total" "${ov[*]:-(no overrides)}"
  "$BIN" "$deck" ${fixed[@]+"${fixed[@]}"} ${ov[@]+"${ov[@]}"} "&output file='$file' /" >"$log" 2>&1
  local rc=$?
  local res
  res=$(grep '^result: ' "$log" | tail -n 1)
  local -A r=()
  local tok
  for tok in ${res#result: }; do
    [[ "$tok" == *=* ]] && r[${tok%%=*}]=${tok#*=}
  done
  if [ -z "$res" ]; then
    case $rc in
      1) r[status]=bad_input ;; 3) r[status]=failed ;; 4) r[status]=interrupted ;;
      *) r[status]=exit$rc ;;
    esac
  fi
  local line="" f
  for k in "${keys[@]}"; do line+="${line:+,}$(csv_field "${r[$k]:-}")"; done
  for v in ${cols[@]+"${cols[@]}"}; do line+=",$(csv_field "$v")"; done
  line+=",$rc,$(csv_field "$file")"
  echo "$line" >>"$csv"
  printf 'sweep:        -> %s outer=%s inner=%s residual=%s (exit %d, log %s)\n' \
    "${r[status]}" "${r[outer]:-}" "${r[inner]:-}" "${r[residual]:-}" "$rc" "$log"
  if [ $rc -eq 1 ]; then
    echo "sweep: bad input (exit 1); stopping. Last lines of $log:" >&2
    tail -n 15 "$log" >&2
    exit 1
  fi
  if [ $stop -eq 1 ]; then
    echo "sweep: interrupted after run $run of $total; CSV so far: $csv" >&2
    exit 4
  fi
}

# ---- cartesian product (odometer, last SPEC fastest) ------------------------------------
cur=()
lens=()
for ((s = 0; s < nspec; s++)); do read -r -a vl <<<"${spec_vals[s]}"; cur+=(0); lens+=(${#vl[@]}); done
while :; do
  run_one ${cur[@]+"${cur[@]}"}
  s=$((nspec - 1))
  while [ $s -ge 0 ]; do
    cur[s]=$((cur[s] + 1))
    [ ${cur[s]} -lt ${lens[s]} ] && break
    cur[s]=0; s=$((s - 1))
  done
  [ $s -lt 0 ] && break
done
echo "sweep: $run runs, CSV: $csv"
