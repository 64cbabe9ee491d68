#!/usr/bin/env bash
# Every shipped deck (its own settings, monolithic, harmonic at delta 0.5) gives the contact
# forces (to 1e-12 relative), status and outer count stored in tests/data/regression.json, and
# every converged run's bodies in equilibrium (their reaction: lines' balance)
# (the release build; the checked debug build rounds differently: --loose).
# After a change meant to alter results: tools/regression.py --store, and say why in the commit.
set -u
cd "$(dirname "$0")/../.."
loose=()
case "${BUILD:-build/release}" in *debug*) loose=(--loose);; esac
exec "${PYTHON:-/usr/bin/python3}" tools/regression.py --bin "${BIN:-bin/robin_contact}" "${loose[@]}"
