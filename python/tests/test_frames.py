"""Frames from and to numpy: dtypes, shapes, views that share the frame's memory, poses, and the
errors for arrays of the wrong shape. The rig, class table and dataset description."""

import gc

import numpy as np
import pytest

import semsegmap as ssm


def pose(x=1.0, yaw=0.3):
    T = np.eye(4)
    T[:2, :2] = [[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]]
    T[0, 3] = x
    return T


def test_a_frame_from_numpy_arrays_round_trips():
    xyzi = np.arange(20, dtype=np.float64).reshape(5, 4)  # float64: cast to float32
    labels = np.array([[4, 0], [4, 0], [7, 3], [9, 0], [0, 0]], dtype=np.int64)
    rgb = np.full((6, 8, 3), 200, np.uint8)
    cls = np.full((6, 8), 4, np.uint8)
    f = ssm.Frame(xyzi, point_labels=labels, point_times=np.linspace(0, 0.1, 5),
                  images=[rgb, None], label_images=[cls, cls], T_odom_base=pose(),
                  T_world_base=pose(2.0), index=7, timestamp_s=1.5)
    assert f.points.dtype == np.float32 and f.points.shape == (5, 4)
    np.testing.assert_array_equal(f.points, xyzi)
    assert f.point_labels.dtype == np.uint16 and f.point_labels.shape == (5, 2)
    np.testing.assert_array_equal(f.point_labels, labels)
    assert f.point_times.dtype == np.float32 and f.point_times.shape == (5,)
    assert f.images[0].shape == (6, 8, 3) and f.images[0].dtype == np.uint8
    assert f.images[1] is None
    assert f.label_images[1].shape == (6, 8) and f.label_images[1][0, 0] == 4
    np.testing.assert_allclose(f.T_odom_base, pose())
    np.testing.assert_allclose(f.T_world_base, pose(2.0))
    assert (f.index, f.timestamp_s) == (7, 1.5)


def test_xyz_only_and_class_only_inputs():
    f = ssm.Frame(np.ones((3, 3), np.float32), point_labels=np.array([1, 2, 3]))
    np.testing.assert_array_equal(f.points[:, 3], 0)
    np.testing.assert_array_equal(f.point_labels, [[1, 0], [2, 0], [3, 0]])
    assert f.point_times.shape == (0,) and f.images == [] and f.T_world_base is None
    np.testing.assert_array_equal(f.T_odom_base, np.eye(4))


def test_the_arrays_are_views_into_the_frame():
    f = ssm.Frame(np.zeros((4, 4), np.float32), point_labels=np.zeros((4, 2)),
                  images=[np.zeros((2, 3, 3), np.uint8)])
    points = f.points
    assert np.shares_memory(points, f.points), "two reads are views of one buffer"
    points[2, 0] = 5.0
    assert f.points[2, 0] == 5.0, "writing the view writes the frame"
    f.point_labels[1] = [11, 2]
    assert f.point_labels[1].tolist() == [11, 2]
    f.images[0][1, 2] = [1, 2, 3]
    assert f.images[0][1, 2].tolist() == [1, 2, 3]
    assert f.points.flags.writeable and not f.points.flags.owndata
    # A view keeps its frame alive.
    del f
    gc.collect()
    assert points[2, 0] == 5.0 and points.shape == (4, 4)


def test_poses_are_copies_that_can_be_set():
    f = ssm.Frame(np.zeros((1, 3)))
    T = f.T_odom_base
    T[0, 3] = 9.0
    assert f.T_odom_base[0, 3] == 0.0
    f.T_odom_base = pose(3.0)
    f.T_world_base = pose(4.0)
    assert f.T_odom_base[0, 3] == 3.0 and f.T_world_base[0, 3] == 4.0
    f.T_world_base = None
    assert f.T_world_base is None


@pytest.mark.parametrize("make, message", [
    (lambda: ssm.Frame(np.zeros((5, 2))),
     r"points: expected an \(N, 3\) or \(N, 4\) array, got shape \(5, 2\)"),
    (lambda: ssm.Frame(np.zeros(5)), r"points: expected .* got shape \(5,\)"),
    (lambda: ssm.Frame(np.zeros((5, 3)), point_labels=np.zeros((4, 2))),
     r"point_labels: expected \(5, 2\) \[class, instance\] or \(5,\) classes"),
    (lambda: ssm.Frame(np.zeros((5, 3)), point_times=np.zeros(6)), r"point_times: expected \(5,\)"),
    (lambda: ssm.Frame(np.zeros((5, 3)), images=[np.zeros((4, 4))]),
     r"images\[0\]: expected \(H, W, 3\) uint8 RGB, got shape \(4, 4\)"),
    (lambda: ssm.Frame(np.zeros((5, 3)), T_odom_base=np.eye(3)),
     r"T_odom_base: expected a 4x4 pose, got shape \(3, 3\)"),
    (lambda: ssm.Frame(np.zeros((5, 3)), T_world_base=np.ones((4, 4))),
     r"T_world_base: the last row of a pose must be 0 0 0 1"),
])
def test_arrays_of_the_wrong_shape_are_value_errors(make, message):
    with pytest.raises(ValueError, match=message):
        make()


def test_the_rig_edits_in_place():
    rig = ssm.SensorRig()
    rig.cameras.append(ssm.Camera(name="front", width=64, height=48, fx=40, fy=40, cx=32, cy=24))
    rig.cameras[0].model = "radtan"
    rig.lidar.rows = 16
    assert len(rig.cameras) == 1 and rig.cameras[0].model == "radtan" and rig.lidar.rows == 16
    with pytest.raises(ValueError, match="unknown|expected"):
        rig.cameras[0].model = "fisheye-ish"
    uv = rig.cameras[0].project(np.array([0.0, 0.0, 2.0]))
    np.testing.assert_allclose(uv, [32, 24])
    assert rig.cameras[0].project(np.array([0.0, 0.0, -2.0])) is None
    sim_rig = ssm.default_sim_rig()
    assert len(sim_rig.cameras) == 3 and sim_rig.T_base_lidar.shape == (4, 4)
    sim_rig.validate()
    rig.cameras[0].fx = -1
    with pytest.raises(ValueError):
        rig.validate()


def test_class_table_and_dataset_info():
    table = ssm.ClassTable.default()
    car = table.find("car")
    assert car is not None and table.at(car).dynamic and table.contains(car)
    with pytest.raises(IndexError):
        table.at(999)
    with pytest.raises(ValueError, match="appears twice"):
        ssm.ClassTable([ssm.SemanticClass(id=1, name="a"), ssm.SemanticClass(id=1, name="b")])
    info = ssm.DatasetInfo(name="mine", has_odometry=True, rig=ssm.default_sim_rig())
    assert info.name == "mine" and info.has_odometry and not info.has_ground_truth_poses
    assert len(info.rig.cameras) == 3 and len(info.classes) == len(table)


def test_the_enriched_point_dtype_matches_the_library():
    dt = ssm.ENRICHED_POINT_DTYPE
    assert dt.names == (
        "x", "y", "z", "h", "s", "v", "class_id", "has_color", "has_class", "instance_id"
    )
    assert dt["class_id"] == np.uint16 and dt["has_color"] == np.bool_
