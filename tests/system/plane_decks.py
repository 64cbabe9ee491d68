"""Deck texts of plane scenes that more than one test runs (written by the tests into their
temporary folders)."""

# The paper's scene, body 1 on a roller (ux = 0 on its left side): held vertically only by
# contact, so a Robin run carries SMALBE multipliers for its rigid motion (about 25 outer
# iterations); the harmonic operator at delta = 0.5, tol = 1e-10.
PAPER_ROLLER = """&body id=1, x0=0.0, y0=1.0, width=3.0, height=1.0, nx=24, ny=16, young=2.1e11, poisson=0.277 /
&body id=2, x0=0.0, y0=0.0, width=3.0, height=1.0, nx=24, ny=16, young=2.1e11, poisson=0.277 /
&boundary body=1, group='left', ux=0.0 /
&boundary body=2, group='left', ux=0.0, uy=0.0 /
&traction body=1, side='top', t0=0.0, -3.0e6, t1=0.0, -1.0e6 /
&traction body=1, side='right', t0=0.0, 2.0e6 /
&contact body1_group='bottom', body2_group='top' /
&solver robin_operator='harmonic', delta=0.5, tol=1e-10 /
"""
