#!/usr/bin/env bash
# The map store's scale benchmark ([fleet]; docs/map-store.md, "At scale (bench)"): builds the
# benchmark and, when missing, the two simulated maps it needs, runs it (niced: the machine is
# shared) and writes its numbers into docs/map-store.md, between the lines
# `<!-- store-bench:begin -->` and `<!-- store-bench:end -->` (everything between them is
# rewritten; nothing else in the document is touched).
#
#   scripts/bench_map_store.sh [--segments N] [--table-only] [-- BENCH_OPTIONS...]
#
# --segments: the store's size (default 10 000 000: about 35 minutes on 2 shared cores, most of
# them building the file map's index; at the peak about 12 GB in /tmp, the server's folder with
# its write-ahead log and the city's map file, and 9 GB of memory). --table-only: rewrite the section from the
# JSON of the last run without measuring. BENCH_OPTIONS go to semsegmap_store_bench (--help).
# The maps are data/bench/s0.map (the tiled source) and data/bench/s2.map (the queries); delete
# them after a change of the descriptor model or config/semsegmap.yaml.
set -euo pipefail
cd "$(dirname "$0")/.."

segments=10000000
table_only=0
bench_options=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --segments)
      [[ $# -ge 2 ]] || { echo "bench_map_store.sh: --segments needs a number" >&2; exit 2; }
      segments="$2"
      shift 2
      ;;
    --table-only) table_only=1; shift ;;
    --) shift; bench_options=("$@"); break ;;
    *) echo "bench_map_store.sh: unknown argument '$1' (see the top of $0)" >&2; exit 2 ;;
  esac
done

out=data/bench
json=$out/store-bench.json
if [[ $table_only == 0 ]]; then
  mkdir -p "$out"
  targets=(semsegmap_store_bench)
  [[ -f $out/s0.map && -f $out/s2.map ]] || targets+=(semsegmap)
  flock /tmp/semsegmap-build.lock cmake --build build -j2 --target "${targets[@]}"
  for run in S0 S2; do
    map=$out/$(echo "$run" | tr 'S' 's').map
    [[ -f $map ]] || nice -n 10 build/semsegmap map --dataset "sim:world=1,run=$run" \
      --config config/semsegmap.yaml --out "$map"
  done
  start=$(date +%s)
  nice -n 10 build/bench/semsegmap_store_bench --source "$out/s0.map" --queries "$out/s2.map" \
    --segments "$segments" --json "$json" "${bench_options[@]}" 2>&1 | tee "$out/store-bench.log"
  echo "bench_map_store.sh: the bench took $(( ($(date +%s) - start) / 60 )) min"
fi

python3 - "$json" docs/map-store.md <<'PY'
import json
import os
import re
import sys
import textwrap

json_path, doc = sys.argv[1], sys.argv[2]
BEGIN, END = "<!-- store-bench:begin -->", "<!-- store-bench:end -->"
try:
    with open(json_path, encoding="utf-8") as f:
        d = json.load(f)
except (OSError, ValueError) as e:
    sys.exit(f"bench_map_store.sh: {json_path}: cannot read the bench's results: {e}")
if d.get("schema") != "semsegmap.store-bench/1":
    sys.exit(f"bench_map_store.sh: {json_path}: not the JSON of semsegmap_store_bench")
if not d.get("complete"):
    sys.exit(f"bench_map_store.sh: {json_path}: the bench did not finish (see {json_path[:-5]}.log)")


def n(v):
    """A count with thin groups: 10 000 000."""
    return f"{int(round(v)):,}".replace(",", " ")


def ms(v):
    if v < 0.05:
        return "< 0.1 ms"
    return f"{v:.0f} ms" if v >= 100 else f"{v:.1f} ms"


def sec(v):
    if v >= 5400:
        return f"{v / 3600:.1f} h"
    return f"{v / 60:.0f} min" if v >= 120 else f"{v:.1f} s"


def gb(v):
    return f"{v / 1e9:.2f} GB"


def verdict(value, limit):
    return "met" if value <= limit else "**not met**"


m, src, city, b = d["machine"], d["source"], d["city"], d["build"]
r, ins, loc, server = d["region_load"], d["insert"], d["localization"], d["server"]
cmd = d["command"]
radii = r["radii"]
main, square = radii[0], radii[1]
big = radii[2]
rows = []


def row(what, measured, target=""):
    rows.append(f"| {what} | {measured} | {target} |")


row("machine", f"{m['nproc']} cores ({m['cpu']}), {m['memory_gb']:.1f} GB; PostgreSQL "
    f"{server['postgresql'].split()[0]} + PostGIS {server['postgis']} on the same machine, over "
    "a Unix socket; load average {0} at the start, {1} at the end".format(
        m["load_average_at_start"].split()[0], m["load_average_at_end"].split()[0]))
row("store", f"{n(city['segments'])} segments (observations) in {n(city['tiles'])} sessions",
    "10 million")
