"""Deck texts of solid (3D) scenes that more than one test runs (written by the tests into
their temporary folders; the settings of &solver are each test's own)."""

# Three boxes stacked, two pairs, rollers on x = 0 and z = 0, the top pressed by 1 MPa: the
# contact patch test through two interfaces (every contact pressure 1e6 Pa), quadrilateral
# faces on triangles and triangles on quadrilaterals, no two surfaces matching
THREE_BOXES = """&scene title = 'three boxes, two pairs', dimension = 3 /
&body id = 1, x0 = 0.0, y0 = 2.0, z0 = 0.0, width = 1.0, height = 1.0, depth = 1.0, nx = 2, ny = 1, nz = 3,
      element = 'Q1', left = 'roller', front = 'roller' /
&body id = 2, x0 = 0.0, y0 = 1.0, z0 = 0.0, width = 1.0, height = 1.0, depth = 1.0, nx = 3, ny = 2, nz = 2,
      element = 'P1', left = 'roller', front = 'roller' /
&body id = 3, x0 = 0.0, y0 = 0.0, z0 = 0.0, width = 1.0, height = 1.0, depth = 1.0, nx = 2, ny = 1, nz = 2,
      element = 'Q1', left = 'roller', front = 'roller', bottom = 'roller' /
&traction body = 1, side = 'top', t0 = 0.0, -1.0e6, 0.0 /
&contact bodies = 1, 2, groups = 'bottom', 'top' /
&contact bodies = 2, 3, groups = 'bottom', 'top' /
"""
