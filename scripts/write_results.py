#!/usr/bin/env python3
"""Writes a results table of docs/results.md from the eval commands' JSON, so that rerunning the
commands regenerates the numbers instead of someone copying them by hand.

    scripts/write_results.py SECTION INPUT [INPUT...] [--table KIND] [--doc FILE]

The table replaces what stands between the lines `<!-- results:SECTION -->` and
`<!-- /results:SECTION -->` of the document; a missing section is an error naming the document,
so that a typo never appends a second table. The document is written to a temporary name and
renamed, so an interrupted run leaves the old one whole. KIND says what the inputs are:

  rigs          LABEL=localization.json ...: a row per run and config, LABEL names the rig
  runs          localization.json ...: the same without the rig (the demo's table)
  table-i       localization.json of `eval localization|paper`: the paper's Table I
  configs       localization.json with many --configs: within 1 m per run, a row per config
  label-noise   LEVEL=localization.json ...: within 1 m per run and config, a row per level
  label-rate    LABELS=localization.json ...: SemSegMap and SegMap within 1 m, SemSegMap's lead
                and the network's share of the cores, a row per way of labelling
  segmentation  segmentation.json of `eval segmentation|paper`
  descriptors   descriptors.json of `eval descriptors|paper`
  completeness  descriptors.json of `eval descriptors|paper`: the run-time completeness
                estimate's agreement, retrieval per estimated band and on one-scan wake-ups
  benchmarks    Google Benchmark JSON (`semsegmap_bench --benchmark_out=FILE`)
  memory        LABEL=rss.csv of `semsegmap_memory_run`: the resident set per kilometre
  segments      LABEL=segments.csv of `semsegmap segment`: count, size and purity
  odometry      LABEL=summary.json of `semsegmap odometry`: KITTI errors and ATE
  revisits      revisits.json of `semsegmap eval revisits`: a row per config and Scan Context
  wake-ups      revisits.json of `eval revisits --wake-up`: localized by frame N
  registration  Google Benchmark JSON: the odometry's registration against the libraries'
  slam          LABEL=summary.json of `semsegmap slam`: loop closures and trajectory errors
"""
import argparse
import csv
import json
import math
import os
import re
import sys

# The paper's Table I (localizations of SegMap and SemSegMap on its S2 and S3): the reference the
# simulator's counts are shown beside, not a measurement of ours.
PAPER_TABLE_I = {("S2", "segmap"): 126, ("S2", "semsegmap"): 258, ("S3", "segmap"): 10,
                 ("S3", "semsegmap"): 108}


def fail(message):
    sys.exit(message)


def load_json(path, needed, what):
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, ValueError) as e:
        fail(f"{path}: cannot read {what}: {e}")
    if needed not in data:
        fail(f"{path}: not {what} (no {needed})")
    return data


def load_localization(path):
    return load_json(path, "results", "a localization.json of semsegmap eval localization")


def labelled(inputs):
    """LABEL=FILE arguments as (label, file) pairs."""
    out = []
    for run in inputs:
        # The file is after the last "=": a label may hold one ("sweep=1, deskewed").
        label, sep, path = run.rpartition("=")
        if not sep or not label or not path:
            fail(f"expected LABEL=FILE, got '{run}'")
        out.append((label, path))
    return out


def shown(value):
    """A count as the table shows it: "-" for one the run did not know (null)."""
    return "-" if value is None else value


def mean_error(r, sep=" / "):
    # Unknown values (no localization, no ground truth) are null: shown as "-", never 0.
    translation, rotation = r.get("mean_translation_error_m"), r.get("mean_rotation_error_deg")
    if not r["n_localizations"] or translation is None or rotation is None:
        return "-"
    return f"{translation:.2f} m{sep}{rotation:.2f} deg"


def table(header, rows):
    """A markdown table: header is a list of (title, right-aligned)."""
    out = "| " + " | ".join(t for t, _ in header) + " |\n"
    out += "| " + " | ".join("---:" if right else "---" for _, right in header) + " |\n"
    return out + "".join("| " + " | ".join(str(c) for c in row) + " |\n" for row in rows)


RUN_HEADER = [("run", 0), ("config", 0), ("localizations", 1), ("< 1 m", 1),
              ("wrong (> 5 m)", 1), ("mean error", 0), ("recall (20 m)", 1)]


