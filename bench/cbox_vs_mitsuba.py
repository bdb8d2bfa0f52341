#!/usr/bin/env python3
"""Side-by-side speed run: rpbrt on ../shared/scenes/mitsuba-cbox/cbox.pbrt
against Mitsuba 3 rendering the same box (mi.cornell_box(), 256x256, 64 spp,
independent sampler, max_depth 8 = pbrt maxdepth 7), in the same run.

    pip install mitsuba
    python3 bench/cbox_vs_mitsuba.py [--variant scalar_spectral] [--threads 2]

Prints one RESULT line. Mitsuba is timed on its render call after a warm-up
render (as the issue asks); rpbrt is timed as a whole process.
"""
import argparse
import os
import subprocess
import sys
import time

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)
scene = os.path.join(root, "..", "shared", "scenes", "mitsuba-cbox", "cbox.pbrt")

ap = argparse.ArgumentParser()
ap.add_argument("--variant", default="scalar_spectral")
ap.add_argument("--threads", type=int, default=2)
ap.add_argument("--spp", type=int, default=64)
args = ap.parse_args()

binary = os.path.join(root, "target", "release", "rpbrt")
if not os.path.exists(binary):
    subprocess.run(["cargo", "build", "--release", "-q"], cwd=root, check=True)

out = os.path.join("/tmp", "rpbrt-cbox-bench.exr")
t0 = time.perf_counter()
subprocess.run([binary, "--quiet", "--nthreads", str(args.threads), "--spp", str(args.spp),
                "--outfile", out, scene], check=True)
t_rpbrt = time.perf_counter() - t0

import mitsuba as mi  # noqa: E402

mi.set_variant(args.variant)
try:
    import drjit as dr
    dr.set_thread_count(args.threads)
except Exception:
    pass
d = mi.cornell_box()
d["sensor"]["film"]["width"] = 256
d["sensor"]["film"]["height"] = 256
d["sensor"]["sampler"] = {"type": "independent", "sample_count": args.spp}
d["integrator"] = {"type": "path", "max_depth": 8}
s = mi.load_dict(d)
mi.render(s, spp=args.spp)  # warm-up (JIT compilation for the LLVM variants)
t0 = time.perf_counter()
img = mi.render(s, spp=args.spp)
try:
    dr.eval(img)
    dr.sync_thread()
except Exception:
    pass
t_mi = time.perf_counter() - t0

print(f"RESULT scene=mitsuba-cbox spp={args.spp} threads={args.threads} rpbrt_s={t_rpbrt:.2f} "
      f"mitsuba_{args.variant}_s={t_mi:.2f} ratio_mitsuba_over_rpbrt={t_mi / t_rpbrt:.2f}")
