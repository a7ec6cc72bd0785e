"""Configs: read as the command line reads them, their fields read and changed by name, and the
same one-line errors."""

import copy
import os
import pathlib

import pytest

import semsegmap as ssm
from conftest import one_line, source_file


def write(tmp_dir, text, name="c.yaml"):
    path = os.path.join(tmp_dir, name)
    with open(path, "w") as f:
        f.write(text)
    return path


def test_the_shipped_config_is_read_with_its_model_beside_it():
    c = ssm.load_config(source_file("config/semsegmap.yaml"))
    assert c.segmentation.d_segment_m == pytest.approx(0.3)
    assert c.descriptor.kind == "semsegmap-net"
    assert c.descriptor.model == source_file("models/semsegmap-net.model")
    assert c.local_map.dynamic_removal == ssm.DynamicRemoval.point
    segmap = ssm.load_config(source_file("config/segmap.yaml"))
    assert segmap.descriptor.kind == "segmap-cnn"


def test_fields_change_in_place_at_any_depth(tmp_dir):
    c = ssm.load_config(write(tmp_dir, "localization:\n  localizer:\n    index:\n      k: 5\n"
                                       "    verification:\n      min_inliers: 7\n"))
    # A YAML key is the attribute path of its field (pipeline/setting_table.h).
    assert c.localization.localizer.index.k == 5
    assert c.localization.localizer.verification.min_inliers == 7
    c.localization.localizer.index.k = 9
    c.local_map.ground.cell_size_m = 2.5
    c.local_map.dynamic_removal = ssm.DynamicRemoval.voxel
    c.descriptor = ssm.DescriptorConfig(kind="eigen")
    assert c.localization.localizer.index.k == 9
    assert c.local_map.ground.cell_size_m == 2.5
    assert c.local_map.dynamic_removal == ssm.DynamicRemoval.voxel
    assert c.descriptor.kind == "eigen" and c.descriptor.batch == 64


def test_an_unknown_field_is_an_error_not_a_new_attribute():
    c = ssm.PipelineConfig()
    with pytest.raises(AttributeError, match="d_segmnt_m"):
        c.segmentation.d_segmnt_m = 0.2
    with pytest.raises(AttributeError, match="bogus"):
        ssm.SegmentationConfig(bogus=1)
    with pytest.raises(TypeError):
        c.segmentation.d_segment_m = "far"


def test_keywords_repr_fields_and_copies():
    s = ssm.SegmentationConfig(d_segment_m=0.5, min_segment_points=20)
    assert s.d_segment_m == 0.5 and s.min_segment_points == 20 and s.hue_penalty == 0.05
    assert s._fields[0] == "d_segment_m" and "keep_all_observation_points" in s._fields
    assert repr(s).startswith("SegmentationConfig(d_segment_m=0.5, hue_threshold=0.1")
    c = ssm.PipelineConfig()
    deep = copy.deepcopy(c)
    deep.segmentation.d_segment_m = 1.0
    assert c.segmentation.d_segment_m == pytest.approx(0.3)
    assert set(ssm.PipelineConfig._fields) == {
        "enrichment", "local_map", "segmentation", "descriptor", "localization", "target_map",
        "loop_closure", "session_merge"}


@pytest.mark.parametrize("text, message", [
    ("segmentation:\n  d_segment_mm: 0.3\n", "segmentation.d_segment_mm: unknown key"),
    ("segmentatoin:\n  d_segment_m: 0.3\n", "segmentatoin: unknown section"),
    ("local_map:\n  voxel_size_m: -1\n", "local_map.voxel_size_m: must be positive"),
    ("segmentation:\n  d_segment_m: far\n", "segmentation.d_segment_m: wrong type"),
])
def test_config_errors_are_the_command_lines(tmp_dir, text, message):
    path = write(tmp_dir, text)
    with pytest.raises(RuntimeError) as e:
        ssm.load_config(path)
    assert one_line(e.value).startswith(f"{path}: {message}")


def test_paths_may_be_path_objects():
    c = ssm.load_config(pathlib.Path(source_file("config/segmap.yaml")))
    assert c.descriptor.kind == "segmap-cnn"


def test_a_missing_config_names_the_file(tmp_dir):
    path = os.path.join(tmp_dir, "none.yaml")
    with pytest.raises(RuntimeError, match=f"^{path}: no such config file$"):
        ssm.load_config(path)


# The datasets read these sections; the Python module binds no config of theirs.
UNBOUND_SECTIONS = ("odometry", "semantics")


def bound_setting_keys():
    return {s["key"] for s in ssm.setting_table()
            if s["key"].split(".")[0] not in UNBOUND_SECTIONS}


def attribute_paths(obj, prefix=""):
    """The paths of the plain attributes under a config, through its nested configs."""
    for name in obj._fields:
        value = getattr(obj, name)
        if hasattr(value, "_fields"):
            yield from attribute_paths(value, prefix + name + ".")
        else:
            yield prefix + name


def test_every_setting_is_an_attribute_path_and_every_attribute_a_setting():
    c = ssm.PipelineConfig()
    for key in bound_setting_keys():
        obj = c
        for name in key.split("."):
            obj = getattr(obj, name)  # an AttributeError names the key that is no path
    assert set(attribute_paths(c)) == bound_setting_keys()


def test_the_stubs_declare_the_settings_as_attribute_paths():
    import ast
    with open(os.path.join(os.path.dirname(ssm.__file__), "_semsegmap.pyi")) as f:
        tree = ast.parse(f.read())
    classes = {node.name: {item.target.id: ast.unparse(item.annotation) for item in node.body
                           if isinstance(item, ast.AnnAssign) and not item.target.id.startswith("_")}
               for node in tree.body if isinstance(node, ast.ClassDef)}

    def paths(cls, prefix=""):
        for name, annotation in classes[cls].items():
            if annotation.endswith("Config"):
                yield from paths(annotation, prefix + name + ".")
            else:
                yield prefix + name

    assert set(paths("PipelineConfig")) == bound_setting_keys()


def test_the_setting_table_says_what_each_setting_is():
    table = {s["key"]: s for s in ssm.setting_table()}
    k = table["localization.localizer.index.k"]
    assert k["kind"] == "count" and k["limits"] == (1, 1000) and k["default"] == "16"
    assert not k["recorded"] and k["description"]
    assert table["local_map.voxel_size_m"]["recorded"]
    assert table["local_map.dynamic_removal"]["choices"] == ["point", "voxel"]
    recorded = [key for key, s in table.items() if s["recorded"]]
    assert recorded == list(ssm.map_parameters(ssm.PipelineConfig()))
