#!/usr/bin/env python3
"""Checks every measured figure quoted in the project's Markdown against the
results file it comes from, so that no figure in the documentation goes stale.

A quoted figure is written in this form (an HTML comment does not render):

    <!-- fig: results/paper_table1.json:wall_seconds .0f -->59<!-- /fig -->

FILE:PATH names a value in a JSON file (relative to the repository root):
PATH is a dot-separated list of steps from the top of the file:

    key          a member of an object
    3            an element of a list
    key=value    the element of a list whose member `key` equals `value`
                 (several conditions joined by `&`: body1=Poly&body2=Ellip)
    key~value    every element of a list whose member `key` equals `value`
                 (none or several; conditions joined by `&` as above)
    *            every element of a list or every member of an object
    key?         a member where it exists (after a *: the elements without it are left out)

and may end in `|op` steps applied in turn: `min`, `max`, `sum`, `len`,
`first`, `*K` or `/K` (multiply or divide by the number K). FMT is a
Python format spec (`.0f`, `.3g`, `,d`, `.7` for the first 7 characters of
a string); two values after a `*` (for instance min and max) are written
"A-B" when FMT is given with the `range` op:

    <!-- fig: results/paper_table1.json:pairs.*.passes.cold.iterations.mean|range .2f -->4.61-5.53<!-- /fig -->

The check fails, naming the Markdown file, its line, the quote and what the
file says, when a quote differs from the value formatted with FMT, when the
file or the path does not exist, or when a figure marker is malformed.

    scripts/check_doc_figures.py                # every *.md of the repository (not build folders)
    scripts/check_doc_figures.py README.md ...  # only these
    scripts/check_doc_figures.py --list         # every quote, with its value
    scripts/check_doc_figures.py --update       # rewrite each quote that disagrees with its file's value
                                                # (after a results file was regenerated: review with git diff)
Exit status: 0 every quote agrees; 1 a quote disagrees or cannot be read;
2 bad command line.
"""
import json
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIG = re.compile(r"<!--\s*fig:\s*(?P<spec>.*?)\s*-->(?P<quote>.*?)<!--\s*/fig\s*-->", re.S)
OPEN = re.compile(r"<!--\s*fig:")
SKIP_DIRS = {".git", "build", "node_modules", "dist", "__pycache__"}


class FigureError(Exception):
    pass


def step(values, s):
    """Applies one path step to a list of current values (a '*' step may
    widen one value into many)."""
    out = []
    for v in values:
        if s == "*":
            if isinstance(v, list):
                out.extend(v)
            elif isinstance(v, dict):
                out.extend(v.values())
            else:
                raise FigureError(f"'*' applied to a {type(v).__name__}")
        elif "~" in s:
            if not isinstance(v, list):
                raise FigureError(f"filter '{s}' applied to a {type(v).__name__}, not a list")
            conds = [c.split("~", 1) for c in s.split("&")]
            out.extend(e for e in v if isinstance(e, dict) and all(str(e.get(k)) == want for k, want in conds))
        elif "=" in s:
            if not isinstance(v, list):
                raise FigureError(f"selector '{s}' applied to a {type(v).__name__}, not a list")
            conds = [c.split("=", 1) for c in s.split("&")]
            hits = [e for e in v if isinstance(e, dict) and all(str(e.get(k)) == want for k, want in conds)]
            if len(hits) != 1:
                raise FigureError(f"selector '{s}' matches {len(hits)} elements, not one")
            out.append(hits[0])
        elif isinstance(v, list):
            if not re.fullmatch(r"-?\d+", s):
                raise FigureError(f"'{s}' applied to a list (use an index, key=value or *)")
            i = int(s)
            if not -len(v) <= i < len(v):
                raise FigureError(f"index {i} out of a list of {len(v)}")
            out.append(v[i])
        elif isinstance(v, dict) and s.endswith("?"):
            if s[:-1] in v:
                out.append(v[s[:-1]])
        elif isinstance(v, dict):
            if s not in v:
                raise FigureError(f"no member '{s}' (members: {', '.join(sorted(v)[:12])})")
            out.append(v[s])
        else:
            raise FigureError(f"'{s}' applied to a {type(v).__name__}")
    return out


