#!/usr/bin/env bash
# Installs every Debian package that the build, the tests and the demo need.
# Idempotent: when everything is present it returns without touching apt.
set -euo pipefail

packages=(
  build-essential cmake pkg-config clang-format
  # keeps compiler output between the builds of one machine (CMakeLists.txt); never required
  ccache
  libeigen3-dev libembree-dev libtbb-dev libyaml-cpp-dev libopencv-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libtorch-dev libonnx-dev libpcl-dev libqhull-dev libfaiss-dev libceres-dev
  libopenblas0-openmp
  nlohmann-json3-dev
  libsqlite3-dev libfastcdr-dev libzstd-dev liblz4-dev
  librosbag-storage-dev libstd-msgs-dev libgeometry-msgs-dev libsensor-msgs-dev libnav-msgs-dev
  libtf2-msgs-dev
  # the ROS 1 node (ros/, SEMSEGMAP_WITH_ROS1_NODE) and its live test: a master, roslaunch,
  # rosbag play and record, rostopic
  libroscpp-dev libtf2-ros-dev libtopic-tools-dev libdiagnostic-msgs-dev libstd-srvs-dev
  libvisualization-msgs-dev
  python3-rosmaster python3-roslaunch python3-rosbag python3-rostopic python3-std-srvs rosout
  gnuplot-nox
  # the map store (store/pg_map_store.h): libpq to build; the server and PostGIS for its tests,
  # which start a throwaway cluster of their own (tests/pg_cluster.h)
  libpq-dev postgresql postgresql-15-postgis-3
  # the tests and the benchmark generate their small ONNX segmentation networks with it
  python3-onnx python3-numpy
  # the Python module (python/, SEMSEGMAP_WITH_PYTHON) and its pytest suite, for Debian's python3
  pybind11-dev python3-dev python3-pytest
  # make fuzz: the parsers' libFuzzer harnesses are built by clang with its fuzzer and sanitizer
  # runtimes (fuzz/, cmake/SemsegmapFuzz.cmake)
  clang libclang-rt-14-dev
  # make bench only: the odometry benchmark compares Open3D's registration (optional in CMake)
  libopen3d-dev
  # semsegmap view: its page is bundled with Node.js at build time (viewer/, npm ci), and its
  # test opens the page in headless Chromium
  nodejs chromium
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# Debian's nodejs comes without npm; a Node.js that brings its own (NodeSource's) conflicts with it.
command -v npm > /dev/null || missing+=(npm)
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -q
  "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# The viewer's npm packages (three.js, esbuild, playwright-core for its browser test) from the
# committed lockfile into viewer/node_modules, here and not in the build, which downloads nothing.
# Again only when the lockfile is newer than the last install.
viewer="$(dirname "$0")/../viewer"
stamp="$viewer/node_modules/.package-lock.json"
if [ ! -f "$stamp" ] || [ "$viewer/package-lock.json" -nt "$stamp" ]; then
  echo "setup: npm ci in viewer/"
  (cd "$viewer" && npm ci --no-audit --no-fund --loglevel=error)
fi
