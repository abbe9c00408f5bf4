#!/usr/bin/python3
"""bench/make_report.py: turns the suite's results.csv and environment.txt into REPORT.md
and the PNG plots, in the same directory. Every number in REPORT.md comes from results.csv
of the same run (ratios are of two timings of that run). Debian's python3 with numpy and
matplotlib; run by bench/run_report.sh.

Usage: /usr/bin/python3 bench/make_report.py REPORT_DIR
"""

import argparse
import csv
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

CONTENT_TITLES = {
    "fractal": "fractal terrain",
    "bricks": "brick surface",
    "sine": "sine grid",
    "blocks": "blocks",
    "noise": "random noise",
    "dem": "real DEM (Jacksboro fault)",
    "city": "city (flat-roofed blocks on a tilted plane)",
    "city_dsm": "city DSM (one-pixel streets and walls, roofs touching at corners, a rotated grid)",
    "city_holes": "city DSM with nodata (a void, a clipped corner, dropouts at walls' feet: 6 % of it)",
}
URBAN = ("city", "city_dsm", "city_holes")
APPROXIMATIONS = ("radius_", "pyramid_")


def num(row, key):
    value = row.get(key, "")
    return float(value) if value not in ("", None) else None


def fmt(value, digits=3):
    """Three significant digits, without exponents between 1e-3 and 1e5."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    if value == 0:
        return "0"
    magnitude = abs(value)
    if magnitude >= 1e5 or magnitude < 1e-3:
        return "%.*g" % (digits, value)
    if magnitude >= 10 ** digits:
        return "%.0f" % value
    return "%.*g" % (digits, value)


def label(row):
    """Method label with its non-default sampling options."""
    text = row["method"]
    extras = []
    if row.get("spu") not in ("", "1"):
        extras.append("spu %s" % row["spu"])
    if extras:
        text += " (" + ", ".join(extras) + ")"
    return text


def fit_exponent(xs, ys):
    """Least-squares slope of log(y) against log(x)."""
    if len(xs) < 2:
        return None
    slope, _ = np.polyfit(np.log(np.array(xs, float)), np.log(np.array(ys, float)), 1)
    return float(slope)


def read_env(path):
    env = {}
    if os.path.exists(path):
        with open(path) as f:
            for line in f:
                if " = " in line:
                    k, v = line.rstrip("\n").split(" = ", 1)
                    env[k] = v
    return env


class Results:
    def __init__(self, directory, csv_name="results.csv", env_name="environment.txt"):
        self.rows = []
        path = os.path.join(directory, csv_name)
        if os.path.exists(path):
            with open(path, newline="") as f:
                self.rows = list(csv.DictReader(f))
        self.env = read_env(os.path.join(directory, env_name))

    def select(self, section, **match):
        out = []
        for r in self.rows:
            if r["section"] != section:
                continue
            if all(r.get(k) == str(v) for k, v in match.items()):
                out.append(r)
        return out

    def one(self, section, **match):
        found = self.select(section, **match)
        return found[0] if found else None

    def metric(self, section, metric, content=None):
        for r in self.rows:
            if r["section"] == section and r["metric"] == metric and (content is None or r["content"] == content):
                return r
        return None


def ratio(a, b, key="t_min_s"):
    if a is None or b is None:
        return None
    x, y = num(a, key), num(b, key)
    return x / y if x and y else None


def verdict(wall, cpu, ok):
    """Verdict on a figure measured by wall time and by CPU time."""
    a = wall is not None and ok(wall)
    b = cpu is not None and ok(cpu)
    if a and b:
        return "met"
    if b:
        return "met by CPU time, not by wall time"
    if a:
        return "met by wall time, not by CPU time"
    return "not met"


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    for r in rows:
        lines.append("| " + " | ".join(str(c) for c in r) + " |")
    return "\n".join(lines)


def timing_cells(r):
    return [fmt(num(r, "t_min_s")), fmt(num(r, "t_median_s")), r["reps"], fmt(num(r, "core_ns_per_pd")),
            fmt(num(r, "cpu_ns_per_pd"))]


def error_cells(r):
    if r.get("err_mean_deg", "") == "":
        # An SVF-only run: its SVF output against the exact horizons' SVF, no angles.
        if r.get("svf_mean_abs", "") != "":
            return ["", "", "", "", "%s / %s" % (fmt(num(r, "svf_mean_abs")), fmt(num(r, "svf_max_abs"))), ""]
        return ["", "", "", "", "", ""]
    return [fmt(num(r, "err_mean_deg")), fmt(num(r, "err_p99_deg")), fmt(num(r, "err_max_deg")),
            "%s / %s / %s" % (fmt(num(r, "int_mean_deg")), fmt(num(r, "int_p99_deg")), fmt(num(r, "int_max_deg"))),
            "%s / %s" % (fmt(num(r, "svf_mean_abs")), fmt(num(r, "svf_max_abs"))),
            "%s / %s" % (fmt(num(r, "ao_mean_abs")), fmt(num(r, "ao_max_abs")))]


MEASUREMENT_HEADER = ["method", "outputs", "K", "min s", "median s", "runs", "core-ns/pd (wall)", "CPU-ns/pd",
                      "mean err deg", "p99 deg", "max deg", "interior mean / p99 / max deg", "SVF mean / max",
                      "AO mean / max"]


def measurement_table(rows):
    return table(MEASUREMENT_HEADER, [[label(r), r["outputs"], r["K"]] + timing_cells(r) + error_cells(r) for r in rows])


# ------------------------------------------------------------------------------------------
# Plots


def plot_error_vs_time(rows, title, path):
    series = {}
    for r in rows:
        if r.get("err_mean_deg", "") == "" or r["outputs"] != "angles":
            continue
        series.setdefault(label(r), []).append((num(r, "t_min_s"), num(r, "err_mean_deg"), int(r["K"])))
    fig, ax = plt.subplots(figsize=(8, 5.5))
    markers = "os^vD<>ph*"
    for i, (name, points) in enumerate(sorted(series.items())):
        points.sort(key=lambda p: p[2])
        xs, ys, ks = zip(*points)
        style = "-" if name.startswith("sweep") else "--"
        ax.plot(xs, [max(y, 1e-4) for y in ys], style, marker=markers[i % len(markers)], label=name, linewidth=1.5,
                markersize=5)
        for x, y, k in points:
            ax.annotate(str(k), (x, max(y, 1e-4)), textcoords="offset points", xytext=(3, 3), fontsize=6, alpha=0.7)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("time per run, min of repeats (s)")
    ax.set_ylabel("mean horizon error vs exact (deg)")
    ax.set_title(title + " (points labelled with K)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_scaling(series, xlabel, title, path):
    """series: (label, xs, wall seconds, CPU seconds) drawn on log axes, wall time on the left and CPU
    time on the right, each with its fitted power law."""
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    for ax, which, ylabel in ((axes[0], 2, "wall time, min of repeats (s)"),
                              (axes[1], 3, "CPU time of the process, min of repeats (s)")):
        for entry in series:
            name, xs = entry[0], entry[1]
            ys = entry[which]
            if not xs or any(y is None or y <= 0 for y in ys):
                continue
            e = fit_exponent(xs, ys)
            text = "%s (exponent %s)" % (name, fmt(e)) if e is not None else name
            line = ax.plot(xs, ys, "o-", label=text)[0]
            if e is not None:
                c = np.polyfit(np.log(xs), np.log(ys), 1)
                grid = np.geomspace(min(xs), max(xs), 20)
                ax.plot(grid, np.exp(np.polyval(c, np.log(grid))), ":", color=line.get_color(), alpha=0.6)
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ------------------------------------------------------------------------------------------
# Intervisibility (visibility.csv, hfvis_bench visibility)

# Timonen (2013): Table 3's speedups of the tree over the naive method (GPU, per
# sweep) and Table 2's m_a, t_a (N = 1024, K = 256); Figure 8's iteration exponents.
PAPER_SPEEDUP = {"fractal": 2.4, "bricks": 4.2, "sine": 13.0, "blocks": 41.0}
PAPER_TABLE2 = {"fractal": (9.25, 11.7, 2.4), "bricks": (3.06, 4.80, 0.99), "sine": (1.68, 3.02, 0.62),
                "blocks": (2.55, 3.76, 0.78)}
PAPER_EXPONENT = {"fractal_detail": 1.65, "random_extent": 1.01}
TUNING_TITLES = {
    "plain": "Algorithm 1 as written",
    "deferred": "deferred link writes",
    "default": "deferred writes + replacement check (library default)",
    "zone": "... + safe zone (16 steps)",
}


def plot_visibility_scaling(series, path):
    """series: (label, ns, iterations per line); log-log with the naive n(n-1)/2 and linear references."""
    fig, ax = plt.subplots(figsize=(7, 5))
    all_n = sorted({n for _, ns, _ in series for n in ns})
    for name, ns, ts in series:
        ax.plot(ns, ts, "o-", label=name)
    if all_n:
        grid = np.array(all_n, float)
        ax.plot(grid, grid * (grid - 1) / 2, "r--", label="naive: n(n-1)/2")
        ax.plot(grid, grid, "g--", label="linear: n")
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel("line length n (samples)")
    ax.set_ylabel("convexity checks t per line")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("Hull tree iterations against line length (Timonen 2013, Figure 8)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def visibility_section(d, say, targets):
    vis = Results(d, "visibility.csv", "visibility_environment.txt")
    if not vis.rows:
        return
    env = vis.env
    say("## Intervisibility: the convex hull tree against the naive visibility march (issue 4)")
    say("")
    say("Measured by `hfvis_bench visibility` (mode **%s**, commit %s, %s, on %s with %s compute units; load "
        "average %s at the start, %s at the end; %s s%s). Every figure in this section comes from "
        "`visibility.csv` of that run." % (
            env.get("mode", "?"), env.get("commit", "?"), env.get("date_utc", "?"), env.get("device", "?"),
            env.get("compute_units", "?"), env.get("load_average_start", "?"), env.get("load_average_end", "?"),
            fmt(float(env.get("suite_seconds", "nan")), 4),
            "; the whole `run_report.sh` command, build and inputs included: %s s" % fmt(
                float(env["command_seconds"]), 4) if "command_seconds" in env else ""))
    say("")
    times = vis.select("vis_time")
    contents = []
    for r in times:
        if r["content"] not in contents:
            contents.append(r["content"])
    if times:
        k = times[0]["K"]
        say("### Time against the naive march, visible counts, K = %s" % k)
        say("")
        say("Each run is the whole library call `computeIntervisibility` with the visible-count output (what "
            "`hfvis viewcount` computes for channel 0): upload, the sweep on lattice lines (each receiver adding "
            "its count into its pixel), download. "
            "The methods' runs are interleaved (one of each per round; the table gives the minimum of the rounds), "
            "so a slow spell of the machine does not land on one method only. Timonen (2013)'s Table 3 gives the "
            "speedup of the tree sweep over the naive method on a GPU (the sweep kernel alone); the target is at "
            "least that ratio here.")
        say("")
        cells = []
        for c in contents:
            tree = vis.one("vis_time", content=c, method="tree", tuning="default")
            naive = vis.one("vis_time", content=c, method="naive")
            if not tree or not naive:
                continue
            wall, cpu = ratio(naive, tree), ratio(naive, tree, "cpu_min_s")
            paper = PAPER_SPEEDUP.get(c)
            outcome = verdict(wall, cpu, lambda x: x >= paper) if paper else "no paper figure"
            size = "%sx%s" % (tree["width"], tree["height"])
            cells.append([CONTENT_TITLES.get(c, c), size, fmt(num(tree, "t_min_s")), fmt(num(naive, "t_min_s")),
                          fmt(wall), fmt(cpu), fmt(num(tree, "core_ns_per_pd")), fmt(num(naive, "core_ns_per_pd")),
                          ("%sx" % fmt(paper)) if paper else "n/a", outcome])
            if paper:
                targets.append(("tree vs naive, %s %s, K = %s: at least %sx (Timonen 2013, Table 3)" % (
                    CONTENT_TITLES.get(c, c), size, k, fmt(paper)), "%sx wall, %sx CPU" % (fmt(wall), fmt(cpu)),
                    outcome))
        say(table(["content", "size", "tree (s)", "naive (s)", "naive / tree, wall", "naive / tree, CPU",
                   "tree core-ns/pd", "naive core-ns/pd", "paper", "verdict"], cells))
        say("")
        dem = vis.one("vis_time", content="dem", method="naive")
        say("%sThe naive march costs O(N) per receiver and direction, the tree O(m) (m horizons), so the ratio "
            "grows with the field's size." % (
                "The DEM is %sx%s pixels (its central part, or all of it when smaller than the synthetic fields). " % (
                    dem["width"], dem["height"]) if dem else ""))
        say("")

        say("### What each tuning buys (Algorithm 2's deferred writes, the replacement check, the safe zone)")
        say("")
        say("Same runs as above. Every tuning builds the same trees and gives the same counts (tested); they "
            "change the work: *t_a* is convexity checks per receiver and direction, *skipped* the share of "
            "receivers whose tree update the safe zone skipped. Ratios are against Algorithm 1 as written "
            "(`plain`) in the same rounds, of the minimum and of the median run; where the two disagree, the "
            "machine's speed changed during the rounds and the difference is noise.")
        say("")
        cells = []
        for c in contents:
            plain = vis.one("vis_time", content=c, method="tree", tuning="plain")
            for name in ("plain", "deferred", "default", "zone"):
                r = vis.one("vis_time", content=c, method="tree", tuning=name)
                if not r:
                    continue
                cells.append([CONTENT_TITLES.get(c, c), TUNING_TITLES.get(name, name), fmt(num(r, "t_min_s")),
                              fmt(num(r, "t_median_s")), fmt(ratio(r, plain)), fmt(ratio(r, plain, "t_median_s")),
                              fmt(ratio(r, plain, "cpu_min_s")), fmt(num(r, "t_a")), fmt(num(r, "m_a")),
                              "%s %%" % fmt(100 * (num(r, "skip_fraction") or 0.0))])
        say(table(["content", "tuning", "min (s)", "median (s)", "min / plain's", "median / plain's",
                   "CPU / plain's", "t_a", "m_a", "skipped"], cells))
        say("")
        zone = vis.select("vis_zone")
        if zone:
            say("The safe zone's span (steps past the receiver before the zone is recomputed), K = %s:" % zone[0]["K"])
            say("")
            cells = []
            for r in zone:
                default = vis.one("vis_time", content=r["content"], method="tree", tuning="default")
                cells.append([CONTENT_TITLES.get(r["content"], r["content"]), r["zone_steps"],
                              fmt(num(r, "t_min_s")), fmt(num(default, "t_min_s")) if default else "n/a",
                              fmt(num(r, "t_a")), "%s %%" % fmt(100 * (num(r, "skip_fraction") or 0.0))])
            say(table(["content", "zone steps", "time (s)", "default (no zone) in vis_time (s)", "t_a",
                       "skipped"], cells))
            say("")
            say("(The zone rows are timed separately from `vis_time`, not interleaved with it: compare them with "
                "care.)")
            say("")

    stats = vis.select("vis_stats")
    if stats:
        k = stats[0]["K"]
        say("### Horizons and iterations per point and direction (Timonen 2013, Table 2)")
        say("")
        say("Over every receiver of every line of K = %s directions (the paper: K = 256, N = 1024, naive "
            "iterations 484 per point). *naive* is the samples the naive method tests per receiver on the same "
            "lines; *t_a / naive* as in the paper. Algorithm 1's *t_a* is the `plain` walk's; the default "
            "tuning's and the safe zone's are the checks they make. Section 6's bound t <= 2m + n was checked on "
            "every line." % k)
        say("")
        cells = []
        for c in contents:
            plain = vis.one("vis_stats", content=c, tuning="plain")
            default = vis.one("vis_stats", content=c, tuning="default")
            zone_r = vis.one("vis_stats", content=c, tuning="zone")
            if not plain:
                continue
            paper = PAPER_TABLE2.get(c)
            t_naive = 100 * num(plain, "t_a") / num(plain, "naive_a") if num(plain, "naive_a") else None
            over = sum(int(r["lines_over_bound"] or 0) for r in (plain, default, zone_r) if r)
            cells.append([CONTENT_TITLES.get(c, c), "%sx%s" % (plain["width"], plain["height"]),
                          fmt(num(plain, "m_a")), fmt(num(plain, "t_a")), "%s %%" % fmt(t_naive),
                          fmt(num(plain, "naive_a")), fmt(num(plain, "visible_a")),
                          fmt(num(default, "t_a")) if default else "n/a", fmt(num(zone_r, "t_a")) if zone_r else "n/a",
                          "%s / %s / %s %%" % (fmt(paper[0]), fmt(paper[1]), fmt(paper[2])) if paper else "n/a",
                          str(over)])
        say(table(["content", "size", "m_a", "t_a (Alg. 1)", "t_a / naive", "naive", "visible", "t_a default",
                   "t_a zone", "paper m_a / t_a / t_a/naive", "lines over 2m + n"], cells))
        say("")

    scale = vis.select("vis_scale")
    if scale:
        say("### Iterations against line length (Timonen 2013, Figure 8)")
        say("")
        say("Lines of n samples (%s lines per n, swept along the rows; Figure 8 counts Algorithm 1's iterations, the "
            "`plain` rows, and the default tuning's are given beside them): *fractal detail* "
            "is one midpoint-displacement profile per line whose each level adds offsets of half the previous "
            "range, so doubling n adds detail between the existing points; *random extent* is independent uniform "
            "heights in a fixed range, fresh for each n. The exponent k of t = O(n^k) is the least-squares slope "
            "of log t against log n for n >= 512, as in the paper." % scale[0]["height"])
        say("")
        series, cells = [], []
        for kind in ("fractal_detail", "random_extent"):
            for tuning in ("plain", "default"):
                rows = [r for r in scale if r["content"] == kind and r["tuning"] == tuning]
                if not rows:
                    continue
                ns = [int(r["n"]) for r in rows]
                ts = [num(r, "t_per_line") for r in rows]
                big = [(n, t) for n, t in zip(ns, ts) if n >= 512]
                e = fit_exponent([n for n, _ in big], [t for _, t in big]) if len(big) >= 2 else None
                if tuning == "plain":
                    series.append(("%s (exponent %s)" % (kind.replace("_", " "), fmt(e)), ns, ts))
                ms = [num(r, "m_per_line") for r in rows]
                em = fit_exponent([n for n in ns if n >= 512], [m for n, m in zip(ns, ms) if n >= 512])
                cells.append([kind.replace("_", " "), TUNING_TITLES.get(tuning, tuning),
                              "%s .. %s" % (min(ns), max(ns)), fmt(e), fmt(em),
                              fmt(PAPER_EXPONENT.get(kind)) if tuning == "plain" else ""])
        say(table(["content", "tuning", "n", "exponent of t (n >= 512)", "exponent of m", "paper (Figure 8)"],
                  cells))
        say("")
        plot_visibility_scaling(series, os.path.join(d, "visibility_scaling.png"))
        say("![iterations against line length](visibility_scaling.png)")
        say("")

    accuracy_section(vis, say)


# Issue 8's target (e): the tree's mean per-pixel relative count error at most this times the
# naive unit march's, on every content of vis_accuracy.
ACCURACY_FACTOR = 1.1


def accuracy_pairs(vis):
    """[(content, tree row, naive row, host unit row or None)] of vis_accuracy, in run order."""
    rows = vis.select("vis_accuracy")
    contents = []
    for r in rows:
        if r["content"] not in contents:
            contents.append(r["content"])
    pairs = []
    for c in contents:
        tree = vis.one("vis_accuracy", content=c, method="tree")
        naive = vis.one("vis_accuracy", content=c, method="naive")
        if tree and naive:
            pairs.append((c, tree, naive, vis.one("vis_accuracy", content=c, method="host_unit")))
    return pairs


def accuracy_ratio(tree, naive):
    """Tree / naive mean relative error as text, three decimals (the verdict's threshold is 1.1)."""
    t, n = num(tree, "rel_err_mean"), num(naive, "rel_err_mean")
    return "%.3f" % (t / n) if t is not None and n else "n/a"


def accuracy_met(tree, naive):
    t, n = num(tree, "rel_err_mean"), num(naive, "rel_err_mean")
    return t is not None and n is not None and t <= ACCURACY_FACTOR * n


# Issue 25's count target: at every K of vis_accuracy at least this, the tree's (default options)
# mean per-pixel relative error against the reference dense in azimuth at most the naive unit
# march's, on every content.
COUNT_TARGET_K = 64


def accuracy_by_k(vis):
    """[(content, K, tree row, naive row)] of vis_accuracy, every K, in run order."""
    out = []
    for r in vis.select("vis_accuracy", method="tree"):
        naive = vis.one("vis_accuracy", content=r["content"], method="naive", K=r["K"])
        if naive:
            out.append((r["content"], int(r["K"]), r, naive))
    return out


def count_target_met(tree, naive):
    t, n = num(tree, "azd_rel_err_mean"), num(naive, "azd_rel_err_mean")
    return t is not None and n is not None and t <= n


def issue25_count_targets(d):
    """Issue 25's count target, one row per content, from visibility.csv in d: [(target, measured, verdict)]."""
    target = ("Counts at K >= %d against the reference dense in azimuth: the tree (default sampling) no worse "
              "than the unit naive march (mean per-pixel relative error)" % COUNT_TARGET_K)
    vis = Results(d, "visibility.csv", "visibility_environment.txt")
    per_content = {}
    for c, k, tree, naive in accuracy_by_k(vis):
        if k >= COUNT_TARGET_K and tree.get("azd_rel_err_mean"):
            per_content.setdefault(c, []).append((k, tree, naive))
    if not per_content:
        return [(target, "no vis_accuracy rows at K >= %d with the error against the reference dense in azimuth "
                 "in visibility.csv (`hfvis_bench visibility --sections accuracy`, quick or full mode)"
                 % COUNT_TARGET_K, "not measured")]
    rows = []
    source = "visibility.csv, commit %s" % vis.env.get("commit", "?")
    for c, runs in per_content.items():
        measured = "; ".join("K = %d: tree %s vs naive %s" % (
            k, fmt(num(tree, "azd_rel_err_mean")), fmt(num(naive, "azd_rel_err_mean"))) for k, tree, naive in runs)
        rows.append(("%s: %s" % (target, CONTENT_TITLES.get(c, c)), "%sx%s, %s azimuths (%s): %s" % (
            runs[0][1]["width"], runs[0][1]["height"], runs[0][1]["azd_dirs"], source, measured),
            "met" if all(count_target_met(tree, naive) for _, tree, naive in runs) else "not met"))
    return rows


def issue8_target_e(d):
    """Issue 8's target (e) from visibility.csv in d: (target, measured, verdict)."""
    target = ("e. visible counts: mean per-pixel relative error against a dense reference <= %s x the "
              "per-pixel unit march's (every content)" % fmt(ACCURACY_FACTOR))
    vis = Results(d, "visibility.csv", "visibility_environment.txt")
    pairs = accuracy_pairs(vis)
    if not pairs:
        return (target, "no vis_accuracy rows in visibility.csv (`hfvis_bench visibility --sections accuracy`)",
                "not measured")
    tree0 = pairs[0][1]
    parts, failures = [], []
    for c, tree, naive, _ in pairs:
        t, n = num(tree, "rel_err_mean"), num(naive, "rel_err_mean")
        parts.append("%s %s vs %s (%s x)" % (c, fmt(t), fmt(n), accuracy_ratio(tree, naive)))
        if not accuracy_met(tree, naive):
            failures.append(c)
    text = ("tree vs naive mean relative error, %sx%s crops, K = %s, reference D = %s samples per pixel: %s" % (
        tree0["width"], tree0["height"], tree0["K"], tree0["dense_per_unit"], "; ".join(parts)))
    if failures:
        text += "; above %s x on: %s" % (fmt(ACCURACY_FACTOR), ", ".join(failures))
    return (target, text, "met" if not failures else "not met")


def accuracy_section(vis, say):
    pairs = accuracy_pairs(vis)
    if not pairs:
        return
    t0 = pairs[0][1]
    seconds = vis.env.get("accuracy_seconds")
    ref_seconds = [num(tree, "ref_seconds") for _, tree, _, _ in pairs if num(tree, "ref_seconds") is not None]
    left_out = [n for _, tree, naive, _ in pairs for n in (tree["note"], naive["note"]) if "reference 0" in n]
    say("### Visible counts against a dense reference (issue 8, target e)")
    say("")
    say("The library's visible count (`IntervisibilityOutputs::visible_count`) is, per pixel, the visible samples "
        "summed over the K directions at 1 sample per pixel length along each ray: about the visible length of "
        "each direction's ray in pixel lengths, summed over the directions. The *dense reference* "
        "(`bench/dense_visibility.cpp`, host, double precision) marches every pixel's ray in each direction "
        "(the library's azimuths and pixel-axis directions, cell sizes included) at 1/D pixel from t = 1/D until "
        "the ray leaves the bilinear domain [0, W-1] x [0, H-1]; a sample is visible when its slope "
        "(h(t) - h0) / t from the pixel's own height h0 is >= the largest slope of every earlier sample (ties "
        "visible, the library's rule; a tie is within 1e-9 of the field's relief, so flat roofs and tilted planes "
        "stay ties in double precision), and the direction counts (visible samples) / D; summed over the K "
        "directions. *tree* is `computeIntervisibility` with the default options (the hull tree, "
        "running on lattice lines through the pixel centres, each pixel the receiver of its own line, in "
        "quadrature directions within half a spacing of phi_k), *naive* the per-pixel unit "
        "march (`IntervisibilityMethod::Naive`), both at 1 sample per unit and the same K. Errors per pixel: "
        "|count - ref| / ref (%s); *mean* is the target's metric (the tree's at most %s x the "
        "naive march's on every content), *aggregate* is sum |count - ref| / sum ref, *bias* the mean of "
        "(count - ref) / ref. *host unit* is the reference's own code at D = 1 (the naive march's samples, "
        "decided in double with the tie tolerance): its error is the unit march's sampling error alone, and "
        "*naive != host unit* counts the pixels where the library's naive march differs from it by more than "
        "half a sample (few on rough content, where it checks the directions and conventions; many on flat "
        "roofs and planes, where the library's single-precision bilinear samples break exact ties and hide "
        "grazing samples). Sizes: %sx%s crops (the synthetic fields at that size, the DEM's centre, the city "
        "generated at that size, seed 2013), K = %s, D = %s. Times: the whole library call, minimum of %s runs "
        "of each method, interleaved (the verdict is on accuracy only).%s" % (
            "pixels with ref = 0 left out: " + "; ".join(left_out) if left_out else "no pixel has ref = 0",
            fmt(ACCURACY_FACTOR), t0["width"], t0["height"], t0["K"], t0["dense_per_unit"], t0["reps"],
            " The section took %s s (the reference about %s s per content)." % (
                fmt(float(seconds), 3), fmt(sum(ref_seconds) / len(ref_seconds))) if seconds and ref_seconds else ""))
    say("")
    cells = []
    for c, tree, naive, unit in pairs:
        t, n = num(tree, "rel_err_mean"), num(naive, "rel_err_mean")
        cells.append([CONTENT_TITLES.get(c, c), "%sx%s" % (tree["width"], tree["height"]), fmt(num(tree, "ref_mean")),
                      fmt(num(tree, "count_mean")), fmt(num(naive, "count_mean")), fmt(t), fmt(n),
                      accuracy_ratio(tree, naive),
                      fmt(num(tree, "rel_err_agg")), fmt(num(naive, "rel_err_agg")),
                      "%s / %s" % (fmt(num(tree, "rel_bias_mean")), fmt(num(naive, "rel_bias_mean"))),
                      fmt(num(unit, "rel_err_mean")) if unit else "n/a",
                      ("%s of %s" % (unit["differ_pixels"], unit["err_pixels"])) if unit else "n/a",
                      fmt(num(tree, "t_min_s")), fmt(num(naive, "t_min_s")),
                      "met" if accuracy_met(tree, naive) else "not met"])
    say(table(["content", "size", "ref mean count", "tree mean count", "naive mean count", "tree mean rel. error",
               "naive mean rel. error", "tree / naive", "tree aggregate", "naive aggregate", "bias tree / naive",
               "host unit mean rel. error", "naive != host unit (pixels)", "tree (s)", "naive (s)",
               "tree <= %s x naive" % fmt(ACCURACY_FACTOR)], cells))
    say("")
    runs = [r for r in accuracy_by_k(vis) if r[2].get("azd_rel_err_mean")]
    if not runs:
        return
    t0 = runs[0][2]
    say("### Visible counts against the integral over azimuth (issue 25)")
    say("")
    say("A count sums K directions; what it estimates is K / (2 pi) times the integral of the visible length over "
        "the azimuth. The *reference dense in azimuth* marches %s directions evenly spaced from azimuth 0 (the same "
        "code, D = %s) and scales their mean by K; the *same-direction* references march each method's own "
        "directions: phi_k = 2 pi k / K with weight 1 for the naive march, the tree's lattice steps with K times "
        "their quadrature weights for the tree (so its same-direction error is its sampling error alone). Errors: "
        "mean (and p99) over the pixels of |count - ref| / ref. At small K the error against the reference dense "
        "in azimuth is mostly the direction set's error, not the method's: both methods look along too few "
        "azimuths, and on urban content streets along the axes, seen far down their length in a narrow wedge, "
        "weigh heavily in the integral (an axis direction stands for its whole wedge). The target (K >= %d): the "
        "tree's mean at most the naive march's against the reference dense in azimuth, on every content." % (
            t0["azd_dirs"], t0["dense_per_unit"], COUNT_TARGET_K))
    say("")
    cells = []
    for c, k, tree, naive in runs:
        t, n = num(tree, "azd_rel_err_mean"), num(naive, "azd_rel_err_mean")
        cells.append([CONTENT_TITLES.get(c, c), str(k), fmt(num(tree, "azd_ref_mean")),
                      fmt(num(tree, "rel_err_mean")), fmt(num(naive, "rel_err_mean")), fmt(t), fmt(n),
                      "%.3f" % (t / n) if t is not None and n else "n/a",
                      "%s / %s" % (fmt(num(tree, "azd_rel_err_p99")), fmt(num(naive, "azd_rel_err_p99"))),
                      ("met" if count_target_met(tree, naive) else "not met") if k >= COUNT_TARGET_K else "-"])
    say(table(["content", "K", "ref mean count (dense in azimuth)", "tree, same directions",
               "naive, same directions", "tree, dense in azimuth", "naive, dense in azimuth", "tree / naive",
               "p99 dense in azimuth, tree / naive", "tree <= naive (K >= %d)" % COUNT_TARGET_K], cells))
    say("")


# ------------------------------------------------------------------------------------------
# Issue 8 targets (receiver-exact horizons)


# Horizon errors below this (degrees) are float rounding: both methods exact there (e.g. K = 4,
# whose rays run along the grid). Such pairs count as met and are left out of the ratios.
EXACT_DEG = 1e-4


def _ratio_of(a, b):
    """a / b for errors: None when both are exact (below EXACT_DEG), inf when only b is."""
    if a is None or b is None:
        return None
    if a < EXACT_DEG and b < EXACT_DEG:
        return None
    if b == 0:
        return float("inf")
    return a / b


def _worst(pairs):
    """The largest (value, where) of pairs whose value is not None."""
    pairs = [p for p in pairs if p[0] is not None]
    return max(pairs, key=lambda p: p[0]) if pairs else (None, None)


def _least(pairs):
    pairs = [p for p in pairs if p[0] is not None]
    return min(pairs, key=lambda p: p[0]) if pairs else (None, None)


def heman_figures(d):
    """`hfvis ao -k 16` against heman from bench/heman_compare.sh's tables in the report directory:
    heman_timings.csv (its timings.csv, as run_report.sh copies it with HEMAN_DIR set), heman/timings.csv
    (heman_compare.sh --out REPORT_DIR/heman), or heman.md (its results.md). Returns
    (source, {size: {"process": heman/hfvis by min wall, "computation": ..., "library": ...}}) or None,
    "library" being hfvis_bench's warm library call (program hfvis_lib) against heman's call."""
    for name in ("heman_timings.csv", "heman/timings.csv"):
        path = os.path.join(d, name)
        if os.path.exists(path):
            best = {}
            with open(path, newline="") as f:
                for r in csv.DictReader(f):
                    for what, key in (("process", "wall_s"), ("computation", "compute_s")):
                        v = r.get(key, "")
                        if v in ("", None):
                            continue
                        slot = best.setdefault(r["size"], {}).setdefault(what, {})
                        slot[r["program"]] = min(float(v), slot.get(r["program"], float("inf")))
            out = {}
            for size, whats in best.items():
                for what, progs in whats.items():
                    if progs.get("hfvis") and progs.get("heman"):
                        out.setdefault(size, {})[what] = progs["heman"] / progs["hfvis"]
                    if what == "computation" and progs.get("hfvis_lib") and progs.get("heman"):
                        out.setdefault(size, {})["library"] = progs["heman"] / progs["hfvis_lib"]
            return name, out
    path = os.path.join(d, "heman.md")
    if os.path.exists(path):
        out = {}
        with open(path) as f:
            for line in f:
                cells = [c.strip() for c in line.strip().strip("|").split("|")]
                whats = {"whole process": "process", "computation": "computation",
                         "library call (program built)": "library"}
                if len(cells) == 8 and "x" in cells[0] and cells[1] in whats:
                    try:
                        value = float(cells[6])
                    except ValueError:
                        continue
                    out.setdefault(cells[0].split("x")[0], {})[whats[cells[1]]] = value
        return "heman.md", out
    return None


def plane_lookup(res):
    """The speed/error plane's rows, its contents in run order, and a finder of the row of one
    content, method, K and samples per unit with the angle planes and their errors."""
    plane = res.select("plane")
    contents = []
    for r in plane:
        if r["content"] not in contents:
            contents.append(r["content"])

    def plane_row(c, method, kk, spu="1"):
        return next((r for r in plane if r["content"] == c and r["method"] == method and r["K"] == kk
                     and r["spu"] == spu and r["outputs"] == "angles" and r["err_mean_deg"] != ""), None)

    return plane, contents, plane_row


def issue8_targets(res, d):
    """Rows (target, measured, verdict) of issue 8's targets from this run's results.csv, and the
    lines of the per-content detail table."""
    rows, detail = [], []
    plane, contents, plane_row = plane_lookup(res)

    # a. sweep (spu 1) mean and p99 no larger than the naive march's (spu 1), every content and K.
    pairs, failures, per_content = 0, [], {}
    mean_ratios, p99_ratios = [], []
    for c in contents:
        ks = sorted({r["K"] for r in plane if r["content"] == c}, key=int)
        for kk in ks:
            sw, nv = plane_row(c, "sweep", kk), plane_row(c, "naive", kk)
            if not sw or not nv:
                continue
            pairs += 1
            where = "%s, K = %s" % (c, kk)
            sm, nm = num(sw, "err_mean_deg"), num(nv, "err_mean_deg")
            sp, np_ = num(sw, "err_p99_deg"), num(nv, "err_p99_deg")
            rm, rp = _ratio_of(sm, nm), _ratio_of(sp, np_)
            mean_ratios.append((rm, where))
            p99_ratios.append((rp, where))
            per = per_content.setdefault(c, {"a_mean": [], "a_p99": [], "b_err": [], "b_speed": [], "ks": []})
            per["a_mean"].append((rm, kk))
            per["a_p99"].append((rp, kk))
            if (sm > nm and rm is not None) or (sp > np_ and rp is not None):
                failures.append("%s (mean %s vs %s deg, p99 %s vs %s deg)" % (where, fmt(sm), fmt(nm), fmt(sp),
                                                                            fmt(np_)))
    if pairs:
        wm, wp = _worst(mean_ratios), _worst(p99_ratios)
        text = ("%d content-K pairs (%s); worst sweep / naive ratio of the mean %s (%s), of the p99 %s (%s)" % (
            pairs, ", ".join(contents), fmt(wm[0]), wm[1], fmt(wp[0]), wp[1]))
        if failures:
            text += "; larger than the naive march's at: " + "; ".join(failures[:6]) + (
                " and %d more" % (len(failures) - 6) if len(failures) > 6 else "")
        rows.append(("a. every plane content and K: sweep (spu 1) mean and p99 horizon error <= the unit naive "
                     "march's", text, "met" if not failures else "not met"))
    else:
        rows.append(("a. every plane content and K: sweep (spu 1) mean and p99 horizon error <= the unit naive "
                     "march's", "no plane rows with both methods", "not measured"))

    # b. sweep spu 4: mean <= 0.5 x the unit naive march's, and >= 10 x faster (same content, same K).
    err_fail, speed_fail, used_ks = [], [], set()
    err_pairs, speed_pairs = [], []
    for c in contents:
        for kk in sorted({r["K"] for r in plane if r["content"] == c}, key=int):
            s4, nv = plane_row(c, "sweep", kk, "4"), plane_row(c, "naive", kk)
            if not s4 or not nv:
                continue
            used_ks.add(int(kk))
            where = "%s, K = %s" % (c, kk)
            re_ = _ratio_of(num(s4, "err_mean_deg"), num(nv, "err_mean_deg"))
            sp = ratio(nv, s4)
            err_pairs.append((re_, where))
            speed_pairs.append((sp, where))
            per = per_content[c]
            per["b_err"].append((re_, kk))
            per["b_speed"].append((sp, kk))
            if re_ is not None and re_ > 0.5:
                err_fail.append(where)
            if sp is None or sp < 10:
                speed_fail.append("%s (%s x)" % (where, fmt(sp)))
    ks_text = ", ".join(str(k) for k in sorted(used_ks))
    if err_pairs:
        we = _worst(err_pairs)
        rows.append(("b. sweep spu 4: mean horizon error <= 0.5 x the unit naive march's, every plane content "
                     "(at every K where both ran: %s)" % ks_text,
                     "worst ratio %s (%s)%s" % (fmt(we[0]), we[1], "; above 0.5 at: " + "; ".join(err_fail[:8]) + (
                         " and %d more" % (len(err_fail) - 8) if len(err_fail) > 8 else "") if err_fail else ""),
                     "met" if not err_fail else "not met"))
        ls = _least(speed_pairs)
        head_naive = res.one("headline", method="naive", outputs="angles")
        head_s4 = res.one("headline", method="sweep", outputs="angles", spu="4")
        context = ""
        if head_naive and head_s4:
            context = "; at the headline size (fractal %sx%s, K = %s) %s x" % (
                head_s4["width"], head_s4["height"], head_s4["K"], fmt(ratio(head_naive, head_s4)))
        size = next((("%sx%s" % (r["width"], r["height"])) for r in plane), "?")
        rows.append(("b. sweep spu 4 >= 10 x faster than the unit naive march (wall, same content and K; plane "
                     "fields %s, K = %s)" % (size, ks_text),
                     "least naive / sweep-spu-4 time %s x (%s)%s%s" % (
                         fmt(ls[0]), ls[1], "; below 10 x at %d of %d content-K pairs" % (
                             len(speed_fail), len(speed_pairs)) if speed_fail else "", context),
                     "met" if not speed_fail else "not met"))
    else:
        rows.append(("b. sweep spu 4 against the unit naive march", "no plane rows of the sweep at spu 4 with a "
                     "naive march at the same K", "not measured"))

    # c. SVF-only at the headline (1024^2 fractal, K = 64): error and time against the naive march.
    sweep_s = res.one("headline", method="sweep", outputs="svf")
    naive_s = res.one("headline", method="naive", outputs="svf")
    if sweep_s and naive_s:
        n, kk = sweep_s["width"], sweep_s["K"]
        at = "fractal %sx%s, K = %s" % (n, sweep_s["height"], kk)
        full = n == "1024" and kk == "64"
        es, en = num(sweep_s, "svf_mean_abs"), num(naive_s, "svf_mean_abs")
        ms, mn = num(sweep_s, "svf_max_abs"), num(naive_s, "svf_max_abs")
        ok = es is not None and en is not None and es <= en
        rows.append(("c. SVF-only runs at 1024^2, K = 64: sweep SVF error <= the unit naive march's (mean abs)",
                     "mean %s vs %s, max %s vs %s (%s)" % (fmt(es), fmt(en), fmt(ms), fmt(mn), at),
                     ("met" if ok else "not met") if full else
                     "not measured at 1024^2 (%s: %s)" % (at, "would be met" if ok else "would not be met")))
        rw, rc = ratio(naive_s, sweep_s), ratio(naive_s, sweep_s, "cpu_min_s")
        rows.append(("c. SVF-only runs at 1024^2, K = 64, whole library call: naive / sweep time >= 50",
                     "%s x by wall time, %s x by CPU time (%s; sweep %s s, naive %s s)" % (
                         fmt(rw), fmt(rc), at, fmt(num(sweep_s, "t_min_s")), fmt(num(naive_s, "t_min_s"))),
                     verdict(rw, rc, lambda v: v >= 50) if full else "not measured at 1024^2 (quick mode)"))
        c, cpu = num(sweep_s, "core_ns_per_pd"), num(sweep_s, "cpu_ns_per_pd")
        rows.append(("c. sweep SVF-only cost: about 37 core-ns per pixel-direction (or less)",
                     "%s core-ns/pd from wall time x %s compute units, %s CPU-ns/pd (%s)" % (
                         fmt(c), res.env.get("compute_units", "?"), fmt(cpu), at),
                     verdict(c, cpu, lambda v: v <= 37) if full else "not measured at 1024^2 (quick mode)"))
    else:
        rows.append(("c. SVF-only runs at 1024^2, K = 64", "no SVF-only sweep and naive rows in the headline",
                     "not measured"))
    # c at 2048: scale_n, same K, both SVF only.
    sn = [r for r in res.select("scale_n") if r["t_min_s"] and r["outputs"] == "svf"]
    naive_k = sorted({r["K"] for r in sn if r["method"] == "naive"}, key=int)
    target_2048 = "c. SVF-only runs at 2048^2 (scale_n series, same K): naive / sweep time >= 100"
    if naive_k:
        kk = naive_k[-1]
        sw = next((r for r in sn if r["method"] == "sweep" and r["K"] == kk and r["width"] == "2048"), None)
        nv = next((r for r in sn if r["method"] == "naive" and r["K"] == kk and r["width"] == "2048"), None)
        if sw and nv:
            rw, rc = ratio(nv, sw), ratio(nv, sw, "cpu_min_s")
            outcome = verdict(rw, rc, lambda v: v >= 100)
            if kk != "64":  # the N series runs the naive march at a small K only
                outcome += " at K = %s only (K = 64, where the sweep's steps are longer, not measured)" % kk
            rows.append((target_2048, "%s x by wall time, %s x by CPU time (K = %s; sweep %s s, naive %s s)" % (
                fmt(rw), fmt(rc), kk, fmt(num(sw, "t_min_s")), fmt(num(nv, "t_min_s"))), outcome))
        else:
            # Not measured: an extrapolation, clearly labelled, from the largest N where both ran.
            both = sorted({int(r["width"]) for r in sn if r["method"] == "naive" and r["K"] == kk} &
                          {int(r["width"]) for r in sn if r["method"] == "sweep" and r["K"] == kk})
            skipped = [r for r in res.select("scale_n") if r["metric"] == "skipped_predicted_seconds"
                       and r["method"] == "naive" and r["width"] == "2048"]
            why = "the naive march at 2048 was skipped for time (predicted %s s)" % fmt(num(skipped[0], "value")) \
                if skipped else "this run's N series stops below 2048"
            text = "not measured: %s" % why
            if both:
                m = str(both[-1])
                sw_m = next(r for r in sn if r["method"] == "sweep" and r["K"] == kk and r["width"] == m)
                nv_m = next(r for r in sn if r["method"] == "naive" and r["K"] == kk and r["width"] == m)
                f = 2048.0 / float(m)
                sw_t = num(sw, "t_min_s") if sw else num(sw_m, "t_min_s") * f ** 2
                est = num(nv_m, "t_min_s") * f ** 3 / sw_t
                text += ("; EXTRAPOLATED, not measured: %s x (K = %s; naive from N = %s as N^3, sweep %s)" % (
                    fmt(est), kk, m, "measured at 2048" if sw else "from N = %s as N^2" % m))
            rows.append((target_2048, text, "not measured"))
    else:
        rows.append((target_2048, "no naive march in the N series", "not measured"))

    # d. hfvis ao K = 16 against heman.
    heman = heman_figures(d)
    if heman and heman[1]:
        source, figures = heman
        parts, ok = [], True
        for size in sorted(figures, key=int):
            f = figures[size]
            library = (", %s x library call (program built)" % fmt(f["library"])) if "library" in f else ""
            parts.append("%sx%s: %s x whole process, %s x computation (the CLI's call)%s" % (
                size, size, fmt(f.get("process")), fmt(f.get("computation")), library))
            ok = ok and f.get("process") is not None and f["process"] >= 3
        rows.append(("d. `hfvis ao -k 16` at least 3 x faster than heman (heman / hfvis time; verdict by the "
                     "whole `hfvis ao` process)",
                     "%s (from %s, a separate run of bench/heman_compare.sh)" % ("; ".join(parts), source),
                     "met" if ok else "not met"))
    else:
        rows.append(("d. `hfvis ao -k 16` at least 3 x faster than heman",
                     "no heman timings in the report directory (run_report.sh with HEMAN_DIR set, or copy "
                     "bench/heman_compare.sh's timings.csv there as heman_timings.csv)", "not measured"))

    # e. intervisibility counts, from visibility.csv (vis_accuracy) in the same directory.
    rows.append(issue8_target_e(d))

    # Per-content detail of a and b.
    if per_content:
        cells = []
        for c, per in per_content.items():
            wm, wp = _worst(per["a_mean"]), _worst(per["a_p99"])
            we, ls = _worst(per["b_err"]), _least(per["b_speed"])
            cells.append([CONTENT_TITLES.get(c, c), ", ".join(k for _, k in per["a_mean"]),
                          "%s (K = %s)" % (fmt(wm[0]), wm[1]) if wm[0] is not None else "n/a",
                          "%s (K = %s)" % (fmt(wp[0]), wp[1]) if wp[0] is not None else "n/a",
                          "%s (K = %s)" % (fmt(we[0]), we[1]) if we[0] is not None else "n/a",
                          "%s (K = %s)" % (fmt(ls[0]), ls[1]) if ls[0] is not None else "n/a"])
        detail.append("Per content (speed/error plane; ratios of the sweep's to the unit naive march's, worst K "
                      "in brackets; errors below %s deg on both sides are float rounding, counted as equal and left "
                      "out of the ratios):" % fmt(EXACT_DEG))
        detail.append("")
        detail.append(table(["content", "K", "a: sweep / naive mean", "a: sweep / naive p99",
                             "b: sweep spu 4 / naive mean", "b: naive / sweep spu 4 time (least)"], cells))
    return rows, detail


def cost_rows(d):
    """Rows of issue 25's cost target from cost_against.md (bench/cost_against.sh) in the report
    directory: each command's current / base ratio of median whole-command times."""
    path = os.path.join(d, "cost_against.md")
    target = "Cost: default `hfvis svf` and `hfvis viewcount` at 1024^2, K = 64, at most 1.15 x bad9286's time"
    if not os.path.exists(path):
        return [(target, "no cost_against.md in the report directory (run bench/cost_against.sh and copy "
                 "bench/out/cost_against.md here)", "not measured")]
    with open(path) as f:
        text = f.read()
    title = next((line[2:] for line in text.splitlines() if line.startswith("# ")), "")
    rows = []
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 8 or not cells[0].startswith("hfvis "):
            continue
        wall, cpu = float(cells[4]), float(cells[7])
        rows.append(("Cost: default `%s` on %s, current / base whole-command time <= 1.15 (CPU time: the machine "
                     "is shared; wall time beside it)" % (cells[0], cells[1]),
                     "CPU %s s against %s s: %.3f x; wall %s s against %s s: %.3f x (%s)" % (
                         cells[6], cells[5], cpu, cells[3], cells[2], wall,
                         title.replace("Whole-command cost: ", "")),
                     "met" if cpu <= 1.15 else "not met"))
    return rows or [(target, "cost_against.md has no rows", "not measured")]


def issue25_targets(res, d):
    """Rows (target, measured, verdict) of issue 25's horizon and cost targets from this run's
    results.csv (speed/error plane, error against samples per unit) and cost_against.md."""
    rows = []
    plane, contents, plane_row = plane_lookup(res)

    failures, urban_failures, pairs, urban = [], [], 0, []
    for c in contents:
        for kk in sorted({r["K"] for r in plane if r["content"] == c}, key=int):
            sw, nv = plane_row(c, "sweep", kk), plane_row(c, "naive", kk)
            if not sw or not nv:
                continue
            pairs += 1
            sm, nm = num(sw, "err_mean_deg"), num(nv, "err_mean_deg")
            sp, np_ = num(sw, "err_p99_deg"), num(nv, "err_p99_deg")
            if sm > nm + EXACT_DEG or sp > np_ + EXACT_DEG:
                failures.append("%s K = %s (mean %s vs %s, p99 %s vs %s deg)" % (c, kk, fmt(sm), fmt(nm), fmt(sp),
                                                                              fmt(np_)))
            if c in URBAN:
                urban.append("%s K = %s: %s vs %s" % (c, kk, fmt(sm), fmt(nm)))
                if sm > 0.5 * nm:
                    urban_failures.append("%s K = %s" % (c, kk))
    name = "Horizons, every content (%s), every K: the default sweep's mean and p99 error <= the unit naive " \
           "march's" % ", ".join(contents)
    if pairs:
        rows.append((name, "%d content-K pairs; %s" % (pairs, "larger at: " + "; ".join(failures) if failures
                                                         else "none larger"), "met" if not failures else "not met"))
    else:
        rows.append((name, "no plane rows with both methods", "not measured"))
    name = "Horizons, urban content: the default sweep's mean error <= 0.5 x the unit naive march's"
    if urban:
        rows.append((name, "mean error, sweep vs naive (deg): " + "; ".join(urban),
                     "met" if not urban_failures else "not met at " + ", ".join(urban_failures)))
    else:
        rows.append((name, "no urban content in the speed/error plane", "not measured"))

    # Samples per unit: S = 1 at least as accurate as the unit march; the sweep's error falls as S grows.
    src = [r for r in res.select("sources") if r["err_mean_deg"] != ""]
    name = "Samples per unit keep their meaning: the sweep at S = 1 <= the unit march; its error does not grow with S"
    parts, bad = [], []
    for c in sorted({r["content"] for r in src}):
        sweep = sorted(((float(r["spu"]), num(r, "err_mean_deg")) for r in src
                        if r["content"] == c and r["method"] == "sweep"))
        naive1 = next((num(r, "err_mean_deg") for r in src if r["content"] == c and r["method"] == "naive"
                       and float(r["spu"]) == 1.0), None)
        if not sweep or naive1 is None:
            continue
        parts.append("%s: sweep %s, unit march %s" % (c, ", ".join("S=%g %s" % (spu, fmt(e)) for spu, e in sweep),
                                                      fmt(naive1)))
        if sweep[0][1] > naive1 + EXACT_DEG or any(b[1] > a[1] * 1.05 + EXACT_DEG for a, b in zip(sweep, sweep[1:])):
            bad.append(c)
    rows.append((name, "mean error (deg): " + "; ".join(parts) if parts else "no sources rows",
                 ("met" if not bad else "not met on " + ", ".join(bad)) if parts else "not measured"))
    rows += cost_rows(d)
    return rows


def issue31_targets(d):
    """Rows (target, measured, verdict) of issue 31's targets (--max-error) from error_target.md
    (bench/error_target.sh) in the report directory: its summary line per output."""
    path = os.path.join(d, "error_target.md")
    if not os.path.exists(path):
        return [("Asking for an error (--max-error)", "no error_target.md in the report directory (run "
                 "bench/error_target.sh)", "not measured")]
    with open(path) as f:
        text = f.read()
    rows = []
    pattern = re.compile(r"^(.+): achieved error at most E in (\d+) of (\d+) cases \((\d+) %\); over the cheapest "
                         r"fixed K: time (?:median ([\d.]+), largest ([\d.]+)|not measured); work median ([\d.]+), largest ([\d.]+); "
                         r"the last run's work alone median ([\d.]+), largest ([\d.]+)$", re.M)
    # The sweeps' lines since the tiles came in (--error-tile): the whole field at one K, then tiles.
    tiled = re.compile(r"^(.+): achieved error at most E in (\d+) of (\d+) cases \((\d+) %\) with the whole field at "
                       r"one K, in (\d+) with tiles of (\d+); over the cheapest fixed K: the whole field's time median "
                       r"([\d.]+), largest ([\d.]+), work median ([\d.]+), largest ([\d.]+), its last run's work alone "
                       r"median ([\d.]+), largest ([\d.]+); the tiles' time median ([\d.]+), largest ([\d.]+), work "
                       r"median ([\d.]+), largest ([\d.]+)$", re.M)
    sections = re.split(r"^### ", text, flags=re.M)[1:]
    matches = sorted(list(pattern.finditer(text)) + list(tiled.finditer(text)), key=lambda m: m.start())
    for m in matches:
        output, met, taken = m.group(1), int(m.group(2)), int(m.group(3))
        if m.re is tiled:
            section = next((x for x in sections if x.startswith(output)), "")
            refused = section.count("| refused:")
            rows.append(("%s: achieved p99 error <= E in >= 95 %% of (content, E) cases" % output,
                         "%d of %d cases taken (%s %%) with the whole field at one K, %s with tiles of %s; %d refused "
                         "(beyond 4096 directions)" % (met, taken, m.group(4), m.group(5), m.group(6), refused),
                         "met" if met >= 0.95 * taken and int(m.group(5)) >= 0.95 * taken else "not met"))
            rows.append(("%s: time <= 1.3 x the cheapest fixed K meeting E" % output,
                         "whole field: time ratio median %s, largest %s; work median %s, largest %s; the last run's "
                         "work alone median %s, largest %s; tiles: time median %s, largest %s, work median %s, "
                         "largest %s" % m.group(7, 8, 9, 10, 11, 12, 13, 14, 15, 16),
                         "met" if max(float(m.group(8)), float(m.group(14))) <= 1.3 else "not met"))
            continue
        section = next((x for x in sections if x.startswith(output)), "")
        refused = section.count("| refused:")
        rows.append(("%s: achieved p99 error <= E in >= 95 %% of (content, E) cases" % output,
                     "%d of %d cases taken (%s %%); %d refused (beyond 4096 directions)" % (met, taken, m.group(4),
                                                                                          refused),
                     "met" if met >= 0.95 * taken else "not met"))
        timed = m.group(5) is not None
        time = "time ratio median %s, largest %s" % m.group(5, 6) if timed else "not timed"
        # Untimed, the load-free work ratio stands for it (the sweep's cost is linear in the samples).
        worst = float(m.group(6) if timed else m.group(8))
        rows.append(("%s: time <= 1.3 x the cheapest fixed K meeting E" % output,
                     "%s; work ratio (samples per receiver, all runs) median %s, largest %s; the last run's alone "
                     "median %s, largest %s" % ((time,) + m.group(7, 8, 9, 10)),
                     "met" if worst <= 1.3 else "not met"))
    return rows or [("Asking for an error (--max-error)", "error_target.md has no summary lines", "not measured")]


# ------------------------------------------------------------------------------------------
# Report


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("report_dir")
    args = ap.parse_args(argv)
    d = args.report_dir
    res = Results(d)
    env = res.env
    out = []
    say = out.append
    targets = []  # (target, measured, verdict)

    say("# hfvis benchmark report")
    say("")
    vis_env = read_env(os.path.join(d, "visibility_environment.txt"))
    if not res.rows:  # `run_report.sh --only visibility` into a directory without horizon results
        command = {"full": "bench/run_report.sh --only visibility",
                   "quick": "bench/run_report.sh --quick --only visibility"}.get(
            vis_env.get("mode"), "hfvis_bench visibility --%s" % vis_env.get("mode"))
        say("Generated by `%s`: the intervisibility suite only (this directory holds no horizon results)." % command)
        say("")
        targets4 = []
        visibility_section(d, say, targets4)
        if targets4:
            out[4:4] = ["## Issue 4 targets (intervisibility)", "", table(["target", "measured", "verdict"], targets4),
                        ""]
        target_e = issue8_target_e(d)
        out[4:4] = ["## Issue 8 targets (receiver-exact horizons)", "",
                    "Only target e (visible counts) is measured from `visibility.csv`; a through d need the horizon "
                    "suite's `results.csv`.", "", table(["target", "measured", "verdict"], [target_e]), ""]
        counts25 = issue25_count_targets(d)
        out[4:4] = ["## Issue 25 targets (sharp-edged surfaces: city DSMs)", "",
                    "Only the count target is measured from `visibility.csv`; the horizon targets need the horizon "
                    "suite's `results.csv`.", "", table(["target", "measured", "verdict"], counts25), ""]
        with open(os.path.join(d, "REPORT.md"), "w") as f:
            f.write("\n".join(out) + "\n")
        for name, measured, outcome in counts25 + [target_e] + targets4:
            print("%-80s %s -> %s" % (name, measured, outcome))
        return 0
    command = {"full": "bench/run_report.sh", "quick": "bench/run_report.sh --quick"}.get(
        env.get("mode"), "hfvis_bench suite --%s" % env.get("mode"))
    if vis_env and vis_env.get("commit") != env.get("commit"):
        say("Generated by `%s`. Two runs feed it: the horizon sections come from `results.csv` (mode **%s**, "
            "commit %s, %s), the intervisibility section from `visibility.csv` (mode **%s**, commit %s, %s; "
            "`--only visibility` reran that suite alone). Every ratio is of two timings taken in the same run." % (
                command, env.get("mode", "?"), env.get("commit", "?"), env.get("date_utc", "?"),
                vis_env.get("mode", "?"), vis_env.get("commit", "?"), vis_env.get("date_utc", "?")))
    else:
        say("Generated by `%s` (mode **%s**); every figure below comes from `results.csv` and `visibility.csv` "
            "of that one run, and every ratio is of two timings taken in it. Regenerate with the same command." % (
                command, env.get("mode", "?")))
    say("")
    say("## Where it ran")
    say("")
    env_rows = [
        ("date (UTC)", env.get("date_utc")), ("commit", env.get("commit")),
        ("device", "%s (%s, %s compute units, %s MiB)" % (env.get("device"), env.get("device_type"),
                                                        env.get("compute_units"), env.get("device_memory_mib"))),
        ("OpenCL platform / driver", "%s, driver %s, %s" % (env.get("platform"), env.get("opencl_driver"),
                                                            env.get("opencl_version"))),
        ("CPU", "%s, %s hardware threads, %s" % (env.get("cpu_model"), env.get("hardware_threads"),
                                                 env.get("memory_total"))),
        ("OS / compiler", "%s; %s" % (env.get("os_kernel"), env.get("compiler"))),
        ("load average (1/5/15 min) at start / end", "%s / %s" % (env.get("load_average_start"),
                                                                  env.get("load_average_end"))),
        ("suite time", "%s s (whole command incl. build and inputs: %s s)" % (
            fmt(float(env.get("suite_seconds", "nan")), 4),
            fmt(float(env["command_seconds"]), 4) if "command_seconds" in env else "n/a")),
    ]
    say(table(["", ""], env_rows))
    say("")
    say("Timing: each measurement is one warm-up run on a 64x64 crop (builds the OpenCL program), one full-size run "
        "discarded as warm-up when it takes under 1 s, then repeated runs (at least 2; more while under the time "
        "budget); the tables give the minimum and median wall time. A run is the whole library call: upload, "
        "every kernel, and the download of what the outputs column names (`angles`: K planes to the host, the "
        "`hfvis horizon` job; `svf`: the sky-view factor only; `device`: planes written on the device, not "
        "downloaded). *core-ns/pd* is wall time x %s compute units per pixel and direction; *CPU-ns/pd* is the "
        "process's CPU time per pixel and direction, which stays close to the work done when other processes "
        "share the cores (the load average above says how busy the machine was)." % env.get("compute_units", "?"))
    say("")
    say("Errors are against the exact horizon of the bilinear surface (double precision, exact direction, from the "
        "exact pixel; the supremum over the whole ray, including its limit at the receiver) on a fixed random "
        "subset of receivers; *interior* excludes receivers within 2 pixels of the field's edge, where rays leave "
        "the field at once. SVF and AO of both sides use the library's formulas from the K angles. The sweep's "
        "directions are lattice steps: with the angle planes, direction k is within the library's azimuth "
        "tolerance (%s deg, the default of this run's library) of 2 pi k / K, and the errors, taken against the "
        "exact horizon at 2 pi k / K, include that offset; with the SVF output only, it integrates over "
        "quadrature directions (the cheapest step within half a spacing of 2 pi k / K, weighted), and its SVF "
        "output is compared as it is with the SVF of the exact horizons at 2 pi k / K (same K) on the truth's "
        "receivers." % env.get("sweep_azimuth_tolerance_deg", "?"))
    say("")

    # ---------------------------------------------------------------- headline
    h = res.select("headline")
    if h:
        sweep_a = res.one("headline", method="sweep", outputs="angles", spu="1")
        sweep_s = res.one("headline", method="sweep", outputs="svf")
        naive_a = res.one("headline", method="naive", outputs="angles")
        naive_s = res.one("headline", method="naive", outputs="svf")
        floor_a = res.one("headline", method="floor", outputs="angles")
        floor_d = res.one("headline", method="floor", outputs="device")
        n = sweep_a["width"] if sweep_a else "?"
        k = sweep_a["K"] if sweep_a else "?"
        say("## Headline: fractal terrain %sx%s, K = %s" % (n, n, k))
        say("")
        say(measurement_table(h))
        say("")
        r_naive = ratio(naive_a, sweep_a)
        r_naive_med = ratio(naive_a, sweep_a, "t_median_s")
        r_naive_cpu = ratio(naive_a, sweep_a, "cpu_min_s")
        bullets = []
        if r_naive:
            bullets.append("**Sweep vs naive march** (both writing K angle planes to the host): the naive march takes "
                           "**%s x** the sweep's wall time (min over runs; %s x by medians) and **%s x** its CPU "
                           "time. Mean horizon error: sweep %s deg, naive %s deg." % (
                               fmt(r_naive), fmt(r_naive_med), fmt(r_naive_cpu), fmt(num(sweep_a, "err_mean_deg")),
                               fmt(num(naive_a, "err_mean_deg"))))
        if naive_a and naive_a.get("core_ns_per_step"):
            bullets.append("The naive march costs %s core-ns per executed ray step (wall; %s CPU-ns), %s steps in "
                           "all, %s of them inside the field." % (
                               fmt(num(naive_a, "core_ns_per_step")), fmt(num(naive_a, "cpu_ns_per_step")),
                               fmt(num(naive_a, "steps_executed")), fmt(num(naive_a, "steps_inside"))))
        if sweep_s and naive_s:
            bullets.append("**SVF only** (the `hfvis svf` job; the sweep integrates over its quadrature directions, "
                           "the naive march over 2 pi k / K): the naive march takes **%s x** the sweep's wall time "
                           "(%s x by CPU time). SVF error against the exact horizons' SVF at K = %s, mean / max abs: "
                           "sweep %s / %s, naive %s / %s." % (
                               fmt(ratio(naive_s, sweep_s)), fmt(ratio(naive_s, sweep_s, "cpu_min_s")), k,
                               fmt(num(sweep_s, "svf_mean_abs")), fmt(num(sweep_s, "svf_max_abs")),
                               fmt(num(naive_s, "svf_mean_abs")), fmt(num(naive_s, "svf_max_abs"))))
        if sweep_s:
            bullets.append("**Sweep cost**: %s CPU-ns per pixel-direction with the SVF output (no planes "
                           "downloaded; %s core-ns from wall time x cores), %s CPU-ns with the K angle planes." % (
                               fmt(num(sweep_s, "cpu_ns_per_pd")), fmt(num(sweep_s, "core_ns_per_pd")),
                               fmt(num(sweep_a, "cpu_ns_per_pd")) if sweep_a else "n/a"))
        if floor_a and sweep_a:
            bullets.append("**Bandwidth floor** (read heights, write one value per pixel-direction, allocation and "
                           "first touch of the planes included): %s CPU-ns/pd with the download, %s on the device "
                           "only. The sweep reaches **%s** of the floor's speed for the angles job (floor time / "
                           "sweep time; %s by CPU time) and %s for the on-device work (floor on the device / sweep "
                           "with SVF only; %s by CPU time)." % (
                               fmt(num(floor_a, "cpu_ns_per_pd")), fmt(num(floor_d, "cpu_ns_per_pd")),
                               fmt(ratio(floor_a, sweep_a)), fmt(ratio(floor_a, sweep_a, "cpu_min_s")),
                               fmt(ratio(floor_d, sweep_s)), fmt(ratio(floor_d, sweep_s, "cpu_min_s"))))
        for b in bullets:
            say("- " + b)
        say("")
        # targets from the headline
        if sweep_a and naive_a:
            targets.append(("sweep >= 50x faster than the naive march at N = 1024, K = 64",
                            "%s x by wall time, %s x by CPU time, at N = %s, K = %s" % (
                                fmt(r_naive), fmt(r_naive_cpu), n, k),
                            verdict(r_naive, r_naive_cpu, lambda v: v >= 50) if n == "1024"
                            else "not measured at N = 1024 (quick mode)"))
            e_s, e_n = num(sweep_a, "err_mean_deg"), num(naive_a, "err_mean_deg")
            targets.append(("sweep's horizon error no larger than the naive march's at the same K",
                            "mean %s vs %s deg; p99 %s vs %s deg" % (fmt(e_s), fmt(e_n), fmt(num(sweep_a, "err_p99_deg")),
                                                                    fmt(num(naive_a, "err_p99_deg"))),
                            "met" if e_s is not None and e_n is not None and e_s <= e_n else "not met"))
        if sweep_s:
            c, cpu = num(sweep_s, "core_ns_per_pd"), num(sweep_s, "cpu_ns_per_pd")
            targets.append(("sweep <= 8 core-ns per pixel-direction",
                            "%s core-ns/pd from wall time, %s by CPU time (SVF output)" % (fmt(c), fmt(cpu)),
                            verdict(c, cpu, lambda v: v <= 8)))
        best = None
        for r in res.select("headline", method="sweep", outputs="angles"):
            if r["spu"] == "1":
                continue
            e = num(r, "err_mean_deg")
            if naive_a and e is not None and e <= 0.5 * num(naive_a, "err_mean_deg") and ratio(naive_a, r) >= 20:
                best = r
        spu_rows = [r for r in res.select("headline", method="sweep", outputs="angles") if r["spu"] != "1"]
        if naive_a and spu_rows:
            text = "; ".join("%s: mean %s deg, %s x faster than naive (%s x by CPU time)" % (
                label(r), fmt(num(r, "err_mean_deg")), fmt(ratio(naive_a, r)), fmt(ratio(naive_a, r, "cpu_min_s")))
                for r in spu_rows)
            targets.append(("sweep with denser sampling: mean error <= half the unit-step naive march's "
                            "(%s deg), >= 20 x faster" % fmt(num(naive_a, "err_mean_deg")), text,
                            "met by %s" % label(best) if best else "not met"))
        headline_rows = [r for r in h if r.get("err_mean_deg")]
        plot_error_vs_time(headline_rows, "fractal %sx%s, K = %s" % (n, n, k), os.path.join(d, "headline_error_vs_time.png"))
        say("![error against time at the headline size](headline_error_vs_time.png)")
        say("")

    # ---------------------------------------------------------------- speed/error plane
    plane = res.select("plane")
    if plane:
        say("## Speed against error, per content")
        say("")
        say("Every method at every K on the same input and device; the error is the mean horizon error over the "
            "receivers of the ground truth. `sweep` at 1 and 4 samples per unit (spu); `naive` is the library's "
            "naive march (unit steps). `radius_R`: the same march limited to R pixels (the baseline kernel "
            "`radius_march`). `pyramid_S`: S unit steps on the surface, then S/2 steps per octave of distance on a "
            "max-height pyramid with step and texel 2^level.")
        say("")
        contents = []
        for r in plane:
            if r["content"] not in contents:
                contents.append(r["content"])
        violations = []
        for c in contents:
            rows = [r for r in plane if r["content"] == c]
            size = "%sx%s" % (rows[0]["width"], rows[0]["height"])
            path = "error_vs_time_%s.png" % c
            plot_error_vs_time(rows, "%s %s" % (CONTENT_TITLES.get(c, c), size), os.path.join(d, path))
            say("### %s, %s" % (CONTENT_TITLES.get(c, c), size))
            say("")
            say("![error against time, %s](%s)" % (c, path))
            say("")
            methods = []
            for r in rows:
                if label(r) not in methods:
                    methods.append(label(r))
            ks = sorted({int(r["K"]) for r in rows})
            cells = []
            for m in methods:
                line = [m]
                for kk in ks:
                    r = next((r for r in rows if label(r) == m and int(r["K"]) == kk), None)
                    line.append("%s s / %s deg" % (fmt(num(r, "t_min_s")), fmt(num(r, "err_mean_deg"))) if r else "")
                cells.append(line)
            say(table(["method"] + ["K = %d: time / mean err" % kk for kk in ks], cells))
            say("")
            for kk in ks:
                sw = next((r for r in rows if r["method"] == "sweep" and int(r["K"]) == kk), None)
                if not sw:
                    continue
                for r in rows:
                    if int(r["K"]) == kk and r["method"].startswith(APPROXIMATIONS):
                        faster_wall = num(r, "t_min_s") < num(sw, "t_min_s")
                        faster_cpu = num(r, "cpu_min_s") < num(sw, "cpu_min_s")
                        if (faster_wall or faster_cpu) and num(r, "err_mean_deg") < num(sw, "err_mean_deg"):
                            violations.append("%s: %s at K = %d (%s s wall / %s s CPU, %s deg vs the sweep's %s s / "
                                              "%s s, %s deg)" % (
                                                  c, r["method"], kk, fmt(num(r, "t_min_s")), fmt(num(r, "cpu_min_s")),
                                                  fmt(num(r, "err_mean_deg")), fmt(num(sw, "t_min_s")),
                                                  fmt(num(sw, "cpu_min_s")), fmt(num(sw, "err_mean_deg"))))
        say("**Dominance.** Approximations faster (by wall or by CPU time) and more accurate (mean error) than the "
            "sweep at the same K: %s" % ("none." if not violations else ""))
        for v in violations:
            say("- " + v)
        say("")
        targets.append(("the sweep dominates every approximation (none both faster and more accurate, same K)",
                        "%d exceptions over %d contents" % (len(violations), len(contents)),
                        "met" if not violations else "not met"))

    # ---------------------------------------------------------------- sources
    src = [r for r in res.select("sources") if r["metric"] == ""]
    if src:
        say("## Error against samples per unit")
        say("")
        say("The naive march samples its ray every 1/S pixel (S samples per unit, `spu`): its error is the "
            "sampling error alone. The sweep's lines run through the pixel centres; it samples them where they "
            "cross the grid (exact bilinear heights) and, with S above 1, about S points per pixel between the "
            "crossings (where the surface can peak inside a cell), and takes the exact limit at the receiver. Its "
            "azimuths are within the library's tolerance of 2 pi k / K, and the errors here are against the exact "
            "horizon at 2 pi k / K, so they include that offset.")
        say("")
        for c in sorted({r["content"] for r in src}):
            rows = [r for r in src if r["content"] == c]
            say("### %s, %sx%s, K = %s" % (CONTENT_TITLES.get(c, c), rows[0]["width"], rows[0]["height"], rows[0]["K"]))
            say("")
            cells = []
            for spu in sorted({r["spu"] for r in rows}, key=float):
                naive = next((r for r in rows if r["method"] == "naive" and r["spu"] == spu), None)
                sweep = next((r for r in rows if r["method"] == "sweep" and r["spu"] == spu), None)
                line = [spu]
                for r in (naive, sweep):
                    line += ([fmt(num(r, "t_min_s")), fmt(num(r, "err_mean_deg")), fmt(num(r, "err_p99_deg")),
                              fmt(num(r, "err_max_deg"))] if r else ["", "", "", ""])
                line.append(fmt(ratio(naive, sweep)))
                cells.append(line)
            say(table(["spu", "naive s", "naive mean deg", "naive p99", "naive max", "sweep s", "sweep mean deg",
                       "sweep p99", "sweep max", "naive / sweep time"], cells))
            say("")

    # ---------------------------------------------------------------- azimuth
    az = res.select("azimuth")
    if az:
        ref = az[0]["value"]
        say("## Azimuthal discretisation alone")
        say("")
        say("SVF and AO of the sweep at K against the same sweep at K = %s, over every pixel (the horizon error "
            "is common to both, so this is the error of summing over K azimuths)." % fmt(float(ref), 4))
        say("")
        cells = [[CONTENT_TITLES.get(r["content"], r["content"]), r["K"], fmt(num(r, "svf_mean_abs")),
                  fmt(num(r, "svf_max_abs")), fmt(num(r, "ao_mean_abs")), fmt(num(r, "ao_max_abs"))] for r in az]
        say(table(["content", "K", "SVF mean abs", "SVF max abs", "AO mean abs", "AO max abs"], cells))
        say("")

    # ---------------------------------------------------------------- scaling
    sn_all = res.select("scale_n")
    sn = [r for r in sn_all if r["t_min_s"]]
    skipped = [r for r in sn_all if r["metric"] == "skipped_predicted_seconds"]
    sk = res.select("scale_k")
    if sn or sk:
        say("## Scaling")
        say("")
        series = []
        fits = []
        groups = {}
        for r in sn:
            groups.setdefault((r["method"], r["outputs"], r["K"]), []).append(r)
        sweep_k_max = max((int(r["K"]) for r in sn if r["method"] == "sweep"), default=None)
        for (m, o, kk), rows in sorted(groups.items()):
            rows.sort(key=lambda r: int(r["width"]))
            xs = [int(r["width"]) for r in rows]
            wall = [num(r, "t_min_s") for r in rows]
            cpu = [num(r, "cpu_min_s") for r in rows]
            name = "%s (%s), K = %s" % (m, o, kk)
            series.append((name, xs, wall, cpu))
            exponents = []
            for ys in (wall, cpu):
                big = [(x, y) for x, y in zip(xs, ys) if x >= 1024]
                exponents += [fit_exponent(xs, ys), fit_exponent(*zip(*big)) if len(big) >= 2 else None]
            fits.append([name, ", ".join(str(x) for x in xs)] + [fmt(e) for e in exponents])
            if m == "sweep" and int(kk) == sweep_k_max:
                e_wall = exponents[1] if exponents[1] is not None else exponents[0]
                e_cpu = exponents[3] if exponents[3] is not None else exponents[2]
                targets.append(("sweep time linear in N^2 K: exponent in N within 2.0 +- 0.15",
                                "%s by wall time, %s by CPU time (N >= 1024; all N: %s, %s)" % (
                                    fmt(exponents[1]), fmt(exponents[3]), fmt(exponents[0]), fmt(exponents[2])),
                                verdict(e_wall, e_cpu, lambda v: abs(v - 2.0) <= 0.15)))
        plot_scaling(series, "N (field is N x N)", "time against N, fractal terrain", os.path.join(d, "time_vs_n.png"))
        say("![time against N](time_vs_n.png)")
        say("")
        for r in skipped:
            say("- Not measured: %s (%s), K = %s at N = %s: %s (about %s s)." % (
                r["method"], r["outputs"], r["K"], r["width"], r["note"], fmt(float(r["value"]))))
        if skipped:
            say("")
        say(table(["series", "N", "exponent, wall (all N)", "wall (N >= 1024)", "CPU (all N)", "CPU (N >= 1024)"],
                  fits))
        say("")
        # same-K ratios per N
        sweep_k = {}
        naive_k = {}
        for r in sn:
            if r["method"] == "sweep":
                sweep_k[(r["width"], r["K"])] = r
            if r["method"] == "naive":
                naive_k[(r["width"], r["K"])] = r
        cells = []
        for (w, kk), nr in sorted(naive_k.items(), key=lambda x: int(x[0][0])):
            sr = sweep_k.get((w, kk))
            if sr:
                cells.append([w, kk, fmt(num(sr, "t_min_s")), fmt(num(nr, "t_min_s")), fmt(ratio(nr, sr)),
                              fmt(ratio(nr, sr, "cpu_min_s"))])
                if w == "2048":
                    rr, rc = ratio(nr, sr), ratio(nr, sr, "cpu_min_s")
                    targets.append(("sweep >= 100x faster than the naive march at N = 2048",
                                    "%s x by wall time, %s x by CPU time (K = %s; both SVF only)" % (
                                        fmt(rr), fmt(rc), kk),
                                    verdict(rr, rc, lambda v: v >= 100)))
        if cells:
            say("Naive march against the sweep at the same K and N (both with the SVF output only, the whole "
                "library call):")
            say("")
            say(table(["N", "K", "sweep s", "naive s", "naive / sweep (wall)", "naive / sweep (CPU)"], cells))
            say("")
        series = []
        fits = []
        if sk:
            rows = sorted(sk, key=lambda r: int(r["K"]))
            name = "sweep (svf), N = %s" % rows[0]["width"]
            series.append((name, [int(r["K"]) for r in rows], [num(r, "t_min_s") for r in rows],
                           [num(r, "cpu_min_s") for r in rows]))
        pf = [r for r in plane if r["content"] == "fractal"] if plane else []
        by_method = {}
        for r in pf:
            by_method.setdefault(label(r), []).append(r)
        for m, rows in sorted(by_method.items()):
            rows.sort(key=lambda r: int(r["K"]))
            series.append(("%s (angles), N = %s" % (m, rows[0]["width"]), [int(r["K"]) for r in rows],
                           [num(r, "t_min_s") for r in rows], [num(r, "cpu_min_s") for r in rows]))
        for name, xs, wall, cpu in series:
            fits.append([name, ", ".join(str(x) for x in xs), fmt(fit_exponent(xs, wall)), fmt(fit_exponent(xs, cpu))])
        if series:
            plot_scaling(series, "K (directions)", "time against K, fractal terrain", os.path.join(d, "time_vs_k.png"))
            say("![time against K](time_vs_k.png)")
            say("")
            say(table(["series", "K", "exponent in K (wall)", "exponent in K (CPU)"], fits))
            say("")

    # ---------------------------------------------------------------- stack
    st = res.select("stack")
    if st:
        say("## Hull stack statistics")
        say("")
        say("Algorithm 1 run on the host over every line of the lattice sweep in %s directions as an SVF / AO run "
            "takes them (quadrature directions, one sample per unit, the library's default), counting per sample "
            "what the kernel `horizon_lattice` does: each receiver's period of line samples (at one sample per "
            "unit, its grid crossings), then the receiver. *samples per receiver* is the samples pushed per pixel and direction."
            % st[0]["note"].split(" directions")[0])
        say("")
        cells = {}
        for r in st:
            key = (r["content"], r["width"], r["height"])
            cells.setdefault(key, {})[r["metric"]] = r["value"]
            cells[key]["samples"] = r["note"].split(", ")[-1]
        say(table(["content", "size", "pops per sample", "mean stack depth", "max depth", "samples per receiver",
                   "samples"],
                  [[CONTENT_TITLES.get(c, c), "%sx%s" % (w, hh), fmt(float(v.get("pops_per_sample", "nan"))),
                    fmt(float(v.get("mean_depth", "nan"))), v.get("max_depth"),
                    fmt(float(v.get("samples_per_receiver", "nan"))), v.get("samples")]
                   for (c, w, hh), v in cells.items()]))
        say("")

    # ---------------------------------------------------------------- lattice directions
    lat = res.select("lattice")
    if lat:
        say("## The sweep's directions and what they cost")
        say("")
        say("The sweep runs each direction along a primitive integer step (a, b): per receiver and direction it "
            "pushes one period's samples (the grid crossings of a step of length |(a, b)| pixels, more with S "
            "above 1), so its cost per pixel-direction follows *samples per receiver*. With the angle planes the "
            "step is the cheapest within the azimuth tolerance of 2 pi k / K (long steps at large K, and at any K "
            "on cells that are not square, as the DEM's); with the SVF output alone, the cheapest within half a "
            "spacing. Host figures of the library's choice, no timing. Beside them, the sweep's measured "
            "core-ns per pixel-direction where this run has it: with the angle planes from the speed/error "
            "plane (same field), with the SVF only from the time-against-K series (fractal%s)." % (
                " %sx%s" % (sk[0]["width"], sk[0]["height"]) if sk else ""))
        say("")
        cells = []
        keys = []
        for r in lat:
            key = (r["content"], r["width"], r["height"], r["K"], r["outputs"])
            if key not in keys:
                keys.append(key)
        for key in keys:
            c, w, hh, kk, o = key
            per_spu = {r["spu"]: r for r in lat if (r["content"], r["width"], r["height"], r["K"], r["outputs"]) == key}
            one, four = per_spu.get("1"), per_spu.get("4")
            note = one["note"] if one else ""
            period = note.split("period ")[1].split(";")[0] if "period " in note else ""
            offset = note.split("offset ")[1] if "offset " in note else ""
            if o == "angles":
                m1 = next((r for r in (plane or []) if r["content"] == c and r["method"] == "sweep" and r["K"] == kk
                           and r["spu"] == "1" and r["width"] == w), None)
                m4 = next((r for r in (plane or []) if r["content"] == c and r["method"] == "sweep" and r["K"] == kk
                           and r["spu"] == "4" and r["width"] == w), None)
            else:
                m1 = next((r for r in sk if r["content"] == c and r["K"] == kk), None) if sk else None
                m4 = None
            cells.append([CONTENT_TITLES.get(c, c), "%sx%s" % (w, hh), kk, o,
                          fmt(num(one, "value")) if one else "", fmt(num(four, "value")) if four else "", period,
                          offset, fmt(num(m1, "core_ns_per_pd")) if m1 else "",
                          fmt(num(m4, "core_ns_per_pd")) if m4 else ""])
        say(table(["content", "size", "K", "outputs", "samples per receiver, S = 1", "S = 4", "period (px)",
                   "largest azimuth offset", "sweep core-ns/pd, S = 1", "S = 4"], cells))
        say("")

    # ---------------------------------------------------------------- naive kernels
    say("## The naive method")
    say("")
    marches = [r for r in (plane or []) if r["method"] == "naive" or r["method"].startswith("radius_")]
    naive_ks = sorted({int(r["K"]) for r in marches if r["method"] == "naive"})
    step_k = "64" if 64 in naive_ks else (str(naive_ks[-1]) if naive_ks else None)
    marches = [r for r in marches if r["K"] == step_k]
    cells = [[CONTENT_TITLES.get(r["content"], r["content"]), "%sx%s" % (r["width"], r["height"]), r["K"], r["method"],
              "`horizon_naive`" if r["method"] == "naive" else "`radius_march`", fmt(num(r, "core_ns_per_step")),
              fmt(num(r, "cpu_ns_per_step")), fmt(num(r, "steps_executed")), fmt(num(r, "steps_inside"))]
             for r in marches]
    say("One naive march serves the library, the CLI (`--method naive`) and this report: the library's "
        "`horizon_naive` (`kernels/horizon.cl`; unit steps, bilinear samples, steepest slope), written to "
        "vectorise on PoCL: one launch per direction, the geometry as kernel arguments, the march loop's trip "
        "count the same for the whole 16 x 4 work-group (the tile's longest ray) and each step ending in a "
        "barrier, so PoCL runs every step as one region over the group's work-items, which LLVM vectorises. "
        "PoCL's remarks therefore list the step loop itself as not vectorised (it is not innermost) and the "
        "vectorised loops as PoCL-generated work-item loops or at a line inside the step. `radius_R` runs the "
        "baselines' kernel `radius_march` (`bench/kernels/horizon_baselines.cl`), the same march cut off after R "
        "pixels; the checks below compare it, with a radius past every ray's end, against the library's march. "
        "The table gives the cost per executed ray step (every lane runs its tile's longest ray: samples past a "
        "pixel's own exit included)%s." % (", from the speed/error plane at K = %s" % step_k if step_k else ""))
    say("")
    if cells:
        say(table(["content", "size", "K", "method", "kernel", "core-ns/step (wall)", "CPU-ns/step",
                   "steps executed", "steps inside"], cells))
        say("")
    vec = res.select("vectorize")
    if vec:
        say("PoCL's loop vectorisation remarks (`POCL_VECTORIZER_REMARKS=1`, kernels built with `-g`; line numbers "
            "of the embedded source):")
        say("")
        for r in vec:
            say("- %s: %s" % (r["method"], r["note"].replace("|", "\\|")))
        say("")

    # ---------------------------------------------------------------- intervisibility
    targets4 = []
    visibility_section(d, say, targets4)

    # ---------------------------------------------------------------- checks
    say("## Checks of the harness")
    say("")
    ck = res.select("checks")
    for r in ck:
        if r["metric"] == "truth_self_check_failures":
            say("- Ground truth self-checks: %s failures; %s." % (r["value"], r["note"]))
        elif r["metric"] == "baseline_march_vs_library_naive_max_deg":
            say("- The baselines' march `radius_march` (as `radius_R` runs it, R past every ray's end) against the "
                "library's naive march (%s %sx%s, %s): max angle difference %s deg." % (
                    r["content"], r["width"], r["height"], r["note"], fmt(float(r["value"]))))
        elif r["metric"].startswith("host_"):
            say("- Host %s formula from the library's angles against the library's own reduction: max abs "
                "difference %s." % (r["metric"].split("_")[1].upper(), fmt(float(r["value"]))))
    # The same measurement taken in two sections of the run: how noisy the machine was.
    head = res.one("headline", method="sweep", outputs="svf")
    if head:
        again = res.one("scale_n", method="sweep", outputs="svf", K=head["K"], width=head["width"], metric="")
        if again:
            say("- Repeatability: the sweep with the SVF output at %sx%s, K = %s, was measured twice in this run "
                "(headline and N scaling): min %s s and %s s wall, %s s and %s s CPU; differences of this size "
                "are the machine's noise (other processes shared the 2 cores; load averages above), not the "
                "method's." % (head["width"], head["height"], head["K"], fmt(num(head, "t_min_s")),
                               fmt(num(again, "t_min_s")), fmt(num(head, "cpu_min_s")), fmt(num(again, "cpu_min_s"))))
    say("")

    # ---------------------------------------------------------------- targets
    targets8, detail8 = issue8_targets(res, d)
    at = out.index("## Where it ran") if "## Where it ran" in out else 2
    if targets4:
        out[at:at] = ["## Issue 4 targets (intervisibility)", "", table(["target", "measured", "verdict"], targets4), ""]
    if targets:
        at = out.index("## Where it ran") if "## Where it ran" in out else 2
        out[at:at] = ["## Issue 3 targets", "", table(["target", "measured", "verdict"], targets), ""]
    # Issue 8's table first, above the earlier issues' (kept as history).
    at = next((i for i, line in enumerate(out) if line.startswith("## ")), 2)
    out[at:at] = ["## Issue 8 targets (receiver-exact horizons)", "",
                  "From this run's `results.csv` (mode **%s**); sizes and K as each row says." % env.get("mode", "?"),
                  "", table(["target", "measured", "verdict"], targets8), ""] + (detail8 + [""] if detail8 else [])
    # Issue 25's table above them all.
    # The counts from this directory's visibility.csv, or else from a run of the accuracy section
    # alone kept in visibility_accuracy/ (`hfvis_bench visibility --sections accuracy`).
    counts25 = issue25_count_targets(d)
    alone = os.path.join(d, "visibility_accuracy")
    if counts25[0][2] == "not measured" and os.path.exists(os.path.join(alone, "visibility.csv")):
        counts25 = [(t, m.replace("visibility.csv", "visibility_accuracy/visibility.csv"), v)
                    for t, m, v in issue25_count_targets(alone)]
    targets25 = issue25_targets(res, d) + counts25
    at = next((i for i, line in enumerate(out) if line.startswith("## ")), 2)
    out[at:at] = ["## Issue 25 targets (sharp-edged surfaces: city DSMs)", "",
                  "From this run's `results.csv` (mode **%s**; the speed/error plane and the error against samples "
                  "per unit) and `cost_against.md` (bench/cost_against.sh, a separate run on the same machine)."
                  % env.get("mode", "?"), "", table(["target", "measured", "verdict"], targets25), "",
                  "Item 1 for the hull tree (counts, area, the bounce): each interval's peak between two samples "
                  "enters the tree as an occluder alone; its accuracy and cost: [tree_peaks.md](tree_peaks.md) "
                  "(not yet for the horizon lists).", ""]

    # Issue 31's table above them all.
    targets31 = issue31_targets(d)
    at = next((i for i, line in enumerate(out) if line.startswith("## ")), 2)
    out[at:at] = ["## Issue 31 targets (asking for an error: --max-error)", "",
                  "From `error_target.md` (bench/error_target.sh, a separate run; its header says where and how), "
                  "and the estimate against the error at each fixed K: [error_curve.md](error_curve.md).", "",
                  table(["target", "measured", "verdict"], targets31), ""]

    with open(os.path.join(d, "REPORT.md"), "w") as f:
        f.write("\n".join(out) + "\n")
    for name, measured, outcome in targets31 + targets25 + targets8 + targets + targets4:
        print("%-80s %s -> %s" % (name, measured, outcome))
    return 0


if __name__ == "__main__":
    sys.exit(main())
