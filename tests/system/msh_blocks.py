"""Write small Gmsh MSH 4.1 files of structured quadrilateral blocks, for tests that need a
mesh the test itself makes (no gmsh needed).

Each block is a rectangle meshed by nx x ny Q1 cells: one physical surface named `name`,
physical curves `<name>_bottom`, `_right`, `_top`, `_left`, and optional physical points
`(label, i, j)` at grid node (i, j), and optional extra physical names of a side's curve
(`aliases={'bottom': ['other_name']}`: the same edges under two names). Blocks share no node.
"""


def block(name, x0, y0, width, height, nx, ny, points=(), aliases=None):
    """A block description for write_msh."""
    return dict(name=name, x0=x0, y0=y0, w=width, h=height, nx=nx, ny=ny, points=list(points),
                aliases=dict(aliases or {}))


def write_msh(path, blocks):
    """Write the blocks to path as MSH 4.1 (ASCII)."""
    names = []          # (dim, tag, name)
    ent_pts, ent_cur, ent_srf = [], [], []
    node_lines, elem_blocks = [], []
    ntag = etag = 0
    for b_i, b in enumerate(blocks):
        nx, ny = b['nx'], b['ny']
        base = ntag
        xs = [b['x0'] + b['w'] * i / nx for i in range(nx + 1)]
        ys = [b['y0'] + b['h'] * j / ny for j in range(ny + 1)]

        def nid(i, j):
            return base + j * (nx + 1) + i + 1
        coords = [(nid(i, j), xs[i], ys[j]) for j in range(ny + 1) for i in range(nx + 1)]
        ntag += len(coords)
        stag = b_i + 1
        phys_s = 100 * (b_i + 1)
        names.append((2, phys_s, b['name']))
        box = (b['x0'], b['y0'], b['x0'] + b['w'], b['y0'] + b['h'])
        sides = {
            'bottom': [(nid(i, 0), nid(i + 1, 0)) for i in range(nx)],
            'right': [(nid(nx, j), nid(nx, j + 1)) for j in range(ny)],
            'top': [(nid(i + 1, ny), nid(i, ny)) for i in reversed(range(nx))],
            'left': [(nid(0, j + 1), nid(0, j)) for j in reversed(range(ny))],
        }
        ctags = []
        for k, (side, segs) in enumerate(sides.items()):
            ctag = 10 * (b_i + 1) + k + 1
            phys_c = phys_s + k + 1
            names.append((1, phys_c, f"{b['name']}_{side}"))
            phys = [phys_c]
            for a_i, alias in enumerate(b.get('aliases', {}).get(side, [])):
                phys.append(phys_s + 10 * (a_i + 1) + k + 1)
                names.append((1, phys[-1], alias))
            ent_cur.append(f"{ctag} {box[0]} {box[1]} 0 {box[2]} {box[3]} 0 {len(phys)} "
                           + " ".join(map(str, phys)) + " 0")
            ctags.append(ctag)
            lines = []
            for s in segs:
                etag += 1
                lines.append(f"{etag} {s[0]} {s[1]}")
            elem_blocks.append((1, ctag, 1, lines))
        ent_srf.append(f"{stag} {box[0]} {box[1]} 0 {box[2]} {box[3]} 0 1 {phys_s} 4 " + " ".join(map(str, ctags)))
        quads = []
        for j in range(ny):
            for i in range(nx):
                etag += 1
                quads.append(f"{etag} {nid(i, j)} {nid(i + 1, j)} {nid(i + 1, j + 1)} {nid(i, j + 1)}")
        elem_blocks.append((2, stag, 3, quads))
        for p_i, (label, i, j) in enumerate(b['points']):
            ptag = 100 * (b_i + 1) + p_i + 1
            phys_p = 1000 * (b_i + 1) + p_i + 1
            names.append((0, phys_p, label))
            ent_pts.append(f"{ptag} {xs[i]} {ys[j]} 0 1 {phys_p}")
            etag += 1
            elem_blocks.append((0, ptag, 15, [f"{etag} {nid(i, j)}"]))
        node_lines.append((2, stag, coords))
    out = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(names))]
    out += [f'{d} {t} "{n}"' for d, t, n in names]
    out += ["$EndPhysicalNames", "$Entities", f"{len(ent_pts)} {len(ent_cur)} {len(ent_srf)} 0"]
    out += ent_pts + ent_cur + ent_srf + ["$EndEntities", "$Nodes"]
    out.append(f"{len(node_lines)} {ntag} 1 {ntag}")
    for d, t, coords in node_lines:
        out.append(f"{d} {t} 0 {len(coords)}")
        out += [str(c[0]) for c in coords]
        out += [f"{c[1]!r} {c[2]!r} 0" for c in coords]
    out += ["$EndNodes", "$Elements", f"{len(elem_blocks)} {etag} 1 {etag}"]
    for d, t, typ, lines in elem_blocks:
        out.append(f"{d} {t} {typ} {len(lines)}")
        out += lines
    out.append("$EndElements")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")
