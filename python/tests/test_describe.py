"""The four describers, made from configs as the command line makes them, on numpy points."""

import numpy as np
import pytest

import semsegmap as ssm
from conftest import needs_pcl, needs_torch, one_line, source_file


def box(n=400, seed=0, size=(1.0, 2.0, 3.0)):
    rng = np.random.default_rng(seed)
    return (rng.random((n, 3)) * size).astype(np.float32)


def enriched(xyz, hue=0.3, cls=4):
    p = np.zeros(len(xyz), ssm.ENRICHED_POINT_DTYPE)
    p["x"], p["y"], p["z"] = xyz.T
    p["h"], p["s"], p["v"] = hue, 0.5, 0.5
    p["class_id"], p["has_color"], p["has_class"] = cls, True, True
    return p


KINDS = [
    pytest.param("eigen", "", id="eigen"),
    pytest.param("fpfh", "", id="fpfh", marks=needs_pcl),
    pytest.param("segmap-cnn", "models/segmap-cnn.model", id="segmap-cnn", marks=needs_torch),
    pytest.param("semsegmap-net", "models/semsegmap-net.model", id="semsegmap-net",
                 marks=needs_torch),
]


@pytest.mark.parametrize("kind, model", KINDS)
def test_each_describer_on_numpy_segments(kind, model):
    config = ssm.DescriptorConfig(kind=kind, model=source_file(model) if model else "")
    d = ssm.make_describer(config, threads=1)
    assert d.kind == kind and d.dimension > 0 and d.fingerprint
    segments = [box(seed=1), enriched(box(seed=2)), box(seed=1)]
    out = d.describe(segments)
    assert out.dtype == np.float32 and out.shape == (3, d.dimension)
    assert np.isfinite(out).all()
    np.testing.assert_allclose(out[0], out[2], rtol=1e-5, atol=1e-6)  # deterministic
    assert not np.allclose(out[0], out[1])
    assert d.describe([]).shape[0] == 0


def test_the_describer_a_config_names(config):
    if ssm.descriptor_not_built(config.descriptor.kind):
        pytest.skip(ssm.descriptor_not_built(config.descriptor.kind))
    d = ssm.make_describer(config.descriptor)
    assert d.kind == config.descriptor.kind


def test_describer_errors():
    with pytest.raises(ValueError, match="bogus"):
        ssm.make_describer(ssm.DescriptorConfig(kind="bogus"))
    eigen = ssm.make_describer(ssm.DescriptorConfig(kind="eigen"))
    with pytest.raises(ValueError, match=r"segments\[1\]: expected \(K, 3\) points"):
        eigen.describe([box(), np.zeros((5, 2))])
    bad = np.zeros(3, [("x", "f4"), ("y", "f4")])
    with pytest.raises(ValueError, match="ENRICHED_POINT_DTYPE"):
        eigen.describe([bad])


@needs_torch
def test_a_missing_model_is_named(tmp_dir):
    missing = f"{tmp_dir}/none.model"
    with pytest.raises(RuntimeError) as e:
        ssm.make_describer(ssm.DescriptorConfig(kind="semsegmap-net", model=missing))
    assert missing in one_line(e.value)


def test_what_this_build_lacks_is_said():
    assert ssm.descriptor_not_built("eigen") == ""
    assert (ssm.descriptor_not_built("semsegmap-net") == "") == ssm.WITH_TORCH
    assert (ssm.descriptor_not_built("fpfh") == "") == ssm.WITH_PCL
    if not ssm.WITH_TORCH:
        with pytest.raises(RuntimeError, match="SEMSEGMAP_WITH_TORCH"):
            ssm.make_describer(ssm.DescriptorConfig(kind="semsegmap-net", model="x.model"))


def test_malloc_tuning_is_the_programs_call_and_keeps_descriptors_unchanged():
    eigen = ssm.make_describer(ssm.DescriptorConfig(kind="eigen"))
    before = eigen.describe([box()])
    assert ssm.keep_freed_memory_for_torch() is None
    ssm.keep_freed_memory_for_torch()  # idempotent
    assert np.array_equal(eigen.describe([box()]), before)
