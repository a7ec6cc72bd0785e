"""scripts/write_results.py writes a results table from JSON that may hold null (a count or error
the run did not know): such a cell is "-", never a made-up 0."""

import json
import os
import re
import shlex
import subprocess
import sys

import pytest

from conftest import source_file


def test_write_results_shows_unknown_values_as_a_dash(tmp_path):
    result = {"run": "S2", "config": "semsegmap", "n_localizations": 3, "n_error_below_1m": None,
              "n_wrong": 0, "mean_translation_error_m": None, "mean_rotation_error_deg": None,
              "recall_along_trajectory": 0.5}
    results = tmp_path / "localization.json"
    results.write_text(json.dumps({"results": [result]}))
    doc = tmp_path / "results.md"
    doc.write_text("before\n<!-- results:t -->\nold\n<!-- /results:t -->\nafter\n")
    subprocess.run([sys.executable, source_file("scripts/write_results.py"), "t",
                    f"front camera={results}", "--doc", str(doc)], check=True)
    row = [line for line in doc.read_text().splitlines() if line.startswith("| front camera |")]
    assert row == ["| front camera | S2 | semsegmap | 3 | - | 0 | - | 0.50 |"], doc.read_text()


# Every kind of table from the JSON (or CSV) its command writes: a fixture of the fields the
# writer reads, and the row it must give.
def write_table(tmp_path, kind, inputs):
    doc = tmp_path / "doc.md"
    doc.write_text("<!-- results:s -->\n<!-- /results:s -->\n")
    subprocess.run([sys.executable, source_file("scripts/write_results.py"), "s", *inputs,
                    "--table", kind, "--doc", str(doc)], check=True, capture_output=True)
    return [line for line in doc.read_text().splitlines() if line.startswith("|")]


def localization_result(run, config, below_1m, odometry="simulated"):
    return {"run": run, "config": config, "frames": 10, "n_localizations": below_1m + 1,
            "n_error_below_1m": below_1m, "n_error_below_5m": below_1m + 1, "n_wrong": 0,
            "mean_translation_error_m": 0.25, "mean_rotation_error_deg": 1.0,
            "recall_along_trajectory": 0.9, "fps": 12.0, "map_segments": 40,
            "map_bytes": 2048}


def localization_json(tmp_path, name, results, odometry="simulated"):
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps({"query_odometry": odometry, "results": results}))
    return str(path)


def test_table_i_shows_the_papers_counts_beside_ours(tmp_path):
    loc = localization_json(tmp_path, "loc", [localization_result("S3", "segmap", 7)])
    rows = write_table(tmp_path, "table-i", [loc])
    assert rows[2] == ("| S3 (10 frames) | segmap | 8 | 7 | 8 | 0 | 0.25 m, 1.00 deg | 0.90 "
                       "| 40 segments, 2.0 KiB | 10 |")


def test_configs_table_names_the_odometry_when_the_runs_differ_in_it(tmp_path):
    drifting = localization_json(tmp_path, "a", [localization_result("S2", "semsegmap", 5),
                                                 localization_result("S3", "semsegmap", 4)])
    lidar = localization_json(tmp_path, "b", [localization_result("S2", "semsegmap", 9)],
                              odometry="lidar")
    rows = write_table(tmp_path, "configs", [drifting, lidar])
    assert rows[0].startswith("| configuration | S2 < 1 m | S2 mean error | S3 < 1 m |")
    assert rows[2] == ("| semsegmap, simulated odometry | 5 | 0.25 m / 1.00 deg | 4 "
                       "| 0.25 m / 1.00 deg | 0 | 0.90 / 0.90 |")
    assert rows[3] == "| semsegmap, lidar odometry | 9 | 0.25 m / 1.00 deg | - | - | 0 | 0.90 |"


