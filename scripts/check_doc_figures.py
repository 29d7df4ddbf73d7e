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
`first`, `unique` (each value once), `*K` or `/K` (multiply or divide by
the number K). FMT is a Python format spec (`.0f`, `.3g`, `,d`, `.7` for
the first 7 characters of a string); two values after a `*` (for instance
min and max) are written "A-B" when FMT is given with the `range` op:

    <!-- fig: results/paper_table1.json:pairs.*.passes.cold.iterations.mean|range .2f -->4.61-5.53<!-- /fig -->

FILE is a JSON file or a JSON Lines file (`.jsonl`: the list of its lines).

The check fails, naming the Markdown file, its line, the quote and what the
file says, when a quote differs from the value formatted with FMT, when the
file or the path does not exist, or when a figure marker is malformed.

It also fails when a quoted file is too old: when more than MAX_CORE_COMMITS
commits that touch core (`git rev-list --count REV..HEAD -- core`, Markdown
aside) lie between the revision the file was made at and HEAD. The revision
is the file's own (`metadata.git_revision` of the harness's files,
`git_revision` of the benchmarks', `context.git_revision`, a history's last
`run.git_revision`; in a Markdown or text results file its "git revision:"
or "git" line). Each quoted file must also be one that an entry of
scripts/regenerate_results.sh remakes (its `--files`), unless it is in
DATED (a record of the revisions it names, whose age is shown and not
bounded). In a clone that lacks the file's revision (a shallow clone: `git
fetch --unshallow`) the check fails saying so; outside a git checkout (a
source archive) it says that it counted no ages, and checks the quotes
alone.

    scripts/check_doc_figures.py                # every *.md of the repository (not build folders)
    scripts/check_doc_figures.py README.md ...  # only these
    scripts/check_doc_figures.py --list         # every quote, with its value, and every quoted file with its age
    scripts/check_doc_figures.py --update       # rewrite each quote that disagrees with its file's value
                                                # (after a results file was regenerated: review with git diff)
    scripts/check_doc_figures.py --max-age N    # another bound (commits that touch core) than MAX_CORE_COMMITS
    scripts/check_doc_figures.py --age FILE...  # the revision and age of any results file, quoted or not
    scripts/check_doc_figures.py --root DIR     # the repository to check (default: this script's)
Exit status: 0 every quote agrees and no quoted file is too old; 1 a quote
disagrees or cannot be read, or a quoted file is too old, names no
revision, or has no entry that remakes it; 2 bad command line.
"""
import json
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIG = re.compile(r"<!--\s*fig:\s*(?P<spec>.*?)\s*-->(?P<quote>.*?)<!--\s*/fig\s*-->", re.S)
OPEN = re.compile(r"<!--\s*fig:")
SKIP_DIRS = {".git", "build", "node_modules", "dist", "__pycache__"}

# How old a quoted file may be: commits that touch core between the
# revision it was made at and HEAD. 30, the most the project allows itself.
# The figures a reader is shown must describe the code in front of them,
# but regenerating every file (scripts/regenerate_results.sh) takes about
# an hour of the 2-core machine by the files' own wall times (its --list),
# so it cannot follow each commit. In the busiest week of the solver
# (2026-11-22 to 27) core took 26 to 128 commits a day: 30 is a working
# day at that pace, a few days at a quieter one, so the results are remade
# about as often as a working day ends. Between regenerations the CI's
# guards (compare's thresholds, instructions on every path) fail a
# regression at the commit that makes it; this bound keeps the quoted
# figures from drifting away from the code unseen.
MAX_CORE_COMMITS = 30
# What counts as touching core: any file under core/ but its Markdown (a
# change to core/README.md changes no figure).
AGE_PATHSPEC = ["core", ":(exclude)core/*.md"]
# Quoted files that are records of the revisions they name, not of HEAD:
# their age is listed, never bounded, and no entry remakes them. A path
# ending in '/' stands for every file under it.
DATED = {
    "results/history.jsonl": "the CI cut's runs at past revisions, each line its own",
    "results/scaling16/side_by_side/": "the binaries before and after 8651f29 timed side by side, as the text says",
    # Only a machine with 16 CPUs remakes it (regenerate_results.sh's
    # cpus_needed), and the project's build and CI machines have 2: bounded,
    # it would stop every change to core until such a machine is lent. Its
    # text names the revision it was made at.
    "results/scaling16/": "solve_batch on a lent 16-core machine at the revision it names, remade when one is lent",
}
# Where a file says its revision, in the order tried (JSON); a JSON Lines
# file (a history) says it in its last line.
REVISION_KEYS = ("metadata.git_revision", "git_revision", "context.git_revision", "run.git_revision")
HEX = re.compile(r"\b[0-9a-f]{7,40}\b")
TEXT_REVISION = re.compile(r"\bgit(?: revision)?\s*[:|]?\s*`?([0-9a-f]{7,40})\b")


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
    if op == "unique":
        return list(dict.fromkeys(values))
    if op == "range":
        return [min(values), max(values)]
    m = re.fullmatch(r"([*/])(-?[0-9.eE+-]+)", op)
    if m:
        k = float(m.group(2))
        return [v * k if m.group(1) == "*" else v / k for v in values]
    raise FigureError(f"unknown op '|{op}' (min, max, sum, len, first, unique, range, *K, /K)")




