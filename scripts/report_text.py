"""Text from a results file as the plot scripts write it into Markdown and figure titles.

A results file may have been edited by hand, and its names (the scene's, a
family's, a failures file's path) are free text: the same escapes as the
harness's Markdown (harness/src/io/text.hpp: escaped, md_text) keep such a
name from breaking a table, a title or a line, or from hiding the text
around it.
"""
import re
import unicodedata

# Characters that print nothing themselves but break a line or a table, or
# change how the text around them shows (io/text.cpp: hides_text): C1
# controls, the soft hyphen, the Arabic letter mark, zero-width and joiner
# characters, the bidirectional marks, embeddings, overrides and isolates,
# the line and paragraph separators, invisible operators, the byte order
# mark, interlinear annotations and tags.
_HIDDEN = [(0x80, 0x9F), (0xAD, 0xAD), (0x61C, 0x61C), (0x180E, 0x180E), (0x200B, 0x200F), (0x2028, 0x202E),
           (0x2060, 0x206F), (0xFEFF, 0xFEFF), (0xFFF9, 0xFFFB), (0xE0000, 0xE007F)]
_NAMED = {"\n": "\\n", "\t": "\\t", "\r": "\\r"}


def _hides_text(cp):
    return any(lo <= cp <= hi for lo, hi in _HIDDEN)


def escaped(text):
    """`text` (any value: str() of it) with a backslash doubled and what would move the cursor, end the line
    or hide text as an escape: \\n, \\t, \\r, \\x1B for the other controls, \\u202E for the formatting ones."""
    out = []
    for ch in str(text):
        cp = ord(ch)
        if ch in _NAMED:
            out.append(_NAMED[ch])
        elif cp < 0x20 or cp == 0x7F:
            out.append(f"\\x{cp:02X}")
        elif _hides_text(cp) or unicodedata.category(ch) == "Cs":
            out.append(f"\\u{cp:04X}" if cp <= 0xFFFF else f"\\U{cp:08X}")
        elif ch == "\\":
            out.append("\\\\")
        else:
            out.append(ch)
    return "".join(out)


def md_text(text):
    """`text` for Markdown prose or a table cell: escaped, '|' as \\| (it would end the cell), '<' as &lt;
    where a letter, '/', '!' or '?' follows (it would open an HTML tag; "x < 1" stays as it is)."""
    return re.sub(r"<(?=[A-Za-z/!?])", "&lt;", escaped(text).replace("|", "\\|"))


def md_code(text):
    """`text` as a Markdown code span: the escapes of escaped() but for the backslash, '|' as \\|, between
    more backticks than any run of them in it."""
    body = escaped(text).replace("\\\\", "\\").replace("|", "\\|")
    longest = run = 0
    for ch in body:
        run = run + 1 if ch == "`" else 0
        longest = max(longest, run)
    fence = "`" * (longest + 1)
    pad = " " if body[:1] == "`" or body[-1:] == "`" else ""
    return f"{fence}{pad}{body}{pad}{fence}"


def title_text(text):
    """`text` for a matplotlib title or label: escaped, and '$' as \\$ (it would start mathtext)."""
    return escaped(text).replace("$", "\\$")