def test_label_noise_table_has_a_row_per_level(tmp_path):
    levels = [f"{level}=" + localization_json(
        tmp_path, f"l{level}", [localization_result("S2", "semsegmap", 10 - level)])
        for level in (0, 3)]
    rows = write_table(tmp_path, "label-noise", levels)
    assert rows[0] == "| label noise | S2 semsegmap | wrong |"
    assert rows[2:] == ["| 0 | 10 | 0 |", "| 3 | 7 | 0 |"]


def test_label_rate_table_takes_each_kind_of_labels_from_a_file_of_several(tmp_path):
    def labelled(run, config, n, labels, share=0.0):
        return dict(localization_result(run, config, n), labels=labels,
                    network_share_of_cores=share)
    # The demo's file: perfect labels, then the network's; a rate run's file: the network's.
    demo = localization_json(tmp_path, "demo", [
        labelled("S2", "semsegmap", 30, "perfect"), labelled("S2", "segmap", 20, "perfect"),
        labelled("S2", "semsegmap", 24, "network", 0.25),
        labelled("S2", "segmap", 16, "network", 0.25)])
    rate = localization_json(tmp_path, "rate", [
        labelled("S2", "semsegmap", 9, "network,rate=1", 0.05),
        labelled("S2", "segmap", 0, "network,rate=1", 0.05)])
    rows = write_table(tmp_path, "label-rate", [
        f"perfect={demo}", f"network at the shipped budget={demo}", f"network at 1 Hz={rate}"])
    assert rows[0] == ("| camera labels | S2 semsegmap | S2 segmap | S2 lead "
                       "| S2 semsegmap of perfect | wrong | network cores |")
    assert rows[2:] == ["| perfect | 30 | 20 | 1.50 | - | 0 | - |",
                        "| network at the shipped budget | 24 | 16 | 1.50 | 80.0 % | 0 | 0.25 |",
                        "| network at 1 Hz | 9 | 0 | - | 30.0 % | 0 | 0.05 |"]
    # Without a row of perfect labels there is nothing to be a share of.
    rows = write_table(tmp_path, "label-rate", [f"network at 1 Hz={rate}"])
    assert rows[2:] == ["| network at 1 Hz | 9 | 0 | - | 0 | 0.05 |"]
    # The label-noise table takes the perfect rows of a file with the network's too.
    assert write_table(tmp_path, "label-noise", [f"0={demo}"])[2] == "| 0 | 30 | 20 | 0 |"


def test_label_rate_table_takes_a_label_pass_by_its_folder(tmp_path):
    # eval localization --labels perfect+network,rate=2: the second pass's runs in its folder.
    def passed(config, n, labels, folder):
        return dict(localization_result("S2", config, n), labels=labels,
                    dir=f"{folder}{config}_S2")
    both = localization_json(tmp_path, "both", [
        passed("semsegmap", 30, "perfect", ""), passed("segmap", 20, "perfect", ""),
        passed("semsegmap", 12, "network,rate=2", "network_rate-2/"),
        passed("segmap", 6, "network,rate=2", "network_rate-2/")])
    rows = write_table(tmp_path, "label-rate", [
        f"perfect={both}", f"network at 2 Hz={both}#network_rate-2"])
    assert rows[2:] == ["| perfect | 30 | 20 | 1.50 | - | 0 | - |",
                        "| network at 2 Hz | 12 | 6 | 2.00 | 40.0 % | 0 | - |"]
    doc = tmp_path / "doc.md"
    failed = subprocess.run([sys.executable, source_file("scripts/write_results.py"), "s",
                             f"x={both}#network_rate-9", "--table", "label-rate", "--doc",
                             str(doc)], capture_output=True, text=True)
    assert failed.returncode != 0 and "no label pass in network_rate-9/" in failed.stderr


