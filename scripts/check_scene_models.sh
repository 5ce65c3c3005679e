#!/usr/bin/env bash
# For every model under a folder (default: assimp's test models) that `palpate info` accepts, writes a scene (touch
# unless --mode says otherwise) with `palpate scene` and records it (lockstep, scene defaults, no frames), then
# reports per model whether the tool made contact (max_force_N > 0, lattice nodes > 0, no NaN). Prints one CSV row
# per accepted model and the counts at the end; exits non-zero when an accepted model gives no contact.
# Usage: scripts/check_scene_models.sh [MODELS_DIR] [--mode touch|pull|cut]
# Environment: PALPATE (the binary, default build/bin/palpate), WORK (scratch folder, default a mktemp folder),
# LIMIT_S (seconds allowed per command, default 120).
set -uo pipefail
cd "$(dirname "$0")/.."

models=/usr/share/assimp/models
mode=touch
while [ $# -gt 0 ]; do
  case "$1" in
    --mode) mode=$2; shift 2 ;;
    *) models=$1; shift ;;
  esac
done
palpate=$(realpath "${PALPATE:-build/bin/palpate}")
work=${WORK:-$(mktemp -d)}
mkdir -p "$work"
limit_s=${LIMIT_S:-120}

accepted=0; contact=0; failed=()
echo "model,max_force_N,nodes,nan_events,note"
while IFS= read -r -d '' f; do
  timeout "$limit_s" "$palpate" info "$f" >/dev/null 2>&1 || continue
  accepted=$((accepted + 1))
  id=$(printf '%04d' "$accepted")
  scene="$work/$id.json"; out="$work/$id"
  if ! note=$(timeout "$limit_s" "$palpate" scene "$f" --mode "$mode" --out "$scene" 2>&1 >/dev/null); then
    echo "$f,,,,scene failed: $(echo "$note" | tail -1)"; failed+=("$f"); continue
  fi
  if ! rec=$(timeout "$limit_s" "$palpate" record "$scene" --no-render -q -o "$out" 2>&1 >/dev/null); then
    echo "$f,,,,record failed: $(echo "$rec" | tail -1)"; failed+=("$f"); continue
  fi
  row=$(python3 - "$out/summary.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
ok = j["max_force_N"] > 0 and j["sim"]["nodes"] > 0 and j["nan_events"] == 0 and j["mode"] == "lockstep"
print(("ok" if ok else "bad") + f',{j["max_force_N"]:.3f},{j["sim"]["nodes"]},{j["nan_events"]},{j.get("no_contact", "")}')
PY
)
  echo "$f,${row#*,}"
  if [ "${row%%,*}" = ok ]; then contact=$((contact + 1)); else failed+=("$f"); fi
  rm -rf "$out"
done < <(find "$models" -type f -print0 | sort -z)

echo "accepted $accepted, with contact $contact (mode $mode)"
for f in "${failed[@]}"; do echo "no contact: $f"; done
[ ${#failed[@]} -eq 0 ]