def load(fname):
    """A results file: JSON, JSON Lines (a list of its lines) or text."""
    full = os.path.join(ROOT, fname)
    try:
        with open(full) as f:
            text = f.read()
    except OSError as e:
        raise FigureError(f"cannot read {fname}: {e}")
    try:
        if fname.endswith(".json"):
            return json.loads(text)
        if fname.endswith(".jsonl"):
            return [json.loads(line) for line in text.splitlines() if line.strip()]
    except ValueError as e:
        raise FigureError(f"cannot read {fname}: {e}")
    return text


def value_of(spec, cache):
    """The formatted value a figure marker's spec names, and its file."""
    parts = spec.split()
    if not parts or len(parts) > 2:
        raise FigureError(f"expected 'FILE:PATH [FMT]', got '{spec}'")
    ref, fmt = parts[0], (parts[1] if len(parts) == 2 else "")
    if ":" not in ref:
        raise FigureError(f"'{ref}' has no ':PATH'")
    fname, path = ref.split(":", 1)
    if not fname.endswith((".json", ".jsonl")):
        raise FigureError(f"{fname}: figures are quoted from JSON or JSON Lines files only")
    if fname not in cache:
        cache[fname] = load(fname)
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
        return text[0], fname
    if len(text) == 2:
        return (text[0] if text[0] == text[1] else f"{text[0]}-{text[1]}"), fname
    raise FigureError(f"the path gives {len(text)} values; reduce them with |min, |max, |range, ...")


def revision_of(fname, data):
    """The git revision a results file says it was made at."""
    if isinstance(data, str):
        m = TEXT_REVISION.search(data)
        if not m:
            raise FigureError(f"{fname} names no git revision (no 'git revision: REV' or 'git REV' in its text)")
        return m.group(1)
    if isinstance(data, list):
        data = data[-1] if data else {}
    for key in REVISION_KEYS:
        v = data
        for k in key.split("."):
            v = v.get(k) if isinstance(v, dict) else None
        m = HEX.search(v) if isinstance(v, str) else None
        if m:
            return m.group(0)
    raise FigureError(f"{fname} names no git revision (none of {', '.join(REVISION_KEYS)} holds one)")


def dated(fname):
    for d, why in DATED.items():
        if fname == d or (d.endswith("/") and fname.startswith(d)):
            return why
    return None


class Ages:
    """Commits that touch core between a revision and HEAD, from git."""

    def __init__(self, limit):
        self.limit, self.cache = limit, {}
        self.checkout = self.git("rev-parse", "--is-inside-work-tree") == "true"
        self.shallow = self.checkout and self.git("rev-parse", "--is-shallow-repository") == "true"

    def git(self, *args):
        try:
            p = subprocess.run(["git", "-C", ROOT, *args], capture_output=True, text=True)
        except OSError:
            return None
        return p.stdout.strip() if p.returncode == 0 else None

    def age(self, rev):
        """The count for a revision; a FigureError if git cannot give it."""
        if rev not in self.cache:
            self.cache[rev] = self.count(rev)
        if isinstance(self.cache[rev], FigureError):
            raise self.cache[rev]
        return self.cache[rev]

    def count(self, rev):
        if self.git("rev-parse", "--verify", "--quiet", rev + "^{commit}") is None:
            why = ("this clone is shallow: 'git fetch --unshallow' fetches the history the age is counted over"
                   if self.shallow else "a commit never merged into this history, or a revision mistyped")
            return FigureError(f"made at {rev}, which this clone does not have ({why})")
        n = self.git("rev-list", "--count", f"{rev}..HEAD", "--", *AGE_PATHSPEC)
        if n is None:
            return FigureError(f"made at {rev}: git rev-list cannot count the commits since")
        return int(n)


def regeneration_entries():
    """Results file (from the repository root) -> the entry of
    scripts/regenerate_results.sh that remakes it (its --files)."""
    script = os.path.join(ROOT, "scripts", "regenerate_results.sh")
    try:
        p = subprocess.run(["bash", script, "--files"], capture_output=True, text=True)
    except OSError as e:
        raise FigureError(f"cannot run {script} --files: {e}")
    if p.returncode != 0:
        raise FigureError(f"scripts/regenerate_results.sh --files failed: {p.stderr.strip()}")
    entries = {}
    for line in p.stdout.splitlines():
        if line.strip():
            entry, f = line.split(None, 1)
            entries[f.strip()] = entry
    return entries