def test_segmentation_table_has_the_change_against_the_paper(tmp_path):
    seg = tmp_path / "segmentation.json"
    seg.write_text(json.dumps({
        "results": [{"config": "semsegmap", "segments": 50, "revisit_segments": 20,
                     "consistent": 12, "inconsistent": 8},
                    {"config": "segmap", "segments": 60, "revisit_segments": 20,
                     "consistent": 10, "inconsistent": 10}],
        "consistent_change_pct": 20.0, "inconsistent_change_pct": -20.0,
        "paper": {"consistent_change_pct": 30.97, "inconsistent_change_pct": -24.24}}))
    rows = write_table(tmp_path, "segmentation", [str(seg)])
    assert rows[2] == "| semsegmap | 50 | 20 | 12 (60 %) | 8 |"
    assert rows[4] == ("| change (semsegmap vs segmap) |  |  | +20.0 % (paper +30.97 %) "
                       "| -20.0 % (paper -24.24 %) |")


def test_descriptor_table_takes_top_16_of_each_band(tmp_path):
    desc = tmp_path / "descriptors.json"
    desc.write_text(json.dumps({"bands": ["< 30 %"], "descriptors": [
        {"name": "eigen", "top1": 0.1, "top16": 0.5, "segments_per_second": 999.6,
         "band_curves": [[0.01 * k for k in range(1, 33)]]}]}))
    rows = write_table(tmp_path, "descriptors", [str(desc)])
    assert rows[0] == "| descriptor | top-1 | top-16 | top-16 < 30 % | segments/s |"
    assert rows[2] == "| `eigen` | 0.100 | 0.500 | 0.160 | 1000 |"


def test_completeness_table_names_the_leader_of_each_estimated_band_and_the_wake_ups(tmp_path):
    desc = tmp_path / "descriptors.json"
    curve = lambda top16: [top16] * 20  # noqa: E731
    desc.write_text(json.dumps({
        "dataset": "sim:world=1,run=S0", "segments": 5, "queries": 9,
        "bands": ["<30%", ">=30%"],
        "completeness_estimate": {"window_frames": 10, "agreement": {
            "window_frames": 10, "spearman": 0.5, "same_band": 0.6,
            "confusion": [[3, 1], [2, 4]]}, "windows": [
            {"window_frames": 5, "spearman": 0.4, "same_band": 0.5, "confusion": []},
            {"window_frames": 10, "spearman": 0.5, "same_band": 0.6, "confusion": []}]},
        "wake_ups": {"dataset": "sim:world=1,run=S2", "every_frames": 20, "wake_ups": 3,
                     "queries": 7, "descriptors": [
                         {"name": "a", "top1": 0.1, "top16": 0.3},
                         {"name": "b", "top1": 0.2, "top16": 0.3}]},
        "descriptors": [
            {"name": "a", "estimated_band_curves": [curve(0.5), curve(0.9)]},
            {"name": "b", "estimated_band_curves": [curve(0.6), curve(0.8)]}]}))
    rows = write_table(tmp_path, "completeness", [str(desc)])
    assert "| 10 (used) | 0.500 | 0.600 |" in rows
    assert "| true <30% | 3 | 1 |" in rows
    assert "| `a` | 0.500 | 0.900 | 0.100 | 0.300 |" in rows
    assert "| leads | `b` | `a` | `b` | `a`, `b` |" in rows


def test_benchmark_table_reads_google_benchmarks_json(tmp_path):
    bench = tmp_path / "bench.json"
    bench.write_text(json.dumps({"context": {"num_cpus": 2, "mhz_per_cpu": 2445,
                                             "date": "2026-12-05T11:10:00+00:00"}, "benchmarks": [
        {"name": "BM_LocalizationQuery/10000/real_time", "run_name": "BM_LocalizationQuery/10000/real_time",
         "real_time": 3500.0, "time_unit": "us", "search_ms": 2.4},
        {"name": "BM_WholePipeline/0/-1/iterations:100/real_time", "real_time": 41.5,
         "time_unit": "ms", "Hz": 24.1},
        {"name": "BM_NotInTheTable", "real_time": 1.0, "time_unit": "ms"}]}))
    rows = write_table(tmp_path, "benchmarks", [str(bench)])
    assert len(rows) == 4, rows
    assert rows[2].endswith("| `BM_WholePipeline/0/-1` | >= 20 Hz | 24.1 Hz (41.5 ms) |")
    assert rows[3].endswith("| <= 5 ms | 3.5 ms (search 2.4 ms) |")
    assert "Measured on 2 CPUs at 2445 MHz, 2026-12-05." in (tmp_path / "doc.md").read_text()


