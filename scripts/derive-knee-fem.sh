#!/usr/bin/env bash
# Derives scenes/knee_fem/ (the FEM knee, scenes/knee.json): the soft tissue between the skin
# and the bones of the default knee (scenes/knee_vhf_small, itself derived from the Visible Human
# Female, CC BY 4.0: see its ATTRIBUTION.md) as linear tetrahedra at two resolutions, meshed by
# TetGen run as a program (`hapsim tetrahedralize`; apt-get install tetgen). Regions by the
# surface around each tet's centre (first match wins):
#   3 patellar tendon, 4 MCL, 5 LCL, 6 cruciate ligaments, 7 cartilage,
#   1 quadriceps (the three vasti), 2 the other muscles, 0 skin and subcutaneous fat (the rest).
# The tets inside the bones are removed: the bones are rigid bodies of the scene, and the tissue's
# nodes on them are fixed there. Deterministic: the same inputs give the same bytes (a test
# re-runs this into a temporary folder and compares). Usage:
#   bash scripts/derive-knee-fem.sh [OUT_DIR]     (default scenes/knee_fem)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
HAPSIM="${HAPSIM:-${ROOT}/build/release/apps/hapsim}"
SRC="${ROOT}/scenes/knee_vhf_small"
OUT="${1:-${ROOT}/scenes/knee_fem}"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
[[ -x "$HAPSIM" ]] || { echo "derive-knee-fem: build hapsim first ($HAPSIM)" >&2; exit 2; }
command -v tetgen >/dev/null || { echo "derive-knee-fem: needs tetgen (apt-get install tetgen)" >&2; exit 2; }
mkdir -p "$OUT"

simplify() {  # INPUT BUDGET OUTPUT
  "$HAPSIM" simplify "$1" --scale 0.001 --target-vertices "$2" --out "$3" | grep hausdorff | sed "s/^/  /"
}

# The bones' nodes: their simplified vertices (a simplification keeps a subset of the vertices,
# so they lie on the bones the scene's rigid bodies use). A PLC needs facets free of
# self-intersection, which the simplified femur is not: its vertices go in as points.
echo "bone points"
for b in "Bone_Femur 350" "Bone_Tibia 350" "Bone_Patella 120" "Bone_Fibula 120"; do
  read -r name budget <<<"$b"
  simplify "$SRC/$name.stl" "$budget" "$WORK/$name.stl"
done

REGIONS=(
  --region "3=$SRC/Tendon_Patellar.stl" --region "4=$SRC/Ligament_MCL.stl"
  --region "5=$SRC/Ligament_LCL.stl" --region "6=$SRC/Ligament_[AP]CL.stl"
  --region "7=$SRC/Cartilage_*.stl" --region "1=$SRC/Muscle_Vastus*.stl"
  --region "2=$SRC/Muscle_*.stl" --default-region 0
)

# name  skin vertices  TetGen switches (q: radius-edge bound)
for level in "knee_20k 500 pq2.0" "knee_80k 1500 pq1.6"; do
  read -r name skin switches <<<"$level"
  echo "$name"
  simplify "$SRC/Skin.stl" "$skin" "$WORK/skin_$name.stl"
  "$HAPSIM" tetrahedralize --outer "$WORK/skin_$name.stl" --points "$WORK/Bone_*.stl" \
    --drop "$SRC/Bone_*.stl" "${REGIONS[@]}" --switches "$switches" --scale 0.001 \
    --out "$OUT/$name" | sed "s/^/  /"
done
sha256sum "$OUT"/knee_*.node "$OUT"/knee_*.ele | sed "s|$OUT/||"
