#!/usr/bin/env python3
"""ctest docs.figures_ages: scripts/check_doc_figures.py's age bound, run on
a scratch git repository that holds a copy of the script, a stand-in for
scripts/regenerate_results.sh --files, a results file and a README quoting
it. Each case says what the check must answer:

  - a file made at HEAD passes; N + 1 commits that touch core later it fails
    naming the file, its revision, its age and the entry that remakes it,
    and passes again with --max-age N + 1;
  - commits outside core, or to core's Markdown, do not age it;
  - a revision the clone does not have fails, saying so; in a shallow clone
    the message says to unshallow;
  - outside a git checkout the quotes are checked and the ages are not, and
    it says so;
  - a quoted file that no entry remakes, or that names no revision, fails;
  - a dated record (results/history.jsonl) is listed with its age, never
    failed for it;
  - --age reads the revision of a Markdown results file.

    scripts/tests/check_doc_figures_test.py     # exit 0: every case as expected
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(os.path.dirname(HERE), "check_doc_figures.py")
FILES = """#!/usr/bin/env bash
# Stand-in for regenerate_results.sh --files: the entry that remakes each file.
[[ $1 == --files ]] || exit 2
echo "run results/run.json"
"""
failed = []


def sh(cwd, *args):
    p = subprocess.run(args, cwd=cwd, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(args)}: {p.stderr}")
    return p.stdout.strip()


def commit(repo, path, text, msg):
    full = os.path.join(repo, path)
    os.makedirs(os.path.dirname(full), exist_ok=True)
    with open(full, "w") as f:
        f.write(text)
    sh(repo, "git", "add", "-A")
    sh(repo, "git", "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", msg)
    return sh(repo, "git", "rev-parse", "HEAD")


def check(repo, *args):
    p = subprocess.run([sys.executable, os.path.join(repo, "scripts", "check_doc_figures.py"), *args],
                       capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


def expect(case, got, rc, *texts):
    code, out = got
    missing = [t for t in texts if t not in out]
    if code != rc or missing:
        failed.append(case)
        print(f"FAIL {case}: exit {code} (expected {rc}), missing {missing}\n{out}")
    else:
        print(f"ok   {case}")


def results(rev, value=7):
    return json.dumps({"metadata": {"git_revision": rev}, "value": value})


def main():
    tmp = tempfile.mkdtemp(prefix="idcol-doc-ages.")
    try:
        repo = os.path.join(tmp, "repo")
        os.makedirs(os.path.join(repo, "scripts"))
        shutil.copy(SCRIPT, os.path.join(repo, "scripts"))
        with open(os.path.join(repo, "scripts", "regenerate_results.sh"), "w") as f:
            f.write(FILES)
        sh(tmp, "git", "init", "-q", repo)
        made = commit(repo, "core/src/solver.cpp", "1\n", "the solver")
        commit(repo, "results/run.json", results(made), "its results")
        commit(repo, "README.md", "<!-- fig: results/run.json:value d -->7<!-- /fig -->\n", "a quote")
        expect("made at HEAD", check(repo), 0, "1 files quoted, 0 too old")

        for k in range(3):
            commit(repo, f"core/src/f{k}.cpp", "x\n", f"core {k}")
        commit(repo, "harness/a.cpp", "x\n", "not core")
        commit(repo, "core/README.md", "words\n", "core's Markdown")
        expect("3 commits that touch core, bound 2", check(repo, "--max-age", "2"), 1,
               "results/run.json: made at " + made[:7] + ", 3 commits that touch core before HEAD (at most 2): too old",
               "scripts/regenerate_results.sh run", "quoted at README.md:1")
        expect("3 commits that touch core, bound 3", check(repo, "--max-age", "3"), 0)
        expect("--list gives the age", check(repo, "--list"), 0,
               "results/run.json: made at " + made[:7] + ", 3 commits that touch core before HEAD; remade by")

        commit(repo, "results/run.json", results("0123456789abcdef0123456789abcdef01234567"), "a revision unknown")
        expect("a revision the clone lacks", check(repo), 1,
               "made at 0123456789abcdef0123456789abcdef01234567, which this clone does not have")
        commit(repo, "results/run.json", results(made), "back")

        shallow = os.path.join(tmp, "shallow")
        sh(tmp, "git", "clone", "-q", "--depth", "1", "file://" + repo, shallow)
        expect("a shallow clone", check(shallow), 1, "this clone is shallow: 'git fetch --unshallow'")

        plain = os.path.join(tmp, "plain")
        shutil.copytree(repo, plain, ignore=shutil.ignore_patterns(".git"))
        expect("no git checkout", check(plain), 0, "ages not checked", "0 wrong")
        with open(os.path.join(plain, "README.md"), "w") as f:
            f.write("<!-- fig: results/run.json:value d -->8<!-- /fig -->\n")
        expect("no git checkout, a wrong quote", check(plain), 1, "figure '8' disagrees")

        now = sh(repo, "git", "rev-parse", "HEAD")
        commit(repo, "results/other.json", results(now), "a file no entry makes")
        commit(repo, "README.md", "<!-- fig: results/other.json:value d -->7<!-- /fig -->\n", "quote it")
        expect("no entry remakes it", check(repo), 1, "results/other.json: made at", "no entry of scripts/regenerate_results.sh")

        commit(repo, "results/run.json", json.dumps({"value": 7}), "no revision")
        commit(repo, "README.md", "<!-- fig: results/run.json:value d -->7<!-- /fig -->\n", "quote it")
        expect("no revision", check(repo), 1, "results/run.json names no git revision")

        line = json.dumps({"run": {"git_revision": made}, "series": "s"})
        commit(repo, "results/history.jsonl", line + "\n" + line + "\n", "a history")
        commit(repo, "README.md", "<!-- fig: results/history.jsonl:*.series|unique|len d -->1<!-- /fig -->\n", "quote it")
        expect("a dated record", check(repo, "--max-age", "0", "--list"), 0, "a dated record, not bounded")

        commit(repo, "results/notes.md", "# Notes\n\n- git revision: " + made[:7] + "\n", "a Markdown result")
        expect("--age of a Markdown file", check(repo, "--age", "results/notes.md"), 0,
               "results/notes.md: made at " + made[:7] + ", ")
    finally:
        shutil.rmtree(tmp)
    print(f"{len(failed)} case(s) failed" if failed else "every case as expected")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
