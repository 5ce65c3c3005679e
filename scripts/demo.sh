#!/usr/bin/env bash
# One command from a fresh machine: install what is missing, build (Release), record the default scene.
# Usage: scripts/demo.sh [SCENE] [OUT_DIR]     (defaults: scenes/bunny_pull.json, out/bunny_pull)
set -euo pipefail
cd "$(dirname "$0")/.."

scene=${1:-scenes/bunny_pull.json}
out=${2:-out/$(basename "$scene" .json)}
scripts/build.sh
echo "recording $scene into $out/"
build/bin/palpate record "$scene" --out "$out"   # prints where the frames, log and summary are
