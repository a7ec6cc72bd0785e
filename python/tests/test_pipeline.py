"""The front end frame by frame on the tiny simulated world: results, local segments, their points
and descriptors, timings; the GIL released while frames are processed."""

import copy
import os
import signal
import threading
import time

import numpy as np
import pytest

import semsegmap as ssm
from conftest import TINY_S1, needs_sim

pytestmark = needs_sim
FRAMES = 25


@pytest.fixture(scope="module")
def eigen_config(config):
    c = copy.deepcopy(config)
    c.descriptor = ssm.DescriptorConfig(kind="eigen")  # in every build, and fast
    return c


@pytest.fixture(scope="module")
def processed(eigen_config):
    ds = ssm.open_dataset(TINY_S1)
    describer = ssm.make_describer(eigen_config.descriptor)
    pipeline = ssm.Pipeline(eigen_config, ds.info, "gt", describer)
    results = [pipeline.process(ds[i]) for i in range(FRAMES)]
    return ds, describer, pipeline, results


def test_frame_results(processed):
    ds, _, _, results = processed
    r = results[-1]
    assert r.frame_index == FRAMES - 1
    np.testing.assert_allclose(r.T_local_base, ds[FRAMES - 1].T_world_base)  # poses "gt"
    assert r.points > 0 and 0 < r.colored_points <= r.points
    assert r.points_inserted + r.points_filtered <= r.points
    assert sum(x.described for x in results) > 0
    assert sum(x.newly_active_voxels for x in results) > 0
    for x in results:
        assert x.finished_descriptors.shape[0] == len(x.finished)
        assert all(isinstance(a, int) and isinstance(b, int) for a, b in x.merges)
        assert all(isinstance(i, int) for i in x.dropped)


def test_timings(processed):
    t = processed[3][-1].times
    assert t.enrich_ms > 0 and t.local_map_ms > 0 and t.segment_ms >= 0
    assert t.total_ms == pytest.approx(
        t.enrich_ms + t.local_map_ms + t.segment_ms + t.describe_ms + t.localize_ms)


def test_local_segments_as_arrays(processed):
    _, describer, pipeline, _ = processed
    s = pipeline.local_segments()
    m = len(s)
    assert m > 0
    assert s.ids.dtype == np.int64 and (np.diff(s.ids) > 0).all(), "ascending ids"
    assert s.centroids.dtype == np.float32 and s.centroids.shape == (m, 3)
    assert s.classes.dtype == np.uint16 and s.n_points.dtype == np.uint32
    assert s.descriptors.shape == (m, describer.dimension) and s.frame_indices.max() < FRAMES
    assert (s.n_points >= 100).all()  # min_segment_points


def test_segment_points_are_what_was_described(processed):
    _, describer, pipeline, _ = processed
    s = pipeline.local_segments()
    for row in range(min(3, len(s))):
        points = pipeline.segment_points(int(s.ids[row]))
        assert points.dtype == ssm.ENRICHED_POINT_DTYPE and len(points) == s.n_points[row]
        xyz = np.stack([points["x"], points["y"], points["z"]], axis=1)
        np.testing.assert_allclose(xyz.mean(axis=0), s.centroids[row], atol=1e-3)
        again = describer.describe([points])[0]
        np.testing.assert_allclose(again, s.descriptors[row], rtol=1e-4, atol=1e-5)
    with pytest.raises(IndexError, match="segment -5 is not in the local segment map"):
        pipeline.segment_points(-5)


def test_enrich_frame(processed):
    ds = processed[0]
    f = ds[0]
    cloud = ssm.enrich_frame(f, ds.info.rig)
    assert cloud.dtype == ssm.ENRICHED_POINT_DTYPE and len(cloud) == len(f.points)
    np.testing.assert_allclose(cloud["x"], f.points[:, 0])
    assert cloud["has_color"].any()
    with pytest.raises(ValueError):  # the frame's images do not match this rig
        ssm.enrich_frame(f, ssm.SensorRig(cameras=ssm.CameraList([ssm.Camera()])))


def test_finish_hands_out_what_is_left(eigen_config):
    ds = ssm.open_dataset(TINY_S1 + ",frames=8")
    d = ssm.make_describer(eigen_config.descriptor)
    p = ssm.Pipeline(eigen_config, ds.info, describer=d)
    for f in ds:
        p.process(f)
    segments, descriptors = p.finish()
    assert len(segments) > 0 and descriptors.shape == (len(segments), d.dimension)
    last = segments[0].last
    assert last.points.dtype == ssm.ENRICHED_POINT_DTYPE and last.centroid.shape == (3,)
    assert len(p.local_segments()) == 0


