#!/usr/bin/env python3
"""Denoising quality and cost (issue 31): renders ../shared/scenes'
cornell-box, killeroos and veach-mis reference variants at several sample
counts with `rpbrt --denoise`, denoises the same raw renders from their
colour alone (`imgtool denoise --color-only`), and prints the relative MSE
of each against pbrt-v4's high-sample reference beside the scene:

    relMSE = mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01)

It also denoises them with the albedo and normal passed as they are
(`imgtool denoise --noisy-aux`), times `imgtool denoise` per megapixel for
each quality setting and mode, and checks, through PyPI's pyoidn (the same
library, driven from Python), that the colour-only and noisy-auxiliary
inputs and options are passed right: each pair of outputs must agree to
float rounding.

    pip install pyoidn numpy
    python3 bench/denoise_quality.py [--spp 4,16,64] [--rpbrt target/release/rpbrt]
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)
scenes_dir = os.path.join(root, "..", "shared", "scenes")
SCENES = [
    ("cornell-box", "ref-256.pbrt", "ref-256-pbrtv4-1024spp.exr"),
    ("killeroos", "ref-256.pbrt", None),
    ("veach-mis", "ref-320.pbrt", None),
]

ap = argparse.ArgumentParser()
ap.add_argument("--spp", default="4,16,64")
ap.add_argument("--rpbrt", default=os.path.join(root, "target", "release", "rpbrt"))
ap.add_argument("--threads", type=int, default=2)
args = ap.parse_args()
tmp = tempfile.mkdtemp(prefix="rpbrt-denoise-")


def run(cmd):
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)


def read_rgb(path, channels="R,G,B"):
    """R, G, B (or three other `channels`) of any image rpbrt reads, as an
    (h, w, 3) float32 array."""
    pfm = os.path.join(tmp, "read.pfm")
    run([args.rpbrt, "imgtool", "convert", "--channels", channels, path, pfm])
    with open(pfm, "rb") as f:
        assert f.readline().strip() == b"PF"
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    # PFM rows run bottom to top.
    return data.reshape(h, w, 3)[::-1].astype(np.float32)


def rel_mse(x, ref):
    return float(np.mean((x - ref) ** 2 / (ref ** 2 + 0.01)))


def reference(scene_dir, given):
    if given:
        return os.path.join(scene_dir, given)
    refs = sorted(f for f in os.listdir(scene_dir) if "pbrtv4" in f and f.endswith(".exr"))
    return os.path.join(scene_dir, refs[-1])


spps = [int(s) for s in args.spp.split(",")]
print("scene spp relMSE_noisy relMSE_color_only relMSE_color_albedo_normal "
      "relMSE_noisy_aux render_s denoise_s")
for name, file, ref in SCENES:
    d = os.path.join(scenes_dir, name)
    ref_rgb = read_rgb(reference(d, ref))
    for spp in spps:
        out = os.path.join(tmp, f"{name}-{spp}.exr")
        t0 = time.perf_counter()
        run([args.rpbrt, "--quiet", "--nthreads", str(args.threads), "--spp", str(spp),
             "--outfile", out, os.path.join(d, file)])
        t_render = time.perf_counter() - t0
        t0 = time.perf_counter()
        run([args.rpbrt, "--quiet", "--nthreads", str(args.threads), "--spp", str(spp),
             "--denoise", "--outfile", out, os.path.join(d, file)])
        t_both = time.perf_counter() - t0
        noisy = out.replace(".exr", "-noisy.exr")
        color_only = os.path.join(tmp, f"{name}-{spp}-color.exr")
        run([args.rpbrt, "imgtool", "denoise", "--color-only", noisy, "--outfile", color_only])
        noisy_aux = os.path.join(tmp, f"{name}-{spp}-noisy-aux.exr")
        run([args.rpbrt, "imgtool", "denoise", "--noisy-aux", noisy, "--outfile", noisy_aux])
        print(f"{name} {spp} {rel_mse(read_rgb(noisy), ref_rgb):.5f} "
              f"{rel_mse(read_rgb(color_only), ref_rgb):.5f} {rel_mse(read_rgb(out), ref_rgb):.5f} "
              f"{rel_mse(read_rgb(noisy_aux), ref_rgb):.5f} "
              f"{t_render:.2f} {t_both - t_render:.2f}", flush=True)

# Time per megapixel: the Cornell box's 16-spp raw render, each pixel
# repeated 4x4 (1024x1024, every channel kept).
small = os.path.join(tmp, f"cornell-box-{spps[min(1, len(spps) - 1)]}-noisy.exr")
noisy = os.path.join(tmp, "big-noisy.exr")
run([args.rpbrt, "imgtool", "convert", "--repeatpix", "4", small, noisy])
mpix = read_rgb(noisy).shape[0] * read_rgb(noisy).shape[1] / 1e6
for q in ["fast", "balanced", "high"]:
    for mode in [[], ["--noisy-aux"], ["--color-only"]]:
        t0 = time.perf_counter()
        run([args.rpbrt, "imgtool", "denoise", "--quality", q, *mode, noisy,
             "--outfile", os.path.join(tmp, "q.exr")])
        dt = time.perf_counter() - t0
        label = {"--color-only": "color-only", "--noisy-aux": "color+noisy albedo+normal"}
        print(f"quality {q} {label.get(mode[0], '?') if mode else 'color+albedo+normal'}: "
              f"{dt / mpix:.2f} s per megapixel ({mpix:.3f} MP, whole command)")

# The same colour-only denoise through pyoidn.
try:
    import pyoidn
except ImportError:
    print("pyoidn not installed: skipping the comparison")
    sys.exit(0)
name, spp = SCENES[0][0], spps[0]
noisy = os.path.join(tmp, f"{name}-{spp}-noisy.exr")
ours = read_rgb(os.path.join(tmp, f"{name}-{spp}-color.exr"))
color = read_rgb(noisy)
color[~np.isfinite(color).all(axis=2)] = 0
theirs = pyoidn.denoise(np.ascontiguousarray(color), hdr=True, quality="high")
print(f"pyoidn colour-only against imgtool denoise --color-only ({name}, {spp} spp): "
      f"max |difference| {float(np.max(np.abs(theirs - ours))):.3e}, "
      f"max value {float(np.max(np.abs(ours))):.3e}")

# The same noisy-auxiliary denoise (colour, albedo clamped to [0, 1] and
# normal, as they are) through pyoidn.
ours = read_rgb(os.path.join(tmp, f"{name}-{spp}-noisy-aux.exr"))
albedo = np.clip(read_rgb(noisy, "Albedo.R,Albedo.G,Albedo.B"), 0, 1)
normal = read_rgb(noisy, "Ns.X,Ns.Y,Ns.Z")
theirs = pyoidn.denoise(np.ascontiguousarray(color), np.ascontiguousarray(albedo),
                        np.ascontiguousarray(normal), hdr=True, quality="high")
print(f"pyoidn noisy-aux against imgtool denoise --noisy-aux ({name}, {spp} spp): "
      f"max |difference| {float(np.max(np.abs(theirs - ours))):.3e}")
