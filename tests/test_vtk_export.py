"""sim_core.vtk_export: the ParaView time series of a telescopic run, read back with meshio."""

import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from sim_core import Result, load_scene, simulate
from sim_core.vtk_export import (
    PART_BOOM,
    PART_CONTACT,
    PART_HOIST_ROPE,
    PART_LUFFING_CYLINDER,
    PART_PAYLOAD,
    discrete_curvature,
    export_vtk,
)

# the time-first outputs of the replay (geometry_section_outlines is per boom, not per time)
TIME_SERIES = ("geometry_centre_lines", "geometry_section_frames", "geometry_luffing_cylinder",
               "geometry_contacts", "contact_point_forces", "luffing_cylinder_force",
               "tip_position", "slider_contact_forces", "payload_position", "hoist_rope_force")


@pytest.fixture(scope="module")
def telescopic():
    """A short telescopic extraction (3 booms, 3 output times; about 2 s)."""
    return simulate(load_scene("telescopic_extraction", overrides={
        "booms.n_nodes": 3, "solver.t_end": 0.2, "solver.n_output": 3}))


@pytest.fixture(scope="module")
def swinging():
    """A short lift with the payload swinging on the hoist rope (about 3 s)."""
    return simulate(load_scene("crane_lift_and_slew", overrides={
        "booms.n_nodes": 3, "solver.t_end": 0.2, "solver.n_output": 3}))


@pytest.fixture(scope="module")
def exported(telescopic, tmp_path_factory):
    out = tmp_path_factory.mktemp("vtk") / "series"
    return telescopic, export_vtk(telescopic, out)


def _frames(pvd):
    """(timestep, path) of every DataSet of the .pvd, in file order."""
    root = ET.parse(pvd).getroot()
    return [(float(d.get("timestep")), pvd.parent / d.get("file")) for d in root.iter("DataSet")]


def _block(mesh, cell_type):
    """index of the cell block of that type (one of each is written)"""
    kinds = [c.type for c in mesh.cells]
    assert kinds.count(cell_type) == 1, kinds
    return kinds.index(cell_type)


def _boom_polylines(mesh):
    """The boom lines as drawn: for every boom (point data ``boom``), its points in the order
    the ``part`` 0 line cells chain them."""
    b = _block(mesh, "line")
    seg = mesh.cells[b].data[mesh.cell_data["part"][b] == PART_BOOM]
    booms = mesh.point_data["boom"]
    lines = []
    for k in range(booms.max() + 1):
        mine = seg[booms[seg[:, 0]] == k]
        assert np.all(booms[mine[:, 1]] == k)
        nxt = dict(mine)
        start = (set(mine[:, 0]) - set(mine[:, 1])).pop()
        chain = [start]
        while chain[-1] in nxt:
            chain.append(nxt[chain[-1]])
        assert len(chain) == len(mine) + 1
        lines.append(mesh.points[chain])
    return np.array(lines)


def _points_dtype(vtu):
    """The type the .vtu declares for its points (its XML header, before the binary data)."""
    head = vtu.read_bytes()[:2000].decode("latin-1")
    tag = head[head.index("<Points>"):]
    return tag[tag.index('type="') + 6:].split('"')[0]


def test_boom_points_equal_the_centre_lines(exported):
    """Every frame's boom polylines (the ``part`` 0 line cells chained, boom by boom) are the
    result's ``geometry_centre_lines`` at that time.

    Tolerance: a value x written as a float of machine epsilon eps is read back within the
    rounding to that format, |x_read - x| <= eps / 2 |x|, and exactly where the written format
    is the float64 of the result (a binary, zlib-compressed VTU stores the raw bytes, base64
    encoded: no decimal text in between).  meshio writes the points in their own dtype; the
    export gives it float64, which the file declares (``type="Float64"``): the check is bit for
    bit."""
    res, pvd = exported
    for i, (_, vtu) in enumerate(_frames(pvd)):
        declared = _points_dtype(vtu)
        mesh = meshio.read(vtu)
        assert declared == "Float64" and mesh.points.dtype == np.float64
        rtol = 0.0 if mesh.points.dtype == np.float64 else np.finfo(mesh.points.dtype).eps / 2
        lines = _boom_polylines(mesh)
        want = res["geometry_centre_lines"][i]
        assert lines.shape == want.shape
        assert np.all(np.abs(lines - want) <= rtol * np.abs(want))
        # the section frames ride along as point data, in the same point order
        on_boom = mesh.point_data["boom"] >= 0
        for r, name in enumerate(("e_t", "e_b", "e_s")):
            np.testing.assert_array_equal(mesh.point_data[name][on_boom],
                                          res["geometry_section_frames"][i][:, :, r].reshape(-1, 3))
        # material_s: from 0 at each boom's start, growing by the point spacing to ~its length
        s = mesh.point_data["material_s"][on_boom].reshape(want.shape[:2])
        np.testing.assert_allclose(s[:, -1], res.scene["booms"]["length"], rtol=1e-3)
        assert np.all(s[:, 0] == 0) and np.all(np.diff(s, axis=1) > 0)