row("the city", f"run S0's map of world 1 ({n(src['entries'])} segments over "
    f"{src['extent_m'][0]:.0f} m x {src['extent_m'][1]:.0f} m, {src['descriptor']} descriptors "
    f"of dimension {src['dimension']}) copied to a {city['columns']} x {city['rows']} grid, "
    f"{cmd['margin_m']:.0f} m between copies: {city['extent_m'][0] / 1000:.1f} km x "
    f"{city['extent_m'][1] / 1000:.1f} km, {n(city['area_km2'])} km²")
tenths = b["tile_ms_median_by_tenth"]
row("build", f"{sec(b['seconds'])}: one `addSession` per tile, median {ms(b['tile_ms']['median'])}"
    f" ({ms(tenths[0])} in the first tenth, {ms(tenths[-1])} in the last); then VACUUM ANALYZE "
    f"{sec(b['vacuum_analyze_s'])}")
row("database size", f"{gb(b['database_bytes'])} (`pg_database_size`): the segments' table "
    f"{gb(b['segments_table_bytes'])}, its indexes {gb(b['segments_index_bytes'])} (the "
    f"centroids' GiST {gb(b['centroid_index_bytes'])})")
row(f"region load, {main['radius_m']:.0f} m disc, first (cold)",
    f"median {ms(r['cold_ms']['median'])}, p95 {ms(r['cold_ms']['p95'])}, at {r['places']} places; "
    f"{n(r['entries']['median'])} entries (median, {n(r['entries']['min'])}-"
    f"{n(r['entries']['max'])})", f"≤ 50 ms: {verdict(r['cold_ms']['median'], 50)}")
row(f"region load, {main['radius_m']:.0f} m disc, warm",
    f"median {ms(r['warm_ms']['median'])}, p95 {ms(r['warm_ms']['p95'])}",
    f"≤ 50 ms: {verdict(r['warm_ms']['median'], 50)}")
for x in (square, big):
    what = ("the disc around the 200 m square" if x is square
            else f"the docs' example, `region=0,0,{x['radius_m']:.0f}`")
    row(f"region load, {x['radius_m']:.0f} m disc ({what}), warm",
        f"median {ms(x['warm_ms']['median'])}, p95 {ms(x['warm_ms']['p95'])}; "
        f"{n(x['entries']['median'])} entries; without parallel query: median "
        f"{ms(x['warm_ms_without_parallel_query']['median'])}, p95 "
        f"{ms(x['warm_ms_without_parallel_query']['p95'])}",
        f"≤ 50 ms: {verdict(x['warm_ms']['median'], 50)}" if x is square else "")
row(f"insert a {n(ins['entries'])}-segment session",
    f"median {ms(ins['ms']['median'])}, p95 {ms(ins['ms']['p95'])}, max {ms(ins['ms']['max'])} "
    f"({ins['ms']['n']} sessions, `addSession`, durable server)",
    f"≤ 1 s: {verdict(ins['ms']['median'], 1000)}")


def recall(x):
    return f"{x['correct']}/{loc['queries']} ({x['recall']:.2f})"


def retrieved(x):
    share = x["segments_with_a_true_candidate"]
    return (f"a segment's true match among its {loc['k']} nearest descriptors: "
            f"{100 * share['mean']:.0f} % of a query's segments (mean)")


reg = loc["region"]
row("localization against the region",
    f"recall {recall(reg)}; {reg['wrong_over_5m']} wrong; {retrieved(reg)}; per query median "
    f"{ms(reg['total_ms']['median'])} (p95 {ms(reg['total_ms']['p95'])}): load "
    f"{ms(reg['load_ms']['median'])} ({n(reg['entries']['median'])} entries), index "
    f"{ms(reg['index_ms']['median'])}, localize {ms(reg['localize_ms']['median'])}")
if "file" in loc:
    f = loc["file"]
    row("localization against the file map of the whole city",
        f"recall {recall(f)}; {f['wrong_over_5m']} wrong, {f['wrong_in_another_tile']} of them "
        f"at the right place of another copy; {retrieved(f)}; localize median {ms(f['localize_ms']['median'])} "
        f"(p95 {ms(f['localize_ms']['p95'])}) after loading the file ({gb(f['bytes'])}) in "
        f"{sec(f['load_s'])} and building its index ({n(f['index_lists'])} IVF lists) in "
        f"{sec(f['index_s'])}" +
        (f" ({sec(f['index_cpu_s'])} of CPU)" if "index_cpu_s" in f else
         " (wall time, on the shared cores)"))
else:
    row("localization against the file map of the whole city", "not measured (--no-file-map)")
one = loc["single_tile"]
row("localization against the source map alone (one copy)",
    f"recall {recall(one)}; {one['wrong_over_5m']} wrong; {retrieved(one)}; localize median "
    f"{ms(one['localize_ms']['median'])}")
