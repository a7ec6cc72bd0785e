#!/usr/bin/python3
"""Prints the per-class IoU of a `semsegmap eval labels` run (its labels.json) as a Markdown
table: one column per dataset and one for all of them, then mIoU (with and without sky), pixel
accuracy and the time per picture. models/MODEL_CARD.md's table of the segmentation network is
this script's output, so that no number is typed by hand.

Usage: labels_table.py DIR/labels.json
"""
import json
import sys


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    with open(sys.argv[1]) as f:
        e = json.load(f)
    columns = [(d["dataset"], d) for d in e["datasets"]] + [("all", e["all"])]
    print("| class | " + " | ".join(f"`{name}`" for name, _ in columns) + " |")
    print("| --- |" + " ---: |" * len(columns))
    for name in e["all"]["classes"]:
        cells = []
        for _, d in columns:
            c = d["classes"].get(name)
            cells.append(f"{c['iou']:.3f}" if c else "-")
        print(f"| {name} | " + " | ".join(cells) + " |")
    for key, label in [("miou", "**mIoU** (all truth classes but unknown)"),
                       ("miou_without_sky", "mIoU without sky"),
                       ("pixel_accuracy", "pixel accuracy")]:
        print(f"| {label} | " + " | ".join(f"{d[key]:.3f}" for _, d in columns) + " |")
    print("| pictures | " + " | ".join(str(d["pictures"]) for _, d in columns) + " |")
    print(f"\n{e['ms_per_picture']:.1f} ms per picture ({e['model']}, at the cameras' 640x480)")


if __name__ == "__main__":
    main()
