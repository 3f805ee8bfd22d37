"""Docstrings as the modalviewer sources write them, made ready for napoleon.

Two conventions of the sources meet reStructuredText and napoleon badly:

- A numpy-style entry is ``name : type`` with the description indented below it; most
  entries here are ``name : description`` on one line (the type is in the signature's
  annotations).  Napoleon would show such a description as the type.  Before napoleon
  reads the docstring, an entry whose text after the colon is a description (long, or
  with no indented block below it) becomes ``name`` with that text as its indented
  description.  ``Returns`` sections written as prose become a ``:returns:`` field.
- Norms are written as plain text, ``|K u - lambda M u|``; reStructuredText reads
  ``|...|`` as a substitution reference, and modalviewer defines none.  Outside literals,
  a bar is escaped so it is shown as written.
"""

from __future__ import annotations

import re

SECTIONS = ("Parameters", "Other Parameters", "Attributes", "Returns", "Yields")
ENTRY = re.compile(r"^(\*{0,2}[A-Za-z_]\w*(?:, \*{0,2}[A-Za-z_]\w*)*) : (.*)$")
LITERAL = re.compile(r"(``.*?``|`[^`]*`)")
#: Longest text after ``name :`` still read as a type when a description follows below.
TYPE_CHARS = 48


def _is_header(lines: list[str], i: int) -> bool:
    return (
        i + 1 < len(lines)
        and lines[i].strip()
        and not lines[i].startswith(" ")
        and re.fullmatch(r"-{3,}", lines[i + 1].strip()) is not None
    )


def _looks_like_type(text: str, indented_below: bool) -> bool:
    return indented_below and len(text) <= TYPE_CHARS and not re.search(r"[.;:]\s|[.;]$", text)


def _section(name: str, body: list[str]) -> list[str]:
    """One section's lines in the form napoleon reads as intended."""
    first = next((line for line in body if line.strip()), "")
    if name in ("Returns", "Yields") and first and not ENTRY.match(first):
        if any(line.startswith("    ") for line in body if line is not first):
            return [name, "-" * len(name), *body]  # numpy style: a type, then its text
        field = ":returns:" if name == "Returns" else ":yields:"
        text = list(body)
        while text and not text[-1].strip():
            text.pop()
        # The blank line in front ends napoleon's previous section (two blank lines do).
        return [
            "",
            f"{field} {text[0].strip()}",
            *["   " + line if line else "" for line in text[1:]],
        ]
    out = [name, "-" * len(name)]
    for i, line in enumerate(body):
        match = ENTRY.match(line)
        if not match:
            out.append(line)
            continue
        below = i + 1 < len(body) and body[i + 1].startswith(" ")
        if _looks_like_type(match.group(2), below):
            out.append(line)
        else:
            out += [match.group(1), "    " + match.group(2)]
    return out


def normalise_sections(lines: list[str]) -> list[str]:
    """The docstring's lines with its project-style entries in napoleon's form."""
    out, i = [], 0
    while i < len(lines):
        if _is_header(lines, i) and lines[i].strip() in SECTIONS:
            name = lines[i].strip()
            j = i + 2
            while j < len(lines) and not _is_header(lines, j):
                j += 1
            body = lines[i + 2 : j]
            trailing = []
            while body and not body[-1].strip():
                trailing.append(body.pop())
            out += _section(name, body) + trailing
            i = j
        else:
            out.append(lines[i])
            i += 1
    return out


def escape_bars(lines: list[str]) -> list[str]:
    return [
        "".join(p if k % 2 else p.replace("|", "\\|") for k, p in enumerate(LITERAL.split(line)))
        for line in lines
    ]


def _process(app, what, name, obj, options, lines) -> None:
    lines[:] = escape_bars(normalise_sections(lines))


def setup(app):
    # before napoleon (priority 500), which turns the sections into fields
    app.connect("autodoc-process-docstring", _process, priority=400)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
