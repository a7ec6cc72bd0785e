"""Map a simulated run and localize another from Python, and the command line on the very same
input: the counts and the localizations must be the same. Then a revisit range of the mapped run
localized frame by frame."""

import csv
import os
import re

import numpy as np
import pytest

import semsegmap as ssm
from conftest import TINY_S1, TINY_S2, finish_cli, needs_sim, needs_torch, source_file, start_cli

pytestmark = [needs_sim, needs_torch]  # the shipped config's describer is learned
FRAMES = 60  # S1's first 60 frames are driven again from frame 395 on, and by S2
QUERY_FRAMES = 40
CONFIG = source_file("config/semsegmap.yaml")


@pytest.fixture(scope="module")
def describer(config):
    return ssm.describer_for(config.descriptor, ssm.open_dataset(TINY_S1).info)


@pytest.fixture(scope="module")
def runs(binary, tmp_path_factory, config, describer):
    """Each command beside its Python twin: the module releases the GIL, and each side keeps
    about one core busy. Python localizes against the command line's map: the same input."""
    work = str(tmp_path_factory.mktemp("e2e"))
    cli_map = os.path.join(work, "cli.map")
    mapping = start_cli(binary, "map", "--dataset", TINY_S1, "--config", CONFIG, "--max-frames",
                        str(FRAMES), "--out", cli_map)
    built = ssm.run_mapping(ssm.open_dataset(TINY_S1), config, describer, max_frames=FRAMES)
    map_out = finish_cli(mapping)
    localized = os.path.join(work, "localize")
    localizing = start_cli(binary, "localize", "--dataset", TINY_S2, "--map", cli_map, "--config",
                           CONFIG, "--max-frames", str(QUERY_FRAMES), "--out", localized)
    run = ssm.run_localization(ssm.open_dataset(TINY_S2), config, ssm.load_map(cli_map),
                               describer, max_frames=QUERY_FRAMES)
    localize_out = finish_cli(localizing)
    return dict(work=work, cli_map=cli_map, map_out=map_out, built=built, run=run,
                localize_out=localize_out, csv=os.path.join(localized, "localizations.csv"))


def test_mapping_counts_equal_the_command_lines(runs):
    m = re.search(r"frames (\d+)  segments (\d+) \((\d+) duplicates removed\)  map (\d+) segments, "
                  r"(\d+) bytes", runs["map_out"])
    assert m, runs["map_out"]
    frames, segments, duplicates, map_segments, map_bytes = [int(g) for g in m.groups()]
    built = runs["built"]
    assert built.stats.frames == frames == FRAMES
    assert (built.segments, built.duplicates_removed, len(built.map)) == (
        segments, duplicates, map_segments)
    ours = os.path.join(runs["work"], "python.map")
    assert ssm.save_map(ours, built.map) == map_bytes
    theirs = ssm.load_map(runs["cli_map"])
    np.testing.assert_allclose(ssm.load_map(ours).centroids, theirs.centroids, atol=1e-5)
    np.testing.assert_allclose(ssm.load_map(ours).descriptors, theirs.descriptors, atol=1e-3)
    assert built.trajectory.shape == (FRAMES, 4, 4)


def test_localization_equals_the_command_lines(runs):
    out = runs["localize_out"]
    m = re.search(r"frames (\d+)  localizations (\d+)  <1 m (\d+)  <5 m (\d+)", out)
    assert m, out
    run = runs["run"]
    s = run.summary()
    assert [run.stats.frames, s.localizations, s.below_1m, s.below_5m] == [
        int(g) for g in m.groups()]
    assert s.localizations > QUERY_FRAMES // 2
    with open(runs["csv"]) as f:
        rows = list(csv.DictReader(f))
    assert [int(r["frame"]) for r in rows] == [l.frame_index for l in run.localizations]
    assert [int(r["inliers"]) for r in rows] == [l.inliers for l in run.localizations]
    for r, l in zip(rows, run.localizations):
        np.testing.assert_allclose([float(r[k]) for k in "xyz"], l.T_map_base[:3, 3], atol=2e-4)
    first = run.localizations[0]
    assert first.T_map_base.shape == (4, 4) and first.T_world_base.shape == (4, 4)
    assert first.matches.shape == (first.inliers, 2, 3) and first.matches.dtype == np.float32
    assert run.trajectory_gt.shape == (QUERY_FRAMES, 4, 4) and run.distance_m > 0


def test_a_session_refuses_a_map_built_with_other_settings(config, describer, runs):
    ds = ssm.open_dataset(TINY_S1)
    other = ssm.load_config(CONFIG)  # a copy: `config` is shared by the module's tests
    other.segmentation.d_segment_m = config.segmentation.d_segment_m + 0.2
    with pytest.raises(RuntimeError) as e:
        ssm.LocalizationSession(other, ds.info, runs["built"].map, describer)
    assert "segmentation.d_segment_m: the map was built with" in str(e.value)
    allowed = ssm.LocalizationSession(other, ds.info, runs["built"].map, describer,
                                      allow_config_mismatch=True)
    assert allowed.run.localizations == []


