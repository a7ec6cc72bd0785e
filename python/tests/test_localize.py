"""Target maps from numpy, saved and loaded, and localization against them with a known answer."""

import os

import numpy as np
import pytest

import semsegmap as ssm
from conftest import one_line

DIM = 16


def synthetic_map(n=30, seed=3, points=0):
    """n segments spread over 60 m, each with a distinct random descriptor."""
    rng = np.random.default_rng(seed)
    centroids = (rng.random((n, 3)) * [60, 60, 4]).astype(np.float32)
    descriptors = rng.standard_normal((n, DIM)).astype(np.float32)
    keep = ssm.TargetMapBuilderConfig(duplicate_distance_m=0, max_points_per_segment=points)
    b = ssm.TargetMapBuilder("eigen", "test", DIM, keep)
    for i in range(n):
        seg = ssm.MapSegment(centroid=centroids[i], n_points=100 + i, majority_class=4)
        if points:
            seg.points = centroids[i] + rng.random((points, 3)).astype(np.float32)
        b.add(seg, descriptors[i])
    return b.build(), centroids, descriptors


def rigid(yaw, t):
    T = np.eye(4)
    T[:2, :2] = [[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]]
    T[:3, 3] = t
    return T


def test_a_map_from_numpy_has_the_arrays_it_was_given():
    m, centroids, descriptors = synthetic_map()
    assert len(m) == 30 and m.dimension == DIM and m.descriptor == "eigen"
    np.testing.assert_array_equal(m.centroids, centroids)
    np.testing.assert_array_equal(m.descriptors, descriptors)
    assert m.descriptors.dtype == np.float32 and m.descriptors.shape == (30, DIM)
    assert np.shares_memory(m.descriptors, m.descriptors), "a view of the map's matrix"
    assert not m.descriptors.flags.writeable, "localizers share the map: read-only"
    assert m.n_points.tolist() == list(range(100, 130)) and set(m.classes.tolist()) == {4}
    np.testing.assert_array_equal(m.segment(2).centroid, centroids[2])
    with pytest.raises(IndexError, match="segment 30 out of range"):
        m.segment(30)


def test_the_builder_refuses_what_the_library_refuses():
    b = ssm.TargetMapBuilder("eigen", "test", DIM)
    with pytest.raises(ValueError, match="dimension 3, expected 16"):
        b.add(ssm.MapSegment(), np.zeros(3, np.float32))
    with pytest.raises(ValueError, match="non-finite"):
        b.add(ssm.MapSegment(centroid=np.array([np.nan, 0, 0], np.float32)),
              np.zeros(DIM, np.float32))


@pytest.mark.parametrize("float16", [False, True])
def test_save_and_load_round_trip(tmp_dir, float16):
    m, centroids, descriptors = synthetic_map(points=5)
    path = os.path.join(tmp_dir, "m.map")
    size = ssm.save_map(path, m, float16=float16)
    assert size == os.path.getsize(path)
    back = ssm.load_map(path)
    assert (len(back), back.dimension) == (30, DIM)
    assert (back.descriptor, back.fingerprint) == ("eigen", "test")
    np.testing.assert_allclose(back.centroids, centroids, atol=1e-5)
    np.testing.assert_allclose(back.descriptors, descriptors, atol=2e-3 if float16 else 0)
    assert back.segment(0).points.shape == (5, 3)


def test_a_map_records_the_settings_it_was_built_with(tmp_dir):
    built = ssm.PipelineConfig()
    b = ssm.TargetMapBuilder("eigen", "test", DIM)
    b.set_parameters(built)
    b.add(ssm.MapSegment(centroid=np.zeros(3, np.float32)), np.ones(DIM, np.float32))
    path = os.path.join(tmp_dir, "settings.map")
    ssm.save_map(path, b.build())
    back = ssm.load_map(path)
    assert back.parameters == ssm.map_parameters(built)
    assert back.parameters["segmentation.d_segment_m"] == "0.3"
    ssm.check_map_parameters(back, built)
    other = ssm.PipelineConfig()
    other.segmentation.d_segment_m = 0.5
    with pytest.raises(RuntimeError) as e:
        ssm.check_map_parameters(back, other, path)
    assert one_line(e.value) == (path + ": segmentation.d_segment_m: the map was built with "
                                 "0.3, the configuration has 0.5 (rebuild the map with this "
                                 "configuration)")
    assert back.source == path


