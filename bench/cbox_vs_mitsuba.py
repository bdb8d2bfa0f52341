#!/usr/bin/env python3
"""Side-by-side speed run: rpbrt on ../shared/scenes/mitsuba-cbox/cbox.pbrt
against Mitsuba 3 rendering the same box (mi.cornell_box(), 256x256, 64 spp,
independent sampler, max_depth 8 = pbrt maxdepth 7), in the same run.

    pip install mitsuba
    apt-get install libllvm19      # for the LLVM variants
    python3 bench/cbox_vs_mitsuba.py [--variants scalar_spectral,llvm_ad_spectral] [--threads 2]

Prints one RESULT line with every variant's time and its ratio to rpbrt's,
for each rpbrt design (--designs scalar,wavefront: --no-wavefront and
--wavefront; the default is the wavefront).
Each Mitsuba variant is timed on its render call after a warm-up render (the
LLVM variants JIT-compile there); rpbrt is timed as a whole process, the
median of --repeat runs interleaved with Mitsuba's (the machine drifts).
DRJIT_LIBLLVM_PATH defaults to Debian's libLLVM-19.so when it exists (Dr.Jit's
default LLVM lookup aborts on this machine).
"""
import argparse
import os
import statistics
import subprocess
import time

LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(LLVM19):
    os.environ["DRJIT_LIBLLVM_PATH"] = LLVM19

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)
scene = os.path.join(root, "..", "shared", "scenes", "mitsuba-cbox", "cbox.pbrt")

ap = argparse.ArgumentParser()
ap.add_argument("--variants", default="scalar_spectral,llvm_ad_spectral")
ap.add_argument("--threads", type=int, default=2)
ap.add_argument("--spp", type=int, default=64)
ap.add_argument("--repeat", type=int, default=3)
ap.add_argument("--rpbrt", default=os.path.join(root, "target", "release", "rpbrt"))
ap.add_argument("--designs", default="scalar,wavefront",
                help="rpbrt designs to time: scalar (--no-wavefront), wavefront (--wavefront)")
args = ap.parse_args()

if not os.path.exists(args.rpbrt):
    subprocess.run(["cargo", "build", "--release", "-q"], cwd=root, check=True)


def time_rpbrt(design):
    out = os.path.join("/tmp", "rpbrt-cbox-bench.exr")
    extra = ["--wavefront"] if design == "wavefront" else ["--no-wavefront"]
    t0 = time.perf_counter()
    subprocess.run([args.rpbrt, "--quiet", "--nthreads", str(args.threads), "--spp",
                    str(args.spp), "--outfile", out] + extra + [scene], check=True)
    return time.perf_counter() - t0


import drjit as dr  # noqa: E402
import mitsuba as mi  # noqa: E402


def mitsuba_renderer(variant):
    mi.set_variant(variant)
    dr.set_thread_count(args.threads)
    d = mi.cornell_box()
    d["sensor"]["film"]["width"] = 256
    d["sensor"]["film"]["height"] = 256
    d["sensor"]["sampler"] = {"type": "independent", "sample_count": args.spp}
    d["integrator"] = {"type": "path", "max_depth": 8}
    s = mi.load_dict(d)

    def render(seed):
        mi.set_variant(variant)
        t0 = time.perf_counter()
        img = mi.render(s, spp=args.spp, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        return time.perf_counter() - t0

    render(0)  # warm-up: JIT compilation for the LLVM variants
    return render


variants = [v for v in args.variants.split(",") if v]
renderers = {v: mitsuba_renderer(v) for v in variants}
designs = [d for d in args.designs.split(",") if d]
times = {f"rpbrt_{d}": [] for d in designs}
times.update({v: [] for v in variants})
for i in range(args.repeat):
    for d in designs:
        times[f"rpbrt_{d}"].append(time_rpbrt(d))
    for v in variants:
        times[v].append(renderers[v](i + 1))

med = {k: statistics.median(v) for k, v in times.items()}
fields = [f"scene=mitsuba-cbox spp={args.spp} threads={args.threads} repeat={args.repeat}"]
for d in designs:
    fields.append(f"rpbrt_{d}_s={med['rpbrt_' + d]:.2f}")
for v in variants:
    for d in designs:
        fields.append(f"ratio_{v}_over_rpbrt_{d}={med[v] / med['rpbrt_' + d]:.2f}")
    fields.insert(len(designs) + 1, f"mitsuba_{v}_s={med[v]:.2f}")
print("RESULT " + " ".join(fields))
