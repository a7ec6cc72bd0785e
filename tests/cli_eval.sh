#!/usr/bin/env bash
# The eval commands as a user types them, on the tiny world with a few frames: each writes its
# JSON and pictures, `eval paper` its report, and mistakes exit non-zero with one line.
# Usage: cli_eval.sh SEMSEGMAP_BINARY. It runs in a temporary folder outside the repository: the
# default configs and models must be found wherever the command runs.
set -euo pipefail
bin="$1"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
cd "$out"
fail() { echo "cli_eval: $*" >&2; exit 1; }

"$bin" eval paper --world-seed 1 --preset tiny --max-frames 30 --descriptors eigen \
  --out "$out/paper" > "$out/paper.txt" 2> /dev/null
for f in report.md segmentation.json segmentation.png descriptors.json descriptors.png \
         localization.json localization_accuracy.png maps/semsegmap.map maps/segmap.map \
         semsegmap_S2/localization.png segmap_S3/summary.json; do
  [ -s "$out/paper/$f" ] || fail "eval paper did not write $f"
done
grep -q '"n_localizations"' "$out/paper/localization.json" || fail "localization.json lacks n_localizations"
grep -q '"revisit_segments"' "$out/paper/segmentation.json" || fail "segmentation.json lacks revisit_segments"
grep -q '## Localization' "$out/paper/report.md" || fail "report.md lacks the localization section"
grep -q '| S3 | segmap |' "$out/paper.txt" || fail "eval paper did not print the localization table"

"$bin" eval localization --preset tiny --max-frames 20 --query-runs S2 --out "$out/loc" \
  > /dev/null 2>&1
grep -q '"run": "S2"' "$out/loc/localization.json" || fail "eval localization --query-runs S2"
! grep -q '"run": "S3"' "$out/loc/localization.json" || fail "eval localization ran S3 unasked"

# A rig of the simulator (docs/results.md): one front camera on a 360-degree LiDAR, and the
# results table written from the JSON by scripts/write_results.py into its section.
"$bin" eval localization --preset tiny --max-frames 20 --query-runs S2 \
  --rig lidar=hdl64,cameras=front --out "$out/front" > /dev/null 2>&1
grep -q '"rig": "lidar=hdl64,cameras=front"' "$out/front/localization.json" || fail "eval localization --rig"
grep -q 'run S2 .*' "$out/front/localization.json" || fail "the front-camera run names no dataset"
scripts="$(dirname "$(readlink -f "$0")")/../scripts"
printf 'before\n<!-- results:front -->\nold\n<!-- /results:front -->\nafter\n' > "$out/results.md"
python3 "$scripts/write_results.py" front "front camera=$out/front/localization.json" \
  --doc "$out/results.md" > /dev/null
grep -q '^| front camera | S2 | semsegmap | ' "$out/results.md" || fail "write_results.py wrote no row"
! grep -q '^old$' "$out/results.md" || fail "write_results.py kept the old table"
grep -q '^after$' "$out/results.md" || fail "write_results.py lost the text after the section"
if python3 "$scripts/write_results.py" nosuch "x=$out/front/localization.json" \
    --doc "$out/results.md" 2> "$out/err.txt"; then fail "a missing section was accepted"; fi
grep -q "no section 'nosuch'" "$out/err.txt" || fail "the error does not name the section"

# Mistakes: one line naming what is wrong, non-zero exit.
if "$bin" eval nonsense --out "$out/x" 2> "$out/err.txt"; then fail "eval nonsense succeeded"; fi
grep -q "nonsense" "$out/err.txt" || fail "the error does not name the experiment"
if "$bin" eval localization --preset tiny --configs missing.yaml --out "$out/x" 2> "$out/err.txt"; then
  fail "a missing config succeeded"
fi
grep -q "missing.yaml" "$out/err.txt" || fail "the error does not name the missing config"
echo "cli_eval: ok"