def run_row(r):
    """A localization result's cells as the rigs and demo tables show them."""
    # Labels from a network (the demo's second half) are said beside the config's name.
    labels = r.get("labels", "perfect")
    config = r["config"] if labels == "perfect" else f"{r['config']}, {labels} labels"
    return [r["run"], config, r["n_localizations"], shown(r.get("n_error_below_1m")),
            r["n_wrong"], mean_error(r), f"{r['recall_along_trajectory']:.2f}"]


def rigs_table(inputs):
    return table([("rig", 0)] + RUN_HEADER,
                 [[label, *run_row(r)] for label, path in labelled(inputs)
                  for r in load_localization(path)["results"]])


def runs_table(inputs):
    return table(RUN_HEADER, [run_row(r) for path in inputs
                              for r in load_localization(path)["results"]])


def table_i(inputs):
    header = [("run", 0), ("config", 0), ("localizations", 1), ("< 1 m", 1), ("< 5 m", 1),
              ("wrong", 1), ("mean error", 0), ("recall", 1), ("map", 1), ("paper", 1)]
    rows = []
    for path in inputs:
        for r in load_localization(path)["results"]:
            paper = PAPER_TABLE_I.get((r["run"], r["config"]), "")
            run = f"{r['run']} ({r['frames']} frames)"
            kib = r["map_bytes"] / 1024
            rows.append([run, r["config"], r["n_localizations"], shown(r.get("n_error_below_1m")),
                         shown(r.get("n_error_below_5m")), r["n_wrong"], mean_error(r, ", "),
                         f"{r['recall_along_trajectory']:.2f}",
                         f"{r['map_segments']} segments, {kib:.1f} KiB", paper])
    return table(header, rows)


def configs_table(inputs):
    """A row per config (and odometry, when the inputs' differ): within 1 m and the mean error
    per run, the wrong ones and the recall of all runs."""
    experiments = [load_localization(path) for path in inputs]
    odometry_differs = len({e.get("query_odometry") for e in experiments}) > 1
    rows, runs = [], []
    for e in experiments:
        configs = {}
        for r in e["results"]:
            configs.setdefault(r["config"], {})[r["run"]] = r
        for config, per_run in configs.items():
            runs = runs or list(per_run)
            label = f"{config}, {e.get('query_odometry')} odometry" if odometry_differs else config
            cells = []
            for run in runs:
                r = per_run.get(run)
                cells += ([shown(r.get("n_error_below_1m")), mean_error(r)] if r else ["-", "-"])
            wrong = sum(r["n_wrong"] for r in per_run.values())
            recall = " / ".join(f"{per_run[run]['recall_along_trajectory']:.2f}"
                                for run in runs if run in per_run)
            rows.append([label, *cells, wrong, recall])
    header = [("configuration", 0)]
    for run in runs:
        header += [(f"{run} < 1 m", 1), (f"{run} mean error", 0)]
    return table(header + [("wrong", 1), ("recall " + " / ".join(runs), 1)], rows)


def results_with_labels(path, wanted):
    """The results of a localization.json whose camera labels are `wanted` ("perfect",
    "network", ...), when it holds several kinds (the demo: perfect, then the network's); a file
    of one kind gives all of its results. FILE#DIR takes the label pass whose files are in DIR
    (eval localization --labels A+B puts each pass but the first in a folder of its own)."""
    path, _, pass_dir = path.partition("#")
    results = load_localization(path)["results"]
    if pass_dir:
        found = [r for r in results if r["dir"].startswith(pass_dir + "/")]
        if not found:
            fail(f"{path}: has no label pass in {pass_dir}/")
        return found
    kinds = {r.get("labels", "perfect") for r in results}
    if len(kinds) <= 1:
        return results
    if wanted not in kinds:
        fail(f"{path}: holds results with labels {', '.join(sorted(kinds))}, not '{wanted}'")
    return [r for r in results if r.get("labels", "perfect") == wanted]


def label_noise_table(inputs):
    rows, columns = [], []
    for level, path in labelled(inputs):
        results = results_with_labels(path, "perfect")
        columns = columns or [(r["run"], r["config"]) for r in results]
        found = {(r["run"], r["config"]): r for r in results}
        cells = [shown(found[c].get("n_error_below_1m")) if c in found else "-" for c in columns]
        wrong = sum(r["n_wrong"] for r in results)
        rows.append([level, *cells, wrong])
    header = ([("label noise", 1)] + [(f"{run} {config}", 1) for run, config in columns] +
              [("wrong", 1)])
    return table(header, rows)


