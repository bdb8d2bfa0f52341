"""The farm against a real Dask LocalCluster of worker processes: tiles and
sample ranges join bit-identically to one rpbrt run, a worker killed while
it holds a part costs nothing, and a part that fails every retry fails the
render with rpbrt's message.

The rpbrt binary comes from $RPBRT_BIN, else the repository's
target/release or target/debug build."""

from __future__ import annotations

import os
import signal
import subprocess
import threading
import time

import pytest

from rpbrt_farm import FarmError, plan_frame, render_frames
from rpbrt_farm.cli import main as farm_main

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(REPO, "scenes", "default.pbrt")


def rpbrt_binary() -> str:
    env = os.environ.get("RPBRT_BIN")
    if env:
        assert os.path.isfile(env), f"RPBRT_BIN={env} does not exist"
        return env
    for profile in ("release", "debug"):
        p = os.path.join(REPO, "target", profile, "rpbrt")
        if os.path.isfile(p):
            return p
    pytest.skip("no rpbrt binary: run `cargo build --release` first or set RPBRT_BIN")


@pytest.fixture(scope="module")
def rpbrt():
    return rpbrt_binary()


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=":0")
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


def single_render(rpbrt: str, out: str, spp: int) -> None:
    subprocess.run([rpbrt, "--quiet", "--spp", str(spp), "--outfile", out, SCENE], check=True)


def differing_pixels(rpbrt: str, a: str, b: str) -> int:
    out = subprocess.run([rpbrt, "imgtool", "diff", a, b], check=True,
                         capture_output=True, text=True).stdout
    line = next(l for l in out.splitlines() if l.startswith("differing pixels: "))
    return int(line.split(": ")[1])


def test_plan_splits_exactly():
    tiles = plan_frame(8, None, None)
    assert [p.rpbrt_args() for p in tiles[:2]] == [["--tile", "0/8"], ["--tile", "1/8"]]
    ranges = plan_frame(None, 3, 8)
    assert [(p.start, p.end) for p in ranges] == [(0, 2), (2, 5), (5, 8)]
    with pytest.raises(ValueError):
        plan_frame(None, 4, None)
    with pytest.raises(ValueError):
        plan_frame(None, 9, 8)
    with pytest.raises(ValueError):
        plan_frame(0, None, None)


@pytest.mark.parametrize("ship,reuse", [("always", True), ("never", True), ("always", False)])
def test_tiles_and_ranges_are_bit_identical(rpbrt, client, tmp_path, ship, reuse):
    spp = 4
    full = str(tmp_path / "full.exr")
    single_render(rpbrt, full, spp)
    for parts in (plan_frame(8, None, None), plan_frame(None, 4, spp)):
        out = str(tmp_path / f"farm-{parts[0].kind}.exr")
        render_frames(client, [SCENE], parts, [out], rpbrt=rpbrt, worker_rpbrt=rpbrt,
                      extra_args=["--spp", str(spp), "--nthreads", "1"], ship=ship,
                      reuse=reuse, progress=None)
        assert differing_pixels(rpbrt, out, full) == 0, parts[0].kind


@pytest.mark.parametrize("split", ["tiles", "ranges"])
def test_denoise_joins_the_parts_then_denoises(rpbrt, client, tmp_path, split):
    """--denoise: the parts record albedo and normal, the joined raw frame
    (kept as <name>-noisy.exr) has one rpbrt run's colour, and the output
    is its denoised image. Skipped where there is no Open Image Denoise."""
    spp = 4
    full = str(tmp_path / "full.exr")
    single_render(rpbrt, full, spp)
    parts = plan_frame(4, None, None) if split == "tiles" else plan_frame(None, 2, spp)
    out = str(tmp_path / "den.exr")
    if split == "ranges":
        with pytest.raises(FarmError, match="--denoise needs tiles"):
            render_frames(client, [SCENE], parts, [out], rpbrt=rpbrt, progress=None, denoise=True)
        return
    try:
        render_frames(client, [SCENE], parts, [out], rpbrt=rpbrt, worker_rpbrt=rpbrt,
                      extra_args=["--spp", str(spp), "--nthreads", "1"], progress=None,
                      denoise=True)
    except FarmError as e:
        if "pip install pyoidn" in str(e):
            pytest.skip(f"no Open Image Denoise here: {e}")
        raise
    noisy = str(tmp_path / "den-noisy.exr")
    assert differing_pixels(rpbrt, full, noisy) == 0
    info = subprocess.run([rpbrt, "imgtool", "info", noisy], check=True,
                          capture_output=True, text=True).stdout
    assert "Albedo.R" in info and "Ns.Z" in info
    assert differing_pixels(rpbrt, out, full) > 0


