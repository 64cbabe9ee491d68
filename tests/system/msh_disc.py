#!/usr/bin/python3
"""Write a disc of quadrilaterals as a Gmsh MSH 4.1 file (ASCII), for tests that need a disc
the test itself makes (no gmsh needed).

The mesh is an O-grid: a square core (half-side `core` x R) and four ring blocks between the
core's sides and the circle. The upper and lower blocks are refined toward the top and the
bottom point of the circle (the contact points of a disc pressed between two plates): their
divisions along the circle shrink toward the middle as sinh(beta t)/sinh(beta), and every
block's divisions across the ring shrink toward the circle likewise (gamma). The core takes the
upper block's x divisions and the side blocks' y divisions, so all cells are convex quads.

Physical groups: the surface `name`; the curves `<name>_upper` and `<name>_lower` (the arcs of
the upper and lower blocks, 90 degrees each, centred on the top and the bottom point),
`<name>_left` and `<name>_right` (the other two arcs), `<name>_axis` (an interior curve: the
vertical diameter across the core, where a deck can set ux = 0 without touching the arcs);
the point `<name>_centre`.

usage: msh_disc.py OUT.msh [R [n [nr]]]   (centre (0, 0))
"""
import math
import os
import sys


def _graded(t, beta):
    """t in [-1, 1] mapped to [-1, 1], divisions shrinking toward 0 by the ratio cosh(beta)."""
    return t if beta == 0.0 else math.sinh(beta * t) / math.sinh(beta)


