"""The radial gap sets the contact circle of the sliding blocks (docs/model.md#input-sections,
docs/model.md#input-springs)."""

import pytest

from sim_core.physics.contact import SliderGeometry


@pytest.mark.parametrize("pair", [1, 2])
def test_default_gap_is_the_table_1_mid_gap(pair):
    """Table 1: 15 mm walls and 5 mm radial gaps, so radial_gap = 5 mm reproduces the mid-gap
    circle of the paper's geometry on every arc."""
    a = SliderGeometry.paper_region(pair, "inner")
    b = SliderGeometry.paper_region(pair, "inner", radial_gap=0.005)
    assert b.arcs[:, 2] == pytest.approx(a.arcs[:, 2], abs=1e-15)


def test_thinner_gap_moves_the_contact_circle_outwards():
    """A block of thickness g below the outer boom's inner face: radius = inner face - g/2."""
    g0 = SliderGeometry.paper_region(1, "outer", radial_gap=0.005).arcs[:, 2]
    g1 = SliderGeometry.paper_region(1, "outer", radial_gap=0.0001).arcs[:, 2]
    assert g1 - g0 == pytest.approx([0.00245] * 3, abs=1e-12)
