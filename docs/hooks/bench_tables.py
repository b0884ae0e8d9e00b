"""MkDocs hook: the tables of the committed benchmark results in the guides.

A line ``<!-- bench-table FILE N -->`` in a page becomes the N-th table (counted from 1) of
``benchmarks/results/FILE`` (of FILE itself, relative to the repository root, where it holds a
"/": ``agents/results/comparison.md``), followed by a collapsed note that gives the file's title, its
text before the first table (what was timed, how, and the machine state) and the text that
follows the table.  The guides never retype a measured figure: a rerun benchmark shows on the
next build.  A missing file or table fails the build, naming the page and the marker.

A prose sentence quotes one figure through ``<!-- bench-cell FILE N ROW | COLUMN -->`` (inline):
the cell of the N-th table of FILE in the row whose first cells are ROW (several leading
cells joined by " & ": ``1e-02 & 1e-07 & auto``; backticks ignored) and the column headed
COLUMN, without a "[min, max]" range that follows the median.  ``<!-- bench-row FILE N ROW -->``
(a line of its own) becomes the table's header and that one row, with the collapsed note.
A key that matches no row or column, or several rows, fails the build.
"""

from __future__ import annotations

import re
from pathlib import Path

from mkdocs.exceptions import PluginError

MARKER = re.compile(r"^<!--[ \t]*bench-table[ \t]+(\S+)[ \t]+(\d+)[ \t]*-->[ \t]*$", re.MULTILINE)
CELL = re.compile(r"<!--[ \t]*bench-cell[ \t]+(\S+)[ \t]+(\d+)[ \t]+([^|>]+?)[ \t]*\|[ \t]*"
                  r"([^>]+?)[ \t]*-->")
ROW = re.compile(r"^<!--[ \t]*bench-row[ \t]+(\S+)[ \t]+(\d+)[ \t]+(.+?)[ \t]*-->[ \t]*$",
                 re.MULTILINE)
# every include marker, for the check that pages quote no measured figure by hand
ANY_MARKER = re.compile(r"<!--[ \t]*bench-(?:table|cell|row)[ \t][^>]*-->")


def _blocks(text: str) -> list[tuple[str, list[str]]]:
    """The file cut at blank lines and headings into ("table" | "heading" | "text", lines)."""
    blocks: list[tuple[str, list[str]]] = []
    after_blank = True
    for line in text.splitlines():
        if not line.strip():
            after_blank = True
            continue
        kind = ("table" if line.lstrip().startswith("|") else
                "heading" if line.startswith("#") else "text")
        if blocks and not after_blank and blocks[-1][0] == kind != "heading":
            blocks[-1][1].append(line)
        else:
            blocks.append((kind, [line]))
        after_blank = False
    return blocks


def _note(title: str, parts: list[list[str]], rel: str) -> str:
    """A collapsed admonition holding the file's context."""
    body: list[str] = [f"From `{rel}`."]
    for p in parts:
        body += [""] + p
    indented = "\n".join(("    " + ln) if ln else "" for ln in body)
    title = title.replace('"', "'").replace("`", "")
    return f'??? info "Source: {title}"\n{indented}\n'


def _table(name: str, index: int, root: Path) -> tuple[str, list, int]:
    """(the file's path relative to root, its blocks, the block index of its index-th table)."""
    rel = name if "/" in name else f"benchmarks/results/{name}"
    path = root / rel
    if not path.is_file():
        raise FileNotFoundError(f"{rel} does not exist")
    blocks = _blocks(path.read_text(encoding="utf-8"))
    tables = [i for i, (kind, _) in enumerate(blocks) if kind == "table"]
    if not 1 <= index <= len(tables):
        raise IndexError(f"{rel} has {len(tables)} table(s), not {index}")
    return rel, blocks, tables[index - 1]


def _cells(line: str) -> list[str]:
    """The cells of one table line, stripped (an escaped "\\|" stays inside its cell)."""
    parts = re.split(r"(?<!\\)\|", line.strip().strip("|"))
    return [p.strip() for p in parts]


def _key(text: str) -> str:
    return " ".join(text.replace("`", "").split())


def _row(lines: list[str], row: str, rel: str) -> int:
    """The index in lines of the one body row whose leading cells are row's keys."""
    keys = [_key(k) for k in row.split(" & ")]
    hits = [i for i, ln in enumerate(lines[2:], start=2)
            if [_key(c) for c in _cells(ln)[:len(keys)]] == keys]
    if len(hits) != 1:
        raise KeyError(f"{rel}: {len(hits)} rows start with {' | '.join(keys)!r}, not one")
    return hits[0]


def cell(name: str, index: int, row: str, column: str, root: Path) -> str:
    """The text of one cell (a trailing "[min, max]" range dropped)."""
    rel, blocks, at = _table(name, index, root)
    lines = blocks[at][1]
    header = [_key(c) for c in _cells(lines[0])]
    if _key(column) not in header:
        raise KeyError(f"{rel}: no column {column!r} (columns: {', '.join(header)})")
    text = _cells(lines[_row(lines, row, rel)])[header.index(_key(column))]
    return re.sub(r"\s*\[[^\]]*\]$", "", text)


def render_row(name: str, index: int, row: str, root: Path) -> str:
    """The header and one row of a table, and its collapsed note."""
    rel, blocks, at = _table(name, index, root)
    lines = blocks[at][1]
    one = [lines[0], lines[1], lines[_row(lines, row, rel)]]
    return render(name, index, root, only=one)


def render(name: str, index: int, root: Path, only: list[str] | None = None) -> str:
    """The markdown that replaces one marker: the table (or its given lines) and its note."""
    rel, blocks, at = _table(name, index, root)
    tables = [i for i, (kind, _) in enumerate(blocks) if kind == "table"]
    title = next((lines[0].lstrip("#").strip() for kind, lines in blocks
                  if kind == "heading" and lines[0].startswith("# ")), name)
    before: list[list[str]] = []
    for kind, lines in blocks[:tables[0]]:
        if kind == "text":
            before.append(lines)
        elif kind == "heading" and not lines[0].startswith("# "):
            break
    after: list[list[str]] = []
    for kind, lines in blocks[at + 1:]:
        if kind != "text":
            break
        after.append(lines)
    table = "\n".join(only if only is not None else blocks[at][1])
    return f"{table}\n\n{_note(title, before + after, rel)}"


def on_page_markdown(markdown, page, config, files, **kwargs):
    root = Path(config["config_file_path"]).resolve().parent

    def failing(make):
        def sub(match: re.Match) -> str:
            try:
                return make(match)
            except (OSError, IndexError, KeyError) as exc:
                raise PluginError(f"{page.file.src_path}: {match.group(0)}: {exc}") from exc
        return sub

    markdown = MARKER.sub(failing(lambda m: render(m.group(1), int(m.group(2)), root)),
                          markdown)
    markdown = ROW.sub(failing(lambda m: render_row(m.group(1), int(m.group(2)), m.group(3),
                                                    root)), markdown)
    return CELL.sub(failing(lambda m: cell(m.group(1), int(m.group(2)), m.group(3),
                                           m.group(4), root)), markdown)
