#!/usr/bin/env python3
"""Checks what semsegmap_node published while a bag played (live_node_test.sh) against the
offline `localize` on the same bag:

- the node received every scan and dropped none (its log's last line);
- it localized the frames the offline run localized, each pose within 1 cm and 0.1 degree;
- map -> odom composed with odom -> base_link, as published on /tf at the pose's time, is that
  pose within 1 cm.

It prints the latency the node measured, for the test's log.

    check_live_node.py PUBLISHED.bag OFFLINE/localizations.csv NODE.log
"""
import csv
import re
import sys

import numpy as np
import rosbag


def matrix(t, q):
    """A 4x4 pose from a translation and a quaternion (x, y, z, w)."""
    x, y, z, w = q
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    m = np.eye(4)
    m[:3, :3] = r
    m[:3, 3] = t
    return m


def of_transform(tr):
    return matrix([tr.translation.x, tr.translation.y, tr.translation.z],
                  [tr.rotation.x, tr.rotation.y, tr.rotation.z, tr.rotation.w])


def degrees_between(a, b):
    c = (np.trace(a[:3, :3].T @ b[:3, :3]) - 1) / 2
    return np.degrees(np.arccos(np.clip(c, -1, 1)))


def published(path):
    poses, tf, matches = [], {}, []
    with rosbag.Bag(path) as bag:
        for topic, msg, _ in bag.read_messages(
                topics=["/semsegmap/pose", "/tf", "/semsegmap/matches"]):
            if topic == "/semsegmap/matches":
                matches.append(len(msg.points) // 2)
            elif topic == "/semsegmap/pose":
                p = msg.pose.pose
                poses.append((msg.header.stamp.to_sec(),
                              matrix([p.position.x, p.position.y, p.position.z],
                                     [p.orientation.x, p.orientation.y, p.orientation.z,
                                      p.orientation.w]),
                              np.array(msg.pose.covariance).reshape(6, 6)))
            else:
                for t in msg.transforms:
                    key = (t.header.frame_id, t.child_frame_id, round(t.header.stamp.to_sec(), 6))
                    tf[key] = of_transform(t.transform)
    return poses, tf, matches


def offline(path):
    with open(path, encoding="utf-8") as f:
        return [(float(r["timestamp"]),
                 matrix([float(r["x"]), float(r["y"]), float(r["z"])],
                        [float(r["qx"]), float(r["qy"]), float(r["qz"]), float(r["qw"])]),
                 np.array([float(r[f"sigma_{a}_m"]) for a in "xyz"]))
                for r in csv.DictReader(f) if r["x"]]


def main():
    bag, csv_path, log_path = sys.argv[1:4]
    with open(log_path, encoding="utf-8") as f:
        log = f.read()
    m = re.search(r"received (\d+) scans, (\d+) worked on, (\d+) dropped.*latency ([\d.]+) ms on "
                  r"average, ([\d.]+) at most", log)
    assert m, "the node's log has no summary line"
    scans, worked, dropped = int(m[1]), int(m[2]), int(m[3])
    print(f"node: {scans} scans received, {worked} worked on, {dropped} dropped; latency "
          f"{m[4]} ms on average, {m[5]} ms at most (a scan's arrival to its pose)")
    assert "LiDAR odometry on the scans" in log, "the node did not say it runs LiDAR odometry"
    assert (scans, worked, dropped) == (10, 10, 0), "every scan of the bag, none dropped"
    poses, tf, matches = published(bag)
    expected = offline(csv_path)
    print(f"localized: {len(poses)} live, {len(expected)} offline")
    assert len(expected) > 0, "the offline run localized nothing to compare with"
    assert len(poses) == len(expected), "as many localizations as the offline run"
    for (t, live, covariance), (t_off, off, sigmas) in zip(poses, expected):
        # The pose's own covariance, each variance at least the node's floor (0.1 m by default).
        assert np.all(np.isfinite(covariance)), f"covariance at {t}"
        np.testing.assert_allclose(np.sqrt(np.diag(covariance)[:3]), np.maximum(sigmas, 0.1),
                                   rtol=1e-3, atol=1e-4, err_msg=f"covariance at {t}")
        assert abs(t - t_off) < 1e-4, f"pose at {t}, offline at {t_off}"
        assert np.linalg.norm(live[:3, 3] - off[:3, 3]) < 0.01, f"pose at {t} off the offline one"
        assert degrees_between(live, off) < 0.1, f"pose at {t} turned from the offline one"
        key = round(t, 6)
        map_odom, odom_base = tf.get(("map", "odom", key)), tf.get(("odom", "base_link", key))
        assert map_odom is not None and odom_base is not None, f"no map -> odom -> base at {t}"
        composed = map_odom @ odom_base
        assert np.linalg.norm(composed[:3, 3] - off[:3, 3]) < 0.01, f"map -> base at {t}"
    # For RViz: each localization's matched segments, a line from each local one to its target.
    assert len(matches) == len(poses) and min(matches) >= 3, f"matches markers {matches}"
    print("ok: every live pose within 1 cm of the offline one, and map -> odom -> base_link too; "
          f"{sum(matches)} matched segments drawn for RViz")


if __name__ == "__main__":
    main()