def test_a_mapping_session_frame_by_frame_is_run_mapping(eigen_config):
    ds = ssm.open_dataset(TINY_S1 + ",frames=8")
    d = ssm.make_describer(eigen_config.descriptor)
    session = ssm.MappingSession(eigen_config, ds.info, d)  # gt poses, as run_mapping's
    for f in ds:
        session.process(f)
    by_frame = session.finish()
    whole = ssm.run_mapping(ds, eigen_config, d)
    assert (len(by_frame.map), by_frame.segments, by_frame.stats.frames) == (
        len(whole.map), whole.segments, 8)
    np.testing.assert_array_equal(by_frame.map.descriptors, whole.map.descriptors)
    np.testing.assert_array_equal(by_frame.trajectory, whole.trajectory)


def test_frames_made_from_numpy_go_through_the_pipeline_alike(eigen_config):
    """What any Python loader gives: arrays and a rig, here copied out of simulated frames."""
    ds = ssm.open_dataset(TINY_S1 + ",frames=10")
    info = ssm.DatasetInfo(name="from numpy", rig=ds.info.rig, has_ground_truth_poses=True,
                           has_odometry=True, has_point_labels=True,
                           first_transient_instance=ds.info.first_transient_instance)
    d = ssm.make_describer(eigen_config.descriptor)
    theirs = ssm.Pipeline(eigen_config, ds.info, "gt", d)
    ours = ssm.Pipeline(eigen_config, info, "gt", d)
    for f in ds:
        mine = ssm.Frame(np.array(f.points), point_labels=np.array(f.point_labels),
                         images=[np.array(i) for i in f.images],
                         label_images=[np.array(i) for i in f.label_images],
                         T_odom_base=f.T_odom_base, T_world_base=f.T_world_base, index=f.index,
                         timestamp_s=f.timestamp_s)
        a, b = theirs.process(f), ours.process(mine)
        assert (a.points, a.colored_points, a.described) == (
            b.points, b.colored_points, b.described)
    assert len(ours.local_segments()) > 0
    np.testing.assert_array_equal(theirs.local_segments().ids, ours.local_segments().ids)
    np.testing.assert_array_equal(theirs.local_segments().descriptors,
                                  ours.local_segments().descriptors)


def test_pose_source_errors(eigen_config):
    info = ssm.DatasetInfo(name="no poses")
    with pytest.raises(ValueError, match="unknown pose source 'slam' \\(expected gt or odom\\)"):
        ssm.Pipeline(eigen_config, info, "slam")
    with pytest.raises(ValueError, match="describer: required"):
        ssm.MappingSession(eigen_config, info, None)


def test_processing_releases_the_gil(eigen_config):
    """Another Python thread runs while frames are processed."""
    ds = ssm.open_dataset(TINY_S1)
    d = ssm.make_describer(eigen_config.descriptor)
    done = {}
    worker = threading.Thread(
        target=lambda: done.update(run=ssm.run_mapping(ds, eigen_config, d, max_frames=8)))
    ticks = 0
    start = time.monotonic()
    worker.start()
    while worker.is_alive():
        time.sleep(0.005)
        ticks += 1
    seconds = time.monotonic() - start
    worker.join()
    assert done["run"].stats.frames == 8
    # Holding the GIL would stall this loop for the whole run (a tick or two).
    assert ticks > 0.1 * seconds / 0.005, (ticks, seconds)


def test_a_stop_flag_ends_a_run_between_frames(eigen_config):
    """StopFlag.set() from another thread ends the run after the frame in hand: the result holds
    the frames done, marked interrupted."""
    ds = ssm.open_dataset(TINY_S1)
    d = ssm.make_describer(eigen_config.descriptor)
    stop = ssm.StopFlag()
    assert not stop.is_set
    done = {}
    worker = threading.Thread(target=lambda: done.update(
        run=ssm.run_mapping(ds, eigen_config, d, max_frames=200, stop=stop)))
    worker.start()
    time.sleep(0.5)
    stop.set()
    worker.join()
    stats = done["run"].stats
    assert stats.interrupted and 0 < stats.frames < 200, stats
    assert len(done["run"].trajectory) == stats.frames

    # Set before the run: no frame starts. clear() makes the flag serve another run.
    map_ = ssm.run_mapping(ds, eigen_config, d, max_frames=3).map
    run = ssm.run_localization(ds, eigen_config, map_, d, max_frames=3, stop=stop)
    assert run.stats.interrupted and run.stats.frames == 0
    stop.clear()
    run = ssm.run_localization(ds, eigen_config, map_, d, max_frames=3, stop=stop)
    assert not run.stats.interrupted and run.stats.frames == 3


def test_ctrl_c_ends_a_run_between_frames_with_keyboard_interrupt(eigen_config):
    """SIGINT during a run raises KeyboardInterrupt once the frame in hand is done, not after the
    last frame."""
    ds = ssm.open_dataset(TINY_S1)
    d = ssm.make_describer(eigen_config.descriptor)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        ssm.run_mapping(ds, eigen_config, d, max_frames=200)
    timer.join()
    whole = time.monotonic()
    ssm.run_mapping(ds, eigen_config, d, max_frames=200)
    # Stopped well before the whole run's time.
    assert whole - start < 0.5 * (time.monotonic() - whole)
