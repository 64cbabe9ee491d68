#!/usr/bin/python3
"""tools/paraview_view.py (run by `make check`): when ParaView's pvpython is installed
(Debian package `paraview`; headless it also needs xvfb-run, package `xvfb`), render a
solved result by its bare file name from the result folder (the case Debian's Xdmf3 readers
abort on without an absolute path), check the PNG is a real picture (not blank), that a
missing array exits 1 listing the available ones, that --list works, and that cell arrays
and a polyline grid without displacement (the XDMF layout being added: body id, contact
line) are handled. Without pvpython the test is skipped, and says so (exit 0)."""
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tools"))
from rc_common import Checks, run_solver  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.abspath(os.environ.get("BIN", "bin/robin_contact"))
OUT = os.path.abspath(os.path.join(os.environ.get("BUILD", "build/release"), "test-out", "paraview"))
TOOL = os.path.join(ROOT, "tools", "paraview_view.py")
check = Checks()

pv = shutil.which("pvpython")
if pv is None:
    print("SKIP  pvpython not found: ParaView is optional (Debian: apt-get install paraview xvfb); "
          "tools/paraview_view.py not tested")
    sys.exit(0)
if not (os.environ.get("DISPLAY") or os.environ.get("RC_PV_OFFSCREEN") or shutil.which("xvfb-run")):
    print("SKIP  pvpython found but no DISPLAY and no xvfb-run (apt-get install xvfb): cannot render here")
    sys.exit(0)

shutil.rmtree(OUT, ignore_errors=True)
os.makedirs(OUT)
p, res = run_solver(BIN, os.path.join(ROOT, "inputs/default.nml"), f"&output file='{OUT}/r.h5' /")
if not check(p.returncode == 0 and os.path.isfile(f"{OUT}/r.xdmf"), "default deck solved, r.xdmf written",
             f"exit {p.returncode}"):
    sys.exit(1)


def view(*args, cwd=OUT):
    q = subprocess.run([pv, TOOL, *args], cwd=cwd, capture_output=True, text=True, timeout=300)
    return q.returncode, q.stdout, q.stderr


def picture(path, what):
    """PNG exists and is not (almost) uniform: pixel standard deviation of the grey levels."""
    if not check(os.path.isfile(path), f"{what}: {os.path.basename(path)} written"):
        return
    import matplotlib.image as mpimg
    img = mpimg.imread(path)
    grey = img[..., :3].mean(axis=2) if img.ndim == 3 else img
    check(grey.std() > 0.05, f"{what}: picture is not blank (grey-level std {grey.std():.3f} > 0.05)",
          f"{img.shape[1]}x{img.shape[0]}")


# 1. bare file name from the result folder (absolute path passed to the reader)
rc, so, se = view("r.xdmf", "-o", "v.png")
check(rc == 0, "paraview_view.py r.xdmf (bare name, cwd = result folder) exits 0", f"exit {rc} {se.strip()[-300:]}")
check(re.search(r"wrote v.png \(von_mises, point data, colour .* Pa", so), "reports field, colour range and unit",
      so.strip())
picture(f"{OUT}/v.png", "von_mises")
# 2. the .h5 name, a vector component, element edges
rc, so, se = view(f"{OUT}/r.h5", "--field", "displacement:Y", "--edges", "-o", f"{OUT}/uy.png", cwd=ROOT)
check(rc == 0, "paraview_view.py r.h5 --field displacement:Y --edges exits 0", f"exit {rc} {se.strip()[-300:]}")
picture(f"{OUT}/uy.png", "displacement:Y")
# 3. a missing array: exit 1 and the list of arrays
rc, so, se = view("r.xdmf", "--field", "no_such_field", "-o", "x.png")
check(rc == 1 and "no array 'no_such_field'" in se and "point arrays:" in se and "von_mises" in se
      and "displacement" in se, "a missing array: exit 1, the available arrays listed", f"exit {rc}")
check(not os.path.exists(f"{OUT}/x.png"), "a missing array writes no picture")
rc, so, se = view("r.xdmf", "--list")
check(rc == 0 and "von_mises" in so and "cell arrays:" in so, "--list exits 0 and lists the arrays", so.strip())
rc, so, se = view("missing.xdmf")
check(rc == 1 and "no XDMF file" in se, "a missing file: exit 1 with a message", se.strip())

# 4. the XDMF layout being added: a cell array (body id) and a polyline grid without displacement
with open(f"{OUT}/r.xdmf") as f:
    s = f.read()
import h5py  # noqa: E402
with h5py.File(f"{OUT}/r.h5", "r") as f:
    ncell = [f[f"body{b}/cells"].shape[0] for b in (1, 2)]
    c = f["contact/coordinates"][()]
    pr = f["contact/pressure"][()]
for b in (1, 2):
    i = s.index(f'<Grid Name="body{b}"')
    j = s.index("</Grid>", i)
    s = s[:j] + (f'  <Attribute Name="body_id" AttributeType="Scalar" Center="Cell">\n'
                 f'          <DataItem Dimensions="{ncell[b - 1]}" NumberType="Int" Format="XML">'
                 f'{" ".join([str(b)] * ncell[b - 1])}</DataItem>\n        </Attribute>\n      ') + s[j:]
m = c.shape[1]
line = (f'  <Grid Name="contact_line" GridType="Uniform">\n'
        f'        <Topology TopologyType="Polyline" NodesPerElement="2" NumberOfElements="{m - 1}">\n'
        f'          <DataItem Dimensions="{m - 1} 2" NumberType="Int" Format="XML">'
        f'{" ".join(f"{k} {k + 1}" for k in range(m - 1))}</DataItem>\n        </Topology>\n'
        f'        <Geometry GeometryType="XYZ">\n          <DataItem Dimensions="{m} 3" NumberType="Float" '
        f'Precision="8" Format="XML">{" ".join(f"{c[0, k]!r} {c[1, k]!r} 0" for k in range(m))}</DataItem>\n'
        f'        </Geometry>\n        <Attribute Name="line_pressure" AttributeType="Scalar" Center="Node">\n'
        f'          <DataItem Dimensions="{m}" NumberType="Float" Precision="8" Format="XML">'
        f'{" ".join(repr(float(v)) for v in pr)}</DataItem>\n        </Attribute>\n      </Grid>\n    ')
k = s.rindex("</Grid>\n  </Domain>")
s = s[:k] + line + s[k:]
with open(f"{OUT}/future.xdmf", "w") as f:
    f.write(s)
rc, so, se = view("future.xdmf", "--list")
check(rc == 0 and re.search(r"cell arrays: .*body_id", so) and "line_pressure" in so,
      "future layout: body_id listed as a cell array, the contact-line array as a point array", so.strip())
rc, so, se = view("future.xdmf", "--field", "body_id", "-o", "body.png")
check(rc == 0 and "cell data" in so, "future layout: --field body_id (cell array) exits 0", f"exit {rc} {se.strip()[-300:]}")
picture(f"{OUT}/body.png", "body_id")
rc, so, se = view("future.xdmf", "--field", "line_pressure", "-o", "line.png")
check(rc == 0, "future layout: --field line_pressure (on the polyline grid only) exits 0",
      f"exit {rc} {se.strip()[-300:]}")

print(f"{len(check.failed)} failed checks")
sys.exit(1 if check.failed else 0)
