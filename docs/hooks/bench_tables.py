"""MkDocs hook: the tables of the committed benchmark results in the guides.

A line ``<!-- bench-table FILE N -->`` in a page becomes the N-th table (counted from 1) of
``benchmarks/results/FILE`` (of FILE itself, relative to the repository root, where it holds a
"/": ``agents/results/comparison.md``), followed by a collapsed note that gives the file's title, its
text before the first table (what was timed, how, and the machine state) and the text that
follows the table.  The guides never retype a measured figure: a rerun benchmark shows on the
next build.  A missing file or table fails the build, naming the page and the marker.
"""

from __future__ import annotations

import re
from pathlib import Path

from mkdocs.exceptions import PluginError

MARKER = re.compile(r"^<!--[ \t]*bench-table[ \t]+(\S+)[ \t]+(\d+)[ \t]*-->[ \t]*$", re.MULTILINE)


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


def render(name: str, index: int, root: Path) -> str:
    """The markdown that replaces one marker: the table and its collapsed note."""
    rel = name if "/" in name else f"benchmarks/results/{name}"
    path = root / rel
    if not path.is_file():
        raise FileNotFoundError(f"{rel} does not exist")
    blocks = _blocks(path.read_text(encoding="utf-8"))
    tables = [i for i, (kind, _) in enumerate(blocks) if kind == "table"]
    if not 1 <= index <= len(tables):
        raise IndexError(f"{rel} has {len(tables)} table(s), not {index}")
    at = tables[index - 1]
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
    table = "\n".join(blocks[at][1])
    return f"{table}\n\n{_note(title, before + after, rel)}"


def on_page_markdown(markdown, page, config, files, **kwargs):
    root = Path(config["config_file_path"]).resolve().parent

    def sub(match: re.Match) -> str:
        try:
            return render(match.group(1), int(match.group(2)), root)
        except (OSError, IndexError) as exc:
            raise PluginError(f"{page.file.src_path}: {match.group(0)}: {exc}") from exc

    return MARKER.sub(sub, markdown)
