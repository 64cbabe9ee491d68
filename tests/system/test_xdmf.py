#!/usr/bin/python3
"""The XDMF files beside a result file describe the HDF5 data correctly and meshio
reads them back to exactly the HDF5 datasets; the result file carries its units and
its string attributes read as str.

Runs $BIN (default bin/robin_contact) on inputs/table1/q1_6x2.nml with Q1 and with P1
elements on both bodies, in mm-N-MPa units, and with an output name holding the XML
special characters & < > " ', into a temporary folder, then for each run:
  1. checks the ParaView file <stem>.xdmf (a spatial Collection of the grids body1, body2
     and contact) with ElementTree: every HDF DataItem names the result file and an
     existing dataset of the declared Dimensions, NumberType and Precision; topology type
     and NumberOfElements match /bodyN/cells and the element attribute (the contact
     line: a Polyline over /contact/segments);
  2. reports whether meshio reads that Collection (meshio's XDMF reader takes one Uniform
     grid per file; it rejects a Collection: an INFO line, not a check);
  3. reads the per-body files <stem>_body1.xdmf and <stem>_body2.xdmf (one Uniform grid
     each, directly under Domain: the layout meshio reads) with meshio.read and compares
     points, cells and point data (displacement, von_mises, contact_pressure, the stress
     components sxx syy sxy szz against the rows of /bodyN/stress) and the cell data
     body_id with the HDF5 datasets read by h5py, exactly (np.array_equal);
  4. reads the contact line <stem>_contact.xdmf with meshio: its points are the contact
     nodes, its cells the m - 1 segments between neighbours, its point data the
     /contact datasets pressure, normal_force, gap, normal_displacement_body1/2;
  5. units: root attributes unit_length, unit_force, unit_stress as the deck says, and a
     `units` attribute of the right unit on every numeric dataset;
  6. string attributes (status, method, title, version, element, units) are str in h5py:
     f.attrs['status'] == 'converged';
  7. every XDMF file names the run that wrote the HDF5 file (the comment run_id equals
     the root attribute run_id).
  8. solid bodies, where a contact grid is a surface: three boxes stacked (hexahedra on
     tetrahedra on hexahedra, two pairs, two load steps) and Hertz's sphere on a block (the
     quarter model inputs/sphere_block.nml on the coarse mesh):
     - each pair's /contact/pair_<k>/faces are the faces of its slave's contact side: the
       deck's nx x nz quadrilaterals (hexahedra) or 2 nx nz triangles (tetrahedra), tiling
       the contact square (their areas sum to its area), each counter-clockwise seen from
       outside the slave (its normal along the file's contact normals); /contact/faces
       stacks them, a triangle's fourth vertex -1 beside quadrilaterals, and
       /contact/topology is their XDMF Mixed list (computed here); no `segments`;
     - the XDMF grids: a Quadrilateral, a Triangle and a Mixed surface with the right
       counts, every DataItem an existing dataset of its Dimensions; meshio reads each
       one-grid file back (TimeSeriesReader: both steps' pressures those of /steps);
     - Hertz: the faces are exactly the file's 'sphere_arc' triangles (read from the .msh
       by meshio) all of whose nodes are contact nodes, and every active contact node is
       on one of them; meshio reads the Triangle surface with its point data.
Prints PASS/FAIL lines; exits 1 if any check failed. Run with /usr/bin/python3.
"""
import io
import contextlib
import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import numpy as np
import h5py
import meshio

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from rc_checks import Checks  # noqa: E402
from rc_results import text_attr  # noqa: E402
from rc_run import run_solver  # noqa: E402
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from solid_decks import THREE_BOXES  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DECK = "inputs/table1/q1_6x2.nml"
BODY_XDMF = "{stem}_body{b}.xdmf"          # per-body files that meshio can read
FIELDS = ("displacement", "von_mises", "contact_pressure", "reaction")
COMPONENTS = ("sxx", "syy", "sxy", "szz")                  # rows of /bodyN/stress
BODY_FIELDS = FIELDS + COMPONENTS + ("body_id",)           # body_id: per cell
CONTACT_XDMF = "{stem}_contact.xdmf"                       # the contact line, for meshio
CONTACT_FIELDS = ("pressure", "normal_force", "gap", "normal_displacement_body1", "normal_displacement_body2")
# the unit of every numeric dataset: L length, S stress, F/L force per unit length, 1, s
UNITS = {"contact/x": "L", "contact/y": "L", "contact/s": "L", "contact/normal": "1", "contact/coordinates": "L", "contact/g0": "L", "contact/tributary_length": "L",
         "contact/normal_force": "F/L", "contact/normal_force_body1": "F/L", "contact/normal_force_body2": "F/L",
         "contact/resultant_body1": "F/L",
         "contact/pressure": "S", "contact/gap": "L", "contact/active": "1",
         "contact/normal_displacement_body1": "L", "contact/normal_displacement_body2": "L",
         "contact/obstacle_body1": "L", "contact/obstacle_body2": "L", "contact/geometry_xyz": "L",
         "contact/segments": "1", "history/criterion": "1", "history/residual": "1", "history/inner": "1",
         "history/active": "1", "history/wall_s": "s"}