def test_benchmark_table_takes_the_fastest_repetition_with_its_local_map_time(tmp_path):
    bench = tmp_path / "bench.json"
    name = "BM_WholePipeline/0/1000/iterations:160/repeats:3/real_time"
    runs = [{"name": name, "run_name": name, "run_type": "iteration", "real_time": t,
             "time_unit": "ms", "Hz": 1000 / t, "map_seg_ms": m} for t, m in ((50, 30), (40, 20))]
    aggregates = [{"name": name + "_" + a, "run_name": name, "run_type": "aggregate",
                   "aggregate_name": a, "real_time": t, "time_unit": "ms", "Hz": 1000 / t,
                   "map_seg_ms": m} for a, t, m in (("mean", 45, 25), ("median", 45, 25),
                                                    ("stddev", 5, 5))]
    bench.write_text(json.dumps({"context": {"num_cpus": 2, "mhz_per_cpu": 2445,
                                             "date": "2026-12-06T11:10:00+00:00"},
                                 "benchmarks": runs + aggregates}))
    rows = write_table(tmp_path, "benchmarks", [str(bench)])
    assert rows[2].endswith(
        "| `BM_WholePipeline/0/1000` | >= 10 Hz | 25.0 Hz (40.0 ms), local map + segmentation "
        "20.0 ms |"), rows
    # A later file's run of a benchmark (the pipeline's rows in a process of their own) wins.
    alone = tmp_path / "alone.json"
    alone.write_text(json.dumps({"context": {}, "benchmarks": [dict(runs[1], real_time=30,
                                                                    Hz=1000 / 30)]}))
    rows = write_table(tmp_path, "benchmarks", [str(bench), str(alone)])
    assert rows[2].endswith("33.3 Hz (30.0 ms), local map + segmentation 20.0 ms |"), rows
    # Aggregates alone (--benchmark_report_aggregates_only): their mean.
    bench.write_text(json.dumps({"context": {"num_cpus": 2, "mhz_per_cpu": 2445,
                                             "date": "2026-12-06T11:10:00+00:00"},
                                 "benchmarks": aggregates}))
    rows = write_table(tmp_path, "benchmarks", [str(bench)])
    assert rows[2].endswith("22.2 Hz (45.0 ms), local map + segmentation 25.0 ms |"), rows


def test_memory_table_gives_the_growth_after_the_first_kilometre(tmp_path):
    rss = tmp_path / "rss.csv"
    rss.write_text("phase,frame,distance_m,rss_mb\nmap,0,0,100\nlocalize,0,0,300\n"
                   "localize,50,1000,400\nlocalize,100,1500,420\nlocalize,150,2100,410\n")
    rows = write_table(tmp_path, "memory", [f"long={rss}"])
    assert rows[0] == "| run | 0 km | 1 km | 2 km | at the end | growth after 1 km |"
    assert rows[2] == "| long | 300 | 400 | 410 | 410 (2.1 km) | +5.0 % |"


def test_memory_table_of_a_long_run_shows_every_few_kilometres(tmp_path):
    rss = tmp_path / "rss.csv"
    rss.write_text("phase,frame,distance_m,rss_mb\n" + "".join(
        f"localize,{k},{k * 500},{400 + k}\n" for k in range(38)))  # 18.5 km
    rows = write_table(tmp_path, "memory", [f"long={rss}"])
    assert rows[0] == ("| run | 0 km | 1 km | 2 km | 4 km | 6 km | 8 km | 10 km | 12 km | 14 km "
                       "| 16 km | 18 km | at the end | growth after 1 km |")
    assert rows[2] == ("| long | 400 | 402 | 404 | 408 | 412 | 416 | 420 | 424 | 428 | 432 | 436 "
                       "| 437 (18.5 km) | +8.7 % |")


