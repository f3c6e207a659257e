"""Layout shared by the plot scripts: a legend beside the axes, never over the data, and point
labels that do not overprint each other or the points.

    fig, ax = plt.subplots()
    ...                                    # draw everything, set limits
    plot_layout.legend_beside(fig, handles, side="right")   # lays the figure out, legend outside
    plot_layout.place_labels(ax, xs, ys, names)             # after the layout: labels in free space
    fig.savefig(...)                                         # no tight_layout after these
"""
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.text import Text


def legend_beside(fig, handles, side="right", **kw):
    """A figure legend at the right edge (side="right") or along the bottom (side="bottom") of
    `fig`, and the axes laid out (tight_layout) in the rest of the figure: the legend covers no
    data. Returns the legend."""
    kw.setdefault("fontsize", 7)
    if side == "right":
        legend = fig.legend(handles=handles, loc="center right", bbox_to_anchor=(1.0, 0.5), **kw)
    else:
        legend = fig.legend(handles=handles, loc="lower center", bbox_to_anchor=(0.5, 0.0), **kw)
    renderer = fig.canvas.get_renderer()
    box = legend.get_window_extent(renderer)
    w, h = fig.bbox.width, fig.bbox.height
    if side == "right":
        fig.tight_layout(rect=(0, 0, 1 - (box.width + 6) / w, 1))
    else:
        fig.tight_layout(rect=(0, (box.height + 6) / h, 1, 1))
    return legend


def text_entry(label):
    """A legend entry that is only text (a key line, e.g. a run code and its settings)."""
    return Line2D([], [], linestyle="none", marker=None, label=label)


def _overlaps(a, b):
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def line_pixels(ax, step=3.0):
    """Window points every `step` pixels along the lines drawn in `ax` (curves, reference lines),
    for labels to keep off them."""
    out = []
    for line in ax.get_lines():
        xy = line.get_transform().transform(np.asarray(line.get_xydata(), dtype=float))
        xy = xy[np.all(np.isfinite(xy), axis=1)]
        if line.get_linestyle() in ("None", "none", "", " ") or len(xy) < 2:
            continue
        for a, b in zip(xy[:-1], xy[1:]):
            n = max(1, int(np.hypot(*(b - a)) / step))
            out.extend(a + (b - a) * f for f in np.linspace(0, 1, n + 1))
    return out


def place_labels(ax, xs, ys, texts, fontsize=7, marker_px=5.0, avoid=()):
    """Labels the points (xs, ys) of `ax` with `texts`, each where its box overlaps no other label,
    no point (a square of 2 marker_px around each) and stays inside the axes: the nearest free
    position of a ring of candidates around its point, farther rings until one is free, joined to
    its point by a thin line when it is not beside it; it keeps off the lines drawn (line_pixels)
    too. Call after the layout is final. Returns the annotations."""
    fig = ax.figure
    renderer = fig.canvas.get_renderer()
    to_px = fig.dpi / 72.0
    pts = ax.transData.transform(np.column_stack([xs, ys]))
    frame = ax.get_window_extent(renderer)
    frame = (frame.x0, frame.y0, frame.x1, frame.y1)
    taken = [(x - marker_px, y - marker_px, x + marker_px, y + marker_px) for x, y in pts]
    taken += [(x - 1, y - 1, x + 1, y + 1) for x, y in line_pixels(ax)]
    if len(avoid):  # other markers (data coordinates) that carry no label
        taken += [(x - marker_px, y - marker_px, x + marker_px, y + marker_px)
                  for x, y in ax.transData.transform(np.asarray(avoid, dtype=float))]
    out = []
    # Crowded points first: they have the fewest free places.
    order = np.argsort([-sum(np.hypot(*(p - q)) < 40 for q in pts) for p in pts], kind="stable")
    for k in order:
        (x, y), text = pts[k], texts[k]
        probe = ax.text(0, 0, text, fontsize=fontsize)
        box = probe.get_window_extent(renderer)
        probe.remove()
        tw, th = box.width, box.height
        best = None
        for ring in range(12):
            r = (marker_px + 2) + ring * th
            # Right, left, above, below, then the diagonals: (dx, dy) of the box's lower-left corner.
            for dx, dy in ((r, -th / 2), (-r - tw, -th / 2), (-tw / 2, r), (-tw / 2, -r - th),
                           (r, r), (-r - tw, r), (r, -r - th), (-r - tw, -r - th)):
                cand = (x + dx, y + dy, x + dx + tw, y + dy + th)
                inside = cand[0] >= frame[0] and cand[1] >= frame[1] and cand[2] <= frame[2] and cand[3] <= frame[3]
                if inside and not any(_overlaps(cand, t) for t in taken):
                    best = (dx, dy, ring)
                    break
            if best:
                break
        if best is None:  # no free place inside the axes: beside the point, as before
            best = (marker_px + 2, -th / 2, 0)
        dx, dy, ring = best
        taken.append((x + dx, y + dy, x + dx + tw, y + dy + th))
        arrow = dict(arrowstyle="-", lw=0.5, color="0.4", shrinkA=0, shrinkB=2) if ring > 0 else None
        out.append(ax.annotate(text, (xs[k], ys[k]), xytext=(dx / to_px, dy / to_px), textcoords="offset points",
                               ha="left", va="bottom", fontsize=fontsize, arrowprops=arrow,
                               annotation_clip=False))
    return out


def label_boxes(annotations):
    """Window boxes (x0, y0, x1, y1) of the annotations' texts (for tests)."""
    fig = annotations[0].figure
    renderer = fig.canvas.get_renderer()
    fig.canvas.draw()
    boxes = []
    for a in annotations:
        b = Text.get_window_extent(a, renderer)  # the text alone, not its leader line
        boxes.append((b.x0, b.y0, b.x1, b.y1))
    return boxes