def markdown_files():
    for d, subdirs, files in os.walk(ROOT):
        subdirs[:] = sorted(s for s in subdirs if s not in SKIP_DIRS and not s.startswith("build"))
        for f in sorted(files):
            if f.endswith(".md"):
                yield os.path.relpath(os.path.join(d, f), ROOT)


def check_quotes(files, cache, where, listing, update):
    """Every quote against its file's value; where[file] collects the places
    each file is quoted. Returns (quotes, wrong)."""
    bad, count = 0, 0
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
                want, fname = value_of(m.group("spec"), cache)
            except FigureError as e:
                print(f"{md}:{line}: figure '{quote}' ({m.group('spec')}): {e}")
                bad += 1
                continue
            places = where.setdefault(fname, [])
            if f"{md}:{line}" not in places:
                places.append(f"{md}:{line}")
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
    return count, bad


def check_ages(where, cache, ages, listing):
    """Each quoted file's age against the bound, and the entry that remakes
    it. Returns the number of files that fail."""
    if not ages.checkout:
        print(f"check_doc_figures: ages not checked: {ROOT} is not a git checkout (no history to count over)")
        return 0
    try:
        entries = regeneration_entries()
    except FigureError as e:
        print(f"check_doc_figures: {e}")
        return 1
    bad = 0
    if listing:
        print(f"quoted files (age: commits that touch core since the file's revision; at most {ages.limit}):")
    for fname in sorted(where):
        places = where[fname]
        shown = ", ".join(places[:4]) + (f" and {len(places) - 4} more" if len(places) > 4 else "")
        why_dated, entry = dated(fname), entries.get(fname)
        try:
            rev = revision_of(fname, cache[fname])
            n = ages.age(rev)
        except FigureError as e:
            print(f"{fname}: {e} (quoted at {shown})")
            bad += 1
            continue
        what = f"made at {rev[:7]}, {n} commits that touch core before HEAD"
        if why_dated:
            if listing:
                print(f"{fname}: {what}; a dated record, not bounded: {why_dated}")
        elif entry is None:
            print(f"{fname}: {what}; no entry of scripts/regenerate_results.sh remakes it "
                  f"(add it to its entries and --files; quoted at {shown})")
            bad += 1
        elif n > ages.limit:
            print(f"{fname}: {what} (at most {ages.limit}): too old; remake it with "
                  f"scripts/regenerate_results.sh {entry} (quoted at {shown})")
            bad += 1
        elif listing:
            print(f"{fname}: {what}; remade by scripts/regenerate_results.sh {entry}")
    if ages.shallow:
        print("check_doc_figures: this clone is shallow: ages are counted over the history it has")
    return bad


def show_ages(files, ages):
    """--age: each file's revision and age, whether quoted or not."""
    bad = 0
    for fname in files:
        try:
            rev = revision_of(fname, load(fname))
            n = ages.age(rev) if ages.checkout else "?"
            print(f"{fname}: made at {rev[:7]}, {n} commits that touch core before HEAD")
        except FigureError as e:
            print(f"{fname}: {e}")
            bad = 1
    return bad


def main(argv):
    global ROOT
    opts = {"--list": False, "--update": False, "--age": False}
    limit, args, it = MAX_CORE_COMMITS, [], iter(argv)
    for a in it:
        if a in opts:
            opts[a] = True
        elif a in ("--max-age", "--root"):
            v = next(it, None)
            if a == "--root" and v:
                ROOT = os.path.abspath(v)
            elif a == "--max-age" and v is not None and re.fullmatch(r"\d+", v):
                limit = int(v)
            else:
                print(f"check_doc_figures: {a} needs {'a folder' if a == '--root' else 'a count of commits'}",
                      file=sys.stderr)
                return 2
        elif a.startswith("-"):
            print(__doc__.split("\n\n")[-1], file=sys.stderr)
            return 2
        else:
            args.append(a)
    ages = Ages(limit)
    if opts["--age"]:
        return show_ages(args, ages)
    files = args or list(markdown_files())
    cache, where = {}, {}
    count, bad = check_quotes(files, cache, where, opts["--list"], opts["--update"])
    old = check_ages(where, cache, ages, opts["--list"])
    print(f"check_doc_figures: {count} quoted figures in {len(files)} files, {bad} wrong; "
          f"{len(where)} files quoted, {old} too old, undated or not remade")
    return 1 if bad or old else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