def label_rate_table(inputs):
    """Within 1 m per run for SemSegMap and SegMap, SemSegMap's lead (x SegMap's), with a row of
    perfect labels among them SemSegMap's share of its count with perfect labels, the wrong ones
    and the network's share of the cores, a row per way of making the camera labels."""
    found_rows, runs = [], []
    for labels, path in labelled(inputs):
        # The label names the kind to take from a file of several: "perfect", "network".
        results = results_with_labels(path, labels.split(" ")[0])
        found_rows.append((labels, results, {(r["run"], r["config"]): r for r in results}))
        runs = runs or sorted({r["run"] for r in results})

    def within_1m(found, run, config):
        return found.get((run, config), {}).get("n_error_below_1m")

    perfect = next((f for labels, _, f in found_rows if labels.split(" ")[0] == "perfect"), None)
    rows = []
    for labels, results, found in found_rows:
        row = [labels]
        for run in runs:
            sem, seg = within_1m(found, run, "semsegmap"), within_1m(found, run, "segmap")
            lead = f"{sem / seg:.2f}" if sem is not None and seg else "-"
            row += [shown(sem), shown(seg), lead]
            if perfect is not None:
                best = within_1m(perfect, run, "semsegmap")
                of = (f"{100 * sem / best:.1f} %" if sem is not None and best and found is not
                      perfect else "-")
                row.append(of)
        share = max((r.get("network_share_of_cores", 0.0) for r in results), default=0.0)
        row += [sum(r["n_wrong"] for r in results), f"{share:.2f}" if share else "-"]
        rows.append(row)
    header = [("camera labels", 0)]
    for run in runs:
        header += [(f"{run} semsegmap", 1), (f"{run} segmap", 1), (f"{run} lead", 1)]
        if perfect is not None:
            header.append((f"{run} semsegmap of perfect", 1))
    return table(header + [("wrong", 1), ("network cores", 1)], rows)


def segmentation_table(inputs):
    header = [("config", 0), ("segments", 1), ("at revisits", 1), ("IoU >= 0.33", 1),
              ("IoU < 0.33", 1)]
    rows = []
    for path in inputs:
        e = load_json(path, "results", "a segmentation.json of semsegmap eval segmentation")
        for r in e["results"]:
            seen = r["revisit_segments"]
            share = f" ({100 * r['consistent'] / seen:.0f} %)" if seen else ""
            rows.append([r["config"], r["segments"], seen, f"{r['consistent']}{share}",
                         r["inconsistent"]])
        if len(inputs) == 1 and len(e["results"]) == 2:
            paper = e.get("paper", {})
            rows.append([f"change ({e['results'][0]['config']} vs {e['results'][1]['config']})",
                         "", "",
                         f"{e['consistent_change_pct']:+.1f} % "
                         f"(paper {paper.get('consistent_change_pct', 0):+.2f} %)",
                         f"{e['inconsistent_change_pct']:+.1f} % "
                         f"(paper {paper.get('inconsistent_change_pct', 0):+.2f} %)"])
    return table(header, rows)


def descriptors_table(inputs):
    rows, bands = [], []
    for path in inputs:
        e = load_json(path, "descriptors", "a descriptors.json of semsegmap eval descriptors")
        bands = e["bands"]
        for d in e["descriptors"]:
            # A band's curve holds the share found within k = 1, 2, ...: its 16th entry is top-16.
            per_band = [f"{c[min(15, len(c) - 1)]:.3f}" if c else "-" for c in d["band_curves"]]
            rows.append([f"`{d['name']}`", f"{d['top1']:.3f}", f"{d['top16']:.3f}", *per_band,
                         f"{d['segments_per_second']:.0f}"])
    header = ([("descriptor", 0), ("top-1", 1), ("top-16", 1)] +
              [(f"top-16 {band}", 1) for band in bands] + [("segments/s", 1)])
    return table(header, rows)


def top16(curve):
    # A band's curve holds the share found within k = 1, 2, ...: its 16th entry is top-16.
    return curve[min(15, len(curve) - 1)] if curve else None


def leaders(columns, names):
    # Per column, the descriptor(s) with the highest value (ties all named).
    out = []
    for col in columns:
        values = [v for v in col if v is not None]
        if not values:
            out.append("-")
            continue
        best = max(values)
        out.append(", ".join(f"`{n}`" for n, v in zip(names, col) if v == best))
    return out


