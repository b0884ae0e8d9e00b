"""Every markdown table the project writes has as many cells in each row as in its header.

A "|" inside a cell (|r - r_rigid|) must be escaped as "\\|" or sit inside a code span, or it
splits the row and the table renders with cells shifted under the wrong header.  The rows are
split the way the documentation's renderer (Python-Markdown's tables extension) splits them:
at "|" outside code spans and not preceded by a backslash.  Checked: the pages under docs/,
the committed benchmark and agent result tables (the site includes them), the README and
CHANGELOG, and the report that benchmarks/paper_comparison.py writes, fed with statements and
values that hold "|".
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

ROOT = Path(__file__).resolve().parents[1]


def split_row(line: str) -> list[str]:
    """The cells of one table row: split at "|" outside code spans and not escaped."""
    text = line.strip()
    cells, cur, i, n = [], [], 0, len(text)
    while i < n:
        c = text[i]
        if c == "\\" and i + 1 < n:
            cur.append(text[i:i + 2])
            i += 2
            continue
        if c == "`":
            run = len(text[i:]) - len(text[i:].lstrip("`"))
            close = text.find("`" * run, i + run)
            while close != -1 and close + run < n and text[close + run] == "`":
                close = text.find("`" * run, close + run + 1)
            if close != -1:                       # a code span: its "|" do not split
                cur.append(text[i:close + run])
                i = close + run
                continue
            cur.append(text[i:i + run])
            i += run
            continue
        if c == "|":
            cells.append("".join(cur))
            cur = []
        else:
            cur.append(c)
        i += 1
    cells.append("".join(cur))
    if text.startswith("|"):
        cells = cells[1:]
    if text.endswith("|") and not text.endswith("\\|"):
        cells = cells[:-1]
    return [c.strip() for c in cells]


def _is_separator(line: str) -> bool:
    cells = split_row(line)
    return bool(cells) and all(c and set(c) <= set(":-") and "-" in c for c in cells)


def tables(text: str) -> list[tuple[int, list[str]]]:
    """(line number of the header, [header, separator, rows...]) of every pipe table outside
    fenced code blocks."""
    lines = text.splitlines()
    out, fence, i = [], None, 0
    while i < len(lines):
        stripped = lines[i].lstrip()
        if stripped.startswith(("```", "~~~")):
            mark = stripped[:3]
            fence = None if fence == mark else (fence or mark)
            i += 1
            continue
        if (fence is None and "|" in lines[i] and i + 1 < len(lines)
                and _is_separator(lines[i + 1])):
            block = [lines[i], lines[i + 1]]
            j = i + 2
            while j < len(lines) and lines[j].strip() and "|" in lines[j]:
                block.append(lines[j])
                j += 1
            out.append((i + 1, block))
            i = j
            continue
        i += 1
    return out


def bad_rows(text: str) -> list[str]:
    """Each row whose cell count differs from its header's, with the line number."""
    bad = []
    for at, block in tables(text):
        width = len(split_row(block[0]))
        for k, row in enumerate(block[1:], start=1):
            if len(split_row(row)) != width:
                bad.append(f"line {at + k}: {len(split_row(row))} cells, header {width}: "
                           f"{row[:120]}")
    return bad


def test_the_splitter_respects_escapes_and_code_spans():
    assert split_row("| a | b |") == ["a", "b"]
    assert split_row(r"| max \|r - r_rigid\| | 8 mm |") == [r"max \|r - r_rigid\|", "8 mm"]
    assert split_row("| `a|b` | c |") == ["`a|b`", "c"]
    assert split_row("| ``x ` | y`` | z |") == ["``x ` | y``", "z"]
    assert split_row("| unclosed ` tick | z |") == ["unclosed ` tick", "z"]
    assert len(split_row("| a | b | c |")) == 3
    # an unescaped "|" splits, as the renderer does: this row is one cell too wide
    assert bad_rows("| a | b |\n|---|---|\n| |r| | 2 |\n") != []


FILES = sorted({*ROOT.glob("docs/*.md"), *ROOT.glob("benchmarks/results/*.md"),
                *ROOT.glob("agents/results/**/*.md"), ROOT / "README.md", ROOT / "CHANGELOG.md",
                ROOT / "agents" / "README.md"})


@pytest.mark.parametrize("path", FILES, ids=[str(p.relative_to(ROOT)) for p in FILES])
def test_every_committed_table_row_has_its_headers_cell_count(path):
    assert bad_rows(path.read_text(encoding="utf-8")) == []


def _paper_comparison():
    spec = importlib.util.spec_from_file_location(
        "paper_comparison_under_test", ROOT / "benchmarks" / "paper_comparison.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    try:
        spec.loader.exec_module(mod)
    finally:
        sys.modules.pop(spec.name, None)
    return mod


def test_the_paper_comparison_report_escapes_pipes_in_its_cells(tmp_path, monkeypatch):
    pc = _paper_comparison()
    Row = getattr(pc, "Row", None)
    if Row is None:                             # the rows live in sim_core.validation
        from sim_core.validation.paper_rows import Row
    row = Row("16-17", "Tip position |r - r_rigid| stays small", "max |r - r_rigid| = 8 mm",
                 True)
    monkeypatch.setattr(pc, "ROWS", {scene: (lambda res, row=row: [row, row])
                                     for scene in pc.ROWS})
    run = SimpleNamespace(stats={"wall_s": 12.0, "n_steps": 345}, error=None)
    results = {case: run for case in pc.cases()}
    text = pc.report(results, tmp_path, tmp_path / "validation.md", quick=True)
    found = tables(text)
    assert len(found) >= 3                      # a statements and a wall-time table per scene
    assert bad_rows(text) == []
    assert r"max \|r - r_rigid\| = 8 mm" in text
