#!/usr/bin/env bash
# Installs missing Debian packages, configures and builds Palpate (Release) into build/.
# Environment: PALPATE_WERROR=ON to treat warnings as errors (CI), BUILD_DIR to build elsewhere,
# JOBS for parallel jobs (default: number of cores).
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install_deps.sh
build_dir=${BUILD_DIR:-build}
# a new build folder is made for Ninja; one configured before keeps its generator
generator=()
if [ ! -f "$build_dir/CMakeCache.txt" ] && command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DPALPATE_WERROR="${PALPATE_WERROR:-OFF}" \
  ${PALPATE_CMAKE_ARGS:-}
cmake --build "$build_dir" -j "${JOBS:-$(nproc)}"
