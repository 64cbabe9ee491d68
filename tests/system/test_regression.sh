#!/usr/bin/env bash
# Every shipped deck (its own settings, monolithic, harmonic at delta 0.5) gives the contact
# forces, status and outer count stored in tests/data/regression.json: the forces to 1e-12
# relative, or to REGRESSION_RTOL (make check DEBUG=1 sets it for the checked build, whose
# -O0 code rounds differently from the release build that stored the reference).
# After a change meant to alter results: tools/regression.py --store, and say why in the commit.
set -u
cd "$(dirname "$0")/../.."
exec "${PYTHON:-/usr/bin/python3}" tools/regression.py --bin "${BIN:-bin/robin_contact}" --rtol "${REGRESSION_RTOL:-1e-12}"
