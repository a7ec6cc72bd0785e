"""The examples of examples/ run as they are documented (with fewer frames)."""

import os
import re
import subprocess
import sys

from conftest import TINY_S1, TINY_S2, needs_sim, needs_torch, run_cli, source_file


@needs_sim
@needs_torch  # the shipped config's describer is learned
def test_map_and_localize_example(tmp_dir):
    out = os.path.join(tmp_dir, "s1.map")
    done = subprocess.run(
        [sys.executable, source_file("examples/map_and_localize.py"), "--frames", "40", "--out",
         out], capture_output=True, text=True, cwd=tmp_dir)
    assert done.returncode == 0, done.stderr
    text = done.stdout
    assert re.search(r"^map: \d+ segments from 40 frames", text, re.M), text
    m = re.search(r"^localized (\d+) of 40 frames, (\d+) within 1 m", text, re.M)
    assert m and int(m.group(1)) > 10, text
    assert "T_map_base =" in text and os.path.getsize(out) > 0


@needs_sim
@needs_torch
def test_segment_overlap_example_finds_the_mapped_segments(tmp_dir, binary):
    """Frames of S2 that drive the streets S1 mapped have local segments the map holds, and
    their descriptors find them."""
    target = os.path.join(tmp_dir, "s1.map")
    run_cli(binary, "map", "--dataset", TINY_S1, "--max-frames", "40", "--config",
            source_file("config/semsegmap.yaml"), "--out", target)
    done = subprocess.run(
        [sys.executable, source_file("examples/segment_overlap.py"), "--map", target,
         "--dataset", TINY_S2, "--frames", "0:39", "--verbose"],
        capture_output=True, text=True, cwd=tmp_dir)
    assert done.returncode == 0, done.stderr
    text = done.stdout
    assert re.search(r"^map: \d+ segments; a localization verifies the 16 nearest descriptors "
                     r"and needs 6 consistent$", text, re.M), text
    rows = re.findall(r"^frame (\d+): (\d+) local segments, (\d+) with a map segment within "
                      r"1.5 m, (\d+) of them among its 16 nearest", text, re.M)
    assert [int(r[0]) for r in rows] == list(range(40)), text
    last = [int(v) for v in rows[-1]]
    assert last[2] >= 6 and last[3] >= 1 and last[3] <= last[2] <= last[1], rows[-1]
    assert re.search(r"^  local \d+ \(\d+ points, seen at frame \d+\) -> map \d+ \([0-9.]+ m, "
                     r"\d+ points\): descriptor rank \d+$", text, re.M), text


def test_segment_overlap_example_refuses_a_dataset_without_ground_truth(tmp_dir):
    """Without ground truth there is nowhere to look for the map's segments: one line, exit 1."""
    scans = os.path.join(tmp_dir, "scans")
    os.makedirs(scans)
    with open(os.path.join(scans, "000000.pcd"), "w") as pcd:
        pcd.write("VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\n"
                  "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n1 0 0\n0 1 0\n0 0 1\n")
    done = subprocess.run(
        [sys.executable, source_file("examples/segment_overlap.py"), "--map", "none.map",
         "--dataset", "folder:" + scans, "--frames", "0", "--config",
         source_file("config/lidar-camera.yaml")],
        capture_output=True, text=True, cwd=tmp_dir)
    assert done.returncode == 1, done.stderr
    assert done.stderr.strip().splitlines()[-1] == (
        f"segment_overlap: error: folder:{scans} has no ground-truth poses"), done.stderr
