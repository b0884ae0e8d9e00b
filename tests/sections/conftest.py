"""The section tests analyse every section with sectionproperties: the on-disk cache of
finite-element results (sim_core.physics.cross_sections._fe) is off for them, except where a
test points it at a folder of its own."""

import pytest


@pytest.fixture(autouse=True)
def _no_disk_cache(monkeypatch):
    monkeypatch.setenv("BOOM_SIM_CACHE_DIR", "")
