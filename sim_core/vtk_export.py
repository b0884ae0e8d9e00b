"""ParaView (VTK) time series of a telescopic run's replay geometry.

:func:`export_vtk` writes, for a result that carries replay geometry (the telescopic full
model's ``geometry_*`` outputs)::

    out_dir/result.pvd                 the collection index: one <DataSet timestep= file=/> a time
    out_dir/frames/frame_0000.vtu      one unstructured grid per output time, in output order
    out_dir/frames/frame_0001.vtu ...

Open ``result.pvd`` in ParaView to step through the run.  Every quantity is in SI units (m, N,
N m, 1/m) and every point and vector in the global frame of the result (X forward, Y lateral,
Z up at zero slew).  A frame's points, in this order: the booms' centre-line points (boom by boom,
``P`` equally spaced material points from s = 0 to the boom's length), the luffing cylinder's
base D2 and head D3, the contact points (overlap by overlap: inner, outer) and the payload.
Its cells come in two blocks:

* ``vertex``: the contact points (``part`` 3), then the payload (``part`` 4);
* ``line``: the boom segments between consecutive centre-line points (``part`` 0), the luffing
  cylinder D2-D3 (``part`` 1) and the hoist rope from the tip (the last boom's last centre-line
  point) to the payload (``part`` 2).

A part the result does not have is not drawn: no cylinder without ``geometry_luffing_cylinder``,
no contact points without ``geometry_contacts``, no rope without ``payload_position`` (the
payload is then drawn at ``tip_position``, where the result has it), and a block with no cells
is left out (meshio cannot write an empty one).

Point data (they describe the boom lines; the other points carry ``boom`` = -1 and zeros):
``boom`` (index, 0 outermost), ``material_s`` (m, arc length along the boom's discrete centre
line from its start, summed from the point spacing), ``curvature`` (1/m, the turning angle
between consecutive segments over their mean length, 0 at the ends: :func:`discrete_curvature`)
and ``e_t``, ``e_b``, ``e_s`` (the section frame: bending axes and boom axis, global unit vectors,
for glyphs).  With section forces in the result (``section_forces``): ``section_force``
((N, Q_t, Q_b), N) and ``section_moment`` ((T, M_t, M_b), N m), section-frame components,
``section_von_mises`` (Pa, the largest von Mises stress over the section's outline points, NaN
for a section without geometry) and ``section_utilisation`` (that over ``material.f_y``), each
interpolated linearly in the material coordinate from the stations of ``section_stations``.

Cell data (every name on every block, zeros where it does not apply): ``part`` (0 boom,
1 luffing cylinder, 2 hoist rope, 3 contact point, 4 payload), ``force`` (N: the luffing
cylinder's force on its cell, the hoist rope's force on its cell), ``contact_force`` (N) and
``contact_moment`` (N m) on the contact points, and with a slider-spring distribution in the
result ``slider_force`` (N, the sum of the region's slider spring normal forces) and, with
``pad_forces``, ``pad_force`` (N, global components: the force of the pad at that contact point
on the overlap's inner boom; the inner pad at the inner point, the outer pad at the outer one).  The contact
loads are ``contact_point_forces``, given in the section frame (s, t, b) of the boom the point
lies on (the inner point on the outer boom k, the outer point on boom k + 1), turned to global
components with that boom's frame at its centre-line point nearest to the contact point:
f = f_s e_s + f_t e_t + f_b e_b (the replay frames are sampled at ``P`` points only, so this is
the frame within half a point spacing of the contact point).

The .vtu files are written by meshio (binary, zlib-compressed, points and data in float64, so a
value reads back bit for bit) rather than by a VTK writer of our own: meshio is a maintained,
tested writer of the format, and a reader for the tests.  meshio is imported on the first export
only: importing this module loads nothing beyond numpy and sim_core.result.  The .pvd index is a
few lines of XML written with the standard library.

The export is atomic: everything is written into a temporary folder next to ``out_dir`` and
renamed into place, replacing an earlier export there; a killed export leaves ``out_dir`` as it
was (or, killed between the two renames of a replacement, absent, the old and new series in the
hidden ``.NAME.*`` folders beside it), never a half-written series.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from sim_core.result import _fsync_dir, _umask

#: cell data ``part``: what a cell draws
PART_BOOM, PART_LUFFING_CYLINDER, PART_HOIST_ROPE, PART_CONTACT, PART_PAYLOAD = 0, 1, 2, 3, 4

PVD_NAME = "result.pvd"
FRAMES_DIR = "frames"


def discrete_curvature(points) -> np.ndarray:
    """Curvature (1/m) of a discrete line ``points`` (..., P, 3) at its points (..., P).

    At an interior point the turning angle between the incoming and the outgoing segment over
    the mean of their lengths; 0 at both ends (and where both segments have zero length).  On
    points equally spaced by the angle a on a circle of radius R this is
    a / (2 R sin(a / 2)) = (1 + a^2 / 24 + ...) / R."""
    x = np.asarray(points, dtype=float)
    kappa = np.zeros(x.shape[:-1])
    if x.shape[-2] < 3:
        return kappa
    a = x[..., 1:-1, :] - x[..., :-2, :]
    b = x[..., 2:, :] - x[..., 1:-1, :]
    angle = np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.einsum("...i,...i", a, b))
    mean = 0.5 * (np.linalg.norm(a, axis=-1) + np.linalg.norm(b, axis=-1))
    kappa[..., 1:-1] = np.divide(angle, mean, out=np.zeros_like(angle), where=mean > 0)
    return kappa


def contact_loads_global(lines, frames, contacts, cpf) -> tuple[np.ndarray, np.ndarray]:
    """The contact forces and moments in global components.

    ``lines`` (n, N, P, 3), ``frames`` (n, N, P, 3, 3) (rows e_t, e_b, e_s), ``contacts``
    (n, N-1, 2, 3), ``cpf`` (n, N-1, 2, 6) (force (s, t, b), moment (s, t, b) in the section
    frame).  Contact (k, j) lies on boom k + j; its frame is that boom's at the centre-line point
    nearest to it.  Returns (force, moment), each (n, N-1, 2, 3)."""
    n, n_pairs = contacts.shape[:2]
    boom = np.arange(n_pairs)[:, None] + np.arange(2)[None, :]            # (N-1, 2)
    on = lines[:, boom]                                                    # (n, N-1, 2, P, 3)
    near = np.argmin(np.linalg.norm(on - contacts[..., None, :], axis=-1), axis=-1)
    i = np.arange(n)[:, None, None]
    R = frames[i, boom[None], near]                                        # (n, N-1, 2, 3, 3)
    tbs = [1, 2, 0]                                                        # (s, t, b) -> (t, b, s)
    force = np.einsum("...ji,...j->...i", R, cpf[..., :3][..., tbs])
    moment = np.einsum("...ji,...j->...i", R, cpf[..., 3:6][..., tbs])
    return force, moment


def export_vtk(result, out_dir: str | Path) -> Path:
    """Write ``result``'s replay geometry as a ParaView time series in ``out_dir`` (layout, data
    and units in the module docstring) and return the path of its ``result.pvd``.

    ``out_dir`` may be missing (it is created, parents included), empty or hold an earlier
    export (``result.pvd`` and ``frames/`` only), which is replaced as a whole (no stale
    frames).  Raises ValueError for a result without replay geometry and FileExistsError,
    touching nothing, where ``out_dir`` holds anything else."""
    frames = _frame_arrays(result)
    out_dir = Path(os.path.abspath(out_dir))
    _check_replaceable(out_dir)
    import meshio  # here: importing this module stays light

    parent = out_dir.parent
    parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=parent, prefix=f".{out_dir.name}.", suffix=".tmp"))
    try:
        os.chmod(tmp, 0o777 & ~_umask())                  # mkdtemp makes it 0700
        (tmp / FRAMES_DIR).mkdir()
        width = max(4, len(str(len(frames["t"]) - 1)))
        names = []
        for i in range(len(frames["t"])):
            name = f"{FRAMES_DIR}/frame_{i:0{width}d}.vtu"
            meshio.write(tmp / name, _frame_mesh(meshio, frames, i), file_format="vtu")
            names.append(name)
        _write_pvd(tmp / PVD_NAME, frames["t"], names)
        for path in [*(tmp / n for n in names), tmp / PVD_NAME]:
            _fsync_file(path)
        _fsync_dir(tmp / FRAMES_DIR)
        _fsync_dir(tmp)
        _swap_into_place(tmp, out_dir)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    _fsync_dir(parent)
    return out_dir / PVD_NAME


# -- the arrays ------------------------------------------------------------------------------

def _frame_arrays(result) -> dict:
    """Everything the frames need, as float arrays over all output times (checked shapes)."""
    keys = set(result.keys())
    if "geometry_centre_lines" not in keys:
        raise ValueError("result has no replay geometry (no 'geometry_centre_lines' output; the "
                         "telescopic full model writes it): nothing to export to VTK")
    t = np.asarray(result.t, dtype=float)
    lines = np.asarray(result["geometry_centre_lines"], dtype=float)
    n = len(t)
    if n == 0 or lines.ndim != 4 or lines.shape[0] != n or lines.shape[-1] != 3 \
            or lines.shape[2] < 2:
        raise ValueError(f"geometry_centre_lines has shape {lines.shape}, expected (n, N, P, 3) "
                         f"with n = {n} output times > 0 and P >= 2 points a boom")
    _, N, P, _ = lines.shape

    def get(key, shape, default=None):
        if key not in keys:
            if default is None:
                raise ValueError(f"incomplete replay geometry: no {key!r} output")
            return default
        a = np.asarray(result[key], dtype=float)
        if a.shape != shape:
            raise ValueError(f"{key} has shape {a.shape}, expected {shape}")
        return a

    out = {"t": t, "lines": lines,
           "frames": get("geometry_section_frames", (n, N, P, 3, 3)),
           "cylinder": get("geometry_luffing_cylinder", (n, 2, 3), np.empty((n, 0, 3))),
           "contacts": get("geometry_contacts", (n, N - 1, 2, 3), np.empty((n, 0, 2, 3))),
           "cylinder_force": get("luffing_cylinder_force", (n,), np.zeros(n))}
    n_pairs = out["contacts"].shape[1]
    cpf = get("contact_point_forces", (n, N - 1, 2, 6), np.zeros((n, n_pairs, 2, 6)))
    if n_pairs:
        out["contact_force"], out["contact_moment"] = contact_loads_global(
            lines, out["frames"], out["contacts"], cpf)
    else:
        out["contact_force"] = out["contact_moment"] = np.zeros((n, 0, 2, 3))
    if "pad_forces" in keys and n_pairs:
        # the pads (outer pad: region II on boom k + 1; inner pad: region I on boom k) as
        # contact loads (force (s, t, b), no moment) of the contact points (k, 1) and (k, 0)
        pf = get("pad_forces", (n, n_pairs, 2, 2))
        pads = np.zeros((n, n_pairs, 2, 6))
        pads[:, :, 0, 1:3], pads[:, :, 1, 1:3] = pf[:, :, 1], pf[:, :, 0]
        out["pad_force"] = contact_loads_global(lines, out["frames"], out["contacts"], pads)[0]
    if "slider_contact_forces" in keys and n_pairs:
        scf = np.asarray(result["slider_contact_forces"], dtype=float)
        if scf.ndim != 3 or scf.shape[:2] != (n, 2 * n_pairs):
            raise ValueError(f"slider_contact_forces has shape {scf.shape}, expected "
                             f"({n}, {2 * n_pairs}, springs)")
        out["slider_force"] = np.nansum(scf, axis=2).reshape(n, n_pairs, 2)
    if "payload_position" in keys:
        out["payload"] = get("payload_position", (n, 3))
        out["rope_force"] = get("hoist_rope_force", (n,), np.zeros(n))
    elif "tip_position" in keys:
        out["payload"] = get("tip_position", (n, 3))
    out["s"] = np.concatenate([np.zeros((n, N, 1)), np.cumsum(
        np.linalg.norm(np.diff(lines, axis=2), axis=-1), axis=2)], axis=2)
    out["curvature"] = discrete_curvature(lines)
    if "section_forces" in keys:
        out.update(_section_point_data(result, n, N, P))
    return out


def _section_point_data(result, n: int, N: int, P: int) -> dict:
    """The section forces, the largest von Mises stress and the utilisation at the centre-line
    points: linear in the material coordinate between the stations (``section_stations``);
    the centre-line points are equally spaced from s = 0 to the boom's length, as the
    stations."""
    st = np.asarray(result["section_stations"], dtype=float)
    forces = np.asarray(result["section_forces"], dtype=float)
    if st.ndim != 2 or st.shape[0] != N or forces.shape != (n, N, st.shape[1], 6):
        raise ValueError(f"section_forces has shape {forces.shape} and section_stations "
                         f"{st.shape}, expected (n, N, S, 6) and (N, S) with n = {n}, N = {N}")
    stress = np.asarray(result["section_stress"], dtype=float)
    vm = np.sqrt(stress[..., 0] ** 2 + 3.0 * stress[..., 1] ** 2)
    vm = np.where(np.isnan(vm).all(axis=-1), np.nan, np.nanmax(
        np.where(np.isnan(vm), -np.inf, vm), axis=-1))
    util = np.asarray(result["section_utilisation"], dtype=float)
    out = {"section_forces": np.empty((n, N, P, 6)), "section_von_mises": np.empty((n, N, P)),
           "section_utilisation": np.empty((n, N, P))}
    for k in range(N):
        s_pts = np.linspace(0.0, st[k, -1], P)
        W = np.stack([np.interp(s_pts, st[k], e) for e in np.eye(st.shape[1])], axis=1)
        out["section_forces"][:, k] = np.einsum("ps,nsc->npc", W, forces[:, k])
        out["section_von_mises"][:, k] = vm[:, k] @ W.T
        out["section_utilisation"][:, k] = util[:, k] @ W.T
    return out


def _frame_mesh(meshio, f: dict, i: int):
    """The meshio.Mesh of output time i (point and cell order as in the module docstring)."""
    lines, frames = f["lines"][i], f["frames"][i]
    N, P, _ = lines.shape
    n_cyl = f["cylinder"].shape[1]
    contacts = f["contacts"][i].reshape(-1, 3)
    payload = f["payload"][i][None] if "payload" in f else np.empty((0, 3))
    points = np.concatenate([lines.reshape(-1, 3), f["cylinder"][i], contacts, payload])
    n_pts, n_boom = len(points), N * P

    def pdata(values, fill_shape=()):
        a = np.zeros((n_pts, *fill_shape), dtype=values.dtype)
        a[:n_boom] = values.reshape(n_boom, *fill_shape)
        return a

    boom = pdata(np.repeat(np.arange(N, dtype=np.int32), P))
    boom[n_boom:] = -1
    point_data = {"boom": boom, "material_s": pdata(f["s"][i]),
                  "curvature": pdata(f["curvature"][i]),
                  "e_t": pdata(frames[..., 0, :], (3,)), "e_b": pdata(frames[..., 1, :], (3,)),
                  "e_s": pdata(frames[..., 2, :], (3,))}
    if "section_forces" in f:
        sf = f["section_forces"][i]
        point_data.update({"section_force": pdata(sf[..., :3], (3,)),
                           "section_moment": pdata(sf[..., 3:], (3,)),
                           "section_von_mises": pdata(f["section_von_mises"][i]),
                           "section_utilisation": pdata(f["section_utilisation"][i])})

    # vertex block: contact points, then the payload
    first_contact = n_boom + n_cyl
    n_contacts = len(contacts)
    vertices = np.arange(first_contact, first_contact + n_contacts + len(payload))[:, None]
    v_part = np.array([PART_CONTACT] * n_contacts + [PART_PAYLOAD] * len(payload), np.int32)
    # line block: boom segments, the cylinder, the rope
    idx = np.arange(n_boom).reshape(N, P)
    segs = [np.stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()], axis=1)]
    l_part = [np.full(N * (P - 1), PART_BOOM, np.int32)]
    l_force = [np.zeros(N * (P - 1))]
    if n_cyl:
        segs.append(np.array([[n_boom, n_boom + 1]]))
        l_part.append(np.array([PART_LUFFING_CYLINDER], np.int32))
        l_force.append(np.array([f["cylinder_force"][i]]))
    if "rope_force" in f:
        segs.append(np.array([[idx[-1, -1], n_pts - 1]]))
        l_part.append(np.array([PART_HOIST_ROPE], np.int32))
        l_force.append(np.array([f["rope_force"][i]]))
    segments, l_part, l_force = np.concatenate(segs), np.concatenate(l_part), \
        np.concatenate(l_force)
    n_v, n_l = len(vertices), len(segments)

    def vector_block(values):              # (n_contacts, 3) on the contacts, zeros elsewhere
        a = np.zeros((n_v, 3))
        a[:n_contacts] = values.reshape(-1, 3)
        return [a, np.zeros((n_l, 3))]

    cell_data = {"part": [v_part, l_part], "force": [np.zeros(n_v), l_force],
                 "contact_force": vector_block(f["contact_force"][i]),
                 "contact_moment": vector_block(f["contact_moment"][i])}
    if "pad_force" in f:
        cell_data["pad_force"] = vector_block(f["pad_force"][i])
    if "slider_force" in f:
        sf = np.zeros(n_v)
        sf[:n_contacts] = f["slider_force"][i].ravel()
        cell_data["slider_force"] = [sf, np.zeros(n_l)]
    cells = [("vertex", vertices.astype(np.int64)), ("line", segments.astype(np.int64))]
    keep = [b for b, (_, c) in enumerate(cells) if len(c)]      # meshio fails on an empty block
    return meshio.Mesh(points, [cells[b] for b in keep], point_data=point_data,
                       cell_data={k: [v[b] for b in keep] for k, v in cell_data.items()})


# -- the files -------------------------------------------------------------------------------

def _write_pvd(path: Path, t: np.ndarray, names: list[str]) -> None:
    root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    coll = ET.SubElement(root, "Collection")
    for tk, name in zip(t, names):
        ET.SubElement(coll, "DataSet", timestep=repr(float(tk)), group="", part="0", file=name)
    ET.indent(root)
    ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)


def _fsync_file(path: Path) -> None:
    with open(path, "rb") as fh:
        os.fsync(fh.fileno())


def _is_export(folder: Path) -> bool:
    """folder holds nothing but an export's result.pvd and frames/frame_*.vtu."""
    for entry in folder.iterdir():
        if entry.name == PVD_NAME and entry.is_file() and not entry.is_symlink():
            continue
        if entry.name == FRAMES_DIR and entry.is_dir() and not entry.is_symlink() and all(
                e.is_file() and e.name.startswith("frame_") and e.suffix == ".vtu"
                for e in entry.iterdir()):
            continue
        return False
    return True


