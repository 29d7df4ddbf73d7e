#!/usr/bin/python3
"""Every function of the library longer than 80 lines says why, above it.

Scans the C++ of core/src, core/include and core/python (tests excluded:
a test's body is its scenario) for function bodies of more than LIMIT
lines, counted from the line of the opening brace to the closing one, and
requires a comment with "Long:" in the block of lines directly above the
body's signature (no blank line between): the reason it is one function.
Exits 1 listing each long function without one, 0 otherwise.

    scripts/check_function_length.py [--limit 80] [--list] [DIR ...]

--list prints every long function, reason or not. The parser is a brace
counter that skips comments and string literals; a brace that opens after
a ")" (a function's parameter list, a lambda's, a constructor's
initialisers) not preceded by a control keyword opens a function body,
and only the outermost body counts.
"""
import argparse
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CONTROL = re.compile(r"\b(if|for|while|switch|catch)\s*\(.*\)\s*$|\b(else|do|try)\s*$")


def strip(line, in_block):
    """The code of a line without comments or string contents; and whether a
    block comment is still open at its end."""
    out, i = [], 0
    while i < len(line):
        if in_block:
            j = line.find("*/", i)
            if j < 0:
                return "".join(out), True
            i, in_block = j + 2, False
        elif line.startswith("//", i):
            break
        elif line.startswith("/*", i):
            in_block, i = True, i + 2
        elif line[i] in "\"'":
            q, j = line[i], i + 1
            while j < len(line) and line[j] != q:
                j += 2 if line[j] == "\\" else 1
            out.append(q + q)
            i = j + 1
        else:
            out.append(line[i])
            i += 1
    return "".join(out), in_block


def long_functions(path, limit):
    lines = open(path, encoding="utf-8", errors="replace").read().split("\n")
    code, in_block = [], False
    for l in lines:
        c, in_block = strip(l, in_block)
        code.append(c)
    found, stack = [], []  # stack: (line, is_function_body)
    for n, c in enumerate(code):
        for k, ch in enumerate(c):
            if ch == "{":
                before = (" ".join(code[max(0, n - 4):n]) + " " + c[:k]).rstrip()
                fn = before.endswith(")") or re.search(r"\)\s*(const|noexcept|override|final|mutable|->\s*[\w:<>, ]+)\s*$", before) \
                    or re.search(r"\)\s*:\s*[\w:]+[({].*[)}]\s*$", before)
                fn = bool(fn) and not CONTROL.search(before) and not before.rstrip().endswith("]")
                stack.append((n, fn and not any(s[1] for s in stack)))
            elif ch == "}" and stack:
                start, outer = stack.pop()
                if outer and n - start + 1 > limit:
                    found.append((start, n - start + 1))
    result = []
    for start, length in found:
        # The signature's first line: up from the brace while the lines are
        # code of the header (not blank, not ending a statement or a body).
        top = start
        while top > 0 and lines[top - 1].strip() and not re.search(r"[;{}]\s*$", code[top - 1]) \
                and not lines[top - 1].strip().startswith(("//", "#")):
            top -= 1
        # The comment block directly above it.
        k, reason = top - 1, False
        while k >= 0 and lines[k].strip().startswith(("//", "///", "*", "/*", "template", "[[", "__attribute__", "inline", "static")):
            reason = reason or "Long:" in lines[k]
            k -= 1
        result.append((length, top + 1, lines[top].strip(), reason))
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--limit", type=int, default=80)
    ap.add_argument("--list", action="store_true")
    ap.add_argument("dirs", nargs="*", default=["core/src", "core/include", "core/python"])
    a = ap.parse_args()
    bad = 0
    for d in a.dirs:
        for root, _, files in os.walk(os.path.join(ROOT, d)):
            if "/tests" in root.replace(os.sep, "/") + "/" and root.rstrip("/").split("/")[-1] == "tests":
                continue
            for f in sorted(files):
                if not f.endswith((".cpp", ".hpp")):
                    continue
                p = os.path.join(root, f)
                for length, line, head, reason in long_functions(p, a.limit):
                    rel = os.path.relpath(p, ROOT)
                    if not reason:
                        bad += 1
                    if a.list or not reason:
                        print(f"{'ok  ' if reason else 'MISSING'} {length:4d} lines  {rel}:{line}  {head[:80]}")
    if bad:
        print(f"{bad} function(s) over {a.limit} lines without a \"Long:\" reason in the comment above them", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
