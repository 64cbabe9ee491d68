#!/usr/bin/python3
"""The XDMF files beside a result file describe the HDF5 data correctly and meshio
reads them back to exactly the HDF5 datasets.

Runs $BIN (default bin/robin_contact) on inputs/table1/q1_6x2.nml twice, with Q1 and
with P1 elements on both bodies, into a temporary folder, then for each run:
  1. checks the ParaView file <stem>.xdmf (a spatial Collection of the grids body1 and
     body2) with ElementTree: every HDF DataItem names the result file and an existing
     dataset of the declared Dimensions, NumberType and Precision; topology type and
     NumberOfElements match /bodyN/cells and the element attribute;
  2. reports whether meshio reads that Collection (meshio's XDMF reader takes one Uniform
     grid per file; it rejects a Collection: an INFO line, not a check);
  3. reads the per-body files <stem>_body1.xdmf and <stem>_body2.xdmf (one Uniform grid
     each, directly under Domain: the layout meshio reads) with meshio.read and compares
     points, cells and point data (displacement, von_mises, contact_pressure) with the
     HDF5 datasets read by h5py, exactly (np.array_equal).
Prints PASS/FAIL lines; exits 1 if any check failed. Run with /usr/bin/python3.
"""
import io
import contextlib
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import numpy as np
import h5py
import meshio

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tools"))
from rc_common import Checks, run_solver, text_attr  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DECK = "inputs/table1/q1_6x2.nml"
BODY_XDMF = "{stem}_body{b}.xdmf"          # per-body files that meshio can read
FIELDS = ("displacement", "von_mises", "contact_pressure")
check = Checks()


def binary():
    b = os.environ.get("BIN", "bin/robin_contact")
    if os.path.isabs(b):
        return b
    for base in (os.getcwd(), ROOT):
        if os.path.exists(os.path.join(base, b)):
            return os.path.abspath(os.path.join(base, b))
    return os.path.join(ROOT, b)


def check_collection(xdmf, h5path, f, tag):
    """Structure of the ParaView Collection file, checked without meshio."""
    try:
        root = ET.parse(xdmf).getroot()
    except (OSError, ET.ParseError) as e:
        check(False, f"{tag}: {os.path.basename(xdmf)} parses as XML ({e})")
        return
    ok = root.tag == "Xdmf" and root.get("Version", "").startswith("3")
    doms = root.findall("Domain")
    ok = ok and len(doms) == 1
    top = doms[0].findall("Grid") if doms else []
    coll = top[0] if len(top) == 1 else None
    ok = ok and coll is not None and coll.get("GridType") == "Collection" \
        and coll.get("CollectionType") == "Spatial"
    grids = coll.findall("Grid") if coll is not None else []
    names = [g.get("Name") for g in grids]
    check(ok and names == ["body1", "body2"],
          f"{tag}: {os.path.basename(xdmf)} is XDMF 3 with one spatial Collection of grids body1, body2 "
          f"(found {names})")
    h5base = os.path.basename(h5path)
    for g in grids:
        b = g.get("Name")
        if b not in f:
            check(False, f"{tag}: grid {b} has a group /{b} in the HDF5 file")
            continue
        bad = []
        for item in g.iter("DataItem"):
            ref = (item.text or "").strip()
            fname, _, dset = ref.partition(":")
            dims = tuple(int(x) for x in item.get("Dimensions", "").split())
            if item.get("Format") != "HDF" or fname != h5base or dset not in f:
                bad.append(f"{ref}: not an HDF reference to a dataset of {h5base}")
                continue
            d = f[dset]
            kind = {"Int": "i", "UInt": "u", "Float": "f"}.get(item.get("NumberType", "Float"), "?")
            prec = int(item.get("Precision", "4"))
            if d.shape != dims:
                bad.append(f"{ref}: Dimensions {dims} but dataset shape {d.shape}")
            if d.dtype.kind != kind or d.dtype.itemsize != prec:
                bad.append(f"{ref}: NumberType/Precision {item.get('NumberType')}/{prec} but dtype {d.dtype}")
        topo = g.find("Topology")
        ncell, nvert = f[b]["cells"].shape
        elem = text_attr(f[b], "element")
        want = {"Q1": ("Quadrilateral", 4), "P1": ("Triangle", 3)}.get(elem, ("?", -1))
        if topo is None or topo.get("TopologyType") != want[0] or nvert != want[1]:
            bad.append(f"topology {None if topo is None else topo.get('TopologyType')} with {nvert} vertices "
                       f"for element {elem!r}")
        if topo is not None and topo.get("NumberOfElements") != str(ncell):
            bad.append(f"NumberOfElements {topo.get('NumberOfElements')} but {ncell} cells")
        attrs = sorted(a.get("Name") for a in g.findall("Attribute"))
        if attrs != sorted(FIELDS):
            bad.append(f"attributes {attrs}")
        check(not bad, f"{tag}: Collection grid {b}: DataItems match the HDF5 datasets"
              + ("" if not bad else " (" + "; ".join(bad) + ")"))


def meshio_read(path):
    """meshio.read, which prints and calls sys.exit(1) when no reader succeeds."""
    out = io.StringIO()
    try:
        with contextlib.redirect_stdout(out):
            return meshio.read(path), None
    except SystemExit:
        return None, out.getvalue().strip() or "meshio.read exited"
    except Exception as e:  # noqa: BLE001 (report any reader failure as a FAIL)
        return None, f"{type(e).__name__}: {e}"


