#!/usr/bin/python3
"""bench/error_target_plot.py: the plot of bench/report/error_target.md (bench/error_target.sh's
tables of --max-error against the cheapest fixed K): per output (sky-view factor, ambient
occlusion, visible count, horizon angles), the error --max-error achieved against the E asked
(each content a line; at or below the diagonal is E met), and its time over the cheapest fixed K's
meeting E (its work where the section was not timed), with the issue's target of 1.3x.

    /usr/bin/python3 bench/error_target_plot.py [bench/report/error_target.md] [-o bench/report/error_target.png]

Reads the tables as error_target.sh writes them (every number plotted is in the report beside
it); cases --max-error refused (a row without numbers) are left out. Debian's python3 with
matplotlib, as bench/make_report.py."""
import argparse
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

# The report's sections (their "### " titles), each plotted from these columns: the whole field's
# achieved error and time ratio (the work ratio where the section was not timed).
OUTPUTS = (
    ("sky-view factor", "sky-view factor (p99 error)", "achieved p99", "time ratio whole", "work ratio whole"),
    ("ambient occlusion", "ambient occlusion (p99 error)", "achieved p99", "time ratio whole", "work ratio whole"),
    ("visible count", "visible count (p99 error / mean)", "achieved p99", "time ratio", "work ratio"),
    ("horizon angles", "horizon angles (mean error, degrees)", "achieved mean", "time ratio", "work ratio"),
)


def number(text):
    try:
        value = float(text.replace("*", "").strip())
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def tables(path):
    """{section title: (header, rows)} of each "### " section's first table."""
    found, title, header = {}, None, None
    for line in open(path):
        line = line.rstrip("\n")
        if line.startswith("### "):
            title, header = line[4:].strip(), None
            continue
        if title is None or not line.startswith("|"):
            if header is not None and title in found:
                title = None  # the section's first table has ended
            continue
        cells = [c.strip() for c in line.strip("|").split("|")]
        if header is None:
            header = cells
            found[title] = (header, [])
        elif not set(line) <= set("|-: "):
            found[title][1].append(dict(zip(header, cells)))
    return found


def series(rows, error_column, ratio_columns):
    """Per content: [(E, achieved, ratio)] in the report's order; which ratio column was used."""
    out, used = {}, None
    for row in rows:
        E, achieved = number(row.get("E", row.get("E (deg)", ""))), number(row.get(error_column, ""))
        if E is None or achieved is None:
            continue  # refused
        ratio = None
        for column in ratio_columns:
            ratio = number(row.get(column, ""))
            if ratio is not None:
                used = used or column
                break
        out.setdefault(row["field"], []).append((E, achieved, ratio))
    return out, used


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "report")
    parser.add_argument("report", nargs="?", default=os.path.join(here, "error_target.md"))
    parser.add_argument("-o", "--output", default=None, help="the PNG (default: beside the report)")
    args = parser.parse_args()
    output = args.output or os.path.join(os.path.dirname(os.path.abspath(args.report)), "error_target.png")
    found = tables(args.report)
    panels = []
    for prefix, label, error_column, time_column, work_column in OUTPUTS:
        title = next((t for t in found if t.startswith(prefix)), None)
        if title is None:
            continue
        header, rows = found[title]
        if "E" not in header and "E (deg)" not in header:
            continue
        data, used = series(rows, error_column, (time_column, work_column))
        if data:
            panels.append((label, data, used))
    if not panels:
        sys.exit(f"error_target_plot.py: no --max-error table in {args.report}")
    fig, axes = plt.subplots(2, len(panels), figsize=(4.2 * len(panels), 7.6), squeeze=False)
    markers = "os^vDP*Xh<>"
    contents = sorted({c for _, data, _ in panels for c in data})
    # One colour and marker per content in every panel, and one legend for all.
    colours = plt.get_cmap("tab10").colors
    style = {c: dict(marker=markers[i % len(markers)], color=colours[i % len(colours)]) for i, c in enumerate(contents)}
    for col, (label, data, used) in enumerate(panels):
        top, bottom = axes[0][col], axes[1][col]
        es = [e for points in data.values() for e, _, _ in points]
        lo, hi = min(es), max(es)
        top.plot([lo / 1.5, hi * 1.5], [lo / 1.5, hi * 1.5], "k--", linewidth=1, label="achieved = E")
        for content, points in sorted(data.items()):
            points = sorted(points)
            # (an achieved error of 0, a run at the reference's own K, has no place on a log axis)
            shown = [p for p in points if p[1] > 0]
            top.plot([p[0] for p in shown], [p[1] for p in shown], linewidth=1, label=content, **style[content])
            ratios = [(p[0], p[2]) for p in points if p[2] is not None]
            if ratios:
                bottom.plot([r[0] for r in ratios], [r[1] for r in ratios], linewidth=1, label=content,
                            **style[content])
        top.set_xscale("log")
        top.set_yscale("log")
        top.set_title(label, fontsize=10)
        top.set_xlabel("E asked")
        top.set_ylabel("achieved against the dense reference")
        top.grid(True, which="both", alpha=0.3)
        bottom.axhline(1.3, color="r", linestyle="--", linewidth=1, label="target 1.3x")
        bottom.axhline(1.0, color="k", linewidth=0.8)
        bottom.set_xscale("log")
        bottom.set_yscale("log")
        bottom.set_xlabel("E asked")
        what = "time" if used and used.startswith("time") else "work (not timed)"
        bottom.set_ylabel(f"{what} over the cheapest fixed K meeting E")
        bottom.grid(True, which="both", alpha=0.3)
        for ax in (top, bottom):  # the decades labelled, not every minor tick of a short range
            ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
            ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    handles = [plt.Line2D([], [], linewidth=1, label=c, **style[c]) for c in contents]
    handles += [plt.Line2D([], [], color="k", linestyle="--", linewidth=1, label="achieved = E (top)"),
                plt.Line2D([], [], color="r", linestyle="--", linewidth=1, label="target 1.3x (bottom)")]
    fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), 7), fontsize=8)
    fig.suptitle("--max-error: the error achieved, and the cost over the cheapest fixed K (" +
                 os.path.basename(args.report) + ")", fontsize=11)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    fig.savefig(output, dpi=90)
    print(f"wrote {output}")


if __name__ == "__main__":
    main()
