#!/usr/bin/env python3
"""Why a frame was (not) localized: its local segments that the map holds, and their descriptors.

    PYTHONPATH=build/python python3 examples/segment_overlap.py --map out/revisits/maps/X.map \\
        --dataset semantickitti:kitti_odometry_00_sparse --frames 24:30 \\
        --config config/lidar-camera.yaml

Builds the local map of --frames (one session, as `eval revisits` localizes them) on the
dataset's ground-truth poses, so that the local segments lie where the map's do when the map was
built on the same ground truth (as `eval revisits` builds it). After each frame it counts the
local segments with a map segment whose centroid is within --radius (horizontally: a recorded
ground truth may be off in height) and, of those, how many have that map segment among their k
nearest descriptors, the candidates a localization verifies. A localization needs min_inliers
consistent candidates: fewer counterparts than that means the local map does not yet hold enough
of the place (the segmentation), counterparts that rank beyond k mean the descriptor does not
recognize them. python/tests/test_example.py runs it.
"""

import argparse
import sys

import numpy as np

import semsegmap as ssm


def frame_range(text):
    first, _, last = text.partition(":")
    return range(int(first), int(last or first) + 1)


def overlap(local, map_centroids, map_descriptors, radius):
    """(local segment, nearest map segment, distance, rank of its descriptor) for each local
    segment with a map segment within `radius`."""
    rows = []
    centroids = np.asarray(local.centroids)
    descriptors = np.asarray(local.descriptors)
    for j in range(len(local)):
        horizontal = np.linalg.norm(map_centroids[:, :2] - centroids[j, :2], axis=1)
        near = int(np.argmin(horizontal))
        if horizontal[near] > radius:
            continue
        distance = np.linalg.norm(map_descriptors - descriptors[j], axis=1)
        rows.append((j, near, float(horizontal[near]), int((distance < distance[near]).sum())))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", required=True, help="a target map built on ground-truth poses")
    parser.add_argument("--dataset", required=True, help="a --dataset spec with ground truth")
    parser.add_argument("--frames", required=True, help="A:B, the frames of one local map")
    parser.add_argument("--config", default=ssm.shipped_file("config/semsegmap.yaml"))
    parser.add_argument("--radius", type=float, default=1.5, help="m, default 1.5")
    parser.add_argument("--verbose", action="store_true", help="one line per counterpart")
    args = parser.parse_args()

    config = ssm.load_config(args.config)
    dataset = ssm.open_dataset(args.dataset)
    if not dataset.info.has_ground_truth_poses:
        sys.exit(f"segment_overlap: error: {args.dataset} has no ground-truth poses")
    target = ssm.load_map(args.map)
    describer = ssm.describer_for(config.descriptor, dataset.info)
    ssm.check_map_compatible(target, describer, args.map)
    ssm.check_map_parameters(target, config, args.map)  # the same segmentation, or no overlap
    map_centroids = np.asarray(target.centroids)
    map_descriptors = np.asarray(target.descriptors)
    k = config.localization.localizer.index.k
    needed = config.localization.localizer.verification.min_inliers
    print(f"map: {len(target)} segments; a localization verifies the {k} nearest descriptors "
          f"and needs {needed} consistent")
    pipeline = ssm.Pipeline(config, dataset.info, "gt", describer)
    for index in frame_range(args.frames):
        pipeline.process(dataset[index])
        local = pipeline.local_segments()
        rows = overlap(local, map_centroids, map_descriptors, args.radius)
        among_k = sum(rank < k for _, _, _, rank in rows)
        print(f"frame {index}: {len(local)} local segments, {len(rows)} with a map segment "
              f"within {args.radius:g} m, {among_k} of them among its {k} nearest descriptors")
        if args.verbose:
            for j, near, distance, rank in rows:
                print(f"  local {local.ids[j]} ({local.n_points[j]} points, seen at frame "
                      f"{local.frame_indices[j]}) -> map {near} ({distance:.2f} m, "
                      f"{target.n_points[near]} points): descriptor rank {rank}")


if __name__ == "__main__":
    main()