def completeness_table(inputs):
    if len(inputs) != 1:
        fail("completeness: give one descriptors.json")
    e = load_json(inputs[0], "descriptors", "a descriptors.json of semsegmap eval descriptors")
    c, w, bands = e["completeness_estimate"], e["wake_ups"], e["bands"]
    rows = [[f"{a['window_frames']}" + (" (used)" if a["window_frames"] == c["window_frames"]
                                          else ""), f"{a['spearman']:.3f}",
             f"{a['same_band']:.3f}"] for a in c["windows"]]
    out = table([("window (frames)", 1), ("Spearman", 1), ("same band", 1)], rows)
    confusion = c["agreement"]["confusion"]
    rows = [[f"true {band}", *confusion[i]] for i, band in enumerate(bands)]
    out += "\n" + table([("queries", 0)] + [(f"estimated {b}", 1) for b in bands], rows)
    names = [d["name"] for d in e["descriptors"]]
    wake = {d["name"]: d for d in w["descriptors"]}
    columns = [[top16(d["estimated_band_curves"][b]) for d in e["descriptors"]]
               for b in range(len(bands))]
    columns.append([wake[n]["top1"] if n in wake else None for n in names])
    columns.append([wake[n]["top16"] if n in wake else None for n in names])
    rows = [[f"`{n}`", *("-" if col[i] is None else f"{col[i]:.3f}" for col in columns)]
            for i, n in enumerate(names)]
    rows.append(["leads", *leaders(columns, names)])
    header = ([("descriptor", 0)] + [(f"top-16 estimated {b}", 1) for b in bands] +
              [("wake-ups top-1", 1), ("wake-ups top-16", 1)])
    out += "\n" + table(header, rows)
    out += (f"\n{e['queries']} partial observations of {e['segments']} segments on "
            f"{e['dataset']}; {w['queries']} segments of {w['wake_ups']} one-scan wake-ups "
            f"(every {w['every_frames']}th frame of {w['dataset']}).\n")
    return out


# What each benchmark measures and the target it is held to (the brief's, or none), in the order
# of the table. A benchmark of the JSON that is not listed here is left out.
BENCHMARKS = [
    ("BM_SimulateFrame", "simulator frame: LiDAR 1920 x 64 + 3 cameras 640 x 480, full world",
     "<= 150 ms", "ms"),
    ("BM_Lidar", "of which the LiDAR sweep", "", "ms"),
    ("BM_Enrich", "semantic enrichment, simulated rig, 3 cameras", "", "ms"),
    ("BM_LocalMapAndSegmentation/0", "local map + incremental segmentation per S2 frame, "
     "ground-truth poses, SemSegMap config", "<= 20 ms", "ms"),
    ("BM_LocalMapAndSegmentation/1", "the same, SegMap config", "<= 20 ms", "ms"),
    ("BM_PipelineFrontEnd", "enrichment + the same inside the pipeline on drifting odometry "
     "(the target is the local map's and segmentation's)", "<= 20 ms", "ms"),
    ("BM_LearnedDescribe/3/2", "descriptor inference, batches of 256, 2 threads: semsegmap-net",
     ">= 300 segments/s", "items"),
    ("BM_LearnedDescribe/2/2", "the same, segmap-cnn", ">= 1000 segments/s", "items"),
    ("BM_WholePipeline/0/-1", "whole pipeline per S2 frame while localizing, SemSegMap",
     ">= 20 Hz", "Hz"),
    ("BM_WholePipeline/1/-1", "the same, SegMap", ">= 20 Hz", "Hz"),
    ("BM_SegmentationNetwork/1", "camera segmentation network, one 640x480 picture, 1 thread",
     "", "ms"),
    ("BM_SegmentationNetwork/2", "the same, 2 threads", "", "ms"),
    ("BM_WholePipeline/0/0", "whole pipeline with the network on every picture", "", "Hz"),
    ("BM_WholePipeline/0/2", "the same, the network at 2 Hz per camera", "", "Hz"),
    ("BM_ShippedSegmentationNetwork/1", "the project's network (models/semsegmap-seg.onnx), one "
     "640x480 picture at 320x240, 1 thread", "<= 40 ms", "ms"),
    ("BM_WholePipeline/0/1000", "whole pipeline, SemSegMap, with the project's network beside "
     "the scans at its shipped budget (0.25 cores)", ">= 10 Hz", "Hz"),
    ("BM_WholePipeline/1/1000", "the same, SegMap", ">= 10 Hz", "Hz"),
    ("BM_WholePipeline/0/1001", "SemSegMap with the project's network on every picture, in the "
     "scan loop", "", "Hz"),
    ("BM_OdometryOurs", "LiDAR odometry, KITTI HDL-64E scans, one core", ">= 20 Hz", "items"),
    ("BM_LocalizationQuery/10000", "localization query (100 segments, k = 16) against 10k "
     "segments", "<= 5 ms", "ms"),
    ("BM_LocalizationQuery/100000", "... 100k segments", "<= 10 ms", "ms"),
    ("BM_LocalizationQuery/1000000", "... 1M segments", "<= 30 ms", "ms"),
    ("BM_Relocalize", "relocalization from one scan (120k points in its segments, the 64 "
     "nearest of each, places, registration check) against a synthetic town of 10k segments",
     "", "ms"),
    ("BM_LostFrame", "a lost frame, whole: one simulated HDL-64E scan's front end, describing, "
     "relocalization and the check of every place proposed, against world 21's map "
     "(config/lidar-camera.yaml as shipped)", "<= 150 ms", "ms"),
    ("BM_LiveLatency/10", "live session, S2 scans arriving at 10 Hz with their pictures and "
     "odometry: a scan's arrival to its pose", "<= 100 ms", "latency"),
    ("BM_LiveLatency/40", "the same fed at 40 Hz, faster than it works: it drops, its queue "
     "stays bounded", "", "latency"),
]

