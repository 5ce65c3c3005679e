#!/usr/bin/env bash
# Installs missing Debian packages, configures and builds Palpate (Release) into build/.
# Environment: PALPATE_WERROR=ON to treat warnings as errors (CI), BUILD_DIR to build elsewhere,
# JOBS for parallel jobs (default: number of cores).
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install_deps.sh
build_dir=${BUILD_DIR:-build}
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DPALPATE_WERROR="${PALPATE_WERROR:-OFF}" \
  ${PALPATE_CMAKE_ARGS:-}
cmake --build "$build_dir" -j "${JOBS:-$(nproc)}"
