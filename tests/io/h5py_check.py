"""Reads seixo's files with h5py alone (no seixo code), as a user's script
would, following docs/file-format.md; exits non-zero on any mismatch.
    python3 h5py_check.py DIR    (DIR holds snapshot.h5, series.h5, series.xmf)"""
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np

d = sys.argv[1]

with h5py.File(d + "/snapshot.h5", "r") as f:
    a = f.attrs
    assert a["format"] == b"seixo", a["format"]
    assert a["format_version"] == 4 and a["kind"] == b"snapshot" and a["dim"] == 3
    assert list(a["seeds"]) == [11], list(a["seeds"])
    x = f["balls/position"][:]
    assert x.shape == (60, 3) and np.all(np.isfinite(x))
    # a ball-ball contact's geometry (format 3): the relative position of its
    # last evaluation, one step's motion from the balls' current one
    bb = f["contacts/ball_ball"]
    assert bb["relative_position"].shape == (bb.attrs["count"], 3)
    assert bb["relative_position"].attrs["units"] == b"m" and "normal" not in bb and "overlap" not in bb
    on = bb["touching"][:] == 1
    rel, pa, pb = bb["relative_position"][:][on], bb["a"][:][on], bb["b"][:][on]
    rad = f["balls/radius"][:]
    assert np.all(np.abs(rel - (x[pb] - x[pa])) < 1e-6), np.abs(rel - (x[pb] - x[pa])).max()
    overlap = rad[pa] + rad[pb] - np.linalg.norm(rel, axis=1)
    assert np.all(overlap > -1e-6), overlap.min()
    w = f["walls"]
    kinds = h5py.check_enum_dtype(w["kind"].dtype)
    assert kinds["cylinder"] == 4 and w["kind"][0] == 4, kinds
    assert w["radius"][0] > 0 and w["height"][0] == 0.05
    assert w["servo"][0] == 1 and w["servo_target"][0] == 1e3 and w["servo"][1] == 0
    assert w["servo_target"].attrs["units"] == b"Pa"
    h = f["histories"]
    order = sorted(h, key=lambda k: h[k].attrs["order"])
    assert order == ["ke", "radius, of the cylinder", "fz"], order
    ke = h["ke"]
    assert ke.attrs["source"] == b"builtin" and ke.attrs["builtin"] == b"kinetic"
    assert ke["step"].maxshape == (None,) and ke["step"].chunks is not None
    n = ke.attrs["count"]
    assert n == 30 and list(ke["step"][:n]) == list(range(10, 301, 10))
    assert h["radius, of the cylinder"].attrs["source"] == b"function"
    fz = h["fz"]
    assert fz.attrs["field"] == b"force" and fz.attrs["component"] == 2 and fz.attrs["id"] == 2
    radius = h["radius, of the cylinder"]["value"][:]
    assert abs(radius[-1] - w["radius"][0]) < 0.05 * w["radius"][0]

with h5py.File(d + "/series.h5", "r") as f:
    assert f.attrs["kind"] == b"series" and f.attrs["format_version"] == 4
    count = f.attrs["count"]
    assert count == 7, count
    last = f["snapshots/%06d" % (count - 1)]
    cells, points = last.attrs["wall_cells"], last.attrs["wall_points"]
    assert cells == 32 + 1 and points == 64 + 4, (cells, points)
    assert last["walls/connectivity"].shape == (cells, 4)
    assert last["walls/points"].shape == (points, 3)
    ke = f["histories/ke"]
    n = ke.attrs["count"]
    assert n == 30 and ke["step"].maxshape == (None,), n
    assert np.all(np.diff(ke["step"][:n]) > 0)

xmf = ET.parse(d + "/series.xmf")
balls = [g for g in xmf.getroot().iter("Grid") if g.get("Name") == "balls"]
assert len(balls) == 1 and balls[0].get("CollectionType") == "Temporal", balls
times = [t.get("Value") for t in balls[0].iter("Time")]
assert len(times) == 7, times
print("h5py %s read the snapshot and the series (%d snapshots)" % (h5py.__version__, len(times)))
