"""The run's report (sim_core.report) in a real browser: headless Chromium driven by Selenium
through the system chromedriver, the page loaded from file:// with nothing else reachable.

Checked: the page logs no error to the browser console, every output's plot is drawn by
plotly (a ``.js-plotly-plot`` in each ``report-plot`` container, with at least one trace
drawn: a line path or a heat map image), and a screenshot of the page is not blank.

Reports checked: the one ``boom-sim run telescopic_extraction --out results/telescopic_extraction``
wrote (CI runs it before the tests: the whole 20 s paper run, with the paper's comparison
rows), where it exists, and one written here from a short real run (telescopic_extraction,
0.02 s simulated, with its replay geometry, contact forces and slider springs).
Skipped with the reason where chromium, chromedriver or selenium is missing.
"""

from __future__ import annotations

import io
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
CI_REPORT = ROOT / "results" / "telescopic_extraction" / "report.html"
CHROMEDRIVER = Path("/usr/bin/chromedriver")
CHROME_FLAGS = ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic",
                "--no-first-run", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--window-size=1280,2000")


def _browser_binary() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    return None


@pytest.fixture(scope="module")
def driver():
    webdriver = pytest.importorskip("selenium.webdriver", reason="selenium is not installed "
                                    "(pip install 'telescopic-boom-sim[dev]')")
    from selenium.webdriver.chrome.service import Service
    binary = _browser_binary()
    if binary is None:
        pytest.skip("no chromium on PATH (apt-get install chromium chromium-driver)")
    if not CHROMEDRIVER.exists():
        pytest.skip(f"no chromedriver at {CHROMEDRIVER} (apt-get install chromium-driver)")
    profile = tempfile.mkdtemp(prefix="report-browser-")
    opts = webdriver.ChromeOptions()
    opts.binary_location = binary
    for flag in CHROME_FLAGS:
        opts.add_argument(flag)
    opts.add_argument(f"--user-data-dir={profile}")
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    # the system chromedriver through an explicit Service: Selenium Manager downloads nothing
    drv = webdriver.Chrome(service=Service(executable_path=str(CHROMEDRIVER)), options=opts)
    drv.set_page_load_timeout(60)
    try:
        yield drv
    finally:
        drv.quit()
        shutil.rmtree(profile, ignore_errors=True)


@pytest.fixture(scope="module")
def short_report(tmp_path_factory):
    """A report of a short real run of the paper's extraction scene."""
    from sim_core import load_scene, simulate
    from sim_core.report import write_report
    res = simulate(load_scene("telescopic_extraction", {"solver.t_end": 0.02,
                                                        "solver.n_output": 11}))
    return write_report(res, tmp_path_factory.mktemp("report") / "report.html"), res


def _check_page(drv, path: Path) -> None:
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait
    drv.get_log("browser")                                 # drop what an earlier page logged
    drv.get(path.resolve().as_uri())
    plots = drv.find_elements(By.CSS_SELECTOR, ".report-plot")
    assert plots, f"{path}: no report-plot container"
    # plotly draws asynchronously: wait until every container has its drawn plot
    script = ("return Array.from(document.querySelectorAll('.report-plot')).filter(d => "
              "!d.querySelector('.js-plotly-plot .main-svg')).length")
    WebDriverWait(drv, 30).until(lambda d: d.execute_script(script) == 0)
    empty = drv.execute_script(
        "return Array.from(document.querySelectorAll('.report-plot')).filter(d => {"
        " const p = d.querySelector('.js-plotly-plot');"
        " if (!p || !p.data || p.data.length === 0) return true;"
        " const lines = Array.from(p.querySelectorAll('.scatterlayer path.js-line'))"
        "   .filter(e => (e.getAttribute('d') || '').length > 1);"
        " const maps = p.querySelectorAll('.heatmaplayer image');"
        " return lines.length === 0 && maps.length === 0;"
        "}).map(d => d.id)")
    assert not empty, f"{path}: plots without a drawn trace: {empty}"
    severe = [e for e in drv.get_log("browser") if e.get("level") == "SEVERE"]
    assert not severe, f"{path}: console errors: {severe}"
    _assert_not_blank(drv.get_screenshot_as_png(), path)


def _assert_not_blank(png: bytes, path: Path) -> None:
    from PIL import Image
    img = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=float)
    assert img.shape[0] > 100 and img.shape[1] > 100, img.shape
    # the page's header band, text and plots: far from a uniform image
    non_white = np.mean(np.any(img < 235.0, axis=2))
    assert non_white > 0.05, f"{path}: screenshot nearly blank ({non_white:.3f} non-white)"
    assert float(img.std()) > 10.0, f"{path}: screenshot nearly uniform (std {img.std():.1f})"


def test_report_of_a_short_run_draws_every_output_without_console_errors(driver, short_report):
    path, res = short_report
    _check_page(driver, path)
    from selenium.webdriver.common.by import By
    ids = {e.get_attribute("id") for e in driver.find_elements(By.CSS_SELECTOR, ".report-plot")}
    # every time series; not the replay geometry, the integrator state and the per-station
    # section arrays (drawn as the section-force envelopes)
    not_plotted = {"state", "section_stations", "section_stress_points", "section_forces",
                   "section_stress", "section_utilisation"}
    assert ids == {f"plot-{name}" for name in res.outputs
                   if name not in not_plotted and not name.startswith("geometry_")}
    assert len(driver.find_elements(By.CSS_SELECTOR, ".report-strength")) == 2


@pytest.mark.skipif(not CI_REPORT.exists(), reason="no results/telescopic_extraction/report.html "
                    "(CI's main job writes it before the tests)")
def test_report_of_the_main_job_draws_every_output_without_console_errors(driver):
    _check_page(driver, CI_REPORT)
    from selenium.webdriver.common.by import By
    rows = driver.find_elements(By.CSS_SELECTOR, "table.paper-rows tr")
    assert len(rows) > 10                       # the paper's statements (header row included)