def disc_mesh(R=1.0, cx=0.0, cy=0.0, n=40, m=12, nr=24, beta=3.0, gamma=2.0, core=0.4):
    """Nodes {key: (x, y)} in order, quads (node indices, counter-clockwise), and the node index
    lists of the arcs and of the axis. n: divisions of the upper and lower arcs (even),
    m: of the side arcs (even), nr: across the ring."""
    if n % 2 or m % 2 or n < 2 or m < 2 or nr < 1:
        raise ValueError("n and m must be even and >= 2, nr >= 1")
    s = core * R
    xs = [_graded(-1.0 + 2.0 * i / n, beta) for i in range(n + 1)]      # core x and the upper arc
    ys = [-1.0 + 2.0 * j / m for j in range(m + 1)]                      # core y and the side arcs

    def ring(u):                       # 0 at the core, 1 on the circle, finer toward 1
        return u if gamma == 0.0 else 1.0 - math.sinh(gamma * (1.0 - u)) / math.sinh(gamma)

    coords, index = [], {}

    def node(x, y):
        key = (round(x, 12), round(y, 12))
        if key not in index:
            index[key] = len(coords)
            coords.append((x, y))
        return index[key]

    quads = []

    def add_quad(a, b, c, d):
        (xa, ya), (xb, yb), (xc, yc), (xd, yd) = (coords[k] for k in (a, b, c, d))
        area = (xa * yb - xb * ya) + (xb * yc - xc * yb) + (xc * yd - xd * yc) + (xd * ya - xa * yd)
        quads.append((a, b, c, d) if area > 0.0 else (a, d, c, b))

    # core
    grid = [[node(cx + s * xs[i], cy + s * ys[j]) for j in range(m + 1)] for i in range(n + 1)]
    for i in range(n):
        for j in range(m):
            add_quad(grid[i][j], grid[i + 1][j], grid[i + 1][j + 1], grid[i][j + 1])
    axis = [grid[n // 2][j] for j in range(m + 1)]
    centre = grid[n // 2][m // 2]

    # ring blocks: inner point on the core's side, outer point on the circle (angle theta)
    blocks = {
        "upper": [((s * xs[i], s), math.pi / 2.0 - math.pi / 4.0 * xs[i]) for i in range(n + 1)],
        "lower": [((s * xs[i], -s), -math.pi / 2.0 + math.pi / 4.0 * xs[i]) for i in range(n + 1)],
        "right": [((s, s * ys[j]), math.pi / 4.0 * ys[j]) for j in range(m + 1)],
        "left": [((-s, s * ys[j]), math.pi - math.pi / 4.0 * ys[j]) for j in range(m + 1)],
    }
    arcs = {}
    for name, edge in blocks.items():
        cols = []
        for (xi, yi), th in edge:
            xo, yo = R * math.cos(th), R * math.sin(th)
            col = []
            for k in range(nr + 1):
                r = ring(k / nr)
                if k == nr:
                    col.append(node(cx + xo, cy + yo))
                else:
                    col.append(node(cx + (1.0 - r) * xi + r * xo, cy + (1.0 - r) * yi + r * yo))
            cols.append(col)
        for i in range(len(cols) - 1):
            for k in range(nr):
                add_quad(cols[i][k], cols[i + 1][k], cols[i + 1][k + 1], cols[i][k + 1])
        arcs[name] = [c[nr] for c in cols]
    return coords, quads, arcs, axis, centre


def write_disc(path, R=1.0, cx=0.0, cy=0.0, name="disc", **kw):
    """Write the disc (disc_mesh's arguments) to path as MSH 4.1 ASCII."""
    coords, quads, arcs, axis, centre = disc_mesh(R, cx, cy, **kw)
    curves = [(f"{name}_{k}", arcs[k]) for k in ("upper", "lower", "left", "right")] + [(f"{name}_axis", axis)]
    names = [(0, 1, f"{name}_centre")] + [(1, 10 + c, cn) for c, (cn, _) in enumerate(curves)] + [(2, 100, name)]
    lo = (cx - R, cy - R)
    hi = (cx + R, cy + R)
    out = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(names))]
    out += [f'{d} {t} "{nm}"' for d, t, nm in names]
    out += ["$EndPhysicalNames", "$Entities", f"1 {len(curves)} 1 0"]
    xc, yc = coords[centre]
    out.append(f"1 {xc!r} {yc!r} 0 1 1")
    for c in range(len(curves)):
        out.append(f"{c + 1} {lo[0]!r} {lo[1]!r} 0 {hi[0]!r} {hi[1]!r} 0 1 {10 + c} 0")
    out.append(f"1 {lo[0]!r} {lo[1]!r} 0 {hi[0]!r} {hi[1]!r} 0 1 100 4 1 2 3 4")
    out += ["$EndEntities", "$Nodes", f"1 {len(coords)} 1 {len(coords)}", f"2 1 0 {len(coords)}"]
    out += [str(k + 1) for k in range(len(coords))]
    out += [f"{x!r} {y!r} 0" for x, y in coords]
    out.append("$EndNodes")
    blocks, tag = [], 0
    for c, (_, nodes) in enumerate(curves):
        lines = []
        for a, b in zip(nodes[:-1], nodes[1:]):
            tag += 1
            lines.append(f"{tag} {a + 1} {b + 1}")
        blocks.append((1, c + 1, 1, lines))
    lines = []
    for q in quads:
        tag += 1
        lines.append(f"{tag} " + " ".join(str(k + 1) for k in q))
    blocks.append((2, 1, 3, lines))
    tag += 1
    blocks.append((0, 1, 15, [f"{tag} {centre + 1}"]))
    out += ["$Elements", f"{len(blocks)} {tag} 1 {tag}"]
    for d, t, typ, ls in blocks:
        out.append(f"{d} {t} {typ} {len(ls)}")
        out += ls
    out.append("$EndElements")
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(out) + "\n")
    os.replace(tmp, path)
    return len(coords), len(quads)


if __name__ == "__main__":
    args = sys.argv[1:]
    if not args:
        print(__doc__)
        sys.exit(1)
    kw = {}
    if len(args) > 2:
        kw["n"] = int(args[2])
    if len(args) > 3:
        kw["nr"] = int(args[3])
    nn, nq = write_disc(args[0], R=float(args[1]) if len(args) > 1 else 1.0, **kw)
    print(f"{args[0]}: {nn} nodes, {nq} quadrangles")
