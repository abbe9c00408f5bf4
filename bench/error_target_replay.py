#!/usr/bin/env python3
"""bench/error_target_replay.py: replays rules for choosing K (HorizonOptions::max_error) on the
curves measured at fixed K in bench/report/error_curve.md (bench/error_target.sh --curve), to see
what the stepping and what the estimate cost, without running the sweep again.

    /usr/bin/python3 bench/error_target_replay.py [bench/report/error_curve.md] [--overhead 30]

A run between the ladder's K takes the error, estimate and samples interpolated log-log; a run's
cost is its samples per receiver plus --overhead (a run's fixed costs, in samples). The cheapest
fixed K is the ladder's first K whose error is at most E. Prints, per output, the share of cases
meeting E and the median and largest cost over the cheapest fixed K's: for the present rule
(detail::nextDirectionsForError, the estimate over detail::richardsonDivisor; --max-order
replays it with another bound on p), the earlier rule (detail::directionsForError, the raw
estimate), the best of a family of other stepping rules, a single run at the first K whose raw
estimate meets E (the stepping's floor), and the earlier rule with the estimate scaled down.
"a perfect estimate" replays the present stepping with the estimate equal to the error. --errors and --contents choose the cases (default: all E above, every content in the file)."""
import argparse
import math
import re
import statistics

ERRORS = (0.001, 0.002, 0.005, 0.01, 0.02, 0.05)


def curves(path):
    data, output = {}, None
    for line in open(path):
        if line.startswith("### "):
            output = "svf" if "sky" in line else "ao"
        m = re.match(r"\| (\w+) \| (\d+) \| (\d+) \| ([\d.]+) \| ([\d.]+) \|", line)
        if m:
            data.setdefault((output, m.group(1)), {})[int(m.group(2))] = tuple(map(float, m.group(3, 4, 5)))
    return data


def at(curve, K, i):  # samples (0), error (1) or estimate (2) at K, log-log between the ladder's
    ks = sorted(curve)
    if K in curve:
        return curve[K][i]
    a, b = (ks[-2], ks[-1]) if K > ks[-1] else (max(k for k in ks if k < K), min(k for k in ks if k > K))
    t = math.log(K / a) / math.log(b / a)
    return math.exp(math.log(curve[a][i]) + t * (math.log(curve[b][i]) - math.log(curve[a][i])))


def rule(first_cap=4.0, p_first=1.0, p_range=(0.5, 3.0), margin=1.05, target=1.0):
    def next_k(K, estimate, earlier, earlier_estimate, E):
        p = p_first
        if earlier and earlier_estimate > estimate > 0:
            p = min(p_range[1], max(p_range[0], math.log(earlier_estimate / estimate) / math.log(K / earlier)))
        factor = (estimate / (target * E)) ** (1 / p) * margin
        if not earlier:
            factor = min(factor, first_cap)
        return int(max(K + 8, min(math.ceil(K * factor / 8) * 8, 8192)))
    return next_k


def richardson_order(runs, max_order):  # detail::estimateOrder
    K, raw = runs[-1]
    for k0, r0 in reversed(runs[:-1]):
        if 2 * k0 <= K:
            if not (r0 > 0 and raw > 0):
                return 1.0
            return min(max_order, max(1.0, math.log(r0 / raw) / math.log(K / k0)))
    return 1.0


def present(data, overhead, max_order=1.1, aim=0.9, perfect=False):
    """detail::nextDirectionsForError and the estimate over detail::richardsonDivisor; perfect: the
    same stepping with the estimate replaced by the achieved error (an estimate that is exact), so
    what is left over the cheapest fixed K is the stepping's own cost."""
    cases = []
    for (output, field), curve in sorted(data.items()):
        for E in ERRORS:
            fixed = next((k for k in sorted(curve) if curve[k][1] <= E), None)
            runs, cost, K = [], 0.0, 16
            while K <= 4096:
                raw = at(curve, K, 1 if perfect else 2)
                cost += at(curve, K, 0) + overhead
                runs.append((K, raw))
                divisor = 1.0 if perfect else 2 ** richardson_order(runs, max_order) - 1
                if raw / divisor <= E:
                    break
                q = 1.0
                if len(runs) >= 2 and runs[-2][1] > raw > 0:
                    q = min(2.0, max(1.0, math.log(runs[-2][1] / raw) / math.log(K / runs[-2][0])))
                divisor = 1.0 if perfect else 2 ** min(q, max_order) - 1
                wanted = min(K * (raw / divisor / (aim * E)) ** (1 / q), 8192)
                if wanted > 4 * K:
                    wanted = min(wanted, max(2 * K, wanted / 6))
                K = int(max(K + 8, math.ceil(wanted / 8) * 8))
            if K <= 4096 and fixed:
                cases.append((output, at(curve, K, 1) <= E, cost / (curve[fixed][0] + overhead)))
    return cases


