"""Write the Gmsh MSH 4.1 file of a bar of two materials, for tests and benchmarks that make
their own mesh (no gmsh needed): [0, 2L] x [0, H] in Q1 cells, its left half surface entity 1,
its right half entity 2, the physical surface 'bar' holding both and 'soft' the right half (a
&region), and the physical curves 'bar_left', 'bar_bottom', 'bar_right'.
"""


def write_bar(path, NX, NY, extra_region=False, L=1.0, H=0.5):
    """The bar [0, 2L] x [0, H] of 2 NX x NY Q1 cells (NX across each half): surface 1 the left half, 2 the right
    half; physical surfaces 'bar' = {1, 2}, 'soft' = {2} (and 'strip' = {1, 2} when
    extra_region: every cell in it), curves 'bar_left', 'bar_bottom', 'bar_right'."""
    nx = 2 * NX
    xs = [2 * L * i / nx for i in range(nx + 1)]
    ys = [H * j / NY for j in range(NY + 1)]

    def nid(i, j):
        return j * (nx + 1) + i + 1
    names = [(2, 100, "bar"), (2, 200, "soft"), (1, 11, "bar_left"), (1, 12, "bar_bottom"), (1, 13, "bar_right")]
    if extra_region:
        names.append((2, 300, "strip"))
    s1 = "100 300" if extra_region else "100"
    s2 = "100 200 300" if extra_region else "100 200"
    n1, n2 = len(s1.split()), len(s2.split())
    out = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(names))]
    out += [f'{d} {t} "{n}"' for d, t, n in names]
    out += ["$EndPhysicalNames", "$Entities", "0 3 2 0",
            f"1 0 0 0 0 {H} 0 1 11 0", f"2 0 0 0 {2 * L} 0 0 1 12 0", f"3 {2 * L} 0 0 {2 * L} {H} 0 1 13 0",
            f"1 0 0 0 {L} {H} 0 {n1} {s1} 0", f"2 {L} 0 0 {2 * L} {H} 0 {n2} {s2} 0", "$EndEntities"]
    nn = (nx + 1) * (NY + 1)
    out += ["$Nodes", f"1 {nn} 1 {nn}", f"2 1 0 {nn}"]
    out += [str(nid(i, j)) for j in range(NY + 1) for i in range(nx + 1)]
    out += [f"{xs[i]!r} {ys[j]!r} 0" for j in range(NY + 1) for i in range(nx + 1)]
    out.append("$EndNodes")
    blocks, tag = [], 0

    def quads(i0, i1):
        nonlocal tag
        q = []
        for j in range(NY):
            for i in range(i0, i1):
                tag += 1
                q.append(f"{tag} {nid(i, j)} {nid(i + 1, j)} {nid(i + 1, j + 1)} {nid(i, j + 1)}")
        return q

    def lines(segs):
        nonlocal tag
        q = []
        for a, b in segs:
            tag += 1
            q.append(f"{tag} {a} {b}")
        return q
    blocks.append((2, 1, 3, quads(0, NX)))
    blocks.append((2, 2, 3, quads(NX, nx)))
    blocks.append((1, 1, 1, lines([(nid(0, j + 1), nid(0, j)) for j in range(NY)])))
    blocks.append((1, 2, 1, lines([(nid(i, 0), nid(i + 1, 0)) for i in range(nx)])))
    blocks.append((1, 3, 1, lines([(nid(nx, j), nid(nx, j + 1)) for j in range(NY)])))
    out += ["$Elements", f"{len(blocks)} {tag} 1 {tag}"]
    for d, t, typ, ls in blocks:
        out.append(f"{d} {t} {typ} {len(ls)}")
        out += ls
    out.append("$EndElements")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")

