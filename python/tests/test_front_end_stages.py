"""The network and LiDAR odometry as stages a Pipeline owns (open_dataset_for_pipeline): code
that embeds the pipeline gets what open_dataset's wrapped frames give, whatever its frames."""

import numpy as np

import semsegmap as ssm
from conftest import TINY_S1, needs_sim

pytestmark = needs_sim
FRAMES = 6


def test_lidar_odometry_as_a_stage_gives_the_wrapped_sources_poses():
    spec = TINY_S1 + f",frames={FRAMES}"
    dataset, stages = ssm.open_dataset_for_pipeline(spec, odometry="lidar")
    assert stages.lidar_odometry and not stages.network
    assert repr(stages) == "FrontEndStages(network=False, lidar_odometry=True)"
    wrapped = ssm.open_dataset(spec, odometry="lidar")
    own = ssm.Pipeline(ssm.PipelineConfig(), dataset.info, "odom", stages=stages)
    by_source = ssm.Pipeline(ssm.PipelineConfig(), wrapped.info, "odom")
    moved = 0.0
    for i in range(FRAMES):
        a, b = by_source.process(wrapped[i]), own.process(dataset[i])
        np.testing.assert_array_equal(a.T_local_base, b.T_local_base)
        moved = np.linalg.norm(b.T_local_base[:3, 3])
    assert moved > 0.5  # the odometry ran: the robot drives on


def test_without_stages_the_frames_own_odometry_is_used():
    dataset, stages = ssm.open_dataset_for_pipeline(TINY_S1 + ",frames=2")
    assert not stages.lidar_odometry and not stages.network
    pipeline = ssm.Pipeline(ssm.PipelineConfig(), dataset.info, "odom", stages=stages)
    frame = dataset[1]
    np.testing.assert_allclose(pipeline.process(dataset[0]).T_local_base, dataset[0].T_odom_base)
    np.testing.assert_allclose(pipeline.process(frame).T_local_base, frame.T_odom_base)