TO_MS = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}


def benchmark_cell(b, unit):
    ms = b["real_time"] * TO_MS[b["time_unit"]]
    if unit == "Hz":
        cell = f"{b['Hz']:.1f} Hz ({ms:.1f} ms)" if "Hz" in b else f"{1000 / ms:.1f} Hz"
        # The whole pipeline's local map and segmentation, for the rows whose target is that
        # they stay the same beside the network.
        if "map_seg_ms" in b:
            cell += f", local map + segmentation {b['map_seg_ms']:.1f} ms"
        return cell
    if unit == "items":
        return f"{b['items_per_second']:.0f} /s"
    if "search_ms" in b:
        return f"{ms:.1f} ms (search {b['search_ms']:.1f} ms)"
    if "map_seg_ms" in b:
        return f"{ms:.1f} ms (local map + segmentation {b['map_seg_ms']:.1f} ms)"
    if unit == "latency":
        return (f"{b['latency_ms']:.1f} ms on average (the pipeline's own "
                f"{b['pipeline_ms']:.1f}), {b['max_latency_ms']:.0f} at most; "
                f"{b['dropped']:.0f} of {b['processed'] + b['dropped']:.0f} frames dropped, "
                f"at most {b['max_queued']:.0f} queued")
    if "localized" in b and "scans" in b:
        return (f"{ms:.1f} ms ({100 * b['localized']:.0f} % of {b['scans']:.0f} wake-ups "
                f"within 1 m, {100 * b['wrong']:.0f} % wrong)")
    if "relocalized" in b:
        return (f"{ms:.1f} ms ({100 * b['relocalized']:.0f} % relocalized, "
                f"{100 * b['wrong']:.0f} % wrong)")
    return f"{ms:.1f} ms"


def machine_line(inputs):
    """Where and when the benchmarks ran, from Google Benchmark's own context."""
    c = load_json(inputs[0], "context", "a Google Benchmark JSON (--benchmark_out)")["context"]
    return (f"\nMeasured on {c.get('num_cpus', '?')} CPUs at {c.get('mhz_per_cpu', '?')} MHz, "
            f"{c.get('date', '?')[:10]}.\n")


def benchmarks_by_name(inputs):
    """The benchmarks of Google Benchmark JSON files by name, without its /real_time suffixes:
    of repetitions the fastest, with its own counters. Other work on a shared machine only ever
    slows a run down, so the fastest of several is the least disturbed one, and it moves less
    from run to run than their mean. Without the single runs (aggregates only) the mean."""
    found = {}
    for path in inputs:
        data = load_json(path, "benchmarks", "a Google Benchmark JSON (--benchmark_out)")
        singles, means = {}, {}
        for b in data["benchmarks"]:
            name = re.sub(r"/(real_time|min_time:[0-9.]+|iterations:[0-9]+|repeats:[0-9]+)", "",
                          b.get("run_name", b["name"]))
            if b.get("run_type") == "aggregate":
                if b.get("aggregate_name") == "mean":
                    means[name] = b
            elif name not in singles or b["real_time"] < singles[name]["real_time"]:
                singles[name] = b
        found.update(means)
        found.update(singles)
    return found


