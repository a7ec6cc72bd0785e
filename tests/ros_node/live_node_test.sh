#!/usr/bin/env bash
# The ROS 1 node live ([live]): a bag written from the shared KITTI raw sample is played by
# `rosbag play` at a quarter of real time to semsegmap_node, started by the documented launch
# file against a map built offline from the same bag, with no odometry topic (the node runs
# LiDAR odometry and says so). rosbag record keeps what it publishes; check_live_node.py compares
# it with the offline `localize` on the same bag. Exit 77 (ctest's skip) without the sample or
# ROS. Arguments: the build folder, the source folder, the shared data folder.
set -euo pipefail
build=$(realpath "$1"); source_dir=$(realpath "$2"); shared=$3
sample=$shared/kitti_raw_2011_09_26_sample/2011_09_26/sample_sync
[ -d "$sample" ] || { echo "SKIP: the real KITTI raw sample ($sample) is absent"; exit 77; }
for tool in rosmaster roslaunch rosbag; do
  command -v "$tool" > /dev/null || { echo "SKIP: no $tool (scripts/setup.sh installs ROS 1)"; exit 77; }
done
tmp=$(mktemp -d)
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -INT "$pid" 2> /dev/null || true; done
  sleep 1
  for pid in "${pids[@]}"; do kill -KILL "$pid" 2> /dev/null || true; done
  rm -rf "$tmp"
}
trap cleanup EXIT
# A master of its own on a free port, logs and ROS_HOME in the scratch folder.
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://localhost:$port ROS_HOME=$tmp/ros ROS_LOG_DIR=$tmp/log
export ROS_PACKAGE_PATH=$build/ros
config=$source_dir/config/lidar-camera.yaml

"$build/tests/ros_node/bag_from_dataset" "kitti-raw:$sample" "$tmp/kitti.bag"
"$build/semsegmap" map --dataset "rosbag:$tmp/kitti.bag" --odometry lidar --config "$config" \
  --out "$tmp/kitti.map"
"$build/semsegmap" localize --dataset "rosbag:$tmp/kitti.bag" --odometry lidar --config "$config" \
  --map "$tmp/kitti.map" --out "$tmp/offline"

rosmaster --core -p "$port" > "$tmp/master.log" 2>&1 &
pids+=($!)
disown  # killed at the end without the shell's "Killed" line
for _ in $(seq 100); do rostopic list > /dev/null 2>&1 && break; sleep 0.1; done
rosbag record -O "$tmp/published.bag" /tf /semsegmap/pose /semsegmap/matches /diagnostics > "$tmp/record.log" 2>&1 &
record=$!
pids+=($record)
roslaunch semsegmap semsegmap.launch config:="$config" map:="$tmp/kitti.map" \
  lidar_topic:=/points camera_topics:="[/camera_0/image_raw]" > "$tmp/node.log" 2>&1 &
node=$!
pids+=($node)
# Every topic the node subscribes to has it before the first message goes out.
rosbag play --quiet --wait-for-subscribers -r 0.25 "$tmp/kitti.bag"
sleep 2
kill -INT "$node"
wait "$node" || true
kill -INT "$record"
wait "$record" || true
cat "$tmp/node.log"

# Mapping live: the same bag into a map, written at shutdown; the offline `map` of the same bag
# is the same file, byte for byte (the same frames, poses and settings).
roslaunch semsegmap semsegmap.launch config:="$config" map:="$tmp/live.map" mode:=map \
  lidar_topic:=/points camera_topics:="[/camera_0/image_raw]" > "$tmp/mapper.log" 2>&1 &
mapper=$!
pids+=($mapper)
rosbag play --quiet --wait-for-subscribers -r 0.25 "$tmp/kitti.bag"
sleep 2
# ~save_map while it runs: the segments finished so far, written where the map goes.
/usr/bin/python3 - <<'PY'
import rospy
from std_srvs.srv import Trigger
rospy.wait_for_service("/semsegmap/save_map", 10)
r = rospy.ServiceProxy("/semsegmap/save_map", Trigger)()
print("~save_map:", r.message)
assert r.success and " segments to " in r.message, r.message
PY
test -s "$tmp/live.map"
kill -INT "$mapper"
wait "$mapper" || true
grep "semsegmap: saved the map" "$tmp/mapper.log"
cmp "$tmp/kitti.map" "$tmp/live.map"
echo "the node's live map is the offline map, byte for byte"
# Debian's Python: its rosbag and numpy packages (scripts/setup.sh).
/usr/bin/python3 "$source_dir/tests/ros_node/check_live_node.py" "$tmp/published.bag" \
  "$tmp/offline/localizations.csv" "$tmp/node.log"
