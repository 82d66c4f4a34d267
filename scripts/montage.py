#!/usr/bin/python3
"""Lays out labelled panels into one figure: scripts/montage.py LAYOUT.json OUT.png

LAYOUT.json: {"title": str, "columns": int, "panels": [{"image": PNG path, "label": str}, ...]}.
Panels are placed row by row, each image at its own pixel size (all panels of a figure have one
size), its label (one to three lines) under it. Written by `clothsim figures` (app/figures.cpp);
needs Debian's python3-matplotlib. Exit status 3: matplotlib missing; 2: bad input.
"""
import json
import math
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.image as mpimg
    import matplotlib.pyplot as plt
except ImportError:
    sys.exit(3)


def main():
    if len(sys.argv) != 3:
        print("usage: montage.py LAYOUT.json OUT.png", file=sys.stderr)
        return 2
    with open(sys.argv[1], encoding="utf-8") as f:
        layout = json.load(f)
    panels = layout["panels"]
    if not panels:
        print("montage.py: no panels", file=sys.stderr)
        return 2
    images = [mpimg.imread(p["image"]) for p in panels]
    height, width = images[0].shape[0], images[0].shape[1]
    columns = max(1, min(int(layout.get("columns", 3)), len(panels)))
    rows = math.ceil(len(panels) / columns)
    dpi = 100.0
    label_px = 58  # room for three lines of 9-pt text under each panel
    title_px = 40
    fig_w = columns * width / dpi
    fig_h = (rows * (height + label_px) + title_px) / dpi
    fig = plt.figure(figsize=(fig_w, fig_h), dpi=dpi)
    fig.text(0.5, 1.0 - 0.5 * title_px / (fig_h * dpi), layout.get("title", ""), ha="center", va="center",
             fontsize=11, fontweight="bold")
    for i, (panel, image) in enumerate(zip(panels, images)):
        r, c = divmod(i, columns)
        top = title_px + r * (height + label_px)
        ax = fig.add_axes([c * width / (fig_w * dpi), 1.0 - (top + height) / (fig_h * dpi),
                           width / (fig_w * dpi), height / (fig_h * dpi)])
        ax.imshow(image, interpolation="nearest")
        ax.set_axis_off()
        fig.text((c + 0.5) * width / (fig_w * dpi), 1.0 - (top + height + 4) / (fig_h * dpi), panel["label"],
                 ha="center", va="top", fontsize=9, linespacing=1.25)
    fig.savefig(sys.argv[2], dpi=dpi, facecolor="white", metadata={"Software": None})
    plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main())
