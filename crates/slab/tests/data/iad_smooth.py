"""Makes iad_smooth.csv: totals of smooth-faced slabs by iadpython's adding-doubling.

Run: python3 -m venv .venv && .venv/bin/pip install iadpython==0.5.3 scipy numpy
     .venv/bin/python crates/slab/tests/data/iad_smooth.py > crates/slab/tests/data/iad_smooth.csv

Quadrature points (column quad_pts): iadpython's diffuse totals through a
Fresnel face converge slowly in its points (URU for a = 0.5, tau = 40, g = 0,
n = 1.5: 0.135356 with 16, 0.136020 with 32, 0.136103 with 64), so faces with
n > 1 use 64 points (32 in each of its two cones). With one cone (n = 1)
iadpython 0.5.3 breaks down beyond about 32 points (a = 0.3, tau = 0.1, g = 0:
UTU = 0.854512 with 16 and 24 points, 0.854448 with 32, 1.348923 with 48,
0.329325 with 64), so n = 1 uses 24 points, where 16 and 24 agree to 1e-5.
"""
import itertools
import iadpython as iad

print("# iadpython %s adding-doubling, quad_pts in its column: a plane-parallel slab with smooth Fresnel faces of index n in air," % iad.__version__)
print("# one Henyey-Greenstein lobe g, single-scattering albedo, optical thickness (sigma_t d); made by iad_smooth.py beside this file")
print("albedo,optical_thickness,g,n,quad_pts,UR1,UT1,URU,UTU")
for a, b, g, n in itertools.product([0.3, 0.9, 0.99, 1.0], [0.1, 1.0, 8.0, 30.0], [0.0, 0.5, 0.85], [1.0, 1.33, 1.5]):
    q = 24 if n == 1.0 else 64
    s = iad.Sample(a=a, b=b, g=g, d=1.0, n=n, n_above=1.0, n_below=1.0, quad_pts=q)
    ur1, ut1, uru, utu = s.rt()
    print("%g,%g,%g,%g,%d,%.6f,%.6f,%.6f,%.6f" % (a, b, g, n, q, ur1, ut1, uru, utu))
