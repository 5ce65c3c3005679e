#!/usr/bin/env bash
# Installs the Debian packages Palpate builds and tests with, when any is missing.
# libdeflate compresses the PNG frames. FFmpeg's libraries encode the MP4 of a recording; the ffmpeg/ffprobe
# programs are used by the tests only.
# capsh (libcap2-bin) lets a test run the servo without the right to lock memory.
# gnuplot-nox draws the benchmarks' --plot figures (pngcairo) from the data and script palpate writes.
# clang builds the libFuzzer targets (scripts/fuzz.sh, CI's fuzz stage). ninja-build runs the builds (a fresh build
# folder is configured for Ninja: it keeps both cores busy across targets where make's recursion idles one).
# libmetis-dev orders the local/global solver's sparse factor (nested dissection: shorter downdate paths).
# cpp-httplib serves the live view (record --serve); Chromium runs its page headless in the `browser` tests.
# pybind11-dev and python3-dev build the Python module (python/); python3-numpy holds its arrays, python3-pytest runs
# its tests, python3-pandas gives a sweep's table as a DataFrame, python3-dask and python3-distributed run sweeps on a
# Dask cluster (a LocalCluster in the tests).
# Runs apt-get as root (or through sudo); does nothing when everything is present.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libmetis-dev libassimp-dev libosmesa6-dev libegl-dev libgl-dev libpng-dev libdeflate-dev
  nlohmann-json3-dev libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev
  assimp-testmodels
  libavcodec-dev libavformat-dev libswscale-dev libavutil-dev
  ffmpeg libcap2-bin
  gnuplot-nox
  libcpp-httplib-dev
  chromium
  clang
  pybind11-dev python3-dev python3-numpy python3-pytest python3-pandas python3-dask python3-distributed
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install_deps: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then sudo_cmd=(sudo); else
    echo "install_deps: need root to install: ${missing[*]}" >&2; exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
