"""Datasets by their --dataset spec, as the command line opens them: frames by index and by
iteration, and the command line's errors."""

import os

import numpy as np
import pytest

import semsegmap as ssm
from conftest import SHARED_DATA, TINY_S1, needs_sim, one_line, run_cli


@needs_sim
def test_a_simulated_frame_as_numpy():
    ds = ssm.open_dataset(TINY_S1)
    assert len(ds) == 761
    info = ds.info
    assert info.has_ground_truth_poses and info.has_odometry and info.has_point_labels
    assert len(info.rig.cameras) == 3
    f = ds[0]
    n = f.points.shape[0]
    assert n > 1000 and f.points.dtype == np.float32 and f.points.shape == (n, 4)
    assert f.point_labels.shape == (n, 2) and f.point_labels.dtype == np.uint16
    cam = info.rig.cameras[0]
    assert [im.shape for im in f.images] == [(cam.height, cam.width, 3)] * 3
    assert [im.shape for im in f.label_images] == [(cam.height, cam.width)] * 3
    assert f.T_world_base.shape == (4, 4) and f.T_odom_base.shape == (4, 4)
    np.testing.assert_array_equal(ds[-761].points, f.points)  # Python's negative indices
    assert ds.frame_time(1) > ds.frame_time(0)


@needs_sim
def test_frames_iterate_and_the_end_is_the_librarys_index_error():
    ds = ssm.open_dataset(TINY_S1 + ",frames=3,cameras=0")
    assert [f.index for f in ds] == [0, 1, 2]
    assert ds.info.rig.cameras.__len__() == 0
    with pytest.raises(IndexError) as e:
        ds[3]
    assert one_line(e.value) == f"{ds.info.name}: frame 3 out of range (3 frames)"
    with pytest.raises(IndexError, match=r": frame -4 out of range \(3 frames\)$"):
        ds[-4]
    assert ds[-1].index == 2


@pytest.mark.parametrize("spec, error, message", [
    ("bogus:x", ValueError,
     "dataset 'bogus:x': unknown kind 'bogus' (expected kitti-raw:, semantickitti:, nclt:, sim:, "
     "folder:, rosbag: or a directory)"),
    ("/no/such/place", RuntimeError, "/no/such/place: no such dataset directory"),
])
def test_spec_errors_are_the_command_lines(spec, error, message):
    with pytest.raises(error) as e:
        ssm.open_dataset(spec)
    assert one_line(e.value) == message


@needs_sim
def test_a_sim_spec_error_names_the_key():
    with pytest.raises(ValueError, match=r"^dataset 'sim:world=1,wrld=2': unknown key 'wrld'$"):
        ssm.open_dataset("sim:world=1,wrld=2")


@needs_sim
def test_a_dataset_folder_written_by_the_command_line(binary, tmp_dir):
    out = os.path.join(tmp_dir, "ds")
    run_cli(binary, "simulate", "--world-seed=1", "--run=S2", "--world=tiny", "--max-frames=2",
            "--out=" + out)
    ds = ssm.open_dataset(out)
    sim = ssm.open_dataset("sim:world=1,run=S2,preset=tiny")
    assert len(ds) == 2
    np.testing.assert_allclose(ds[1].points[:, :3], sim[1].points[:, :3], atol=1e-5)
    np.testing.assert_array_equal(ds[1].point_labels, sim[1].point_labels)


def test_real_kitti_scans_with_their_poses():
    sparse = os.path.join(SHARED_DATA, "kitti_odometry_00_sparse")
    if not os.path.exists(os.path.join(sparse, "poses.txt")):
        pytest.skip(f"no real KITTI sample ({sparse}): ../shared/data is not beside this checkout")
    ds = ssm.open_dataset("semantickitti:" + sparse)
    assert len(ds) == 36 and ds.info.has_ground_truth_poses
    f = ds[0]
    assert f.points.shape[1] == 4 and f.points.shape[0] > 10000 and f.T_world_base is not None
