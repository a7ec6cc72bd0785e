"""What results say when printed and what they leave unknown: without ground truth a summary or
a record has None where a number would be made up, a result's repr shows its key numbers, and an
error names the keyword argument a Python user gives (odometry=...), not the command line's
option."""

import copy
import re

import pytest

import semsegmap as ssm
from conftest import TINY_S1, needs_sim


def test_a_summary_of_nothing_prints_its_numbers_and_has_no_mean_error():
    s = ssm.summarize([])
    assert (s.localizations, s.with_ground_truth, s.below_1m, s.below_5m) == (0, 0, 0, 0)
    assert s.mean_translation_error_m is None and s.mean_rotation_error_deg is None
    assert repr(s) == ("LocalizationSummary(localizations=0, with_ground_truth=0, below_1m=0, "
                       "below_5m=0, mean_translation_error_m=None, mean_rotation_error_deg=None)")


def test_no_odometry_is_refused_naming_the_keyword_arguments(config):
    with pytest.raises(RuntimeError) as error:
        ssm.Pipeline(config, ssm.DatasetInfo(name="scans only"), "odom")
    message = str(error.value)
    assert "give odometry=FILE (TUM or KITTI poses) or odometry=\"lidar\"" in message, message
    assert "--" not in message, message


@needs_sim
def test_localizations_without_ground_truth_leave_their_errors_unknown(config):
    c = copy.deepcopy(config)
    c.descriptor = ssm.DescriptorConfig(kind="eigen")  # in every build, and fast
    describer = ssm.make_describer(c.descriptor)
    ds = ssm.open_dataset(TINY_S1 + ",frames=30")
    built = ssm.run_mapping(ds, c, describer)
    assert re.fullmatch(r"MappingRun\(segments=\d+, duplicates_removed=\d+, "
                        r"map=TargetMap\(descriptor='eigen', segments=\d+, dimension=\d+, "
                        r"source=''\), stats=RunStats\(frames=30, fps=[\d.e+]+\)\)", repr(built))
    session = ssm.LocalizationSession(c, ds.info, built.map, describer)
    records = []
    for frame in ds:
        frame.T_world_base = None  # a robot without ground truth
        record = session.process(frame)
        if record is not None:
            records.append(record)
    assert records, "the run localizes against its own map"
    r = records[0]
    assert r.T_world_base is None
    assert r.translation_error_m is None and r.rotation_error_deg is None
    assert r.frame_number is None  # the simulator does not name its scans by number
    assert r.timestamp_s == pytest.approx(ds[r.frame_index].timestamp_s)
    assert repr(r).startswith(f"LocalizationRecord(frame_index={r.frame_index}, "
                              f"frame_number=None, timestamp_s=")
    s = session.run.summary()
    assert (s.localizations, s.with_ground_truth) == (len(records), 0)
    assert s.below_1m is None and s.below_5m is None and s.mean_translation_error_m is None
    assert "below_1m=None" in repr(s)
    assert repr(session.run) == (f"LocalizationRun(frames=30, localizations={len(records)}, "
                                 f"distance_m={session.run.distance_m:.4g}, "
                                 f"has_ground_truth=False)")