def test_pvd_lists_every_output_time_in_order(exported):
    """The .pvd has one DataSet per output time, timesteps equal to ``result.t`` (written with
    repr: they parse back exactly) in order, each naming an existing .vtu under frames/, and
    frames/ holds nothing else."""
    res, pvd = exported
    frames = _frames(pvd)
    assert pvd.name == "result.pvd"
    np.testing.assert_array_equal([t for t, _ in frames], res.t)
    assert all(f.is_file() and f.parent == pvd.parent / "frames" for _, f in frames)
    assert sorted(f.name for _, f in frames) == [f.name for _, f in frames]
    assert sorted(os.listdir(pvd.parent / "frames")) == [f.name for _, f in frames]
    assert sorted(os.listdir(pvd.parent)) == ["frames", "result.pvd"]


def test_contact_force_is_the_section_force_turned_to_global(exported):
    """The contact points' ``contact_force``/``contact_moment`` (vertex cells, ``part`` 3, at
    ``geometry_contacts``) are ``contact_point_forces`` turned from the section frame (s, t, b)
    to global, f = f_s e_s + f_t e_t + f_b e_b, with the frame of the boom the point lies on
    (inner: boom k, outer: boom k + 1) at its centre-line point nearest to the contact point
    (computed here point by point); a rotation keeps the magnitudes."""
    res, pvd = exported
    lines, fr = res["geometry_centre_lines"], res["geometry_section_frames"]
    cps, cpf = res["geometry_contacts"], res["contact_point_forces"]
    for i, (_, vtu) in enumerate(_frames(pvd)):
        mesh = meshio.read(vtu)
        b = _block(mesh, "vertex")
        is_cp = mesh.cell_data["part"][b] == PART_CONTACT
        at = mesh.points[mesh.cells[b].data[is_cp, 0]]
        np.testing.assert_array_equal(at, cps[i].reshape(-1, 3))
        force = mesh.cell_data["contact_force"][b][is_cp]
        moment = mesh.cell_data["contact_moment"][b][is_cp]
        want_f, want_m = [], []
        for k in range(cps.shape[1]):
            for j in range(2):
                boom = k + j
                p = min(range(lines.shape[2]),
                        key=lambda q: np.linalg.norm(lines[i, boom, q] - cps[i, k, j]))
                e_t, e_b, e_s = fr[i, boom, p]
                f, m = cpf[i, k, j, :3], cpf[i, k, j, 3:]
                want_f.append(f[0] * e_s + f[1] * e_t + f[2] * e_b)
                want_m.append(m[0] * e_s + m[1] * e_t + m[2] * e_b)
        np.testing.assert_allclose(force, want_f, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(moment, want_m, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(np.linalg.norm(force, axis=1),
                                   np.linalg.norm(cpf[i, :, :, :3], axis=-1).ravel(), rtol=1e-9)
        # zeros on every other cell
        assert not np.any(mesh.cell_data["contact_force"][_block(mesh, "line")])
        assert not np.any(mesh.cell_data["contact_force"][b][~is_cp])


def test_pad_force_is_the_pads_transverse_reaction(exported):
    """``pad_force`` on the contact points is the force each slider pad puts on the overlap's
    inner boom (``pad_forces``, contact-section frame) in global components: the sum of the
    pad's springs is the transverse reaction of its contact region, so at the outer point
    (region II, on the inner boom) it equals the transverse part (t, b) of ``contact_force``, at
    the inner point (region I, on the outer boom) minus it (action and reaction), to the
    micro-motion solve's tolerance; its size is |(f_t, f_b)| of ``pad_forces``."""
    res, pvd = exported
    pads = res["pad_forces"]
    for i, (_, vtu) in enumerate(_frames(pvd)):
        mesh = meshio.read(vtu)
        b = _block(mesh, "vertex")
        is_cp = mesh.cell_data["part"][b] == PART_CONTACT
        pad = mesh.cell_data["pad_force"][b][is_cp].reshape(-1, 2, 3)
        cf = mesh.cell_data["contact_force"][b][is_cp].reshape(-1, 2, 3)
        # the boom axis of each point's frame: the transverse part drops the e_s component
        lines, fr, cps = (res["geometry_centre_lines"][i], res["geometry_section_frames"][i],
                          res["geometry_contacts"][i])
        for k in range(cps.shape[0]):
            for j in range(2):
                p = np.argmin(np.linalg.norm(lines[k + j] - cps[k, j], axis=-1))
                e_s = fr[k + j, p, 2]
                transverse = cf[k, j] - (cf[k, j] @ e_s) * e_s
                scale = np.max(np.abs(pads[i]))
                np.testing.assert_allclose(pad[k, j], transverse if j else -transverse,
                                           atol=1e-6 * scale)
        np.testing.assert_allclose(np.linalg.norm(pad, axis=-1),
                                   np.linalg.norm(pads[i][:, ::-1], axis=-1), rtol=1e-9,
                                   atol=1e-9 * np.max(np.abs(pads[i])))
        assert not np.any(mesh.cell_data["pad_force"][b][~is_cp])


def test_luffing_cylinder_payload_and_rope(swinging, tmp_path):
    """The luffing cylinder is one ``part`` 1 line D2-D3 carrying its force, the payload a
    ``part`` 4 vertex at ``payload_position`` and the hoist rope a ``part`` 2 line from the tip
    (the last boom's last centre-line point) to it, carrying ``hoist_rope_force``; the boom
    cells carry no force."""
    res = swinging
    pvd = export_vtk(res, tmp_path / "swing")
    for i, (_, vtu) in enumerate(_frames(pvd)):
        mesh = meshio.read(vtu)
        lb, vb = _block(mesh, "line"), _block(mesh, "vertex")
        part, force, cells = mesh.cell_data["part"][lb], mesh.cell_data["force"][lb], \
            mesh.cells[lb].data
        (cyl,) = np.flatnonzero(part == PART_LUFFING_CYLINDER)
        (rope,) = np.flatnonzero(part == PART_HOIST_ROPE)
        np.testing.assert_array_equal(mesh.points[cells[cyl]], res["geometry_luffing_cylinder"][i])
        assert force[cyl] == res["luffing_cylinder_force"][i]
        np.testing.assert_array_equal(mesh.points[cells[rope]], [
            res["geometry_centre_lines"][i, -1, -1], res["payload_position"][i]])
        assert force[rope] == res["hoist_rope_force"][i] > 0
        assert not np.any(force[part == PART_BOOM])
        (payload,) = np.flatnonzero(mesh.cell_data["part"][vb] == PART_PAYLOAD)
        np.testing.assert_array_equal(mesh.points[mesh.cells[vb].data[payload, 0]],
                                      res["payload_position"][i])


def test_curvature_on_a_circle():
    """discrete_curvature on points equally spaced by the angle a on a circle of radius R: the
    turning angle a over the chord 2 R sin(a/2) at the interior points (1/R to a^2/24), 0 at the
    ends; 0 on a straight line."""
    R, a = 2.5, 0.1
    phi = a * np.arange(12)
    circle = np.stack([R * np.cos(phi), R * np.sin(phi), np.zeros_like(phi)], axis=1)
    kappa = discrete_curvature(circle)
    assert kappa[0] == kappa[-1] == 0.0
    np.testing.assert_allclose(kappa[1:-1], a / (2 * R * np.sin(a / 2)), rtol=1e-12)
    np.testing.assert_allclose(kappa[1:-1], 1 / R, rtol=a**2 / 24 * 1.01)
    straight = np.outer(np.linspace(0, 3, 7), [0.3, -0.2, 0.9])
    assert np.all(np.abs(discrete_curvature(straight)) < 1e-12)


def _frame_along(line):
    """Section frames (rows e_t, e_b, e_s) of a line in the XY plane: e_s along it, e_b = Z."""
    e_s = np.gradient(line, axis=0)
    e_s /= np.linalg.norm(e_s, axis=1, keepdims=True)
    e_b = np.broadcast_to([0.0, 0.0, 1.0], e_s.shape)
    return np.stack([np.cross(e_b, e_s), e_b, e_s], axis=1)


def test_curvature_point_data_of_a_synthetic_result(tmp_path):
    """Exported ``curvature``: 1/R (to the discretisation's a^2/24) inside a boom bent to a
    circle of radius R, ~0 along a straight boom, 0 at the ends; ``material_s`` the arc length
    along the drawn points.  A synthetic Result with only the centre lines and frames (no
    cylinder, contacts or payload: none is drawn, and the empty vertex block is left out)."""
    R, a, P = 4.0, 0.05, 11
    phi = a * np.arange(P)
    arc = np.stack([R * np.sin(phi), R * (1 - np.cos(phi)), np.zeros(P)], axis=1)
    straight = np.outer(np.linspace(0, 5, P), [1.0, 0.0, 0.0])
    lines = np.array([[arc, straight]] * 2)
    frames = np.array([[_frame_along(arc), _frame_along(straight)]] * 2)
    res = Result(np.array([0.0, 0.5]), {"geometry_centre_lines": lines,
                                         "geometry_section_frames": frames})
    pvd = export_vtk(res, tmp_path / "synthetic")
    mesh = meshio.read(_frames(pvd)[1][1])
    assert [c.type for c in mesh.cells] == ["line"]          # the empty vertex block left out
    kappa = mesh.point_data["curvature"].reshape(2, P)
    assert np.all(kappa[:, [0, -1]] == 0)
    np.testing.assert_allclose(kappa[0, 1:-1], 1 / R, rtol=a**2 / 24 * 1.01)
    assert np.all(np.abs(kappa[1]) < 1e-12)
    s = mesh.point_data["material_s"].reshape(2, P)
    np.testing.assert_allclose(s[0, -1], 2 * R * np.sin(a / 2) * (P - 1), rtol=1e-12)
    np.testing.assert_allclose(s[1], np.linspace(0, 5, P), rtol=1e-12, atol=1e-15)


def test_result_without_geometry_raises(tmp_path):
    """A result without ``geometry_centre_lines`` raises ValueError in one line naming the
    missing replay geometry, and nothing is written."""
    res = Result(np.array([0.0, 1.0]), {"tip_position": np.zeros((2, 3))})
    with pytest.raises(ValueError, match="no replay geometry") as info:
        export_vtk(res, tmp_path / "out")
    assert "\n" not in str(info.value)
    assert os.listdir(tmp_path) == []


def _first(res, n):
    """res cut to its first n output times"""
    return Result(res.t[:n], {k: res[k][:n] for k in TIME_SERIES if k in res})


def test_reexport_replaces_the_series(telescopic, tmp_path):
    """Exporting into a folder that holds an earlier export replaces it as a whole: a shorter
    run leaves no stale frames, and no temporary folder stays beside it."""
    out = tmp_path / "series"
    export_vtk(telescopic, out)
    assert len(os.listdir(out / "frames")) == 3
    pvd = export_vtk(_first(telescopic, 2), out)
    assert sorted(os.listdir(out / "frames")) == ["frame_0000.vtu", "frame_0001.vtu"]
    assert [t for t, _ in _frames(pvd)] == list(telescopic.t[:2])
    assert os.listdir(tmp_path) == ["series"]


def test_folder_with_other_files_is_not_replaced(telescopic, tmp_path):
    """A folder holding anything but an export is left alone (FileExistsError)."""
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    with pytest.raises(FileExistsError, match="not replaced"):
        export_vtk(telescopic, out)
    assert os.listdir(out) == ["notes.txt"]
    assert sorted(os.listdir(tmp_path)) == ["mine"]


def test_failed_export_leaves_the_earlier_one(telescopic, tmp_path, monkeypatch):
    """An export that fails mid-way (here the third frame's write) leaves the earlier export
    untouched and no temporary folder behind."""
    out = tmp_path / "series"
    export_vtk(_first(telescopic, 2), out)
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    calls = []
    real = meshio.write

    def flaky(path, mesh, *args, **kwargs):
        calls.append(path)
        if len(calls) == 3:
            raise OSError("disk full")
        return real(path, mesh, *args, **kwargs)

    monkeypatch.setattr(meshio, "write", flaky)
    with pytest.raises(OSError, match="disk full"):
        export_vtk(telescopic, out)
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before
    assert os.listdir(tmp_path) == ["series"]


def test_import_is_light():
    """Importing sim_core.vtk_export does not import meshio (it is imported on export)."""
    code = "import sys, sim_core.vtk_export; print('meshio' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
