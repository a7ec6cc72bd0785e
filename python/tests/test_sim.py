"""The simulator: frames rendered on demand, with the sim: spec's keys as keywords."""

import numpy as np
import pytest

import semsegmap as ssm
from conftest import TINY_S1, needs_sim

pytestmark = needs_sim


def test_a_rendered_frame_is_the_specs():
    sim = ssm.Simulator(world=1, run="S1", preset="tiny", frames=3)
    assert isinstance(sim, ssm.Dataset) and len(sim) == 3
    f = sim[2]
    same = ssm.open_dataset(TINY_S1 + ",frames=3")[2]
    np.testing.assert_array_equal(f.points, same.points)
    np.testing.assert_array_equal(f.images[1], same.images[1])
    traj = sim.trajectory_world
    assert traj.shape[1:] == (4, 4) and len(traj) >= 3 and sim.length_m > 0
    np.testing.assert_allclose(f.T_world_base, traj[2])
    np.testing.assert_allclose(f.T_odom_base, sim.trajectory_odom[2])
    assert sim.traffic_seed == 2  # the run's own: S1 + 1


def test_a_rig_of_ones_own():
    rig = ssm.default_sim_rig()
    front = rig.cameras[1]
    front.width, front.height, front.fx, front.fy, front.cx, front.cy = 160, 120, 80, 80, 80, 60
    rig.cameras = ssm.CameraList([front])
    rig.lidar.rows = 16
    sim = ssm.Simulator(world=1, run="S2", preset="tiny", frames=1, rig=rig, traffic=7)
    f = sim[0]
    assert [im.shape for im in f.images] == [(120, 160, 3)]
    assert len(sim.info.rig.cameras) == 1 and sim.traffic_seed == 7
    assert ssm.Simulator(preset="tiny", frames=1, cameras=False)[0].images == []


@pytest.mark.parametrize("kwargs, message", [
    ({"run": "S9"}, r"unknown run 'S9' \(expected S0, S1, S2 or S3\)"),
    ({"label_noise": 7}, "label"),
    ({"preset": "huge"}, "huge"),
])
def test_simulator_errors(kwargs, message):
    with pytest.raises(ValueError, match=message):
        ssm.Simulator(**{"preset": "tiny", **kwargs})
