#!/usr/bin/env bash
# One command from a fresh machine: install what is missing, build, run the whole test suite with ctest.
# Extra arguments go to ctest (e.g. scripts/test.sh -L sim).
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/build.sh
cd "${BUILD_DIR:-build}"
ctest --output-on-failure -j "${JOBS:-$(nproc)}" "$@"