def test_slam_table_shows_an_unknown_error_as_a_dash(tmp_path):
    summary = tmp_path / "summary.json"
    summary.write_text(json.dumps({"frames": 9, "loop_closures": 3, "ate_odometry": None,
                                   "ate_slam": {"rmse_m": 1.234}, "ate_odometry_aligned": None,
                                   "ate_slam_aligned": None}))
    rows = write_table(tmp_path, "slam", [f"S1={summary}"])
    assert rows[2] == "| S1 | 9 | 3 | - | 1.23 m | - | - |"


def test_segments_table_refuses_segments_without_ground_truth(tmp_path):
    csv_file = tmp_path / "segments.csv"
    csv_file.write_text("id,points,gt_purity\n1,100,0.9\n2,300,0.8\n")
    assert write_table(tmp_path, "segments", [f"a={csv_file}"])[2] == "| a | 2 | 200 | 0.850 |"
    csv_file.write_text("id,points,gt_purity\n1,100,\n")
    with pytest.raises(subprocess.CalledProcessError) as e:
        write_table(tmp_path, "segments", [f"a={csv_file}"])
    assert b"ground-truth purity" in e.value.stderr


def revisit_result(config, method, descriptor, wake_ups, ms_per_query):
    return {"config": config, "method": method, "descriptor": descriptor, "n_localizations": 3,
            "n_error_below_0_5m": 1, "n_error_below_1m": 2, "n_error_below_5m": 3, "n_wrong": 0,
            "mean_translation_error_m": 0.5, "mean_rotation_error_deg": 1.0,
            "n_revisits_localized": 2, "n_registered_compared": 0, "n_registered_below_0_3m": 0,
            "ms_per_query": ms_per_query, "wake_ups": wake_ups}


