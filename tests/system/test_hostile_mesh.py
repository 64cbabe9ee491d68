#!/usr/bin/env python3
"""Whole-program tests of the Gmsh reader under hostile or unusual input, run by `make check`.
Every mesh is written by this script into a temporary folder, from the paper's scene
(inputs/gmsh/paper.msh, inputs/gmsh_paper.nml) or from scratch.

Bad input must end with exit 1 and one line naming the file and the real cause: no Fortran
runtime error, no backtrace, no hang (each run has a timeout), no result file. Covered:
1. declared counts the file cannot hold ($Entities, physical tags, $Nodes, $Elements, a block);
2. a FIFO as the mesh ("not a regular file");
3. a deck and mesh in a folder whose absolute path is about 600 characters (runs), and a
   mesh path beyond the system's limit (said so);
4. a quadrangle listed twice (rotated) and a boundary line listed twice (both tags named);
5. 100k physical groups (the file reads; its time is printed, not asserted);
9. a UTF-8 byte-order mark (accepted), node and element tags < 1, a 10,000-character
   physical name (accepted), coordinates whose products overflow, a missing $Entities;
10. the same for solid (3D) sections (inputs/gmsh/blocks_3d.msh: tetrahedra and hexahedra):
   a block count the file cannot hold, a tetrahedron listed twice with its nodes rotated
   (both tags named), a cell on a node the file lacks and on node 0, coordinates whose
   volume products overflow, no $Entities.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from rc_checks import Checks  # noqa: E402
from rc_run import solver_env  # noqa: E402

BIN = os.path.abspath(os.environ.get("BIN", "bin/robin_contact"))
ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
PAPER_MSH = open(os.path.join(ROOT, "inputs", "gmsh", "paper.msh")).read()
PAPER_NML = open(os.path.join(ROOT, "inputs", "gmsh_paper.nml")).read()
check = Checks()
TMP = tempfile.mkdtemp(prefix="rc_hostile_")


def deck_text(mesh):
    """The paper deck reading `mesh` (a path relative to the deck's folder or absolute)."""
    return PAPER_NML.replace("gmsh/paper.msh", mesh)


def run_case(name, mesh_text, mesh_name="m.msh", folder=None, timeout=60, mesh_bytes=None, deck_of=None):
    """Write the mesh and the deck (deck_of(mesh name), default the paper's) into a fresh
    folder and run there; returns (CompletedProcess or None on timeout, folder)."""
    folder = folder or os.path.join(TMP, name)
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, mesh_name)
    if mesh_bytes is not None:
        with open(path, "wb") as f:
            f.write(mesh_bytes)
    elif mesh_text is not None:
        with open(path, "w") as f:
            f.write(mesh_text)
    deck = os.path.join(folder, "d.nml")
    with open(deck, "w") as f:
        f.write((deck_of or deck_text)(mesh_name))
    try:
        p = subprocess.run([BIN, deck, "&output file='out.h5' /"], capture_output=True, text=True,
                           cwd=folder, env=solver_env("2"), timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, folder
    return p, folder


def written(folder):
    """Files the run left beside its inputs (a result or checkpoint)."""
    return sorted(f for f in os.listdir(folder) if f not in ("m.msh", "d.nml"))


def bad(name, mesh_text, patterns, **kw):
    """A case that must give exit 1 and one clean line matching every regular expression."""
    p, folder = run_case(name, mesh_text, **kw)
    if p is None:
        check(False, f"{name}: exit 1", "timed out")
        return
    err = p.stderr.strip()
    clean = ("Fortran runtime" not in p.stderr and "Backtrace" not in p.stderr and
             "Error termination" not in p.stderr and len(err.splitlines()) == 1)
    check(p.returncode == 1 and clean, f"{name}: exit 1 with one clean line",
          f"exit {p.returncode}: {err[-300:]}")
    print(f"       message: {err[-400:]}")
    for pat in patterns:
        check(re.search(pat, err) is not None, f"{name}: the message says /{pat}/", err[-300:])
    check(written(folder) == [], f"{name}: nothing written", str(written(folder)))


def good(name, mesh_text, **kw):
    p, folder = run_case(name, mesh_text, **kw)
    ok = p is not None and p.returncode == 0
    check(ok, f"{name}: exit 0", "timed out" if p is None else f"exit {p.returncode}: {p.stderr[-300:]}")
    return p


def section(text, name):
    """(start, end) of the lines inside $name ... $Endname."""
    s = text.index(f"${name}\n") + len(name) + 2
    return s, text.index(f"$End{name}\n")


def replace_section(text, name, body):
    s, e = section(text, name)
    return text[:s] + body + text[e:]


def elements_with(extra_blocks):
    """paper.msh with element blocks appended: each (dim, entity, type, [(tag, nodes...)])."""
    s, e = section(PAPER_MSH, "Elements")
    lines = PAPER_MSH[s:e].splitlines()
    nb, nt, lo, hi = map(int, lines[0].split())
    add = []
    for dim, ent, etype, elems in extra_blocks:
        add.append(f"{dim} {ent} {etype} {len(elems)}")
        add += [" ".join(map(str, el)) for el in elems]
        nt += len(elems)
        hi = max([hi] + [el[0] for el in elems])
        nb += 1
    body = "\n".join([f"{nb} {nt} {lo} {hi}"] + lines[1:] + add) + "\n"
    return replace_section(PAPER_MSH, "Elements", body)


def first_element(dim, ent):
    """The first element (tag, nodes...) of entity (dim, ent) in paper.msh."""
    s, e = section(PAPER_MSH, "Elements")
    lines = PAPER_MSH[s:e].splitlines()
    k = 1
    while k < len(lines):
        d, t, _, n = map(int, lines[k].split())
        if (d, t) == (dim, ent):
            return list(map(int, lines[k + 1].split()))
        k += n + 1
    raise ValueError("no such entity")


HEAD = '$MeshFormat\n4.1 0 8\n$EndMeshFormat\n'
TRI = ('$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n'
       '$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 3\n$EndElements\n')

# ---- 1. declared counts ------------------------------------------------------------------
bad("entities_huge_points", HEAD + "$Entities\n2147483647 0 0 0\n1 0 0 0 0\n$EndEntities\n" + TRI,
    [r"m\.msh", r"\$Entities", r"2147483647"])
bad("entities_sum_overflow", HEAD + "$Entities\n715827883 715827883 715827883 0\n1 0 0 0 0\n$EndEntities\n" + TRI,
    [r"m\.msh", r"\$Entities", r"715827883"])
bad("entity_huge_physical_tags", HEAD + "$Entities\n1 0 0 0\n1 0 0 0 2147483647 1\n$EndEntities\n" + TRI,
    [r"m\.msh", r"physical tags", r"2147483647"])
bad("nodes_huge_total", HEAD + "$Nodes\n1 2147483647 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n",
    [r"m\.msh", r"\$Nodes announces 2147483647 nodes", r"at most \d+ bytes"])
bad("elements_huge_total", HEAD + TRI.replace("$Elements\n1 1 1 1\n", "$Elements\n1 2147483647 1 1\n"),
    [r"m\.msh", r"\$Elements announces 2147483647 elements", r"at most \d+ bytes"])
bad("elements_huge_second_block",
    HEAD + TRI.replace("$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 3\n",
                       "$Elements\n2 2 1 2\n2 1 2 1\n1 1 2 3\n2 1 2 2147483647\n2 1 2 3\n"),
    [r"m\.msh", r"2147483647 elements", r"at most \d+ bytes"])
bad("physical_names_huge", HEAD + '$PhysicalNames\n2147483647\n2 1 "a"\n$EndPhysicalNames\n' + TRI,
    [r"m\.msh", r"\$PhysicalNames", r"2147483647"])

# ---- 2. a FIFO ---------------------------------------------------------------------------
fifo_dir = os.path.join(TMP, "fifo")
os.makedirs(fifo_dir)
os.mkfifo(os.path.join(fifo_dir, "m.msh"))
bad("fifo", None, [r"m\.msh", r"not a regular file"], folder=fifo_dir, timeout=20)

# ---- 3. long paths -----------------------------------------------------------------------
long_dir = TMP
while len(long_dir) < 600:
    long_dir = os.path.join(long_dir, "d" * 100)
p = good("long_path", PAPER_MSH, folder=long_dir)
too_long = "/".join(["x" * 200] * 21) + "/m.msh"       # 4226 characters, beyond PATH_MAX
p, folder = run_case("path_too_long_dir", PAPER_MSH)
with open(os.path.join(folder, "d.nml"), "w") as f:
    f.write(deck_text(too_long))
p = subprocess.run([BIN, os.path.join(folder, "d.nml"), "&output file='out.h5' /"], capture_output=True,
                   text=True, cwd=folder, env=solver_env("2"), timeout=60)
check(p.returncode == 1 and re.search(r"too long|longer than", p.stderr) is not None and
      "Backtrace" not in p.stderr, "a mesh path beyond PATH_MAX: exit 1 saying it is too long",
      f"exit {p.returncode}: {p.stderr[-300:]}")

# ---- 4. duplicate elements ---------------------------------------------------------------
quad = first_element(2, 5)          # a quadrangle of the upper body (surface entity 5)
rot = quad[2:] + quad[1:2]          # the same nodes, rotated by one
bad("duplicate_quad", elements_with([(2, 5, 3, [[900001] + rot])]),
    [r"m\.msh", rf"\b{quad[0]}\b", r"\b900001\b", r"same nodes|twice|duplicate"])
line = first_element(1, 2)          # a line of upper_top (curve entity 2)
bad("duplicate_line", elements_with([(1, 2, 1, [[900002, line[2], line[1]]])]),
    [r"m\.msh", rf"\b{line[0]}\b", r"\b900002\b", r"same nodes|twice|duplicate"])
# a line of upper_top across a cell's diagonal: both nodes in the body, no cell has that edge
# (a corrupted node number); its load would be lost without a word
# a cell of the upper body whose nodes were corrupted into the lower body's: the upper region
# is then two pieces (it solved to exit 3 "not positive definite", a numerical failure)
lower = first_element(2, 10)        # a quadrangle of the lower body (surface entity 10)
bad("two_pieces", elements_with([(2, 5, 3, [[900004] + lower[1:]])]),
    [r"m\.msh", r"\b900004\b", r"more than one piece"])
bad("line_not_an_edge", elements_with([(1, 2, 1, [[900003, quad[1], quad[3]]])]),
    [r"m\.msh", r"\b900003\b", r"upper_top", r"not an edge"])

# ---- 5. many physical groups -------------------------------------------------------------
s, e = section(PAPER_MSH, "PhysicalNames")
names = PAPER_MSH[s:e].splitlines()
many = [str(int(names[0]) + 100000)] + names[1:] + [f'1 {1000 + k} "g{k}"' for k in range(100000)]
t0 = time.time()
good("many_groups", replace_section(PAPER_MSH, "PhysicalNames", "\n".join(many) + "\n"), timeout=120)
print(f"       100k physical groups: {time.time() - t0:.2f} s for the whole run (not asserted)")

# ---- 9. messages -------------------------------------------------------------------------
good("bom", None, mesh_bytes=b"\xef\xbb\xbf" + PAPER_MSH.encode())
s, e = section(PAPER_MSH, "Nodes")
nodes = PAPER_MSH[s:e].splitlines()
tag_line = nodes.index("1", 1)        # the first block's only tag (node 1)
neg = nodes[:tag_line] + ["-1"] + nodes[tag_line + 1:]
bad("node_tag_negative", replace_section(PAPER_MSH, "Nodes", "\n".join(neg) + "\n"),
    [r"m\.msh", r"-1", r"must be >= 1"])
zero_elem = elements_with([(1, 2, 1, [[0, first_element(1, 2)[1], first_element(1, 2)[2]]])])
bad("element_tag_zero", zero_elem, [r"m\.msh", r"\b0\b", r"must be >= 1"])
s, e = section(PAPER_MSH, "PhysicalNames")
names = PAPER_MSH[s:e].splitlines()
long_name = [str(int(names[0]) + 1)] + names[1:] + ['1 77 "' + "n" * 10000 + '"']
good("long_physical_name", replace_section(PAPER_MSH, "PhysicalNames", "\n".join(long_name) + "\n"))
s, e = section(PAPER_MSH, "Nodes")
scaled = [" ".join(f"{float(v) * 1e160:.17g}" for v in ln.split()) if len(ln.split()) == 3 else ln
          for ln in PAPER_MSH[s:e].splitlines()]     # coordinate lines have 3 numbers
big = replace_section(PAPER_MSH, "Nodes", "\n".join(scaled) + "\n")
bad("coordinates_overflow", big, [r"m\.msh", r"overflow"])
s, e = section(PAPER_MSH, "Entities")
no_ent = PAPER_MSH[:s - len("$Entities\n")] + PAPER_MSH[e + len("$EndEntities\n"):]
bad("missing_entities", no_ent, [r"m\.msh", r"\$Entities"])

# ---- 10. solid (3D) sections ---------------------------------------------------------------
# inputs/gmsh/blocks_3d.msh (hexahedra below, tetrahedra above) under the patch deck of
# test_gmsh_3d.py, corrupted: counts the file cannot hold, a tetrahedron listed twice (its
# nodes rotated, the same cell), a cell on a node the file does not have, a node tag 0,
# coordinates whose volume products overflow, no $Entities
BLOCKS = open(os.path.join(ROOT, "inputs", "gmsh", "blocks_3d.msh")).read()


def solid_deck(mesh):
    return ("&scene dimension=3 /\n"
            f"&body id=1, mesh='{mesh}', region='upper', young=2.1e11, poisson=0.3 /\n"
            f"&body id=2, mesh='{mesh}', region='lower', young=2.1e11, poisson=0.3 /\n"
            "&contact bodies=1,2, groups='upper_bottom','lower_top' /\n"
            "&boundary body=1, group='upper_x0', ux=0.0 /\n&boundary body=1, group='upper_z0', uz=0.0 /\n"
            "&boundary body=2, group='lower_x0', ux=0.0 /\n&boundary body=2, group='lower_z0', uz=0.0 /\n"
            "&boundary body=2, group='lower_bottom', uy=0.0 /\n"
            "&traction body=1, group='upper_top', pressure=1.0e6 /\n")


good("solid_as_shipped", BLOCKS, deck_of=solid_deck)
tet_head = "3 2 4 686\n"
bad("solid_count_beyond_file", BLOCKS.replace(tet_head, "3 2 4 686000000\n"), [r"m\.msh", r"686000000"],
    deck_of=solid_deck)
s, e = section(BLOCKS, "Elements")
lines = BLOCKS[s:e].splitlines()
nb, nt, lo, hi = map(int, lines[0].split())
first_tet = lines.index(tet_head.strip()) + 1
t = lines[first_tet].split()                       # tag a b c d: the same cell as (b c a d)
twice = [f"{nb} {nt + 1} {lo} {hi + 1}"] + lines[1:first_tet - 1] + ["3 2 4 687"] + lines[first_tet:] + \
    [f"{hi + 1} {t[2]} {t[3]} {t[1]} {t[4]}"]
bad("solid_tetrahedron_twice", replace_section(BLOCKS, "Elements", "\n".join(twice) + "\n"),
    [r"m\.msh", rf"\b{t[0]}\b", rf"\b{hi + 1}\b"], deck_of=solid_deck)
lost = list(lines)
lost[first_tet] = f"{t[0]} {t[1]} {t[2]} {t[3]} 99999"
bad("solid_node_missing", replace_section(BLOCKS, "Elements", "\n".join(lost) + "\n"), [r"m\.msh", r"99999"],
    deck_of=solid_deck)
zero = list(lines)
zero[first_tet] = f"{t[0]} {t[1]} {t[2]} {t[3]} 0"
bad("solid_node_zero", replace_section(BLOCKS, "Elements", "\n".join(zero) + "\n"), [r"m\.msh", r"\b0\b"],
    deck_of=solid_deck)
s, e = section(BLOCKS, "Nodes")
scaled = [" ".join(f"{float(v) * 1e120:.17g}" for v in ln.split()) if len(ln.split()) == 3 and "." in ln else ln
          for ln in BLOCKS[s:e].splitlines()]
bad("solid_coordinates_overflow", replace_section(BLOCKS, "Nodes", "\n".join(scaled) + "\n"),
    [r"m\.msh", r"overflow"], deck_of=solid_deck)
s, e = section(BLOCKS, "Entities")
bad("solid_missing_entities", BLOCKS[:s - len("$Entities\n")] + BLOCKS[e + len("$EndEntities\n"):],
    [r"m\.msh", r"\$Entities"], deck_of=solid_deck)

shutil.rmtree(TMP, ignore_errors=True)
if check.failed:
    print(f"test_hostile_mesh: {len(check.failed)} failed check(s)")
    sys.exit(1)
print("test_hostile_mesh: 0 failed check(s)")
