"""Griffe extension for the API reference: reStructuredText markup in docstrings as Markdown.

The package's docstrings name other objects the Sphinx way (``:class:`sim_core.SceneError```,
``:meth:`load```); in Markdown the role would show as literal text.  This extension rewrites
each role to a code span of its target before mkdocstrings renders the docstring, so the
source keeps one convention and the site shows ``sim_core.SceneError``.  Two more reST forms
of the module docstrings (the environments') are rewritten: a section title underlined with
dashes becomes a bold line (a Markdown heading inside an API entry would break the page's
heading order), and a simple table (``====  ====`` borders) becomes a preformatted block
that keeps its columns.  Loaded by the mkdocstrings handler (``extensions`` in mkdocs.yml).
"""

from __future__ import annotations

import re

import griffe

ROLE = re.compile(r":(?:py:)?(?:class|func|meth|attr|data|mod|exc|obj|const):`~?([^`]+)`")
#: a border line of a reST simple table: columns of "=" separated by spaces
TABLE_BORDER = re.compile(r"^\s*=+(?: +=+)+\s*$")
#: a reST section underline of dashes (or "=" without column gaps)
UNDERLINE = re.compile(r"^(-{3,}|={3,})\s*$")


def markdown_of(text: str) -> str:
    """``text`` with reST roles as code spans, section titles as bold lines and simple tables
    as preformatted blocks."""
    lines = ROLE.sub(r"`\1`", text).split("\n")
    out: list[str] = []
    i = 0
    while i < len(lines):
        line = lines[i]
        if TABLE_BORDER.match(line):
            # a simple table: up to its closing border (the one followed by a blank line or
            # the end of the text)
            j = i + 1
            while j < len(lines) and not (TABLE_BORDER.match(lines[j]) and
                                          (j + 1 == len(lines) or not lines[j + 1].strip())):
                j += 1
            out += ["```text", *lines[i:j + 1], "```"]
            i = j + 1
            continue
        nxt = lines[i + 1] if i + 1 < len(lines) else ""
        if (line.strip() and not line.startswith(" ") and UNDERLINE.match(nxt)
                and len(nxt.strip()) >= len(line.strip()) // 2):
            out += [f"**{line.strip()}**", ""]
            i += 2
            continue
        out.append(line)
        i += 1
    return "\n".join(out)


class RstRoles(griffe.Extension):
    """Rewrite every loaded object's docstring with :func:`markdown_of`."""

    def on_instance(self, *, obj, **kwargs) -> None:
        if obj.docstring is not None:
            obj.docstring.value = markdown_of(obj.docstring.value)
