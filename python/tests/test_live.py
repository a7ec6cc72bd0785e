"""The live session from Python: a robot's program hands in scans, pictures and odometry as its
drivers publish them and polls the poses; never dropping, it gives the offline run's poses."""

import copy

import numpy as np
import pytest

import semsegmap as ssm
from conftest import TINY_S2, needs_sim, one_line

pytestmark = needs_sim
QUERY = TINY_S2 + ",frames=40,condition=sunrise"


@pytest.fixture(scope="module")
def mapped(config):
    c = copy.deepcopy(config)
    c.descriptor = ssm.DescriptorConfig(kind="eigen")
    d = ssm.make_describer(c.descriptor)
    run = ssm.run_mapping(ssm.open_dataset(TINY_S2 + ",frames=40"), c, d)
    return c, d, run.map


def feed(live, ds):
    for f in ds:
        live.add_odometry(f.timestamp_s, f.T_odom_base)
        live.add_scan(f.timestamp_s, f.points)
        for k, (rgb, labels) in enumerate(zip(f.images, f.label_images)):
            live.add_picture(k, f.timestamp_s + 0.01, rgb, labels)


def test_never_dropping_it_gives_the_offline_poses(mapped):
    c, d, target = mapped
    ds = ssm.open_dataset(QUERY)
    offline = ssm.run_localization(ds, c, target, d)
    assert len(offline.localizations) > 3
    live = ssm.LiveSession(c, ds.info, target, d, never_drop=True)
    feed(live, ds)
    live.finish()
    poses = live.poll()
    assert [p.record.frame_index for p in poses] == [
        r.frame_index for r in offline.localizations]
    for p, r in zip(poses, offline.localizations):
        np.testing.assert_allclose(p.record.T_map_base, r.T_map_base, atol=1e-9)
        np.testing.assert_allclose(p.T_map_odom @ p.T_odom_base, r.T_map_base, atol=1e-9)
        assert p.latency_ms > 0
    s = live.stats
    assert (s.scans, s.frames, s.processed, s.dropped) == (40, 40, 40, 0)
    assert s.localized == len(poses) and live.poll() == []


def test_messages_it_cannot_use_are_refused(mapped):
    c, d, target = mapped
    ds = ssm.open_dataset(QUERY)
    live = ssm.LiveSession(c, ds.info, target, d)
    cameras = len(ds.info.rig.cameras)
    with pytest.raises(ValueError) as e:
        live.add_picture(cameras, 0.0, np.zeros((4, 4, 3), np.uint8))
    assert f"the rig has {cameras} camera(s)" in one_line(e.value)
    with pytest.raises(ValueError):
        live.add_picture(0, 0.0, np.zeros((4, 4), np.uint8))  # labels given as colour
    with pytest.raises(ValueError):
        live.add_odometry(0.0, np.eye(3))
    live.finish()
    with pytest.raises(Exception):
        live.finish()