UNITS.update({f"contact/pair_1/{k}": u for k, u in [
    ("x", "L"), ("y", "L"), ("s", "L"), ("normal", "1"), ("g0", "L"), ("tributary_length", "L"),
    ("normal_force", "F/L"), ("normal_force_side1", "F/L"), ("normal_force_side2", "F/L"),
    ("resultant_on_first_body", "F/L"), ("pressure", "S"), ("gap", "L"), ("active", "1"),
    ("normal_displacement_side1", "L"), ("normal_displacement_side2", "L"), ("geometry_xyz", "L"),
    ("segments", "1")]})
for _b in ("body1", "body2"):
    UNITS.update({f"{_b}/{k}": u for k, u in [
        ("coordinates", "L"), ("displacement", "L"), ("geometry_xyz", "L"), ("displacement_xyz", "L"),
        ("cells", "1"), ("body_id", "1"), ("stress", "S"), ("sxx", "S"), ("syy", "S"), ("sxy", "S"),
        ("szz", "S"), ("von_mises", "S"), ("contact_pressure", "S"), ("reaction", "F/L"), ("reaction_xyz", "F/L")]})
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
    check(ok and names == ["body1", "body2", "contact"],
          f"{tag}: {os.path.basename(xdmf)} is XDMF 3 with one spatial Collection of grids body1, body2, contact "
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
        if b == "contact":
            bad += check_contact_topology(g, f)
            attrs = sorted(a.get("Name") for a in g.findall("Attribute"))
            if attrs != sorted(CONTACT_FIELDS):
                bad.append(f"attributes {attrs}")
            check(not bad, f"{tag}: Collection grid contact: DataItems match the HDF5 datasets"
                  + ("" if not bad else " (" + "; ".join(bad) + ")"))
            continue
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
        if attrs != sorted(BODY_FIELDS):
            bad.append(f"attributes {attrs}")
        centers = {a.get("Name"): a.get("Center") for a in g.findall("Attribute")}
        if centers.get("body_id") != "Cell" or any(centers.get(n) != "Node" for n in FIELDS + COMPONENTS):
            bad.append(f"centers {centers}")
        check(not bad, f"{tag}: Collection grid {b}: DataItems match the HDF5 datasets"
              + ("" if not bad else " (" + "; ".join(bad) + ")"))


def check_contact_topology(g, f):
    """The contact grid: a Polyline (2 nodes per element) over /contact/segments."""
    bad = []
    topo = g.find("Topology")
    m = f["contact/x"].shape[0]
    if topo is None or topo.get("TopologyType") != "Polyline" or topo.get("NodesPerElement") != "2" \
            or topo.get("NumberOfElements") != str(m - 1):
        bad.append(f"contact topology {None if topo is None else topo.attrib} for m = {m}")
    return bad


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
    check(sorted(m.point_data) == sorted(FIELDS + COMPONENTS), f"{tag}: point data {sorted(m.point_data)}")
    stress = g["stress"][()]
    for k, name in enumerate(COMPONENTS):
        v = np.asarray(m.point_data.get(name, np.zeros(0))).reshape(-1)
        check(np.array_equal(v, stress[k]) and np.array_equal(v, g[name][()]),
              f"{tag}: {name} == /{g.name.strip('/')}/stress[{k}] == /{g.name.strip('/')}/{name}")
    bid = m.cell_data.get("body_id")
    want_id = int(g.name.strip("/").replace("body", ""))
    check(bid is not None and len(bid) == 1 and np.asarray(bid[0]).shape == (cells.shape[0],)
          and np.all(np.asarray(bid[0]) == want_id),
          f"{tag}: cell data body_id == {want_id} on every cell")
    if "displacement" in m.point_data:
        d = np.asarray(m.point_data["displacement"])
        check(np.array_equal(d, g["displacement_xyz"][()]) and np.array_equal(d[:, :2], g["displacement"][()].T)
              and np.all(d[:, 2] == 0.0),
              f"{tag}: displacement == displacement_xyz == displacement' (+ z = 0), max |u| = "
              f"{np.abs(d).max():.3e}")
    if "reaction" in m.point_data:
        rxn = np.asarray(m.point_data["reaction"])
        check(np.array_equal(rxn, g["reaction_xyz"][()]) and np.array_equal(rxn[:, :2], g["reaction"][()].T)
              and np.all(rxn[:, 2] == 0.0),
              f"{tag}: reaction == reaction_xyz == reaction' (+ z = 0), max |r| = {np.abs(rxn).max():.3e}")
    for name in ("von_mises", "contact_pressure"):
        if name in m.point_data:
            check(np.array_equal(np.asarray(m.point_data[name]).reshape(-1), g[name][()])
                  and np.asarray(m.point_data[name]).size == nnode,
                  f"{tag}: {name} == /{g.name.strip('/')}/{name} ({nnode} values)")
    # contact_pressure lives on the contact line only: the polyline of the rows' nodes,
    # extended at each end by its end segment (a master node next to the last row, or a
    # node without a row whose neighbour's dual function reaches it)
    cp = g["contact_pressure"][()]
    on = np.zeros(nnode, dtype=bool)
    pts = contact_xy.T
    if len(pts) >= 2:
        pts = np.vstack([2 * pts[0] - pts[1], pts, 2 * pts[-1] - pts[-2]])
    scale = 1.0 + np.abs(pts).max()
    for k in range(max(len(pts) - 1, 1)):
        a_, b_ = pts[k], pts[min(k + 1, len(pts) - 1)]
        d = b_ - a_
        t = np.clip(((xy.T - a_) @ d) / max(d @ d, 1e-300), 0.0, 1.0)
        on |= np.hypot(*(xy.T - (a_ + t[:, None] * d)).T) <= 1e-12 * scale
    check(np.all(cp[~on] == 0.0) and np.any(cp[on] > 0.0),
          f"{tag}: contact_pressure is zero off the contact line and positive on part of it "
          f"({int(np.count_nonzero(cp))} nonzero nodes)")


def compare_contact(path, f, tag):
    """The contact line read by meshio against /contact."""
    m, err = meshio_read(path)
    if not check(m is not None, f"{tag}: meshio.read({os.path.basename(path)})" + (f": {err}" if err else "")):
        return
    c = f["contact"]
    n = c["x"].shape[0]
    xy = c["coordinates"][()]
    check(np.array_equal(m.points, c["geometry_xyz"][()]) and np.array_equal(m.points[:, :2], xy.T)
          and np.all(m.points[:, 2] == 0.0), f"{tag}: contact points == /contact/coordinates' (+ z = 0), {n} nodes")
    seg = np.array([[k, k + 1] for k in range(n - 1)])
    blocks = [(b.type, np.asarray(b.data)) for b in m.cells]
    check(len(blocks) == 1 and blocks[0][0] == "line" and np.array_equal(blocks[0][1], seg)
          and np.array_equal(c["segments"][()], seg),
          f"{tag}: contact cells: {n - 1} line segments between neighbouring contact nodes")
    check(np.all(np.diff(c["x"][()]) > 0), f"{tag}: contact nodes in order along the line")
    check(sorted(m.point_data) == sorted(CONTACT_FIELDS), f"{tag}: contact point data {sorted(m.point_data)}")
    for name in CONTACT_FIELDS:
        if name in m.point_data:
            check(np.array_equal(np.asarray(m.point_data[name]).reshape(-1), c[name][()]),
                  f"{tag}: contact {name} == /contact/{name}")


def check_units(f, tag, units):
    """Root unit attributes and the units attribute of every numeric dataset."""
    L, F, S = units
    got = tuple(f.attrs.get(k) for k in ("unit_length", "unit_force", "unit_stress"))
    check(got == units, f"{tag}: root attributes unit_length, unit_force, unit_stress == {units}", str(got))
    want = {"L": L, "S": S, "F/L": f"{F}/{L}", "1": "1", "s": "s"}
    bad = []
    seen = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "fiu":
            seen.append(name)
            u = obj.attrs.get("units")
            if name not in UNITS:
                bad.append(f"{name}: not in the test's table")
            elif u != want[UNITS[name]] or not isinstance(u, str):
                bad.append(f"{name}: units {u!r}, expected {want[UNITS[name]]!r}")
    f.visititems(visit)
    check(not bad and len(seen) == len(UNITS), f"{tag}: every numeric dataset ({len(seen)}) has its units attribute"
          + ("" if not bad else " (" + "; ".join(bad[:6]) + ")"))


def check_strings(f, tag):
    """String attributes come back as str (variable-length UTF-8), comparable with ==."""
    names = [k for k in f.attrs if isinstance(f.attrs[k], (str, bytes, np.bytes_))]
    kinds = {k: type(f.attrs[k]).__name__ for k in names}
    check(len(names) >= 8 and all(isinstance(f.attrs[k], str) for k in names),
          f"{tag}: root string attributes are str ({len(names)})", str(kinds))
    st = f.attrs["status"]
    check(st in ("converged", "max_outer", "diverged"), f"{tag}: f.attrs['status'] == {st!r} compares as str")
    check(f.attrs["method"] == "robin" and f["body1"].attrs["element"] in ("Q1", "P1")
          and f.attrs["version"] == text_attr(f, "version") != "",
          f"{tag}: method, element, version compare equal to str")


def check_run_marker(f, paths, tag):
    """Each XDMF file says which run wrote it: the same run_id as the HDF5 file."""
    rid = f.attrs.get("run_id")
    bad = []
    for p in paths:
        text = open(p, encoding="utf-8").read() if os.path.isfile(p) else ""
        mk = re.search(r"<!-- robin_contact \S+ run_id (\S+) -->", text)
        if mk is None or mk.group(1) != rid:
            bad.append(f"{os.path.basename(p)}: {mk.group(1) if mk else None}")
    check(isinstance(rid, str) and rid and not bad, f"{tag}: every XDMF file has the run_id of the HDF5 file ({rid})",
          "; ".join(bad))


def run_case(tmp, tag, overrides, units=("m", "N", "Pa"), name=None):
    h5 = os.path.join(tmp, f"{name or tag}.h5")
    cmd = [binary(), DECK] + overrides + ["&output file='" + h5.replace("'", "''") + "' /"]
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
        check_units(f, tag, units)
        check_strings(f, tag)
        cpath = CONTACT_XDMF.format(stem=stem)
        if check(os.path.isfile(cpath), f"{tag}: contact line file {os.path.basename(cpath)} exists"):
            compare_contact(cpath, f, tag)
        check_run_marker(f, [xdmf, cpath] + [BODY_XDMF.format(stem=stem, b=b) for b in (1, 2)], tag)
        for b in (1, 2):
            path = BODY_XDMF.format(stem=stem, b=b)
            if not check(os.path.isfile(path),
                         f"{tag}: per-body file {os.path.basename(path)} exists (one Uniform grid under Domain, "
                         f"the layout meshio.read can read)"):
                continue
            compare_body(path, f[f"body{b}"], cxy, f"{tag} body{b}")


# ---- solid bodies: contact surfaces ---------------------------------------------------------
STACK3 = THREE_BOXES + "&solver load_steps = 2 /\n"


def face_vectors(xyz, faces):
    """(area, unit normal by the right-hand rule) of each face (a -1 fourth vertex: a triangle;
    a quadrilateral by its diagonals)."""
    areas, normals = [], []
    for fc in faces:
        v = fc[fc >= 0]
        p = xyz[v]
        c = np.cross(p[2] - p[0], p[3] - p[1]) if v.size == 4 else np.cross(p[1] - p[0], p[2] - p[0])
        areas.append(0.5 * np.linalg.norm(c))
        normals.append(c / np.linalg.norm(c))
    return np.array(areas), np.array(normals)


def check_surface_grid(xdmf, f, tag, want):
    """A one-grid (or temporal) XDMF file of a contact surface: its Topology and that every
    DataItem is an existing dataset of its Dimensions."""
    root = ET.parse(xdmf).getroot()
    bad = []
    topos = list(root.iter("Topology"))
    got = {(t.get("TopologyType"), t.get("NumberOfElements")) for t in topos}
    if got != {want}:
        bad.append(f"topologies {got}, expected {want}")
    for item in root.iter("DataItem"):
        ref = (item.text or "").strip()
        dset = ref.partition(":")[2]
        dims = tuple(int(x) for x in item.get("Dimensions", "").split())
        if dset not in f or f[dset].shape != dims:
            bad.append(f"{ref}: dims {dims}, dataset {f[dset].shape if dset in f else 'missing'}")
    check(not bad, f"{tag}: {os.path.basename(xdmf)}: a {want[0]} surface of {want[1]} faces, every DataItem a "
          "dataset of its Dimensions" + ("" if not bad else " (" + "; ".join(bad[:4]) + ")"))


def solid_stack(tmp):
    tag = "solid stack"
    deck = os.path.join(tmp, "stack3.nml")
    with open(deck, "w") as fh:
        fh.write(STACK3)
    h5 = os.path.join(tmp, "stack3.h5")
    p, _ = run_solver(binary(), deck, f"&output file='{h5}' /", cwd=tmp, timeout=600)
    if not check(p.returncode == 0 and os.path.isfile(h5), f"{tag}: three boxes, two pairs, two load steps solved",
                 f"exit {p.returncode} {p.stderr.strip()[-300:]}"):
        return
    with h5py.File(h5, "r") as f:
        c = f["contact"]
        xyz = c["geometry_xyz"][()]
        normal = c["normal"][()].T
        f1, f2 = c["pair_1/faces"][()], c["pair_2/faces"][()]
        n1 = c["pair_1/normal_force"].shape[0]
        # the deck: body 1 (2 x 3 hexahedra) on body 2 (3 x 2 cells of tetrahedra) on body 3; the
        # upper body of each pair has the finer contact side: the slave
        check(f1.shape == (6, 4) and f2.shape == (12, 3) and f1.min() >= 0 and f2.min() >= 0
              and int(c["pair_1"].attrs["slave_body"]) == 1 and int(c["pair_2"].attrs["slave_body"]) == 2,
              f"{tag}: pair 1's faces the 2 x 3 quadrilaterals of body 1's bottom, pair 2's the 2 x 3 x 2 triangles "
              "of body 2's", f"{f1.shape}, {f2.shape}")
        for k, (fk, r0) in enumerate(((f1, 0), (f2, n1)), start=1):
            pts = xyz[r0:r0 + c[f"pair_{k}/normal_force"].shape[0]]
            area, nf = face_vectors(pts, fk)
            rows = np.unique(fk[fk >= 0])
            nodal = np.array([normal[r0 + fc[fc >= 0]].mean(axis=0) for fc in fk])
            check(abs(area.sum() - 1.0) <= 1e-12 and np.all(np.sum(nf * nodal, axis=1) > 0.999)
                  and np.array_equal(rows, np.arange(pts.shape[0])),
                  f"{tag}: pair {k}'s faces tile the contact square (area {area.sum():.15g}), outward from the "
                  "slave (along the contact normals), over every contact node of the pair")
        stacked = np.vstack([np.c_[f1, -np.ones((6, 0), dtype=int)], np.c_[f2 + n1, -np.ones((12, 1), dtype=int)]])
        topo = np.concatenate([np.r_[5, fc] for fc in f1] + [np.r_[4, fc + n1] for fc in f2])
        check(np.array_equal(c["faces"][()], stacked) and np.array_equal(c["topology"][()], topo)
              and "segments" not in c and "segments" not in c["pair_1"],
              f"{tag}: /contact/faces stacks the pairs' faces (a triangle's fourth -1), /contact/topology their "
              "XDMF Mixed list, no segments")
        check(all(f[d].attrs.get("units") == "1"
                  for d in ("contact/faces", "contact/topology", "contact/pair_1/faces")),
              f"{tag}: faces and topology have units '1'")
        stem = h5[:-3]
        check_surface_grid(stem + "_contact.xdmf", f, tag, ("Mixed", "18"))
        check_surface_grid(stem + "_contact1.xdmf", f, tag, ("Quadrilateral", "6"))
        check_surface_grid(stem + "_contact2.xdmf", f, tag, ("Triangle", "12"))
        grids = [g.get("Name") for g in ET.parse(stem + ".xdmf").getroot().iter("Grid")
                 if g.get("GridType") == "Uniform"]
        check(grids == ["body1", "body2", "body3", "contact_pair1", "contact_pair2"] * 2,
              f"{tag}: the collection has the bodies and both contact surfaces at each step", str(grids))
        for name, k, cells in (("_contact1", 1, [("quad", f1)]), ("_contact2", 2, [("triangle", f2)]),
                               ("_contact", 0, [("quad", f1), ("triangle", f2 + n1)])):
            g = c if k == 0 else c[f"pair_{k}"]
            try:
                with meshio.xdmf.TimeSeriesReader(stem + name + ".xdmf") as r:
                    pts, blocks = r.read_points_cells()
                    steps = [r.read_data(s)[1]["pressure"] for s in range(r.num_steps)]
            except Exception as e:  # noqa: BLE001 (report any reader failure as a FAIL)
                check(False, f"{tag}: meshio reads {os.path.basename(stem + name)}.xdmf ({type(e).__name__}: {e})")
                continue
            want = [f[f"steps/step_{s}/contact" + ("" if k == 0 else f"/pair_{k}") + "/pressure"][()] for s in (1, 2)]
            check(np.array_equal(pts, g["geometry_xyz"][()])
                  and [(b.type, np.asarray(b.data).tolist()) for b in blocks] == [(t, d.tolist()) for t, d in cells]
                  and len(steps) == 2 and all(np.array_equal(np.ravel(a), b) for a, b in zip(steps, want)),
                  f"{tag}: meshio reads {os.path.basename(stem + name)}.xdmf back: points, "
                  f"{' and '.join(t for t, _ in cells)} cells, both steps' pressures")


def solid_hertz(tmp):
    tag = "solid Hertz"
    h5 = os.path.join(tmp, "sphere.h5")
    msh = os.path.join(ROOT, "inputs", "gmsh", "sphere_block_h0.02.msh")
    p, _ = run_solver(binary(), os.path.join(ROOT, "inputs", "sphere_block.nml"), f"&body id=1, mesh='{msh}' /",
                      f"&body id=2, mesh='{msh}' /", f"&output file='{h5}' /", cwd=tmp, timeout=600)
    if not check(p.returncode == 0 and os.path.isfile(h5), f"{tag}: sphere on a block solved", f"exit {p.returncode}"):
        return
    with contextlib.redirect_stdout(io.StringIO()):
        mesh = meshio.read(msh)
    arc = mesh.field_data["sphere_arc"][0]
    tris = np.vstack([b.data for b, tags in zip(mesh.cells, mesh.cell_data["gmsh:physical"])
                      if b.type == "triangle" and np.all(tags == arc)])
    with h5py.File(h5, "r") as f:
        c = f["contact"]
        xyz = c["geometry_xyz"][()]
        faces = c["faces"][()]
        lam = c["normal_force"][()]
        normal = c["normal"][()].T
        row = {tuple(q): k for k, q in enumerate(xyz.tolist())}
        mapped = [[row.get(tuple(mesh.points[v].tolist())) for v in t] for t in tris]
        want = {frozenset(t) for t in mapped if None not in t}
        got = [frozenset(t) for t in faces.tolist()]
        check(len(got) == len(set(got)) and set(got) == want and 0 < len(want) < len(tris),
              f"{tag}: the faces are the 'sphere_arc' triangles of the mesh file whose nodes are all contact nodes "
              f"({len(want)} of {len(tris)})", f"{len(got)} faces in the file")
        _, nf = face_vectors(xyz, faces)
        nodal = normal[faces].mean(axis=1)
        check(np.all(np.sum(nf * nodal, axis=1) > 0.9), f"{tag}: every face counter-clockwise seen from outside "
              "the sphere (along the contact normals)")
        check(np.all(np.isin(np.nonzero(lam > 0)[0], faces)), f"{tag}: every active contact node is on a face "
              f"({int(np.sum(lam > 0))} active nodes)")
        check_surface_grid(h5[:-3] + "_contact.xdmf", f, tag, ("Triangle", str(len(faces))))
        m, err = meshio_read(h5[:-3] + "_contact.xdmf")
        if check(m is not None, f"{tag}: meshio.read(sphere_contact.xdmf)" + (f": {err}" if err else "")):
            check([b.type for b in m.cells] == ["triangle"] and np.array_equal(m.cells[0].data, faces)
                  and np.array_equal(m.points, xyz) and sorted(m.point_data) == sorted(CONTACT_FIELDS)
                  and all(np.array_equal(np.ravel(m.point_data[k]), c[k][()]) for k in CONTACT_FIELDS),
                  f"{tag}: meshio reads the contact surface back: triangles == /contact/faces, points, point data")


def main():
    print(f"meshio {meshio.__version__}, h5py {h5py.__version__}, binary {binary()}")
    with tempfile.TemporaryDirectory(prefix="test_xdmf_") as tmp:
        run_case(tmp, "q1_6x2_Q1", [])
        run_case(tmp, "q1_6x2_P1", ['&body id=1, element="P1" /', '&body id=2, element="P1" /'])
        run_case(tmp, "q1_6x2_mm", ["&scene units='mm-N-MPa' /"], units=("mm", "N", "MPa"))
        # a name with the XML special characters: the XDMF files stay well-formed
        run_case(tmp, "xml_chars", [], name="a&b<c>d\"e'f")
        solid_stack(tmp)
        solid_hertz(tmp)
    print(f"test_xdmf: {len(check.failed)} failed check(s)")
    return 1 if check.failed else 0


if __name__ == "__main__":
    sys.exit(main())
