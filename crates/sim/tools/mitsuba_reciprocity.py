"""Reciprocity of Mitsuba 3's brute-force slab (reference/tools/slabref.py) for devA at grazing
light: R(75 -> 0) against R(0 -> 75) and variants. The physical slab is reciprocal
(eta_f = eta_b); the reference devA.csv rows R at theta_i = 75 are not.

usage: python mitsuba_reciprocity.py PATH/TO/reference"""
import sys, os, json, time
ref = sys.argv[1]
sys.path.insert(0, os.path.join(ref, 'tools'))
import slabref
base = json.load(open(os.path.join(ref, 'devA.json')))
for name, ch in [('devA', {}), ('sigma_s=0', dict(sigma_s=0.0)), ('d=0.01', dict(d=0.01))]:
    p = dict(base); p.update(ch)
    for ti, to in [(75, 0), (0, 75), (75, 60), (60, 75)]:
        t = time.time(); m, s = slabref.measure(p, ti, to, False, 16384, 8)
        print('%-10s R(%d -> %d) = %.5f +- %.5f  (%.1f s)' % (name, ti, to, m, s, time.time() - t), flush=True)