def test_revisit_tables_say_which_method_gave_each_row_and_its_time(tmp_path):
    """eval revisits compares the segment configurations with Scan Context: each row names its
    method and the time a query took; a file from before Scan Context (no method, no time)
    still reads as segments, its time unknown."""
    wake_ups = [{"revisit": True, "localized_at_frame": 2, "wrong_first": False},
                {"revisit": True, "localized_at_frame": None, "wrong_first": False},
                {"revisit": False, "localized_at_frame": None, "wrong_first": True}]
    older = revisit_result("segmap", "segments", "segmap-cnn", wake_ups, None)
    del older["method"], older["ms_per_query"]
    path = tmp_path / "revisits.json"
    path.write_text(json.dumps({"n_revisits": 4, "results": [
        revisit_result("semsegmap", "segments", "semsegmap-net", wake_ups, 41.25), older,
        revisit_result("scan-context", "scan-context", "scan-context", wake_ups, 180.0)]}))
    rows = write_table(tmp_path, "revisits", [str(path)])
    assert rows[0].startswith("| config | method | localizations |") and rows[0].endswith(
        "| ms / query |"), rows[0]
    assert rows[2] == ("| semsegmap | segments (semsegmap-net) | 3 | 1 | 2 | 3 | 0 | "
                       "0.50 m / 1.00 deg | 2 of 4 | - | 41.2 |")
    assert rows[3].startswith("| segmap | segments (segmap-cnn) | 3 |") and rows[3].endswith(
        "| - |"), rows[3]
    assert rows[4].startswith("| scan-context | Scan Context (whole scan) | 3 |"), rows[4]
    assert rows[4].endswith("| 180.0 |"), rows[4]
    rows = write_table(tmp_path, "wake-ups", [str(path)])
    assert rows[0].startswith("| config | method | wake-ups at a revisit | by frame 1 |"), rows[0]
    # Older files have no ambiguous count and no covariances: "-".
    assert rows[4] == ("| scan-context | Scan Context (whole scan) | 2 | 0 | 1 | 1 | 1 | 1 | 1 "
                       "| 0 | - | - | - | - | 180.0 |")
    # A file with them: the wrong poses of any wake-up, the ambiguous ones and the calibration.
    with_covariances = revisit_result("semsegmap", "segments", "semsegmap-net", wake_ups, 41.25)
    with_covariances.update({"n_wrong": 2, "n_ambiguous": 3, "covariance_calibration": {
        "share_mahalanobis_within_3": 0.962, "mean_nees": 2.514, "median_sigma_m": 0.123}})
    path.write_text(json.dumps({"n_revisits": 4, "results": [with_covariances]}))
    rows = write_table(tmp_path, "wake-ups", [str(path)])
    assert rows[2] == ("| semsegmap | segments (semsegmap-net) | 2 | 0 | 1 | 1 | 1 | 1 | 1 "
                       "| 2 | 3 | 96 % | 2.51 | 0.12 m | 41.2 |"), rows[2]
    path.write_text(json.dumps({"n_revisits": 4, "results": [
        revisit_result("semsegmap", "segments", "semsegmap-net", wake_ups, 41.25), older,
        revisit_result("scan-context", "scan-context", "scan-context", wake_ups, 180.0)]}))
    # One file per rig, each labelled: a first column names the rig.
    rows = write_table(tmp_path, "wake-ups", [f"paper={path}", f"HDL-64E={path}"])
    assert rows[0].startswith("| rig | config | method | wake-ups at a revisit |"), rows[0]
    assert rows[2].startswith("| paper | semsegmap | segments (semsegmap-net) | 2 |"), rows[2]
    assert rows[7].startswith("| HDL-64E | scan-context |"), rows[7]
    # One-scan wake-ups: no column for frames they were not given.
    path.write_text(json.dumps({"n_revisits": 4, "wake_up_frames": 1, "results": [
        revisit_result("semsegmap", "segments", "semsegmap-net", wake_ups, 41.25)]}))
    rows = write_table(tmp_path, "wake-ups", [str(path)])
    assert "| by frame 1 | first localization wrong |" in rows[0], rows[0]
    assert rows[2] == ("| semsegmap | segments (semsegmap-net) | 2 | 0 | 1 | 0 | - | - | - | - "
                       "| 41.2 |"), rows[2]


def documented_writes():
    """Every scripts/write_results.py call of docs/*.md, as its arguments."""
    calls = []
    for doc in sorted(os.listdir(source_file("docs"))):
        if doc.endswith(".md"):
            text = open(source_file(f"docs/{doc}"), encoding="utf-8").read()
            calls += [shlex.split(line)[1:] for line in text.replace("\\\n", " ").splitlines()
                      if line.startswith("scripts/write_results.py ")]
    return calls


def test_fleet_table_shows_each_session_and_the_fifth_run_against_both_maps(tmp_path):
    session = {"aligned": True, "frames": 10, "localizations": 4, "entries": 30,
               "same_segments": 12, "tie_residual_m": 0.25, "trajectory_error_m": 0.31,
               "centroid_error_m": 0.4}
    fleet = {"sessions": [dict(session, run="S0", localizations=0),
                          dict(session, run="S1"), dict(session, run="S2", aligned=False)],
             "entries": 60, "segments": 48, "centroid_mean_m": 0.123, "centroid_median_m": 0.1,
             "queries": [{"run": "S0,traffic=7", "frames": 50,
                          "merged": {"localizations": 20, "within_1m": 18, "wrong": 0},
                          "first": {"localizations": 19, "within_1m": 15, "wrong": 1}}]}
    path = tmp_path / "fleet.json"
    path.write_text(json.dumps(fleet))
    lines = write_table(tmp_path, "fleet", [str(path)])
    assert lines[2].startswith("| S0 | 10 | map frame | 0 | 30 | 12 | 0.25 m | 0.31 m |")
    assert lines[4].startswith("| S2 | 10 | no |")
    text = (tmp_path / "doc.md").read_text()
    assert "centroids 0.12 m from the truth on average (median 0.10 m)" in text
    assert "| S0,traffic=7 | 50 | the merged map | 20 | 18 | 0 |" in lines
    assert "| S0,traffic=7 | 50 | S0 alone | 19 | 15 | 1 |" in lines


