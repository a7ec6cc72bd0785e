#!/usr/bin/env bash
# A descriptor model on a LiDAR without a camera, as models/MODEL_CARD.md measures every
# candidate: map S0 of world seed 1 and localize S2 and S3 against it, rendered by the simulator
# without cameras or classes for each LiDAR preset given, with config/lidar-camera.yaml naming
# MODEL as its descriptor.model_lidar_only (the model every command takes for such input).
# Prints, per LiDAR, the localizations within 1 m and those more than 5 m off.
#   scripts/eval_geometry_only.sh MODEL OUT_DIR LIDAR [LIDAR...]   (LIDAR: hdl64 vlp32 os128 solid paper)
set -euo pipefail
[ $# -ge 3 ] || { sed -n 2,7p "$0"; exit 2; }
model=$(realpath "$1"); out=$2; shift 2
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${SEMSEGMAP:-$root/build/semsegmap}
[ -f "$model" ] || { echo "$model: no such model file" >&2; exit 1; }
mkdir -p "$out"
config=$out/config.yaml
sed -e "s|  model: ../models/|  model: $root/models/|" -e "s|model_lidar_only: .*|model_lidar_only: $model|" \
  "$root/config/lidar-camera.yaml" > "$config"
grep -q "model_lidar_only: $model" "$config" || { echo "$config: could not name the model" >&2; exit 1; }
for lidar in "$@"; do
  sim=sim:world=1,cameras=0,classes=0,lidar=$lidar
  "$bin" map --dataset "$sim,run=S0" --config "$config" --poses gt --out "$out/$lidar.map" > "$out/$lidar.map.log"
  for run in S2 S3; do
    "$bin" localize --dataset "$sim,run=$run" --config "$config" --map "$out/$lidar.map" \
      --out "$out/$lidar-$run" > "$out/$lidar-$run.log"
    python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); print(sys.argv[2], sys.argv[3], "within 1 m:", s["n_error_below_1m"], "of", s["n_localizations"], "localizations,", s["n_localizations"]-s["n_error_below_5m"], "more than 5 m off")' \
      "$out/$lidar-$run/summary.json" "$lidar" "$run"
  done
done