def benchmarks_table(inputs):
    found = benchmarks_by_name(inputs)
    rows = [[what, f"`{name}`", target, benchmark_cell(found[name], unit)]
            for name, what, target, unit in BENCHMARKS if name in found]
    if not rows:
        fail(f"{', '.join(inputs)}: none of the benchmarks the table shows")
    return (table([("what", 0), ("benchmark", 0), ("target", 0), ("measured", 0)], rows) +
            machine_line(inputs))


def memory_table(inputs):
    """The resident set while localizing, at each kilometre, and its growth after the first."""
    runs = []
    for label, path in labelled(inputs):
        try:
            with open(path, encoding="utf-8") as f:
                samples = [(float(r["distance_m"]) / 1000, float(r["rss_mb"]))
                           for r in csv.DictReader(f) if r["phase"] == "localize"]
        except (OSError, KeyError, ValueError) as e:
            fail(f"{path}: not an rss.csv of semsegmap_memory_run: {e}")
        if not samples or samples[-1][0] < 1:
            fail(f"{path}: localized less than 1 km, too short to measure growth")
        runs.append((label, samples))
    # Whole kilometres, one set of columns for every run (the longest decides); beyond 10 km every
    # few kilometres (at most about ten columns), the first kept.
    longest = max(samples[-1][0] for _, samples in runs)
    step = max(1, math.ceil(longest / 10))
    kms = sorted({0, 1, *range(0, int(longest) + 1, step)})

    def row(label, samples):
        # The first sample at or after each kilometre, as the run prints it; blank past its end.
        at_km = [next((f"{mb:.0f}" for km, mb in samples if km >= k), "") for k in kms]
        at_1km = next(mb for km, mb in samples if km >= 1)
        growth = 100 * (max(mb for km, mb in samples if km >= 1) - at_1km) / at_1km
        last = samples[-1]
        return [label, *at_km, f"{last[1]:.0f} ({last[0]:.1f} km)", f"{growth:+.1f} %"]

    header = ([("run", 0)] + [(f"{k} km", 1) for k in kms] +
              [("at the end", 1), ("growth after 1 km", 1)])
    return table(header, [row(label, samples) for label, samples in runs])


def slam_table(inputs):
    header = [("run", 0), ("frames", 1), ("loop closures", 1), ("ATE odometry", 1),
              ("ATE loop-closed", 1), ("aligned: odometry", 1), ("aligned: loop-closed", 1)]
    rows = []
    for label, path in labelled(inputs):
        s = load_json(path, "loop_closures", "a summary.json of semsegmap slam")
        rmse = lambda key: "-" if s.get(key) is None else f"{s[key]['rmse_m']:.2f} m"  # noqa
        rows.append([label, s["frames"], s["loop_closures"], rmse("ate_odometry"),
                     rmse("ate_slam"), rmse("ate_odometry_aligned"), rmse("ate_slam_aligned")])
    return table(header, rows)


def segments_table(inputs):
    header = [("config", 0), ("segments", 1), ("mean points", 1), ("mean purity", 1)]
    rows = []
    for label, path in labelled(inputs):
        try:
            with open(path, encoding="utf-8") as f:
                segments = [(int(r["points"]), r["gt_purity"]) for r in csv.DictReader(f)]
        except (OSError, KeyError, ValueError) as e:
            fail(f"{path}: not a segments.csv of semsegmap segment: {e}")
        if not segments or any(purity == "" for _, purity in segments):
            fail(f"{path}: no segments with ground-truth purity (a run on the simulator has it)")
        n = len(segments)
        rows.append([label, n, f"{sum(p for p, _ in segments) / n:.0f}",
                     f"{sum(float(q) for _, q in segments) / n:.3f}"])
    return table(header, rows)


def odometry_table(inputs):
    header = [("input", 0), ("frames", 1), ("KITTI translation", 1), ("KITTI rotation", 1),
              ("ATE (first pose anchored / aligned)", 0), ("frames on the prediction alone", 1)]
    rows = []
    for label, path in labelled(inputs):
        s = load_json(path, "kitti_relative_error", "a summary.json of semsegmap odometry")
        kitti, ate, aligned = s["kitti_relative_error"], s.get("ate"), s.get("ate_aligned")
        if kitti is None or kitti.get("translation_percent") is None or not ate or not aligned:
            fail(f"{path}: the run has no ground truth, or is too short for the KITTI error")
        used = sum(s["diagnostics"]["prediction_used"].values())
        rows.append([label, s["frames"], f"{kitti['translation_percent']:.2f} %",
                     f"{kitti['rotation_deg_per_100m']:.3f} deg/100 m",
                     f"{ate['rmse_m']:.2f} m / {aligned['rmse_m']:.2f} m",
                     used])
    return table(header, rows)


