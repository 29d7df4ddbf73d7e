#!/usr/bin/python3
"""Runs the commands of the project's Markdown exactly as written.

Every ```sh (```bash, ```shell) block and every ```python block of the files
checked is a command a reader may paste. A marker comment in the three lines
above a block says how it is checked (no marker: run):

    (none)                               run the block as written, with bash -euo pipefail
                                         (```python: /usr/bin/python3 with PYTHONPATH=build/python),
                                         in a scratch copy of the checkout (below)
    <!-- doc-test: source-tree -->        run it in the checkout itself (a command that builds)
    <!-- doc-test: dry-run CMD -->        too long for a test: run CMD instead, which must exit 0
                                         and print every line of the block as one of its lines
    <!-- doc-test: elsewhere WHERE -->    run by something else: WHERE is a ctest (it must exist
                                         in the build) or a file, which must contain every line
    <!-- doc-test: not-run REASON -->     not run by any test (hours, Slurm, a fuzzing toolchain,
                                         a timing that needs a quiet machine): REASON, which must
                                         be given, is printed; the reader sees the marker too
    <!-- doc-test: cpp-example -->        (```cpp) compiled and run by the ctest docs.cpp_example

Every fenced block must name its language: a block with none is a failure,
so that no command escapes the test as an unlabelled block (write ```text for
output, a synopsis or a table of options).

The scratch copy links every top-level entry of the checkout except
`results/` (copied) and `build/` (a folder of links to the build's entries,
so that `build/out` is new and empty). After each block, the copy of
`results/` must be unchanged and `git status` of the checkout the same as
before: a recipe never writes over checked-in files. The blocks of all the
files run one after the other in the same scratch copy, in file order.

    check_doc_commands.py --build BUILD [--kind run|source-tree|dry-run|elsewhere|not-run|python] [FILE.md...]
    check_doc_commands.py --list [FILE.md...]
    check_doc_commands.py --extract-cpp README.md OUT.cpp    the cpp-example block, for CMake
Default files: README.md and the component READMEs (DEFAULT_FILES). Exit
status: 0 every block passed; 1 a block failed; 2 bad command line.
"""
import filecmp
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FENCE = re.compile(r"^```(\w*)\s*$")
MARK = re.compile(r"<!--\s*doc-test:\s*(?P<kind>[\w-]+)\s*(?P<arg>.*?)\s*-->")
PY = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
TIMEOUT = 600
SHELLS = ("sh", "bash", "shell")
DEFAULT_FILES = ["README.md", "core/README.md", "harness/README.md", "baselines/README.md", "results/README.md"]
SOURCE_TREE_TIMEOUT = 1500


def blocks(md):
    """(line, language, kind, arg, text) of each fenced block of md."""
    lines = open(os.path.join(ROOT, md)).read().split("\n")
    out, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        lang, start = m.group(1), i
        j = i + 1
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        kind, arg = "run", ""
        for k in range(max(0, start - 3), start):
            mm = MARK.search(lines[k])
            if mm:
                kind, arg = mm.group("kind"), mm.group("arg")
        out.append((start + 1, lang, kind, arg, "\n".join(lines[start + 1:j])))
        i = j + 1
    return out


def command_lines(text):
    return [l.strip() for l in text.split("\n") if l.strip() and not l.strip().startswith("#")]


def git_status():
    if not os.path.isdir(os.path.join(ROOT, ".git")) and not os.path.isfile(os.path.join(ROOT, ".git")):
        return None
    r = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=all"],
                       capture_output=True, text=True)
    return r.stdout if r.returncode == 0 else None


def scratch(build):
    work = tempfile.mkdtemp(prefix="idcol-doc-commands.")
    for e in os.listdir(ROOT):
        if e in ("results", ".git") or e.startswith("build"):
            continue
        os.symlink(os.path.join(ROOT, e), os.path.join(work, e))
    shutil.copytree(os.path.join(ROOT, "results"), os.path.join(work, "results"), symlinks=True)
    os.mkdir(os.path.join(work, "build"))
    for e in os.listdir(build):
        if e != "out":
            os.symlink(os.path.join(build, e), os.path.join(work, "build", e))
    return work


def results_changed(work):
    changed = []
    def walk(cmp, rel):
        changed.extend(os.path.join(rel, f) for f in cmp.diff_files + cmp.left_only + cmp.right_only)
        for name, sub in cmp.subdirs.items():
            walk(sub, os.path.join(rel, name))
    walk(filecmp.dircmp(os.path.join(ROOT, "results"), os.path.join(work, "results")), "results")
    return changed


def run(cmd, cwd, env=None, shell_text=None, timeout=TIMEOUT):
    """Runs cmd in a session of its own, so that a timeout ends every process
    it started (a build's compilers too), not only the shell."""
    p = subprocess.Popen(cmd, cwd=cwd, env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True, start_new_session=True)
    try:
        out, _ = p.communicate(shell_text, timeout=timeout)
        return p.returncode, out
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        out, _ = p.communicate()
        return 124, f"timed out after {timeout} s\n{out[-4000:]}"