def replay(data, next_k, overhead, first=16, scale=1.0):
    cases = []
    for (output, field), curve in sorted(data.items()):
        for E in ERRORS:
            fixed = next((k for k in sorted(curve) if curve[k][1] <= E), None)
            K, earlier, earlier_estimate, cost = first, 0, 0.0, 0.0
            while K <= 4096:
                estimate = at(curve, K, 2) * scale
                cost += at(curve, K, 0) + overhead
                if estimate <= E:
                    break
                K, earlier, earlier_estimate = next_k(K, estimate, earlier, earlier_estimate, E), K, estimate
            if K <= 4096 and fixed:
                cases.append((output, at(curve, K, 1) <= E, cost / (curve[fixed][0] + overhead)))
    return cases


def floor(data, overhead):
    cases = []
    for (output, field), curve in sorted(data.items()):
        for E in ERRORS:
            fixed = next((k for k in sorted(curve) if curve[k][1] <= E), None)
            K = next((k for k in range(8, 4097, 8) if at(curve, k, 2) <= E), None)
            if K and fixed:
                cases.append((output, at(curve, K, 1) <= E, (at(curve, K, 0) + overhead) / (curve[fixed][0] + overhead)))
    return cases


def summary(name, cases):
    for output in ("svf", "ao"):
        c = [x for x in cases if x[0] == output]
        ratios = sorted(x[2] for x in c)
        print("%-58s %-3s E met %2d of %2d, cost over the cheapest fixed K: median %.2f, largest %.2f" % (
            name, output, sum(x[1] for x in c), len(c), statistics.median(ratios), ratios[-1]))


def main():
    global ERRORS
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("curve", nargs="?", default="bench/report/error_curve.md")
    ap.add_argument("--overhead", type=float, default=30.0)
    ap.add_argument("--max-order", type=float, default=1.1)
    ap.add_argument("--errors", default="0.001,0.002,0.005,0.01,0.02,0.05")
    ap.add_argument("--contents", default="")
    args = ap.parse_args()
    ERRORS = tuple(float(e) for e in args.errors.split(","))
    data = curves(args.curve)
    if args.contents:
        data = {key: curve for key, curve in data.items() if key[1] in args.contents.split(",")}
    summary("present rule (p at most %g)" % args.max_order, present(data, args.overhead, args.max_order))
    summary("present stepping, a perfect estimate", present(data, args.overhead, perfect=True))
    summary("earlier rule", replay(data, rule(), args.overhead))
    best = None
    for first in (8, 16, 24, 32):
        for cap in (2, 3, 4, 8, 100):
            for p_first in (1.0, 1.3, 1.6):
                for p_range in ((0.5, 3.0), (0.8, 2.0)):
                    for margin in (1.0, 1.05, 1.15):
                        for target in (1.0, 0.9):
                            cases = replay(data, rule(cap, p_first, p_range, margin, target), args.overhead, first)
                            key = statistics.median(x[2] for x in cases)
                            if best is None or key < best[0]:
                                best = (key, cases, (first, cap, p_first, p_range, margin, target))
    summary("best other stepping (first, cap, p, p range, margin, aim) %s" % (best[2],), best[1])
    summary("one run at the first K whose estimate meets E", floor(data, args.overhead))
    for scale in (0.9, 0.8, 0.75, 0.7):
        summary("earlier rule, estimate x %.2f" % scale, replay(data, rule(), args.overhead, scale=scale))


if __name__ == "__main__":
    main()
