#!/usr/bin/env python3
"""Writes a results table of docs/results.md from the eval commands' JSON, so that rerunning the
commands regenerates the numbers instead of someone copying them by hand.

    scripts/write_results.py SECTION LABEL=DIR/localization.json [LABEL=...] [--doc FILE]

Each LABEL=FILE is the localization.json of one `semsegmap eval localization` run (LABEL names
its rig in the table). The table replaces what stands between the lines
`<!-- results:SECTION -->` and `<!-- /results:SECTION -->` of the document; a missing section is
an error naming the document, so that a typo never appends a second table. The document is
written to a temporary name and renamed, so an interrupted run leaves the old one whole.
"""
import argparse
import json
import os
import sys

HEADER = ("| rig | run | config | localizations | < 1 m | wrong (> 5 m) | mean error "
          "| recall (20 m) |\n| --- | --- | --- | ---: | ---: | ---: | --- | ---: |\n")


def shown(value):
    """A count as the table shows it: "-" for one the run did not know (null)."""
    return "-" if value is None else value


def rows(label, path):
    try:
        with open(path, encoding="utf-8") as f:
            experiment = json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"{path}: cannot read the localization results: {e}")
    if "results" not in experiment:
        sys.exit(f"{path}: not a localization.json of semsegmap eval localization (no results)")
    out = []
    for r in experiment["results"]:
        # Unknown values (no localization, no ground truth) are null: shown as "-", never 0.
        translation, rotation = r.get("mean_translation_error_m"), r.get("mean_rotation_error_deg")
        error = (f"{translation:.2f} m / {rotation:.2f} deg"
                 if r["n_localizations"] and translation is not None and rotation is not None
                 else "-")
        below_1m = shown(r.get("n_error_below_1m"))
        out.append(f"| {label} | {r['run']} | {r['config']} | {r['n_localizations']} "
                   f"| {below_1m} | {r['n_wrong']} | {error} "
                   f"| {r['recall_along_trajectory']:.2f} |\n")
    return out


def replace_section(text, section, table, doc):
    begin, end = f"<!-- results:{section} -->\n", f"<!-- /results:{section} -->"
    start = text.find(begin)
    stop = text.find(end, start + 1) if start >= 0 else -1
    if start < 0 or stop < 0:
        sys.exit(f"{doc}: no section '{section}' (lines {begin.strip()} and {end})")
    return text[:start + len(begin)] + table + text[stop:]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("section")
    parser.add_argument("runs", nargs="+", metavar="LABEL=FILE")
    parser.add_argument("--doc", default=os.path.join(os.path.dirname(__file__), "..", "docs",
                                                      "results.md"))
    args = parser.parse_args()
    table = HEADER
    for run in args.runs:
        label, sep, path = run.partition("=")
        if not sep or not label or not path:
            sys.exit(f"expected LABEL=FILE, got '{run}'")
        table += "".join(rows(label, path))
    try:
        with open(args.doc, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        sys.exit(f"{args.doc}: {e.strerror}")
    text = replace_section(text, args.section, table, args.doc)
    tmp = args.doc + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, args.doc)
    print(f"wrote section {args.section} of {args.doc}")


if __name__ == "__main__":
    main()
