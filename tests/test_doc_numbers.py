"""The pages quote no measured time or speed by hand: every such figure comes from a table of
``benchmarks/results/`` through an include marker (``docs/hooks/bench_tables.py``:
``bench-table``, ``bench-row``, ``bench-cell``), so a rerun benchmark updates every page.

The check finds every number with a unit of time or speed (``12.3 s``, ``0.8 ms``, ``0–4 s``,
``RTF 1.2``, ``real-time factor of 3``, ``1000 × real time``, ``20 000 env steps/s``) in
README.md and docs/*.md outside the markers, and fails on any that no entry of ``ALLOWED``
explains.  An entry allows a hit by the text just before it and/or just after it (regular
expressions, the page's paragraph joined into one line) and states why such a number is not a
measurement: simulated time (an instant or window of a manoeuvre, a step size, a scene
parameter), or a limit the code sets.  Speeds and timings have no entry.
"""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

_spec = importlib.util.spec_from_file_location("bench_tables_hook",
                                               ROOT / "docs" / "hooks" / "bench_tables.py")
bench_tables = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(bench_tables)

NUM = r"\d+(?:[.,]\d+)?"
FIGURE = re.compile(
    rf"(?<![\w.^−-]){NUM}(?:\s?[–-]\s?{NUM})?\s?(?:ms|s)\b(?![/⁻])"       # 12.3 s, 0–4 s, 5 ms
    rf"|\bRTF\s*(?:of\s*)?[~≈=]?\s*\d"                                   # RTF 1.2
    rf"|real-time factor\s*(?:of\s*)?[~≈=]?\s*\d"                        # real-time factor of 3
    rf"|{NUM}\s*(?:x|×|times)\s*real[- ]time"                            # 1000 × real time
    rf"|\d[\d ,]*\s*(?:env\s)?steps/s")                                  # 20 000 env steps/s

SIM_BEFORE = (r"(?:\b(?:at|after|from|until|till|to|over|before|during|within|on|every|for|"
              r"in the first|the first|the last|beyond)\s+(?:about\s+|~|≈\s?)?)$")

# (page name or None for every page, text before the hit, text after it, why it is allowed)
ALLOWED: list[tuple[str | None, str | None, str | None, str]] = [
    ("scene_reference.md", None, None,
     "generated from the declared scene fields: defaults and allowed ranges of scene keys"),
    ("validation.md", None, None,
     "written by benchmarks/paper_comparison.py: instants and windows of simulated time of the "
     "paper's statements; its run times sit in tables labelled with their machine load"),
    ("gallery.md", None, None,
     "written by benchmarks/gallery.py from the scene descriptions and the runs' simulated "
     "durations; it quotes no run time (each report carries its own run's)"),
    (None, SIM_BEFORE, None,
     "an instant or window of simulated time (at 8 s, over 16–20 s, every 0.05 s)"),
    (None, SIM_BEFORE.replace(")$", rf"){NUM}(?:–{NUM})?\s?(?:ms|s)?,? (?:and|or|to) $"), None,
     "the second instant of a pair of simulated times (at 4 s and 12 s)"),
    (None, r"(?:\b[A-Za-zτθξ_][\w.'₁₂]*|\)) ?(?:=|≥|≤|≈|<|>) ?~?$", None,
     "a scene or solver parameter, or a variable of simulated time (t = 8 s, h = 0.01 s)"),
    (None, None, r"^\s?(?:steps?\b|ramps\b|episodes\b|window\b|control step\b|per episode|"
                 r"of (?:steady |simulated )|simulated\b|when extracting|\)\s*per episode|"
                 r"scenario\b|manoeuvre\b|for orders\b)",
     "a step size or duration of simulated time (12 ms steps, 30 s episodes)"),
    (None, r"(?:steps? (?:of )?(?:about |~)?|held at ~?|window |step |ramps? of |"
           r"\(held |time constant[^.]*?(?:, |\())$",
     None, "a step size, a hold or a time constant of the simulated motion"),
    (None, r"advance\([\d.]+,[^)]*\)\s*# $", None,
     "the simulated interval given to Simulation.advance, in a code comment"),
    (None, r"(?:max_wall_s=[\d.]+\)` stops an integration that takes longer than |"
           r"gets at most |the budget \+ |backing off to )$", None,
     "a wall-time limit or retry delay the code sets, not a measurement"),
    (None, None, r"^\(t\)", "the stroke s(t) in a formula (2 s(t)), not a time"),
]


