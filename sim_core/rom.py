"""The public surface of the telescopic crane's modal reduced-order model and of the crane
geometry it describes, for environments and controllers (SI units).

The ROM itself is stepped through :class:`sim_core.Simulation` on a scene with
``model.reduction = "modal"`` (e.g. ``telescopic_extraction_rl``); this module gives what a
caller needs beside it:

* :data:`TABLE_BOOMS`: the boom counts with shipped modal tables (3: the paper's crane, 5);
* :func:`allowed_ranges`: the payload, luffing-angle and stroke ranges the tables cover;
* :func:`tables_for` / :class:`ModalTables`: the tables of one configuration, interpolated in
  the stroke L_s: ``coefficients(L)`` (omega, zeta, Gamma, ... of every mode),
  ``static_tip(L)`` (the static-equilibrium tip and its stroke derivative), ``L_range``;
* :func:`static_tip`: the static tip of a configuration at one stroke, in one call;
* :func:`luffing_geometry` / :class:`LuffingGeometry`: the crane's luffing geometry at an
  angle (boom 1's origin ``origin`` and axis ``e_s``, the cylinder's length and lever);
* :func:`boom_masses`: every boom's mass (kg) of the shorthand crane of ``n_booms`` sections.

These names are stable; the modules behind them (``sim_core.systems.telescopic.*``) are not.
How the tables are built and what the ROM neglects: :mod:`sim_core.systems.telescopic.modal`.
"""

from __future__ import annotations

import numpy as np

from sim_core.systems.telescopic.luffing import LuffingGeometry, luffing_geometry
from sim_core.systems.telescopic.modal import TABLE_BOOMS as _TABLE_BOOMS
from sim_core.systems.telescopic.modal import ModalTables
from sim_core.systems.telescopic.modal import allowed_ranges as _allowed_ranges
from sim_core.systems.telescopic.modal import tables_for as _tables_for

__all__ = ["TABLE_BOOMS", "allowed_ranges", "tables_for", "ModalTables", "static_tip",
           "luffing_geometry", "LuffingGeometry", "boom_masses"]

#: boom counts with shipped modal tables (synchronized drive)
TABLE_BOOMS: tuple[int, ...] = tuple(sorted(_TABLE_BOOMS))


def allowed_ranges(n_booms: int = 3) -> tuple[tuple[float, float], tuple[float, float],
                                              tuple[float, float]]:
    """((payload lo, hi) kg, (luffing angle lo, hi) deg, (L_s lo, hi) m) covered by the modal
    tables of ``n_booms`` sections.  ValueError for a count without tables."""
    return _allowed_ranges(n_booms=n_booms)


def tables_for(payload: float, luffing_angle_deg: float, n_modes: int = 4,
               n_booms: int = 3) -> ModalTables:
    """The modal tables of one configuration (payload kg, luffing angle deg), interpolated
    bilinearly between the tabulated ones, with the lowest ``n_modes`` in-plane modes.
    ValueError outside :func:`allowed_ranges` (no extrapolation) and for a boom count without
    tables."""
    return _tables_for(payload, luffing_angle_deg, n_modes, n_booms=n_booms)


def static_tip(stroke: float, payload: float, luffing_angle_deg: float,
               n_booms: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """The static-equilibrium tip position r_s (3,) m of the innermost boom and d r_s/dL_s (3,)
    at piston length ``stroke`` (m), from the modal tables (cubic Hermite in L_s;
    :meth:`ModalTables.static_tip`).  For many strokes of one configuration call
    ``tables_for(...).static_tip`` instead (the interpolation in payload and angle once)."""
    return _tables_for(payload, luffing_angle_deg, 1, n_booms=n_booms).static_tip(stroke)


def boom_masses(n_booms: int = 3) -> tuple[float, ...]:
    """Mass (kg) of every boom, outermost first, of the shorthand crane of ``n_booms`` sections
    (the paper's Table 2 sections for three; the U family's for more: ``params.crane_sections``)."""
    from sim_core.systems.telescopic.params import TelescopicParams, boom_section
    p = TelescopicParams(n_booms=n_booms)
    return tuple(float(boom_section(k, p).rhoA * p.lengths[k]) for k in range(n_booms))
