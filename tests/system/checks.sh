# Sourced by the shell tests (not a test itself): PASS/FAIL lines, the lines run_tests.sh
# counts, with the number of failures in $fails, and a scratch folder $tmp removed at exit.
# Usage: . tests/system/checks.sh NAME      (NAME: the scratch folder's prefix in /tmp)
fails=0
pass() { echo "PASS  $*"; }
fail() { echo "FAIL  $*"; fails=$((fails + 1)); }
check() { local what=$1; shift; if "$@"; then pass "$what"; else fail "$what"; fi; }
tmp=$(mktemp -d "/tmp/$1.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