if "whole_load" in d:
    row("the whole map from the store", f"{sec(d['whole_load']['seconds'])} for "
        f"{n(d['whole_load']['entries'])} entries (what `map --into` on a store loads first)")
row("the run", f"{sec(d['seconds'])} in all; peak memory of the bench {d['peak_rss_mb'] / 1000:.1f} GB")

share = 100.0 * 3.141592653589793 / 4.0
def prose(paragraph):
    """One paragraph wrapped at 100 columns, never inside a number such as 10 000 000."""
    glued = re.sub(r"(?<=\d) (?=\d{3}\b)", "\x00", " ".join(paragraph.split()))
    return textwrap.fill(glued, width=100, break_on_hyphens=False).replace("\x00", " ")


parallel = ""
if big["warm_ms"]["median"] > 2 * big["warm_ms_without_parallel_query"]["median"]:
    parallel = f""" PostgreSQL plans a larger disc with a parallel worker, and starting it
costs more than the query: the {big['radius_m']:.0f} m disc loads in {ms(big['warm_ms']['median'])}
(median) as the store asks, in {ms(big['warm_ms_without_parallel_query']['median'])} through a
connection without parallel query (`&options=-c%20max_parallel_workers_per_gather%3D0` in the URI,
which passes it to libpq)."""
method = prose(f"""The city is the target map of run S0 of world 1 (`semsegmap map`, `config/semsegmap.yaml`)
copied over a grid, each copy shifted by the map's extent plus {cmd['margin_m']:.0f} m so that no
two overlap, until {n(city['segments'])} segments; each copy is one session with an empty
trajectory, written by the library's own path (`PgMapStore::create` for the first,
`addSession` for the others, one transaction each: no bulk path). The server is the tests'
(`tests/pg_cluster.h`), on this machine: built with fsync off, then restarted for the
measurements with fsync, full-page writes and synchronous commit on and 1 GB of shared buffers,
its files written out and evicted from the page cache (`posix_fadvise`), so that the first load
of a place reads the disk. A region is a disc: the 200 m x 200 m target is measured as the disc
of {main['radius_m']:.0f} m inscribed in it ({share:.1f} % of its area) and as the disc around it
({square['radius_m']:.0f} m, a superset of its entries). A load is timed from the call of
`PgMapStore::load` to the map it returns; the connection is made before (once,
{ms(r['connect_ms'])}) and not timed. Each of {r['places']} places, uniform over the city, is
loaded once cold, then again warm.{parallel} The
inserts are sessions of {n(ins['entries'])} entries at new places beside the city, on the durable
server, dropped again afterwards.""")
queries = prose(f"""The localization queries are a robot's segments of another drive: run S2's map of the same world
({loc['queries']} places, its segments within {cmd['query_radius_m']:.0f} m of one of them,
{n(loc['local_segments']['median'])} a query in the median, turned into a local frame by a random
yaw), each put into a random copy. The localizer is the project's (k = {loc['k']} nearest
descriptors, then geometric verification); a query is found when its pose is within
{loc['correct_within']['m']:.0f} m and {loc['correct_within']['deg']:.0f} degrees of the truth. Each query
is localized against the region loaded around its true place (the load, the index and the
localization timed for each query) and against a file map of the very same segments
(`saveTargetMap` of the whole city, loaded and indexed once, each timed apart). Every copy of the city is exact, so in the file map each place has
{n(city['tiles'] - 1)} look-alikes with the very same descriptors: a local segment's
{loc['k']} nearest descriptors are those of {loc['k']} copies, which copies is the index's
choice, and the verification finds the place, consistently, in one of them: the wrong place.
This is the point of loading a region; a real city has no exact copies, but its look-alikes
(facades, trees, parked cars) grow with the map in the same way. The source map alone, one copy
without look-alikes, is the reference the region should match.""")
text = f"""{BEGIN}
Written by `scripts/bench_map_store.sh` from `data/bench/store-bench.json`; rerun it rather than
edit these numbers:

```sh
scripts/bench_map_store.sh                      # 10 million segments; --segments N for fewer
scripts/bench_map_store.sh --table-only         # this section again from the last run's JSON
```

{method}

{queries}

| what | measured | target |
| --- | --- | --- |
""" + "\n".join(rows) + f"\n{END}"

with open(doc, encoding="utf-8") as fh:
    current = fh.read()
if current.count(BEGIN) != 1 or current.count(END) != 1 or current.index(BEGIN) > current.index(END):
    sys.exit(f"bench_map_store.sh: {doc}: needs one '{BEGIN}' and one '{END}' after it")
new = current[:current.index(BEGIN)] + text + current[current.index(END) + len(END):]
tmp = doc + ".tmp"
with open(tmp, "w", encoding="utf-8") as fh:
    fh.write(new)
os.replace(tmp, doc)
print(f"bench_map_store.sh: wrote the store-bench section of {doc}")
PY
