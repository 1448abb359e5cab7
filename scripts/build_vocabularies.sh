#!/usr/bin/env bash
# Rebuilds the ORB feature-index vocabulary shipped in config/ (docs/conventions.md; thesis §6.6.3)
# from training images that no evaluation uses: 30 s of the team3_aerial flights rendered over
# a different aerial world (seed 77; scenarios render seed 1 by default), every 5th left image
# of the three UAVs, plus the 95 real EuRoC frames of data/euroc_micro.
#
#   scripts/build_vocabularies.sh [BUILD_DIR]      (default: build)
#
# Deterministic: the renderer and the k-means training are seeded.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
for exe in "$BUILD/sensors_replay/cvslam_simulate" "$BUILD/tools/cvslam_build_vocabulary"; do
  [ -x "$exe" ] || { echo "build_vocabularies: $exe missing: build first" >&2; exit 2; }
done
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
sed 's/^name: team3_aerial/name: vocabulary_training/' config/scenarios/team3_aerial.yaml \
  > "$WORK/scenario.yaml"
printf 'render:\n  world: {kind: aerial, seed: 77}\n' >> "$WORK/scenario.yaml"
"$BUILD/sensors_replay/cvslam_simulate" --scenario "$WORK/scenario.yaml" --out "$WORK/sim" \
  --duration 30 --quiet
mkdir "$WORK/images"
for uav in "$WORK"/sim/uav*; do
  n=$(basename "$uav")
  ls "$uav/mav0/cam0/data" | awk 'NR % 5 == 0' | while read -r f; do
    ln -s "$uav/mav0/cam0/data/$f" "$WORK/images/${n}_$f"
  done
done
for f in data/euroc_micro/mav0/cam0/data/*.png; do
  [ -e "$f" ] && ln -s "$(realpath "$f")" "$WORK/images/euroc_$(basename "$f")"
done
"$BUILD/tools/cvslam_build_vocabulary" --images "$WORK/images" --detector orb \
  --output config/vocabulary_orb.cvoc