def compare_body(path, g, contact_xy, tag):
    m, err = meshio_read(path)
    if not check(m is not None, f"{tag}: meshio.read({os.path.basename(path)})" + (f": {err}" if err else "")):
        return
    xyz = g["geometry_xyz"][()]
    xy = g["coordinates"][()]
    nnode = xy.shape[1]
    check(np.array_equal(m.points, xyz) and np.array_equal(m.points[:, :2], xy.T)
          and np.all(m.points[:, 2] == 0.0),
          f"{tag}: points == geometry_xyz == coordinates' (+ z = 0), {nnode} nodes")
    cells = g["cells"][()]
    elem = text_attr(g, "element")
    want = {"Q1": "quad", "P1": "triangle"}.get(elem, "?")
    blocks = [(c.type, np.asarray(c.data)) for c in m.cells]
    check(len(blocks) == 1 and blocks[0][0] == want and np.array_equal(blocks[0][1], cells),
          f"{tag}: one cell block of {want} == /cells ({cells.shape[0]} cells, element {elem})")
    check(cells.min() == 0 and cells.max() == nnode - 1 and np.unique(cells).size == nnode,
          f"{tag}: cells are 0-based and reference every node 0..{nnode - 1}")
    check(sorted(m.point_data) == sorted(FIELDS), f"{tag}: point data {sorted(m.point_data)}")
    if "displacement" in m.point_data:
        d = np.asarray(m.point_data["displacement"])
        check(np.array_equal(d, g["displacement_xyz"][()]) and np.array_equal(d[:, :2], g["displacement"][()].T)
              and np.all(d[:, 2] == 0.0),
              f"{tag}: displacement == displacement_xyz == displacement' (+ z = 0), max |u| = "
              f"{np.abs(d).max():.3e}")
    for name in ("von_mises", "contact_pressure"):
        if name in m.point_data:
            check(np.array_equal(np.asarray(m.point_data[name]).reshape(-1), g[name][()])
                  and np.asarray(m.point_data[name]).size == nnode,
                  f"{tag}: {name} == /{g.name.strip('/')}/{name} ({nnode} values)")
    # contact_pressure lives on the contact line only
    cp = g["contact_pressure"][()]
    on = np.zeros(nnode, dtype=bool)
    for x, y in contact_xy.T:
        on |= (np.abs(xy[0] - x) <= 1e-12 * (1 + abs(x))) & (np.abs(xy[1] - y) <= 1e-12 * (1 + abs(y)))
    check(np.all(cp[~on] == 0.0) and np.any(cp[on] > 0.0),
          f"{tag}: contact_pressure is zero off the contact line and positive on part of it "
          f"({int(np.count_nonzero(cp))} nonzero nodes)")


def run_case(tmp, tag, overrides):
    h5 = os.path.join(tmp, f"{tag}.h5")
    cmd = [binary(), DECK] + overrides + [f"&output file='{h5}' /"]
    try:
        p, _ = run_solver(*cmd, env=dict(os.environ), cwd=ROOT, timeout=600)
    except (OSError, subprocess.TimeoutExpired) as e:
        check(False, f"{tag}: run {' '.join(cmd)}: {e}")
        return
    # the layout is under test, not convergence: exit 2 (not converged) also writes the result
    if not check(p.returncode in (0, 2) and os.path.isfile(h5),
                 f"{tag}: robin_contact {' '.join([DECK] + overrides)} wrote its result (exit {p.returncode})"):
        sys.stdout.write(p.stdout[-1500:] + p.stderr[-1500:])
        return
    stem = h5[:-3]
    xdmf = stem + ".xdmf"
    if not check(os.path.isfile(xdmf), f"{tag}: {os.path.basename(xdmf)} written beside the .h5"):
        return
    with h5py.File(h5, "r") as f:
        check_collection(xdmf, h5, f, tag)
        try:
            meshio.xdmf.read(xdmf)
            print(f"INFO  {tag}: meshio reads the spatial Collection {os.path.basename(xdmf)} itself")
        except Exception as e:  # noqa: BLE001
            print(f"INFO  {tag}: meshio cannot read the spatial Collection {os.path.basename(xdmf)} "
                  f"({type(e).__name__}: {e}); checking the per-body files")
        cxy = f["/contact/coordinates"][()]
        for b in (1, 2):
            path = BODY_XDMF.format(stem=stem, b=b)
            if not check(os.path.isfile(path),
                         f"{tag}: per-body file {os.path.basename(path)} exists (one Uniform grid under Domain, "
                         f"the layout meshio.read can read)"):
                continue
            compare_body(path, f[f"body{b}"], cxy, f"{tag} body{b}")


def main():
    print(f"meshio {meshio.__version__}, h5py {h5py.__version__}, binary {binary()}")
    with tempfile.TemporaryDirectory(prefix="test_xdmf_") as tmp:
        run_case(tmp, "q1_6x2_Q1", [])
        run_case(tmp, "q1_6x2_P1", ['&body id=1, element="P1" /', '&body id=2, element="P1" /'])
    print(f"test_xdmf: {len(check.failed)} failed check(s)")
    return 1 if check.failed else 0


if __name__ == "__main__":
    sys.exit(main())
