"""Time Mitsuba 3's volpath (reference/tools/slabref.py) to a 1% standard error on one
in-plane BSDF value of devA (theta_i = 30, R at theta_o = 0), for comparison with
`cargo run --release -p paperbsdf-sim --example speed -- devA 262144`.

usage: python mitsuba_speed.py PATH/TO/reference [SPP BATCHES]
(needs `pip install mitsuba numpy`; run from anywhere)."""
import sys, os, json, time, resource
ref = sys.argv[1]
sys.path.insert(0, os.path.join(ref, 'tools'))
import slabref
spp = int(sys.argv[2]) if len(sys.argv) > 2 else 16384
batches = int(sys.argv[3]) if len(sys.argv) > 3 else 32
p = json.load(open(os.path.join(ref, 'devA.json')))
slabref.measure(p, 30, 0, False, 256, 2)  # load plugins once
r0 = resource.getrusage(resource.RUSAGE_SELF); t = time.time()
m, s = slabref.measure(p, 30, 0, False, spp, batches)
dt = time.time() - t; r1 = resource.getrusage(resource.RUSAGE_SELF)
cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
k = (s / m / 0.01) ** 2
print("mitsuba devA R(30,0) = %.5f +- %.5f (%.2f%%), %d samples: wall %.2f s, cpu %.2f s; to 1%%: wall %.2f s, cpu %.2f s"
      % (m, s, 100 * s / m, spp * batches, dt, cpu, dt * k, cpu * k))