def _pages() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def _paragraphs(text: str) -> list[tuple[int, str]]:
    """(first line number, the paragraph joined into one line), include markers removed."""
    out, start, buf = [], 1, []
    for i, line in enumerate(text.splitlines(), 1):
        if line.strip():
            if not buf:
                start = i
            buf.append(line.strip())
        elif buf:
            out.append((start, " ".join(buf)))
            buf = []
    if buf:
        out.append((start, " ".join(buf)))
    return [(n, bench_tables.ANY_MARKER.sub("", p)) for n, p in out]


def _allowed(page: str, before: str, after: str) -> bool:
    return any((name is None or name == page)
               and (b is None or re.search(b, before))
               and (a is None or re.search(a, after))
               for name, b, a, _ in ALLOWED)


def unexplained(page: str, text: str) -> list[str]:
    """Every time or speed figure of text that no ALLOWED entry explains."""
    out = []
    for line, para in _paragraphs(text):
        for m in FIGURE.finditer(para):
            before, after = para[max(0, m.start() - 80):m.start()], para[m.end():m.end() + 40]
            if not _allowed(page, before, after):
                out.append(f"{page}:{line}: {m.group(0)!r} in "
                           f"{para[max(0, m.start() - 60):m.end() + 20]!r}")
    return out


def test_no_page_quotes_a_measured_time_by_hand():
    bad = [b for p in _pages() for b in unexplained(p.name, p.read_text(encoding="utf-8"))]
    assert bad == [], ("time or speed figures typed into a page: include them from their "
                       "table (<!-- bench-cell FILE N ROW | COLUMN -->) or, where they are not "
                       "a measurement, say why in ALLOWED:\n" + "\n".join(bad))


@pytest.mark.parametrize("text", [
    "The main job takes about 19 s on an idle 2-core machine.",
    "at rtol 1e-2 auto takes 12.3 s instead of 14.2 s pinned to one core",
    "About 20 000 env steps/s, ~1000 × real time on one core.",
    "Slow (real-time factor ~2.4 on one core).",
    "a right-hand side costs about 0.8 ms at 3 nodes",
    "the first run adds ~20–30 s of compilation",
])
def test_a_typed_measurement_is_found(text):
    assert unexplained("user_guide.md", text), text


@pytest.mark.parametrize("text", [
    "A run starts in static equilibrium and ends at 20 s.",
    "the paper states it at 4 s and 12 s",
    "`--set solver.t_end=2` with h = 0.01 s and t ≥ 30 s",
    "RK45 takes steps of about 12 ms while the booms slide",
    "The figures add <!-- bench-cell user_crane_speed.md 1 default | wall s --> s.",
])
def test_simulated_times_and_included_figures_pass(text):
    assert unexplained("model.md", text) == []


def test_every_cell_marker_of_the_pages_resolves():
    """Each bench-cell marker names an existing file, table, row and column (the build
    would fail on it; this finds it without building)."""
    n = 0
    for page in _pages():
        for m in bench_tables.CELL.finditer(page.read_text(encoding="utf-8")):
            value = bench_tables.cell(m.group(1), int(m.group(2)), m.group(3), m.group(4), ROOT)
            assert re.fullmatch(r"[\d.e+-]+(?: \w+)?", value), (page.name, m.group(0), value)
            n += 1
    assert n >= 10
