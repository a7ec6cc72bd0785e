#!/usr/bin/env bash
# cmake --install into a fresh prefix, then configure, build and run a consumer project against
# it with find_package(semsegmap): what a user who installs the library does.
set -euo pipefail
build_dir=$1
source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build_dir" --prefix "$work/prefix" > "$work/install.log"
for f in bin/semsegmap share/semsegmap/config/semsegmap.yaml share/semsegmap/models/MODEL_CARD.md \
         lib/cmake/semsegmap/semsegmapConfig.cmake include/semsegmap/core/frame.h; do
  [ -e "$work/prefix/$f" ] || { echo "install_consumer: $f was not installed"; exit 1; }
done
cmake -S "$source_dir/tests/consumer" -B "$work/build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix" > "$work/configure.log" 2>&1 || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/build" > "$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }
"$work/build/consumer" "$work/map.bin"
"$work/prefix/bin/semsegmap" --version