def test_map_file_errors_name_the_file(tmp_dir):
    missing = os.path.join(tmp_dir, "none.map")
    with pytest.raises(RuntimeError) as e:
        ssm.load_map(missing)
    assert one_line(e.value).startswith(missing + ": ")
    unwritable = os.path.join(tmp_dir, "no", "such", "dir.map")
    with pytest.raises(RuntimeError) as e:
        ssm.save_map(unwritable, synthetic_map()[0])
    assert one_line(e.value).startswith(unwritable + ": ")
    corrupt = os.path.join(tmp_dir, "bad.map")
    with open(corrupt, "wb") as f:
        f.write(b"SSMMAP" + b"\0" * 40)
    with pytest.raises(RuntimeError) as e:
        ssm.load_map(corrupt)
    assert one_line(e.value).startswith(corrupt + ": ")


def test_a_map_path_may_be_a_store_uri():
    # The store itself is tested against a real server by tests/test_map_store.cpp; here, that a
    # postgresql:// path goes to it (a server that cannot be reached, in one line naming it).
    uri = "postgresql://nohost.invalid/fleet?map=town&connect_timeout=5"
    said = (uri + ": cannot connect", uri + ": this build has no PostgreSQL map store")
    with pytest.raises(RuntimeError) as e:
        ssm.load_map(uri)
    assert one_line(e.value).startswith(said)
    with pytest.raises(RuntimeError) as e:
        ssm.save_map(uri, synthetic_map()[0])
    assert one_line(e.value).startswith(said)


def test_localization_recovers_a_known_pose():
    m, centroids, descriptors = synthetic_map()
    T_map_local = rigid(0.4, [5.0, -3.0, 0.2])
    # The map's segments seen from a local frame: p_local = inverse(T_map_local) * p_map.
    inv = np.linalg.inv(T_map_local)
    local = (centroids @ inv[:3, :3].T + inv[:3, 3]).astype(np.float32)
    localizer = ssm.Localizer(m, ssm.LocalizerConfig())
    found = localizer.localize(local[:20], descriptors[:20])
    assert found is not None
    np.testing.assert_allclose(found.T_map_local, T_map_local, atol=1e-3)
    assert found.inliers >= 6 and found.candidates >= found.inliers
    matches = found.matches
    assert matches.dtype == np.int64 and matches.shape == (found.inliers, 2)
    np.testing.assert_array_equal(matches[:, 0], matches[:, 1])  # query row i is segment i
    assert localizer.localize(local[:3], descriptors[:3]) is None  # too few segments


def test_localize_checks_the_query_against_the_map():
    m, _, descriptors = synthetic_map()
    localizer = ssm.Localizer(m)
    with pytest.raises(ValueError, match="expected 16 columns"):
        localizer.localize(np.zeros((8, 3)), np.zeros((8, 5), np.float32))
    with pytest.raises(ValueError, match="one descriptor per centroid"):
        localizer.localize(np.zeros((8, 3)), descriptors[:7])
    with pytest.raises(ValueError, match=r"centroids: expected \(K, 3\)"):
        localizer.localize(np.zeros((8, 2)), descriptors[:8])


def test_a_map_of_another_describer_is_refused():
    m, _, _ = synthetic_map()
    eigen = ssm.make_describer(ssm.DescriptorConfig(kind="eigen"))
    with pytest.raises(RuntimeError, match="^mine.map: "):
        ssm.check_map_compatible(m, eigen, "mine.map")