def ctest_has(build, name):
    """Whether the build defines a ctest of that name, read from its
    CTestTestfile.cmake files (running `ctest -N` here would overwrite the log
    of the ctest that runs this check)."""
    pat = re.compile(r"^add_test\(\s*(?:\[=\[)?" + re.escape(name) + r"(?:\]=\])?[\s)]", re.M)
    for d, _, files in os.walk(build):
        if "CTestTestfile.cmake" in files:
            with open(os.path.join(d, "CTestTestfile.cmake")) as f:
                if pat.search(f.read()):
                    return True
    return False


def check_block(md, line, lang, kind, arg, text, build, work):
    """None when the block passes, else why not."""
    env = dict(os.environ, PYTHONPATH=os.path.join("build", "python"))
    if kind == "cpp-example":
        return None if lang == "cpp" else "cpp-example marks a block that is not ```cpp"
    if not lang:
        return "a block with no language: name it (```sh to run it, ```text for output or a synopsis)"
    if lang not in SHELLS + ("python",):
        return None
    if kind == "not-run":
        if not arg:
            return "not-run gives no reason"
        print(f"    not run: {arg}")
        return None
    if kind == "elsewhere":
        if not arg:
            return "elsewhere names no ctest or file"
        path = os.path.join(ROOT, arg)
        if os.path.isfile(path):
            body = open(path).read()
            missing = [l for l in command_lines(text) if l not in body]
            return f"{arg} does not contain: {missing}" if missing else None
        return None if ctest_has(build, arg) else f"no ctest or file named '{arg}'"
    if kind == "dry-run":
        rc, out = run(["bash", "-c", arg], work, env)
        if rc != 0:
            return f"'{arg}' exited {rc}:\n{out}"
        printed = {l.strip() for l in out.split("\n")}
        missing = [l for l in command_lines(text) if l not in printed]
        return f"'{arg}' does not print: {missing}\n{out}" if missing else None
    if kind not in ("run", "source-tree"):
        return f"unknown doc-test kind '{kind}'"
    cwd = ROOT if kind == "source-tree" else work
    # A block that builds (scripts/run.sh) may recompile after a commit: more time.
    limit = SOURCE_TREE_TIMEOUT if kind == "source-tree" else TIMEOUT
    if lang == "python":
        rc, out = run([PY, "-"], cwd, env, text, limit)
    else:
        rc, out = run(["bash", "-euo", "pipefail", "-s"], cwd, env, text + "\n", limit)
    if rc != 0:
        return f"exited {rc}:\n{out[-4000:]}"
    print("\n".join("    | " + l for l in out.rstrip().split("\n")[-8:]))
    return None


def main(argv):
    if argv[:1] == ["--extract-cpp"] and len(argv) == 3:
        found = [b for b in blocks(argv[1]) if b[2] == "cpp-example"]
        if len(found) != 1:
            print(f"{argv[1]}: {len(found)} cpp-example blocks, expected one", file=sys.stderr)
            return 1
        text = f"// Extracted from {argv[1]} line {found[0][0]} by scripts/check_doc_commands.py\n{found[0][4]}\n"
        if not os.path.exists(argv[2]) or open(argv[2]).read() != text:
            open(argv[2], "w").write(text)
        return 0
    build, kinds, files, listing = None, None, [], False
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--build" and i + 1 < len(argv):
            build, i = os.path.abspath(argv[i + 1]), i + 1
        elif a == "--kind" and i + 1 < len(argv):
            kinds, i = set(argv[i + 1].split(",")), i + 1
        elif a == "--list":
            listing = True
        elif a.startswith("-"):
            print(__doc__.split("\n\n")[-1], file=sys.stderr)
            return 2
        else:
            files.append(a)
        i += 1
    files = files or DEFAULT_FILES
    blocks_to_run = [(md, *b) for md in files for b in blocks(md) if b[1] in SHELLS + ("python", "cpp", "")]
    if listing:
        for md, line, lang, kind, arg, text in blocks_to_run:
            print(f"{md}:{line}: ```{lang} {kind} {arg}".rstrip())
        return 0
    if not build:
        print("check_doc_commands.py: --build BUILD is needed", file=sys.stderr)
        return 2
    before = git_status()
    work = scratch(build)
    bad = 0
    try:
        for md, line, lang, kind, arg, text in blocks_to_run:
            ran_kind = "python" if lang == "python" and kind == "run" else kind
            if kinds and ran_kind not in kinds:
                print(f"{md}:{line}: ```{lang} {kind}: skipped (--kind)")
                continue
            print(f"{md}:{line}: ```{lang} {kind} {arg}".rstrip(), flush=True)
            start = time.monotonic()
            why = check_block(md, line, lang, kind, arg, text, build, work)
            changed = results_changed(work)
            after = git_status()
            if not why and changed:
                why = f"wrote over checked-in results files: {changed}"
            if not why and before is not None and after != before:
                why = f"changed the checkout (git status before:\n{before}after:\n{after})"
            if why:
                bad += 1
                print(f"  FAIL {md}:{line}: {why}")
            else:
                print(f"  ok ({time.monotonic() - start:.1f} s)", flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(f"check_doc_commands: {len(blocks_to_run)} blocks, {bad} failed")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
