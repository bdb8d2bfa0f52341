"""``rpbrt-farm``: the command line."""

from __future__ import annotations

import argparse
import os
import sys
from typing import List, Optional

from .plan import plan_frame
from .render import FarmError, render_frames

USAGE_EPILOG = """\
Options after "--" go to every rpbrt run (e.g. -- --seed 3).

Without --scheduler a LocalCluster of --workers processes starts on this
machine. With --scheduler tcp://host:8786 the render runs on that cluster;
its workers need the rpbrt binary (their PATH, or --worker-rpbrt) and either
a shared file system holding the scene (--ship never) or nothing (--ship
always; "auto" ships scene folders up to 256 MiB with the tasks).

Tiles suit the path-tracing integrators; bdpt, lightpath and light-tracing
splats cross tile edges, so split those with --ranges (sample ranges).
"""


def parse_args(argv: Optional[List[str]] = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="rpbrt-farm",
        description="Render rpbrt frames across a Dask cluster, bit-identical to one rpbrt run.",
        epilog=USAGE_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("scenes", nargs="+", help="scene file (several with --frames)")
    split = p.add_mutually_exclusive_group()
    split.add_argument("--tiles", type=int, help="split each frame into this many tiles (default 64)")
    split.add_argument("--ranges", type=int, help="split each frame's samples into this many ranges (needs --spp)")
    p.add_argument("--spp", type=int, help="samples per pixel (overrides the scene's Sampler)")
    p.add_argument("--outfile", help="output image; with --frames a pattern with {frame} (default: <scene>.exr)")
    p.add_argument("--frames", action="store_true", help="render every scene file as one frame of a sequence")
    p.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://host:8786)")
    p.add_argument("--workers", type=int, default=None, help="LocalCluster worker processes (default: cores)")
    p.add_argument("--threads", type=int, default=1, help="rpbrt threads per task (default 1)")
    p.add_argument("--rpbrt", help="the rpbrt binary on this machine (default: PATH)")
    p.add_argument("--worker-rpbrt", help="the rpbrt binary on the workers (default: --rpbrt, else their PATH)")
    p.add_argument("--ship", choices=["auto", "always", "never"], default="auto",
                   help="send the scene's folder with the tasks (default auto: folders up to 256 MiB)")
    p.add_argument("--no-reuse", action="store_true",
                   help="one rpbrt run per part (default: each worker parses a scene once and "
                        "renders all its parts of it in one rpbrt --serve-parts process)")
    p.add_argument("--retries", type=int, default=2, help="retries of a failed part (default 2)")
    p.add_argument("--denoise", action="store_true",
                   help="record albedo and normal in the parts, then denoise each joined frame with "
                        "Intel Open Image Denoise (pip install pyoidn); the raw frame is kept as "
                        "<name>-noisy.exr")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    argv = list(sys.argv[1:] if argv is None else argv)
    # After "--": more rpbrt options for every part (e.g. -- --seed 3).
    rpbrt_args: List[str] = []
    if "--" in argv:
        cut = argv.index("--")
        argv, rpbrt_args = argv[:cut], argv[cut + 1:]
    args = p.parse_args(argv)
    args.rpbrt_args = rpbrt_args
    if len(args.scenes) > 1 and not args.frames:
        p.error("several scene files render as a sequence only with --frames")
    if args.tiles is None and args.ranges is None:
        args.tiles = 64
    return args


def output_names(args: argparse.Namespace) -> List[str]:
    if not args.frames:
        return [args.outfile or os.path.splitext(os.path.basename(args.scenes[0]))[0] + ".exr"]
    if args.outfile is None:
        return [os.path.splitext(os.path.basename(s))[0] + ".exr" for s in args.scenes]
    if "{frame" not in args.outfile:
        raise FarmError("with --frames, --outfile needs {frame} (e.g. frame-{frame:04d}.exr)")
    return [args.outfile.format(frame=i) for i in range(len(args.scenes))]


def main(argv: Optional[List[str]] = None) -> int:
    args = parse_args(argv)
    try:
        parts = plan_frame(args.tiles, args.ranges, args.spp)
        outfiles = output_names(args)
        extra = list(args.rpbrt_args)
        if args.spp is not None:
            extra = ["--spp", str(args.spp), *extra]
        extra = ["--nthreads", str(args.threads), *extra]
        from distributed import Client, LocalCluster

        if args.scheduler:
            client = Client(args.scheduler)
            cluster = None
        else:
            n = args.workers or os.cpu_count() or 1
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                   dashboard_address=":0")
            client = Client(cluster)
        if not args.quiet and client.dashboard_link:
            print(f"rpbrt-farm: Dask dashboard at {client.dashboard_link}", file=sys.stderr)
        try:
            worker_rpbrt = args.worker_rpbrt
            if worker_rpbrt is None and args.rpbrt:
                worker_rpbrt = os.path.abspath(args.rpbrt)
            written = render_frames(
                client, args.scenes, parts, outfiles,
                rpbrt=args.rpbrt, worker_rpbrt=worker_rpbrt, extra_args=extra,
                ship=args.ship, retries=args.retries, reuse=not args.no_reuse,
                progress=None if args.quiet else sys.stderr,
                denoise=args.denoise,
            )
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
        if not args.quiet:
            for w in written:
                print(f"rpbrt-farm: wrote {w}", file=sys.stderr)
        return 0
    except (FarmError, ValueError) as e:
        print(f"rpbrt-farm: error: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