def load_revisits(path):
    return load_json(path, "results", "a revisits.json of semsegmap eval revisits")


def revisit_method(r):
    """Which method gave a row: the segments and their descriptor, or Scan Context's whole
    scans. Files written before Scan Context have segment rows alone, and no method."""
    method = r.get("method", "segments")
    if method == "scan-context":
        return "Scan Context (whole scan)"
    return f"{method} ({r['descriptor']})"


def ms_per_query(r):
    ms = r.get("ms_per_query")
    return "-" if ms is None else f"{ms:.1f}"


def revisits_table(inputs):
    header = [("config", 0), ("method", 0), ("localizations", 1), ("< 0.5 m", 1), ("< 1 m", 1),
              ("< 5 m", 1), ("wrong (> 5 m)", 1), ("mean error", 0),
              ("revisits localized (< 1 m)", 1), ("registered truth < 0.3 m", 1),
              ("ms / query", 1)]
    rows = []
    for path in inputs:
        e = load_revisits(path)
        for r in e["results"]:
            compared = r.get("n_registered_compared") or 0
            rows.append([r["config"], revisit_method(r), r["n_localizations"],
                         r["n_error_below_0_5m"], r["n_error_below_1m"], r["n_error_below_5m"],
                         r["n_wrong"], mean_error(r),
                         f"{r['n_revisits_localized']} of {e['n_revisits']}",
                         f"{r['n_registered_below_0_3m']} of {compared}" if compared else "-",
                         ms_per_query(r)])
    return table(header, rows)


WAKE_UP_BY = (1, 2, 3, 5, 10)


def wake_ups_table(inputs):
    """One revisits.json, or RIG=FILE for each of several (a column names the rig)."""
    runs = labelled(inputs) if any("=" in i for i in inputs) else [(None, i) for i in inputs]
    rig = [("rig", 0)] if runs[0][0] is not None else []
    loaded = [(label, path, load_revisits(path)) for label, path in runs]
    # Up to the frames a wake-up was given: a one-scan wake-up has no second frame.
    frames = max(e.get("wake_up_frames") or WAKE_UP_BY[-1] for _, _, e in loaded)
    by_frame = [k for k in WAKE_UP_BY if k <= frames]
    header = (rig + [("config", 0), ("method", 0), ("wake-ups at a revisit", 1)] +
              [(f"by frame {k}", 1) for k in by_frame] +
              [("first localization wrong", 1), ("wrong poses, any wake-up", 1),
               ("ambiguous", 1), ("within 3 sigma", 1), ("mean NEES", 1), ("median sigma", 1),
               ("ms / query", 1)])
    rows = []
    for label, path, e in loaded:
        for r in e["results"]:
            at_revisit = [w for w in r["wake_ups"] if w["revisit"]]
            if not r["wake_ups"]:
                fail(f"{path}: no wake-ups (run eval revisits with --wake-up N[/EVERY])")
            by = [sum(1 for w in at_revisit if w["localized_at_frame"] is not None
                      and w["localized_at_frame"] <= k) for k in by_frame]
            wrong = sum(1 for w in r["wake_ups"] if w["wrong_first"])
            rows.append(([label] if rig else []) +
                        [r["config"], revisit_method(r), len(at_revisit), *by, wrong,
                         r["n_wrong"], r.get("n_ambiguous", "-"), *calibration_cells(r),
                         ms_per_query(r)])
    return table(header, rows)


def calibration_cells(r):
    """The share within 3 sigma, the mean NEES and the median sigma of a result's poses."""
    c = r.get("covariance_calibration") or {}
    share, nees, sigma = (c.get(k) for k in ("share_mahalanobis_within_3", "mean_nees",
                                             "median_sigma_m"))
    return (f"{100 * share:.0f} %" if share is not None else "-",
            f"{nees:.2f}" if nees is not None else "-",
            f"{sigma:.2f} m" if sigma is not None else "-")


# The registrations the odometry was chosen among (bench/bench_odometry.cpp), in table order.
REGISTRATIONS = [("BM_OdometryOurs", "ours: scan to voxel map, point-to-plane, Geman-McClure"),
                 ("BM_OdometryPclNdt", "PCL NDT (1 m cells)"),
                 ("BM_OdometryOpen3dIcpPointToPlane", "Open3D ICP point-to-plane (normals r = 1 m)"),
                 ("BM_OdometryPclGicp", "PCL GICP"),
                 ("BM_OdometryOpen3dGicp", "Open3D GICP"),
                 ("BM_OdometryPclIcpPointToPlane", "PCL ICP point-to-plane (normals r = 1 m)")]


