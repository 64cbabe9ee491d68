#!/usr/bin/env bash
# Every shipped deck (its own settings, monolithic, harmonic at delta 0.5) gives the contact
# forces (to 1e-12 relative), status and outer count stored in tests/data/regression.json.
# After a change meant to alter results: tools/regression.py --store, and say why in the commit.
set -u
cd "$(dirname "$0")/../.."
exec "${PYTHON:-/usr/bin/python3}" tools/regression.py --bin "${BIN:-bin/robin_contact}" | sed 's/^PASS /PASS /'
