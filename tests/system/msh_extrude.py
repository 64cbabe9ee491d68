"""Extrude a 2D Gmsh mesh of triangles (read by meshio) along z into a Gmsh MSH 4.1 volume
mesh of tetrahedra, for tests that compare a solid body with the plane program on the same
cross-section (no gmsh needed).

Each triangle becomes `layers` prisms of height depth/layers, each prism three tetrahedra. The
split is conforming without any bookkeeping: every quadrilateral side face of a prism, over the
2D edge (i, j) with i < j (global node numbers), is cut by the diagonal from i's lower node to
j's upper node, the same in both prisms that share it. With the triangle's nodes sorted,
a < b < c, the tetrahedra are (a0 b0 c0 c1), (a0 b0 b1 c1), (a0 a1 b1 c1).

Names: each 2D physical surface becomes a physical volume of the same name; each physical curve
a physical surface of the same name (its edges' side faces, two triangles each); each volume
also gets `<name>_front` (z = 0) and `<name>_back` (z = depth), its triangles at the ends.
"""
import numpy as np


def extrude(msh2d, path, depth, layers=1):
    """Write the extrusion of the 2D mesh file msh2d to path; returns (nodes, tetrahedra)."""
    import meshio
    m = meshio.read(msh2d)
    xy = m.points[:, :2]
    n2 = len(xy)
    zs = np.linspace(0.0, depth, layers + 1)

    def nid(i, k):           # 1-based tag of 2D node i (0-based) on level k
        return k * n2 + i + 1

    names = {}               # 2D physical tag -> (dim, name)
    for name, (tag, dim) in m.field_data.items():
        names[(int(dim), int(tag))] = name
    vols, surfs = {}, {}     # name -> list of cells (node tags)
    for cells, phys in zip(m.cells, m.cell_data["gmsh:physical"]):
        for nodes, t in zip(cells.data, phys):
            if cells.type == "triangle":
                name = names[(2, int(t))]
                a, b, c = sorted(int(v) for v in nodes)
                for k in range(layers):
                    vols.setdefault(name, []).extend([
                        (nid(a, k), nid(b, k), nid(c, k), nid(c, k + 1)),
                        (nid(a, k), nid(b, k), nid(b, k + 1), nid(c, k + 1)),
                        (nid(a, k), nid(a, k + 1), nid(b, k + 1), nid(c, k + 1))])
                surfs.setdefault(name + "_front", []).append(tuple(nid(int(v), 0) for v in nodes))
                surfs.setdefault(name + "_back", []).append(tuple(nid(int(v), layers) for v in nodes))
            elif cells.type == "line":
                name = names[(1, int(t))]
                i, j = sorted(int(v) for v in nodes)
                for k in range(layers):
                    surfs.setdefault(name, []).extend([(nid(i, k), nid(j, k), nid(j, k + 1)),
                                                       (nid(i, k), nid(i, k + 1), nid(j, k + 1))])
    nn = n2 * (layers + 1)
    lo = [xy[:, 0].min(), xy[:, 1].min(), 0.0]
    hi = [xy[:, 0].max(), xy[:, 1].max(), depth]
    box = " ".join(repr(float(v)) for v in lo + hi)
    out = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(vols) + len(surfs))]
    vtag = {name: k + 1 for k, name in enumerate(vols)}
    stag = {name: k + 1 for k, name in enumerate(surfs)}
    out += [f'3 {vtag[n]} "{n}"' for n in vols] + [f'2 {100 + stag[n]} "{n}"' for n in surfs]
    out += ["$EndPhysicalNames", "$Entities", f"0 0 {len(surfs)} {len(vols)}"]
    out += [f"{stag[n]} {box} 1 {100 + stag[n]} 0" for n in surfs]
    out += [f"{vtag[n]} {box} 1 {vtag[n]} 0" for n in vols]
    out += ["$EndEntities", "$Nodes", f"1 {nn} 1 {nn}", f"3 1 0 {nn}"]
    out += [str(t) for t in range(1, nn + 1)]
    out += [f"{x!r} {y!r} {z!r}" for z in zs for x, y in ((float(p[0]), float(p[1])) for p in xy)]
    nel = sum(len(c) for c in vols.values()) + sum(len(c) for c in surfs.values())
    out += ["$EndNodes", "$Elements", f"{len(vols) + len(surfs)} {nel} 1 {nel}"]
    e = 0
    for name, cells in list(surfs.items()):
        out.append(f"2 {stag[name]} 2 {len(cells)}")
        for c in cells:
            e += 1
            out.append(f"{e} " + " ".join(map(str, c)))
    ntet = 0
    for name, cells in vols.items():
        out.append(f"3 {vtag[name]} 4 {len(cells)}")
        ntet += len(cells)
        for c in cells:
            e += 1
            out.append(f"{e} " + " ".join(map(str, c)))
    out.append("$EndElements")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")
    return nn, ntet