def test_a_revisit_range_localized_frame_by_frame(config, describer, runs):
    ds = ssm.open_dataset(TINY_S1)
    session = ssm.LocalizationSession(config, ds.info, runs["built"].map, describer)
    records = [r for r in (session.process(ds[i]) for i in range(395, 426)) if r is not None]
    assert len(records) >= 5  # once its local map holds enough segments
    assert all(395 <= r.frame_index <= 425 for r in records)
    assert max(r.translation_error_m for r in records) < 5.0  # none wrong
    assert [r.frame_index for r in session.run.localizations] == [r.frame_index for r in records]


def test_one_scan_is_relocalized_by_the_command_line_and_python_alike(binary, tmp_path):
    """localize --relocalize on a run's first scan, and LocalizationSession.relocalize on the
    same scan, as a Frame and as arrays. The whole-map query is made to fail (min_inliers 1000)
    so that the pose comes from the relocalization path."""
    text = open(CONFIG).read()
    assert "      min_inliers: 6" in text
    config_path = str(tmp_path / "strict.yaml")
    with open(config_path, "w") as f:
        f.write(text.replace("      min_inliers: 6", "      min_inliers: 1000", 1))
    dense = str(tmp_path / "dense.map")
    finish_cli(start_cli(binary, "map", "--dataset", TINY_S1, "--config", config_path,
                         "--max-frames", str(FRAMES), "--points", "512", "--out", dense))
    out = str(tmp_path / "loc")
    finish_cli(start_cli(binary, "localize", "--dataset", TINY_S2, "--map", dense, "--config",
                         config_path, "--max-frames", "1", "--relocalize", "--out", out))
    with open(os.path.join(out, "localizations.csv")) as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 1 and rows[0]["path"] == "relocalization", rows

    config = ssm.load_config(config_path)
    assert not config.localization.relocalization.enabled  # the call relocalizes regardless
    ds = ssm.open_dataset(TINY_S2)
    session = ssm.LocalizationSession(config, ds.info, ssm.load_map(dense),
                                      ssm.describer_for(config.descriptor, ds.info))
    frame = ds[0]
    record = session.relocalize(frame)
    assert record is not None and record.path == "relocalization"
    np.testing.assert_allclose([float(rows[0][k]) for k in "xyz"], record.T_map_base[:3, 3],
                               atol=2e-4)
    assert record.registration_fitness == pytest.approx(float(rows[0]["fitness"]), abs=1e-3)
    # Its covariance, from the registration's evidence, as the command line wrote it.
    assert record.status == "localized" and rows[0]["status"] == "localized"
    assert record.covariance.shape == (6, 6) and np.all(np.isfinite(record.covariance))
    np.testing.assert_allclose(record.covariance, record.covariance.T)
    sigmas = np.sqrt(np.diag(record.covariance))
    np.testing.assert_allclose(sigmas[:3], [float(rows[0][f"sigma_{a}_m"]) for a in "xyz"],
                               rtol=1e-3, atol=1e-4)
    assert sigmas[0] >= config.localization.covariance.min_sigma_m
    assert session.run.localizations == []
    assert record.translation_error_m < 0.3
    # The scan as arrays: its own frame is the local map's (no odometry, no ground truth), so its
    # voxels fall otherwise; the same place.
    arrays = session.relocalize(frame.points, frame.images, label_images=frame.label_images)
    assert arrays is not None and arrays.translation_error_m is None
    assert np.linalg.norm(arrays.T_map_base[:3, 3] - frame.T_world_base[:3, 3]) < 0.3
    far = record.T_map_base[:2, 3] + 500.0
    assert session.relocalize(frame, prior=(far[0], far[1], 50.0)) is None
    with pytest.raises(ValueError, match="prior: expected"):
        session.relocalize(frame, prior=(1.0,))


def test_a_lost_robot_gives_no_pose_its_scan_does_not_register_to(describer):
    """The whole-map query made loose (two inliers): a wake-up's first scan then matches the map
    at wrong places. While the robot is lost, with relocalization on, a pose of any path must
    pass the registration check, which refuses them."""
    config = ssm.load_config(CONFIG)
    config.target_map.max_points_per_segment = 512
    built = ssm.run_mapping(ssm.open_dataset(TINY_S1), config, describer, max_frames=80)
    config.localization.localizer.verification.min_inliers = 2
    ds = ssm.open_dataset(TINY_S2)

    def first_errors(relocalize):
        config.localization.relocalization.enabled = relocalize
        errors = []
        for i in (14, 42, 49):
            r = ssm.LocalizationSession(config, ds.info, built.map, describer).process(ds[i])
            errors.append(None if r is None else r.translation_error_m)
        return errors

    off = first_errors(False)
    assert sum(e is not None and e > 5 for e in off) >= 2, off
    on = first_errors(True)
    assert all(e is None or e < 1 for e in on), on
    assert any(e is not None for e in on), on