def apply_op(values, op):
    if op in ("min", "max", "sum"):
        return [{"min": min, "max": max, "sum": sum}[op](values)]
    if op == "len":
        if len(values) == 1 and isinstance(values[0], (list, dict)):
            return [len(values[0])]
        return [len(values)]
    if op == "first":
        return values[:1]
    if op == "range":
        return [min(values), max(values)]
    m = re.fullmatch(r"([*/])(-?[0-9.eE+-]+)", op)
    if m:
        k = float(m.group(2))
        return [v * k if m.group(1) == "*" else v / k for v in values]
    raise FigureError(f"unknown op '|{op}' (min, max, sum, len, first, range, *K, /K)")


def value_of(spec, cache):
    """The formatted value a figure marker's spec names."""
    parts = spec.split()
    if not parts or len(parts) > 2:
        raise FigureError(f"expected 'FILE:PATH [FMT]', got '{spec}'")
    ref, fmt = parts[0], (parts[1] if len(parts) == 2 else "")
    if ":" not in ref:
        raise FigureError(f"'{ref}' has no ':PATH'")
    fname, path = ref.split(":", 1)
    full = os.path.join(ROOT, fname)
    if fname not in cache:
        try:
            with open(full) as f:
                cache[fname] = json.load(f)
        except (OSError, ValueError) as e:
            raise FigureError(f"cannot read {fname}: {e}")
    path, *ops = path.split("|")
    values = [cache[fname]]
    for s in path.split(".") if path else []:
        values = step(values, s)
    for op in ops:
        values = apply_op(values, op)
    try:
        text = [format(v, fmt) for v in values]
    except (ValueError, TypeError) as e:
        raise FigureError(f"format '{fmt}' does not apply to {values!r}: {e}")
    if len(text) == 1:
        return text[0]
    if len(text) == 2:
        return text[0] if text[0] == text[1] else f"{text[0]}-{text[1]}"
    raise FigureError(f"the path gives {len(text)} values; reduce them with |min, |max, |range, ...")


def markdown_files():
    for d, subdirs, files in os.walk(ROOT):
        subdirs[:] = sorted(s for s in subdirs if s not in SKIP_DIRS and not s.startswith("build"))
        for f in sorted(files):
            if f.endswith(".md"):
                yield os.path.relpath(os.path.join(d, f), ROOT)


def check(files, listing=False, update=False):
    cache, bad, count = {}, 0, 0
    for md in files:
        try:
            with open(os.path.join(ROOT, md)) as f:
                text = f.read()
        except OSError as e:
            print(f"{md}: {e}")
            bad += 1
            continue
        spans, edits = [], []
        for m in FIG.finditer(text):
            count += 1
            spans.append(m.start())
            line = text.count("\n", 0, m.start()) + 1
            quote = m.group("quote")
            try:
                want = value_of(m.group("spec"), cache)
            except FigureError as e:
                print(f"{md}:{line}: figure '{quote}' ({m.group('spec')}): {e}")
                bad += 1
                continue
            if quote != want and update:
                edits.append((m.start("quote"), m.end("quote"), want))
                print(f"{md}:{line}: figure '{quote}' updated to '{want}' ({m.group('spec')})")
            elif quote != want:
                print(f"{md}:{line}: figure '{quote}' disagrees with {m.group('spec')}: the file says '{want}'")
                bad += 1
            elif listing:
                print(f"{md}:{line}: {quote}  <- {m.group('spec')}")
        for m in OPEN.finditer(text):  # an opening marker without its closing one
            if m.start() not in spans:
                line = text.count("\n", 0, m.start()) + 1
                print(f"{md}:{line}: a '<!-- fig:' marker without its '<!-- /fig -->' (or spanning a malformed spec)")
                bad += 1
        if edits:
            for a, b, want in reversed(edits):
                text = text[:a] + want + text[b:]
            tmp = os.path.join(ROOT, md) + ".tmp"
            with open(tmp, "w") as f:
                f.write(text)
            os.replace(tmp, os.path.join(ROOT, md))
    print(f"check_doc_figures: {count} quoted figures in {len(files)} files, {bad} wrong")
    return 1 if bad else 0


def main(argv):
    listing = "--list" in argv
    update = "--update" in argv
    args = [a for a in argv if a not in ("--list", "--update")]
    if any(a.startswith("-") for a in args):
        print(__doc__.split("\n\n")[-1], file=sys.stderr)
        return 2
    files = args or list(markdown_files())
    return check(files, listing, update)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
