"""Every page of the documentation site in headless Chromium at 1400 px width, offline.

The site is built (``mkdocs build --strict``) and served on 127.0.0.1 by the ``site`` fixture of
:mod:`tests.test_docs_site`; every other host name resolves to nothing.  For every page:

(a) no table cell breaks inside a word or number: every whitespace-separated piece of text of
    every ``td``/``th`` (collapsed notes opened; a piece is also cut after "-", "–", "/", the
    places a browser breaks a line without ``overflow-wrap``) lies on one line, i.e. a DOM
    Range over it has its client rectangles on one line;
(b) the equations render: ``model/`` holds KaTeX output (``.katex``) for every
    ``.arithmatex`` element and no page has a ``.katex-error``;
(c) no request leaves the machine: every ``performance.getEntriesByType('resource')`` URL is
    on the local server;
(d) the browser console has no SEVERE entry.

Skips, naming what is missing, without mkdocs and its plugins, selenium, chromium or
chromedriver.
"""

from __future__ import annotations

import pytest

from tests.test_docs_site import _load, _pages, browser, site  # noqa: F401

WIDTH = 1400               # px: a desktop window, navigation and table of contents shown

pytestmark = pytest.mark.slow

# every piece of text of every table cell that spans more than one line
BREAKS_JS = r"""
document.querySelectorAll('details').forEach(d => { d.open = true; });
const art = document.querySelector('article.md-content__inner');
if (!art) { return null; }
const out = [];
art.querySelectorAll('td, th').forEach(cell => {
  const walker = document.createTreeWalker(cell, NodeFilter.SHOW_TEXT);
  for (let node = walker.nextNode(); node; node = walker.nextNode()) {
    const text = node.textContent;
    for (const m of text.matchAll(/[^\s\-\u2013\u2014\/]+[\-\u2013\u2014\/]?|[\-\u2013\u2014\/]/g)) {
      if (m[0].length < 2) { continue; }
      const range = document.createRange();
      range.setStart(node, m.index);
      range.setEnd(node, m.index + m[0].length);
      const tops = new Set();
      for (const r of range.getClientRects()) {
        if (r.width > 0 && r.height > 0) { tops.add(Math.round(r.bottom / 4)); }
      }
      if (tops.size > 1) {
        out.push(m[0].slice(0, 60) + '  (cell: ' + cell.innerText.replace(/\s+/g, ' ')
                 .slice(0, 80) + ')');
      }
    }
  }
});
return out;
"""

MATH_JS = """
return {arithmatex: document.querySelectorAll('.arithmatex').length,
        rendered: document.querySelectorAll('.arithmatex .katex').length,
        unrendered: Array.from(document.querySelectorAll('.arithmatex'))
                         .filter(e => !e.querySelector('.katex'))
                         .map(e => e.textContent.slice(0, 80)),
        errors: Array.from(document.querySelectorAll('.katex-error'))
                     .map(e => (e.title || e.textContent).slice(0, 160))};
"""

RESOURCES_JS = "return performance.getEntriesByType('resource').map(e => e.name);"


@pytest.fixture(scope="module")
def wide_browser(browser):  # noqa: F811 - the fixture imported above
    """tests.test_docs_site's headless Chromium, its window WIDTH px wide."""
    browser.set_window_size(WIDTH, 1000)
    assert browser.execute_script("return window.innerWidth") >= WIDTH - 20
    return browser


@pytest.fixture(scope="module")
def pages(site, wide_browser):  # noqa: F811
    """page -> (console SEVERE entries, outside resources, cell breaks, math counts, every
    resource loaded)."""
    folder, base = site
    seen = {}
    for page in _pages(folder):
        logs = _load(wide_browser, f"{base}/{page}")
        severe = [e["message"][:300] for e in logs if e["level"] == "SEVERE"]
        loaded = wide_browser.execute_script(RESOURCES_JS)
        outside = [u for u in loaded if not u.startswith(base + "/")]
        breaks = wide_browser.execute_script(BREAKS_JS) if page != "404.html" else []
        seen[page] = (severe, outside, breaks or [], wide_browser.execute_script(MATH_JS),
                      loaded)
    return seen


def test_no_table_cell_breaks_inside_a_word(pages):
    bad = [f"{page}: {b}" for page, (_, _, breaks, *_) in pages.items() for b in breaks]
    assert bad == [], "table cells broken inside a word or number:\n" + "\n".join(bad)


def test_the_equations_render(pages):
    math = pages["model/index.html"][3]
    # KaTeX and its fonts come from the site itself
    loaded = pages["model/index.html"][4]
    assert any(u.endswith("/katex/katex.min.js") for u in loaded), loaded
    assert any(u.endswith(".woff2") and "/katex/fonts/" in u for u in loaded), loaded
    assert math["arithmatex"] >= 10, math
    assert math["unrendered"] == [], math["unrendered"]
    errors = [f"{page}: {e}" for page, (*_, m, _) in pages.items() for e in m["errors"]]
    assert errors == [], "\n".join(errors)


def test_no_request_leaves_the_machine(pages):
    bad = [f"{page}: {u}" for page, (_, outside, *_) in pages.items() for u in outside]
    assert bad == [], "\n".join(bad)


def test_no_console_errors(pages):
    bad = [f"{page}: {m}" for page, (severe, *_) in pages.items() for m in severe]
    assert bad == [], "\n".join(bad)


def test_the_break_check_finds_a_forced_break(site, wide_browser):  # noqa: F811
    """The check of (a) sees a break: cells squeezed to 40 px with ``word-break: break-all``
    on the performance page break inside their words."""
    folder, base = site
    _load(wide_browser, f"{base}/performance/index.html")
    assert wide_browser.execute_script(BREAKS_JS) == []
    wide_browser.execute_script(
        "document.querySelectorAll('td').forEach(td => { td.style.wordBreak = 'break-all';"
        " td.style.whiteSpace = 'normal'; td.style.maxWidth = '40px'; });")
    assert len(wide_browser.execute_script(BREAKS_JS)) > 10
