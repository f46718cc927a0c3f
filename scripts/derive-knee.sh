#!/usr/bin/env bash
# Derives scenes/knee_vhf_small/ (the default knee, scenes/knee_paper.json) from the Visible Human Female
# left knee in ../shared/data/knee_vhf_left/stl (CC BY 4.0, Andreassen et al., Scientific Data 10
# (2023)): the parts a surgeon palpates, cut to the knee region, simplified to the knee paper's
# budget (~13.5k vertices over all parts), a modelled femur and patellar tendon (CSG, the data has
# neither), and a skin 5 mm over everything. Every step is a hapsim command; the meshes it writes
# are committed, so the scene needs no ../shared. Usage: bash scripts/derive-knee.sh [DATA_DIR]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SRC="${1:-${ROOT}/../shared/data/knee_vhf_left}/stl"
HAPSIM="${HAPSIM:-${ROOT}/build/release/apps/hapsim}"
OUT="${ROOT}/scenes/knee_vhf_small"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
[[ -d "$SRC" ]] || { echo "derive-knee: no source meshes in $SRC" >&2; exit 2; }
[[ -x "$HAPSIM" ]] || { echo "derive-knee: build hapsim first ($HAPSIM)" >&2; exit 2; }
mkdir -p "$OUT"
rm -f "$OUT"/*.stl

# The knee region, millimetres in the Visible Human frame (z up, joint line at z ~ 488): 110 mm
# below to 130 mm above; x and y are not cut.
CROP=(--crop-min 0,0,380 --crop-max 1000,1000,620)
SKIN_CROP=(--crop-min 0,0,376 --crop-max 1000,1000,624)

# part  vertex budget  cut (yes: polygonised inside the region first, 0.8 mm cells)
PARTS=(
  "Bone_Tibia 1200 yes" "Bone_Fibula 400 yes" "Bone_Patella 300 no"
  "Cartilage_FemurDistal 600 no" "Cartilage_Patella 200 no"
  "Cartilage_TibiaLateral 150 no" "Cartilage_TibiaMedial 150 no"
  "Ligament_MCL 200 no" "Ligament_LCL 150 no" "Ligament_ACL 120 no" "Ligament_PCL 120 no"
  "Muscle_VastusMedialis 700 yes" "Muscle_VastusLateralis 700 yes"
  "Muscle_VastusIntermedius 500 yes" "Muscle_BicepsFemorisLong 350 yes"
  "Muscle_BicepsFemorisShort 350 yes" "Muscle_Semitendinosus 250 yes"
  "Muscle_Semimembranosus 400 yes" "Muscle_Gracilis 200 yes" "Muscle_Sartorius 300 yes"
  "Muscle_GastrocnemiusMedial 600 yes" "Muscle_GastrocnemiusLateral 500 yes"
  "Muscle_TibialisAnterior 400 yes" "Muscle_PeroneusLongus 350 yes"
)
# Dropped: rectus femoris (above the region), soleus, popliteus, plantaris (deep, not palpated).

simplify() {  # NAME INPUT BUDGET
  "$HAPSIM" simplify "$2" --scale 0.001 --target-vertices "$3" --out "$OUT/$1.stl" \
    --json "$WORK/$1.json" | sed "s/^/  /"
}

for spec in "${PARTS[@]}"; do
  read -r name budget cut <<<"$spec"
  echo "$name"
  input="$SRC/VHF_Left_${name}_smooth.stl"
  if [[ "$cut" == yes ]]; then
    "$HAPSIM" polygonize --mesh "$input" --scale 0.001 "${CROP[@]}" --cell-m 0.0008 \
      --out "$WORK/$name.stl" | sed "s/^/  /"
    input="$WORK/$name.stl"
  fi
  simplify "$name" "$input" "$budget"
done

# Modelled parts (CSG, metres, in the same frame): the distal femur (two condyles fitted inside
# the distal femoral cartilage, a trochlea, the metaphysis and the shaft) and the patellar tendon
# (patella's apex to the tibial tuberosity).
for modelled in "Bone_Femur femur 1000" "Tendon_Patellar patellar_tendon 200"; do
  read -r name file budget <<<"$modelled"
  echo "$name (modelled: scripts/knee/$file.csg.json)"
  "$HAPSIM" polygonize --csg "${ROOT}/scripts/knee/$file.csg.json" --scale 0.001 "${CROP[@]}" \
    --cell-m 0.0008 --out "$WORK/$name.stl" | sed "s/^/  /"
  simplify "$name" "$WORK/$name.stl" "$budget"
done

# The skin: a morphological closing of all parts (their exact signed distances): grown by 12 mm,
# then the result shrunk by 7 mm, so it lies 5 mm over everything and bridges the gaps between
# muscles (a plain 5 mm offset leaves tunnels); cut 4 mm beyond the parts' cut.
echo "Skin"
meshes=()
for f in "$OUT"/*.stl; do meshes+=(--mesh "$f"); done
"$HAPSIM" polygonize "${meshes[@]}" --scale 0.001 --offset-m 0.012 --cell-m 0.002 \
  --out "$WORK/grown.stl" | sed "s/^/  /"
"$HAPSIM" polygonize --mesh "$WORK/grown.stl" --scale 0.001 --offset-m -0.007 "${SKIN_CROP[@]}" \
  --cell-m 0.0015 --out "$WORK/Skin.stl" | sed "s/^/  /"
simplify Skin "$WORK/Skin.stl" 3000

# The table in ATTRIBUTION.md: vertices and the Hausdorff distance each simplification caused.
python3 - "$WORK" <<'EOF'
import json, pathlib, sys
rows = sorted(pathlib.Path(sys.argv[1]).glob("*.json"))
total = 0
print("| part | source vertices | vertices | triangles | Hausdorff (mm) | bound (mm) |")
print("|---|---:|---:|---:|---:|---:|")
for p in rows:
    j = json.loads(p.read_text())
    total += j["vertices"]
    print(f"| {p.stem} | {j['source_vertices']} | {j['vertices']} | {j['triangles']} | "
          f"{j['hausdorff_m'] * 1e3:.3f} | {j['hausdorff_bound_m'] * 1e3:.3f} |")
print(f"| **all {len(rows)} parts** | | **{total}** | | | |")
EOF
