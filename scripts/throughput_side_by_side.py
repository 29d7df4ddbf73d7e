#!/usr/bin/python3
"""batch / loop of two revisions' idcol_bench_throughput runs, made alternately.

  scripts/throughput_side_by_side.py DIR OLD NEW I [I ...]

reads DIR/OLD_I.json and DIR/NEW_I.json for each run number I and prints a
Markdown table: each pair and mode's batch / loop in every run of each
revision, and the median over the runs of NEW's ratio over OLD's in the
same pair of runs (so that the machine's drift from one pair of runs to
the next falls on both alike). Exit 2 if a file is missing or its rows
differ from the first file's.
"""
import json
import statistics
import sys


def ratios(path):
    try:
        with open(path) as f:
            rows = json.load(f)["rows"]
    except (OSError, KeyError, ValueError) as e:
        print(f"throughput_side_by_side.py: cannot read rows of {path}: {e}", file=sys.stderr)
        sys.exit(2)
    return {(r["pair"], r["mode"]): r["batch_over_loop"] for r in rows}


def main(argv):
    if len(argv) < 5:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    d, old, new, runs = argv[1], argv[2], argv[3], argv[4:]
    O = [ratios(f"{d}/{old}_{i}.json") for i in runs]
    N = [ratios(f"{d}/{new}_{i}.json") for i in runs]
    keys = list(O[0])
    for x in O + N:
        if list(x) != keys:
            print("throughput_side_by_side.py: the runs hold different pairs or modes", file=sys.stderr)
            return 2
    print(f"| pair, mode | {old} | {new} | median of {new} / {old}, run by run |")
    print("|---|---|---|---:|")
    for k in keys:
        o = [x[k] for x in O]
        n = [x[k] for x in N]
        m = statistics.median(b / a for a, b in zip(o, n))
        print(f"| {k[0]} {k[1]} | {', '.join(f'{v:.2f}' for v in o)} | {', '.join(f'{v:.2f}' for v in n)} | {100 * (m - 1):+.1f}% |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