def test_every_results_section_is_written_by_a_documented_command():
    """docs/*.md and the README: each section is written by a write_results.py call of docs/
    with a table kind the script has, and each call names a section of its document, so that
    scripts/regenerate_results.py regenerates every table and only those."""
    listed = subprocess.run([sys.executable, source_file("scripts/regenerate_results.py"),
                             "--list"], check=True, capture_output=True, text=True).stdout
    written = {}
    for args in documented_writes():
        doc = args[args.index("--doc") + 1] if "--doc" in args else "docs/results.md"
        kind = args[args.index("--table") + 1] if "--table" in args else "rigs"
        assert kind in write_results_kinds(), args
        written.setdefault(doc, set()).add(args[0])
    for doc, sections in written.items():
        text = open(source_file(doc), encoding="utf-8").read()
        in_doc = set(re.findall(r"^<!-- results:([\w-]+) -->$", text, re.M))
        assert sections == in_doc, doc
    assert set(listed.split()) == set().union(
        *(sections for doc, sections in written.items() if doc.startswith("docs/")))
    assert "README.md" in written, "the README's demo table is written by a documented command"
    for doc in ["README.md"] + [f"docs/{d}" for d in os.listdir(source_file("docs"))]:
        if doc.endswith(".md") and doc not in written:
            text = open(source_file(doc), encoding="utf-8").read()
            assert "<!-- results:" not in text, f"{doc} has a results section nothing writes"


def write_results_kinds():
    help_text = subprocess.run([sys.executable, source_file("scripts/write_results.py"), "-h"],
                               check=True, capture_output=True, text=True).stdout
    return set(re.search(r"--table \{([^}]*)\}", help_text).group(1).split(","))


def test_regenerate_runs_the_block_before_a_section_once_and_refuses_an_unknown_one(tmp_path):
    """The runner on a copy of the repository's layout: a block that writes two sections runs
    once, --tables-only keeps only the write and copy lines, an unknown section is refused."""
    root = tmp_path / "repo"
    (root / "scripts").mkdir(parents=True)
    (root / "docs").mkdir()
    for script in ("regenerate_results.py", "write_results.py"):
        (root / "scripts" / script).write_text(open(source_file(f"scripts/{script}")).read())
    (root / "docs" / "a.md").write_text(
        "```sh\necho measured >> data.log\ncp data.log copy.log\n```\n"
        "<!-- results:one -->\n<!-- /results:one -->\n<!-- results:two -->\n"
        "<!-- /results:two -->\n")
    runner = [sys.executable, str(root / "scripts" / "regenerate_results.py")]
    subprocess.run(runner + ["one", "two"], check=True, cwd=tmp_path, capture_output=True)
    assert (root / "data.log").read_text() == "measured\n"
    subprocess.run(runner + ["--tables-only"], check=True, cwd=tmp_path, capture_output=True)
    assert (root / "data.log").read_text() == "measured\n", "--tables-only measured again"
    listed = subprocess.run(runner + ["--list"], check=True, capture_output=True, text=True)
    assert listed.stdout.split() == ["one", "two"]
    refused = subprocess.run(runner + ["three"], capture_output=True, text=True)
    assert refused.returncode != 0 and "no section three" in refused.stderr
