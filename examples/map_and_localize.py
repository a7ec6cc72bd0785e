#!/usr/bin/env python3
"""Maps a run and localizes another run against the map, from Python (README, "Python").

    PYTHONPATH=build/python python3 examples/map_and_localize.py
    PYTHONPATH=build/python python3 examples/map_and_localize.py --frames 200 --out s1.map

By default both runs come from the tiny simulated world (S1 maps, S2 drives the same streets
with other traffic); --map-dataset and --query-dataset take any --dataset spec of the command
line. python/tests/test_example.py runs it.
"""

import argparse

import numpy as np

import semsegmap as ssm


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map-dataset", default="sim:world=1,run=S1,preset=tiny")
    parser.add_argument("--query-dataset", default="sim:world=1,run=S2,preset=tiny")
    parser.add_argument("--config", default=ssm.shipped_file("config/semsegmap.yaml"))
    parser.add_argument("--frames", type=int, default=60, help="frames of each run, 0: all")
    parser.add_argument("--out", default="", help="save the target map there")
    args = parser.parse_args()

    ssm.keep_freed_memory_for_torch()  # a program that describes many segments: its own choice
    config = ssm.load_config(args.config)
    mapping = ssm.open_dataset(args.map_dataset)
    describer = ssm.describer_for(config.descriptor, mapping.info)
    built = ssm.run_mapping(mapping, config, describer, max_frames=args.frames)
    print(f"map: {len(built.map)} segments from {built.stats.frames} frames "
          f"({built.stats.fps:.1f} Hz)")
    if args.out:
        print(f"wrote {args.out}, {ssm.save_map(args.out, built.map)} bytes")

    query = ssm.open_dataset(args.query_dataset)
    run = ssm.run_localization(query, config, built.map, describer, max_frames=args.frames)
    s = run.summary()
    print(f"localized {s.localizations} of {run.stats.frames} frames", end="")
    if s.below_1m is not None:  # None: no ground truth measured it
        print(f", {s.below_1m} within 1 m", end="")
    if s.mean_translation_error_m is not None:
        print(f", mean error {s.mean_translation_error_m:.2f} m", end="")
    print()
    if run.localizations:
        last = run.localizations[-1]
        print(f"frame {last.frame_index}: {last.inliers} inliers, T_map_base =")
        print(np.array2string(last.T_map_base, precision=3, suppress_small=True))


if __name__ == "__main__":
    main()
