#!/usr/bin/env python3
"""Exit 0 iff MERGED (a merge of shards) holds exactly the aggregates of WHOLE
(one process, no --shard): every pair's statistics, and a shard covering all
poses. Used by the scale-out tests; prints the first difference otherwise."""
import json
import sys


def first_difference(a, b, path="pairs"):
    if type(a) is not type(b):
        return f"{path}: {a!r} != {b!r}"
    if isinstance(a, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                return f"{path}.{k}: present in only one file"
            d = first_difference(a[k], b[k], f"{path}.{k}")
            if d:
                return d
        return None
    if isinstance(a, list):
        if len(a) != len(b):
            return f"{path}: lengths {len(a)} != {len(b)}"
        for i, (x, y) in enumerate(zip(a, b)):
            d = first_difference(x, y, f"{path}[{i}]")
            if d:
                return d
        return None
    return None if a == b else f"{path}: {a!r} != {b!r}"


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: same_aggregates.py MERGED.json WHOLE.json")
    with open(sys.argv[1]) as f:
        merged = json.load(f)
    with open(sys.argv[2]) as f:
        whole = json.load(f)
    if merged["shard"]["poses"] != whole["shard"]["poses"]:
        sys.exit(f"merged poses {merged['shard']['poses']} != single-process poses {whole['shard']['poses']}")
    shards = len(merged["shard"].get("merged_from", []))
    d = first_difference(merged["pairs"], whole["pairs"])
    if d:
        sys.exit(f"{sys.argv[1]} differs from {sys.argv[2]}: {d}")
    print(f"{sys.argv[1]}: {len(whole['pairs'])} pairs, poses {whole['shard']['poses']}, merged from {shards} shards, "
          f"equal to the single-process run")


if __name__ == "__main__":
    main()