def _check_replaceable(out_dir: Path) -> None:
    if not os.path.lexists(out_dir):
        return
    if out_dir.is_symlink() or not out_dir.is_dir():
        raise FileExistsError(f"{out_dir} exists and is not a folder: not replaced by the VTK "
                              "export")
    if not _is_export(out_dir):
        raise FileExistsError(f"{out_dir} holds other files than an earlier VTK export "
                              f"({PVD_NAME}, {FRAMES_DIR}/): not replaced (choose another folder)")


def _swap_into_place(tmp: Path, out_dir: Path) -> None:
    """Rename the finished folder tmp to out_dir, replacing an earlier export there (moved
    aside first: a folder cannot be renamed over a non-empty one, then removed)."""
    if not os.path.lexists(out_dir):
        os.replace(tmp, out_dir)
        return
    _check_replaceable(out_dir)                   # again: it may have changed meanwhile
    old = Path(tempfile.mkdtemp(dir=out_dir.parent, prefix=f".{out_dir.name}.", suffix=".old"))
    try:
        os.replace(out_dir, old)                  # onto the empty placeholder folder
    except BaseException:
        os.rmdir(old)
        raise
    try:
        os.replace(tmp, out_dir)
    except BaseException:
        os.replace(old, out_dir)
        raise
    shutil.rmtree(old, ignore_errors=True)
