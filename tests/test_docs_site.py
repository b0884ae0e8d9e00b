"""The documentation site builds without warnings and renders in a browser without a network.

The site is built into a temporary folder (``mkdocs build --strict``, as CI does), served on
127.0.0.1 and every page is loaded in headless Chromium (the system's chromium and
chromedriver, started through selenium's Service: no driver download).  Every other host name
resolves to nothing (``--host-resolver-rules``), so a font, script or style sheet fetched
from the internet fails to load.  For every page:

* the browser console has no SEVERE entry (a failed resource, a script error);
* every resource the page loaded came from the local server;
* no table's box is wider than the article's content column: every table's scroll wrapper
  (the theme's, in which a wide table scrolls sideways) ends within the article, no code span
  in a table breaks across lines and the page does not scroll sideways (collapsed notes
  opened, so their tables count too);
* every row of every table has as many cells as its header row (colspans counted).

The gallery's reports are loaded too and checked for console errors and local resources.
Skips, naming what is missing, where mkdocs with its theme and plugins, selenium, chromium or
chromedriver is not installed.
"""

from __future__ import annotations

import functools
import http.server
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
WINDOW = (1280, 900)            # px: a laptop screen, navigation and table of contents shown
FLAGS = ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1")

pytestmark = pytest.mark.slow


def _missing() -> str | None:
    for mod, pip in (("mkdocs", "mkdocs"), ("material", "mkdocs-material"),
                     ("mkdocstrings_handlers.python", "mkdocstrings[python]"),
                     ("selenium", "selenium")):
        try:
            found = importlib.util.find_spec(mod) is not None
        except ModuleNotFoundError:
            found = False
        if not found:
            return f"{pip} is not installed (pip install -e '.[docs]' and selenium)"
    for path, pkg in ((CHROMIUM, "chromium"), (CHROMEDRIVER, "chromium-driver")):
        if not os.access(path, os.X_OK):
            return f"{path} not found (apt-get install {pkg})"
    return None


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The built site, served on 127.0.0.1: (folder, base URL)."""
    why = _missing()
    if why:
        pytest.skip(why)
    out = tmp_path_factory.mktemp("site") / "site"
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir",
                           str(out)], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=600, check=False)
    assert proc.returncode == 0, f"mkdocs build --strict failed:\n{proc.stderr[-4000:]}"
    handler = functools.partial(_QuietHandler, directory=str(out))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield out, f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):      # the test reports what matters
        pass


@pytest.fixture(scope="module")
def browser(site):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    profile = tempfile.mkdtemp(prefix="docs_site_chromium_")
    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for flag in (*FLAGS, f"--user-data-dir={profile}",
                 f"--window-size={WINDOW[0]},{WINDOW[1]}"):
        opts.add_argument(flag)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=opts)
    try:
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


# the geometry and the cell counts of every table, measured in the page
TABLES_JS = """
document.querySelectorAll('details').forEach(d => { d.open = true; });
const art = document.querySelector('article.md-content__inner');
if (!art) { return null; }
const box = art.getBoundingClientRect();
const page = document.scrollingElement;
const cells = row => Array.from(row.cells).reduce((n, c) => n + (c.colSpan || 1), 0);
const out = {pageScroll: page.scrollWidth, pageWidth: page.clientWidth, right: box.right,
             tables: []};
art.querySelectorAll('table').forEach((t, k) => {
  const rows = Array.from(t.rows);
  const head = t.tHead && t.tHead.rows.length ? t.tHead.rows[0] : rows[0];
  const width = head ? cells(head) : 0;
  const bad = rows.filter(row => row !== head && cells(row) !== width)
                  .map(row => row.innerText.slice(0, 100));
  const caption = (head ? head.innerText : '').replace(/\\s+/g, ' ').slice(0, 80);
  const wrap = t.closest('.md-typeset__scrollwrap');
  const broken = Array.from(t.querySelectorAll('td code, th code'))
                      .filter(c => c.getClientRects().length > 1).map(c => c.innerText);
  // the wrapper's right edge less its (negative) right margin: the theme lets it reach into
  // the article's padding by that margin, for the scroll shadow
  const right = wrap ? wrap.getBoundingClientRect().right
                       + (parseFloat(getComputedStyle(wrap).marginRight) || 0)
                     : t.getBoundingClientRect().right;
  out.tables.push({index: k, right: right, header: caption, columns: width, bad: bad,
                   broken: broken});
});
return out;
"""

RESOURCES_JS = """
return performance.getEntriesByType('resource').map(e => e.name);
"""


def _pages(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*.html")
                  if "gallery" not in p.relative_to(folder).parts[:-1]
                  or p.name == "index.html")


def _reports(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in (folder / "gallery").rglob("*.html")
                  if p.name != "index.html") if (folder / "gallery").is_dir() else []


def _load(driver, url: str) -> list[dict]:
    """Open url, wait until it is loaded and its scripts settled; the console entries."""
    driver.get(url)
    for _ in range(100):
        if driver.execute_script("return document.readyState") == "complete":
            break
        time.sleep(0.05)
    time.sleep(0.3)                                    # late errors (workers, fetches)
    return driver.get_log("browser")


def _check(driver, base: str, page: str, tables: bool) -> list[str]:
    problems = []
    logs = _load(driver, f"{base}/{page}")
    problems += [f"{page}: console {e['level']}: {e['message'][:300]}" for e in logs
                 if e["level"] == "SEVERE"]
    for name in driver.execute_script(RESOURCES_JS):
        if not name.startswith(base + "/"):
            problems.append(f"{page}: loaded {name} from outside the site")
    if not tables:
        return problems
    geo = driver.execute_script(TABLES_JS)
    assert geo is not None, f"{page}: no article (not a page of the theme?)"
    if geo["pageScroll"] > geo["pageWidth"] + 1:
        problems.append(f"{page}: the page scrolls sideways ({geo['pageScroll']} px of "
                        f"content in a {geo['pageWidth']} px window)")
    for t in geo["tables"]:
        for code in t["broken"]:
            problems.append(f"{page}: table {t['index']} ({t['header']}): code span "
                            f"{code!r} breaks across lines")
        if t["right"] > geo["right"] + 1:
            problems.append(f"{page}: table {t['index']} ({t['header']}) ends "
                            f"{t['right'] - geo['right']:.0f} px right of the content column")
        for row in t["bad"]:
            problems.append(f"{page}: table {t['index']} ({t['header']}): a row without "
                            f"{t['columns']} cells: {row!r}")
    return problems


def test_every_page_renders_offline_with_tables_inside_the_column(site, browser):
    folder, base = site
    pages = _pages(folder)
    assert "index.html" in pages and "api/index.html" in pages
    problems = []
    for page in pages:
        problems += _check(browser, base, page, tables=page != "404.html")
    for report in _reports(folder):
        problems += _check(browser, base, report, tables=False)
    assert problems == [], "\n".join(problems)
