"""A result file is data: no string in it (output names, stats keys and values, self-check
names and texts, the error message, scene fields) can add an element or a script to the report
page.  HTML text is escaped with ``html.escape``; the figure JSON inside ``<script>`` blocks
carries ``<``, ``>`` and ``/`` as ``\\u003c`` etc. and the plot config holds no string of the
file, so a ``</script>`` in a name never closes its block."""

from __future__ import annotations

from html.parser import HTMLParser

import numpy as np
import pytest

from sim_core import report as rp
from sim_core.result import Result

pytest.importorskip("plotly")

SCRIPT = "</script><script>alert(9)</script>"
IMG = "<img src=x onerror=alert(9)>"
COMMENT = "<!--<script>"


class _Elements(HTMLParser):
    """Every start tag of the page with its attributes, the text of every script block and
    the page's text outside scripts."""

    def __init__(self):
        super().__init__()
        self.tags, self.scripts, self.text = [], [], []
        self._in_script = False

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))
        if tag == "script":
            self._in_script = True
            self.scripts.append("")

    def handle_endtag(self, tag):
        if tag == "script":
            self._in_script = False

    def handle_data(self, data):
        if self._in_script:
            self.scripts[-1] += data
        else:
            self.text.append(data)


def _result(tag: str) -> Result:
    """A result whose every string field carries ``tag`` (a time series, a per-component
    series, a time-independent (x, y) outline, a text output; stats, checks, error, scene)."""
    n = 11
    t = np.linspace(0.0, 1.0, n)
    outputs = {f"series{tag}": np.sin(t),
               f"xyz{tag}": np.c_[t, 2 * t, 3 * t],
               f"outline{tag}": np.array([[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]]),
               f"text{tag}": np.array([f"label{tag}"] * n)}
    stats = {"method": f"auto{tag}", f"key{tag}": f"value{tag}", "wall_time_s": 1.0,
             "checks": {f"check{tag}": {"value": 0.5, "limit": 0.1, "fail_limit": 1.0,
                                        "ok": False, "gross": False, "what": f"what{tag}"}},
             "suspect": True}
    scene = {"kind": f"telescopic{tag}", "name": f"crane{tag}", "description": f"d{tag}",
             "contact": {"moment_model": f"m{tag}"}, f"extra{tag}": [f"x{tag}"]}
    return Result(t, outputs, stats, scene, error=f"stopped{tag}")


def _render(tmp_path, res: Result, name: str) -> tuple[str, _Elements]:
    path = rp.write_report(Result.load(res.save(tmp_path / f"{name}.npz")),
                           tmp_path / f"{name}.html", include_plotlyjs=False)
    text = path.read_text(encoding="utf-8")
    page = _Elements()
    page.feed(text)
    page.close()
    return text, page


@pytest.mark.parametrize("payload", [SCRIPT, IMG, COMMENT])
def test_no_string_of_a_result_file_adds_an_element_to_the_report(tmp_path, payload):
    plain_text, plain = _render(tmp_path, _result("_plain"), "plain")
    text, page = _render(tmp_path, _result(payload), "hostile")
    # the same elements as the page of a harmless result of the same layout
    assert [tag for tag, _ in page.tags] == [tag for tag, _ in plain.tags]
    assert len(page.scripts) == len(plain.scripts) > 0
    assert not [a for _, attrs in page.tags for a in attrs if a.startswith("on")]
    # no script block is cut short: each still ends with plotly's closing of its call
    for body, ref in zip(page.scripts, plain.scripts):
        assert body.rstrip()[-3:] == ref.rstrip()[-3:]
        assert "alert(9)" not in body or "</" not in body.replace("</script>", "")
    # the raw markup of the payload appears nowhere in the file ...
    assert payload not in text
    # ... and the payload is shown as text (escaped, so the browser prints it)
    shown = "".join(page.text)
    for field in ("series", "check", "what", "stopped", "crane", "value", "auto"):
        assert f"{field}{payload}" in shown, field