def registration_table(inputs):
    found = benchmarks_by_name(inputs)
    rows = []
    for name, what in REGISTRATIONS:
        b = found.get(name)
        if b is None:
            continue
        rate = b["items_per_second"]
        verdict = "yes" if rate >= 20 else f"no: {20 / rate:.1f} times too slow"
        rows.append([what, f"{rate:.1f}", f"{b['t_err_m']:.3f} m, {b['r_err_deg']:.3f} deg",
                     verdict])
    if not rows:
        fail(f"{', '.join(inputs)}: no odometry benchmarks (BM_Odometry*)")
    return (table([("registration", 0), ("scans / s (one core)", 1),
                   ("frame-to-frame error", 0), ("meets 20 Hz?", 0)], rows) + machine_line(inputs))


def fleet_table(inputs):
    """The sessions of `eval fleet` merged into one map, and the fifth run against it."""
    if len(inputs) != 1:
        fail("the fleet table takes one fleet.json")
    e = load_json(inputs[0], "sessions", "a fleet.json of semsegmap eval fleet")
    header = [("session", 0), ("frames", 1), ("aligned", 0), ("localizations", 1),
              ("entries", 1), ("of segments the map held", 1), ("tie residual", 1),
              ("trajectory error", 1), ("centroid error", 1)]
    rows = []
    for i, r in enumerate(e["sessions"]):
        aligned = "map frame" if i == 0 else ("yes" if r["aligned"] else "no")
        rows.append([r["run"], r["frames"], aligned, r["localizations"], r["entries"],
                     r["same_segments"], f"{r['tie_residual_m']:.2f} m",
                     f"{r['trajectory_error_m']:.2f} m", f"{r['centroid_error_m']:.2f} m"])
    out = table(header, rows)
    out += (f"\nMerged map: {e['entries']} entries of {e['segments']} segments; centroids "
            f"{e['centroid_mean_m']:.2f} m from the truth on average (median "
            f"{e['centroid_median_m']:.2f} m) after one rigid alignment to the world.\n")
    if e.get("interrupted"):
        out += "\nThe run was interrupted: these numbers are partial.\n"
    if not e.get("queries"):
        return out
    first = e["sessions"][0]["run"]
    header = [("run", 0), ("frames", 1), ("against", 0), ("localizations", 1),
              ("within 1 m", 1), ("wrong (> 5 m)", 1)]
    rows = []
    for q in e["queries"]:
        for key, against in (("merged", "the merged map"), ("first", f"{first} alone")):
            r = q[key]
            rows.append([q["run"], q["frames"], against, r["localizations"], r["within_1m"],
                         r["wrong"]])
    return out + "\n" + table(header, rows)


TABLES = {"rigs": rigs_table, "runs": runs_table, "table-i": table_i, "configs": configs_table,
          "label-noise": label_noise_table, "label-rate": label_rate_table,
          "segmentation": segmentation_table,
          "descriptors": descriptors_table, "completeness": completeness_table,
          "benchmarks": benchmarks_table,
          "memory": memory_table, "slam": slam_table,
          "segments": segments_table, "odometry": odometry_table,
          "revisits": revisits_table, "wake-ups": wake_ups_table,
          "registration": registration_table, "fleet": fleet_table}


def replace_section(text, section, new_table, doc):
    begin, end = f"<!-- results:{section} -->\n", f"<!-- /results:{section} -->"
    start = text.find(begin)
    stop = text.find(end, start + 1) if start >= 0 else -1
    if start < 0 or stop < 0:
        fail(f"{doc}: no section '{section}' (lines {begin.strip()} and {end})")
    return text[:start + len(begin)] + new_table + text[stop:]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("section")
    parser.add_argument("inputs", nargs="+", metavar="INPUT")
    parser.add_argument("--table", choices=sorted(TABLES), default="rigs")
    parser.add_argument("--doc", default=os.path.join(os.path.dirname(__file__), "..", "docs",
                                                      "results.md"))
    args = parser.parse_args()
    new_table = TABLES[args.table](args.inputs)
    try:
        with open(args.doc, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        fail(f"{args.doc}: {e.strerror}")
    text = replace_section(text, args.section, new_table, args.doc)
    tmp = args.doc + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, args.doc)
    print(f"wrote section {args.section} of {args.doc}")


if __name__ == "__main__":
    main()