def test_a_killed_worker_loses_nothing(rpbrt, client, tmp_path):
    spp = 32
    full = str(tmp_path / "full.exr")
    single_render(rpbrt, full, spp)
    pids_before = client.run(os.getpid)
    killed = {}

    def kill_a_busy_worker(_futures):
        def run():
            deadline = time.monotonic() + 60
            while time.monotonic() < deadline:
                busy = {w: keys for w, keys in client.processing().items() if keys}
                if busy:
                    worker = sorted(busy)[0]
                    pid = pids_before[worker]
                    os.kill(pid, signal.SIGKILL)
                    killed["pid"] = pid
                    killed["parts"] = busy[worker]
                    return
                time.sleep(0.02)
        threading.Thread(target=run, daemon=True).start()

    out = str(tmp_path / "farm.exr")
    render_frames(client, [SCENE], plan_frame(6, None, None), [out], rpbrt=rpbrt,
                  worker_rpbrt=rpbrt, extra_args=["--spp", str(spp), "--nthreads", "1"],
                  progress=None, on_submitted=kill_a_busy_worker)
    assert killed, "no worker was ever seen holding a part"
    assert killed["pid"] not in client.run(os.getpid).values()
    assert differing_pixels(rpbrt, out, full) == 0


@pytest.mark.parametrize("reuse", [True, False])
def test_a_failing_part_fails_the_render_with_rpbrts_message(rpbrt, client, tmp_path, reuse):
    bad = tmp_path / "bad.pbrt"
    bad.write_text('Film "rgb" "integer xresolution" 16 "integer yresolution" 16\n'
                   'WorldBegin\nShape "sphere" "float radius" "big"\n')
    with pytest.raises(FarmError) as e:
        render_frames(client, [str(bad)], plan_frame(2, None, None), [str(tmp_path / "x.exr")],
                      rpbrt=rpbrt, worker_rpbrt=rpbrt, retries=1, reuse=reuse, progress=None)
    msg = str(e.value)
    assert "bad.pbrt:3:" in msg and "failed 2 times" in msg, msg


def test_command_line_sequence(rpbrt, tmp_path):
    scenes = []
    for i, color in enumerate(["0.8 0.2 0.2", "0.2 0.8 0.2"]):
        s = tmp_path / f"f{i}.pbrt"
        s.write_text('LookAt 0 0 -3 0 0 0 0 1 0\nCamera "perspective"\n'
                     'Film "rgb" "integer xresolution" 24 "integer yresolution" 16\n'
                     'Sampler "zsobol" "integer pixelsamples" 4\nWorldBegin\n'
                     'LightSource "infinite" "rgb L" [1 1 1]\n'
                     f'Material "diffuse" "rgb reflectance" [{color}]\nShape "sphere"\n')
        scenes.append(str(s))
    pattern = str(tmp_path / "frame-{frame:02d}.exr")
    rc = farm_main([*scenes, "--frames", "--tiles", "3", "--workers", "2", "--rpbrt", rpbrt,
                    "--outfile", pattern, "--quiet", "--", "--seed", "7"])
    assert rc == 0
    for i, s in enumerate(scenes):
        ref = str(tmp_path / f"ref{i}.exr")
        subprocess.run([rpbrt, "--quiet", "--seed", "7", "--outfile", ref, s], check=True)
        assert differing_pixels(rpbrt, pattern.format(frame=i), ref) == 0
    # Bad arguments: a clear message and status 1.
    assert farm_main([scenes[0], "--ranges", "2", "--rpbrt", rpbrt, "--quiet"]) == 1
