"""The client side: submit a frame's parts to Dask, follow them, join them."""

from __future__ import annotations

import hashlib
import io
import os
import shutil
import subprocess
import sys
import tarfile
import tempfile
import time
import uuid
from typing import Callable, Dict, List, Optional, Sequence, TextIO

from .plan import Part
from .task import RenderTaskError, TaskSpec, close_session, render_part

#: Scenes whose folder is at most this large are shipped with the tasks
#: when shipping is "auto"; larger ones are read by path.
SHIP_LIMIT_BYTES = 256 * 1024 * 1024


class FarmError(RuntimeError):
    """A frame could not be rendered: a part failed every retry, or the
    parts could not be joined."""


def folder_size(path: str) -> int:
    """Bytes in the files under ``path``."""
    total = 0
    for root, _dirs, files in os.walk(path):
        for f in files:
            p = os.path.join(root, f)
            if os.path.isfile(p) and not os.path.islink(p):
                total += os.path.getsize(p)
    return total


def pack_folder(path: str) -> bytes:
    """The folder as a gzipped tar (files and folders only)."""
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w:gz", compresslevel=1) as tar:
        for root, dirs, files in os.walk(path):
            dirs.sort()
            for f in sorted(files):
                p = os.path.join(root, f)
                if os.path.isfile(p) and not os.path.islink(p):
                    tar.add(p, arcname=os.path.relpath(p, path))
    return buf.getvalue()


def should_ship(scene: str, ship: str) -> bool:
    """Whether the scene's folder travels with the tasks: "always",
    "never", or "auto" (when the folder is at most SHIP_LIMIT_BYTES)."""
    if ship == "always":
        return True
    if ship == "never":
        return False
    return folder_size(os.path.dirname(os.path.abspath(scene))) <= SHIP_LIMIT_BYTES


class Progress:
    """A one-line progress bar over parts with elapsed time and ETA."""

    def __init__(self, total: int, stream: Optional[TextIO]):
        self.total = total
        self.done = 0
        self.start = time.monotonic()
        self.stream = stream

    def step(self, label: str) -> None:
        self.done += 1
        if self.stream is None:
            return
        elapsed = time.monotonic() - self.start
        eta = elapsed / self.done * (self.total - self.done)
        width = 30
        filled = width * self.done // self.total
        bar = "#" * filled + "." * (width - filled)
        self.stream.write(
            f"\r[{bar}] {self.done}/{self.total} parts  {_clock(elapsed)} elapsed, "
            f"ETA {_clock(eta)}  ({label})\x1b[K"
        )
        if self.done == self.total:
            self.stream.write("\n")
        self.stream.flush()


def _clock(seconds: float) -> str:
    s = int(round(seconds))
    return f"{s // 3600}:{s % 3600 // 60:02d}:{s % 60:02d}" if s >= 3600 else f"{s // 60}:{s % 60:02d}"


def find_rpbrt(path: Optional[str]) -> str:
    """The rpbrt binary the client joins parts with."""
    found = path if path else shutil.which("rpbrt")
    if not found or not os.path.isfile(found):
        raise FarmError(
            f"rpbrt binary {'not found on PATH' if not path else path + ' not found'}"
            " (install it or give --rpbrt)"
        )
    return os.path.abspath(found)


def join_parts(rpbrt: str, kind: str, files: Sequence[str], outfile: str) -> None:
    """Joins part files with ``rpbrt imgtool assemble`` (tiles) or
    ``merge`` (sample ranges) into ``outfile``."""
    cmd = [rpbrt, "imgtool", "assemble" if kind == "tile" else "merge", "--outfile", outfile, *files]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise FarmError(f"joining the parts into {outfile} failed: {proc.stderr.strip()}")


def noisy_name(outfile: str) -> str:
    """Where a denoised frame's raw (joined) render goes: beside it, as
    ``<stem>-noisy.exr`` (rpbrt --denoise's name)."""
    stem = os.path.splitext(os.path.basename(outfile))[0]
    return os.path.join(os.path.dirname(outfile), f"{stem}-noisy.exr")


def denoise_frame(rpbrt: str, raw: str, outfile: str) -> None:
    """Denoises the joined ``raw`` frame (with its albedo and normal) into
    ``outfile`` with ``rpbrt imgtool denoise``."""
    proc = subprocess.run([rpbrt, "imgtool", "denoise", raw, "--outfile", outfile],
                          capture_output=True, text=True)
    if proc.returncode != 0:
        raise FarmError(f"denoising {raw} failed: {proc.stderr.strip()}")
    if proc.stderr.strip():
        print(proc.stderr.strip(), file=sys.stderr)


def render_frames(
    client,
    scenes: Sequence[str],
    parts: Sequence[Part],
    outfiles: Sequence[str],
    *,
    rpbrt: Optional[str] = None,
    worker_rpbrt: Optional[str] = None,
    extra_args: Sequence[str] = (),
    ship: str = "auto",
    retries: int = 2,
    reuse: bool = True,
    progress: Optional[TextIO] = sys.stderr,
    on_submitted: Optional[Callable[[List], None]] = None,
    denoise: bool = False,
) -> List[str]:
    """Renders each scene in ``scenes`` as one frame split into ``parts`` on
    the Dask ``client``'s cluster, writing frame i to ``outfiles[i]``.

    ``rpbrt`` is the client's binary (for joining); ``worker_rpbrt`` the
    workers' (None: their PATH). ``extra_args`` go to every rpbrt run (e.g.
    ``--spp 64``). A part that fails is retried ``retries`` times on any
    worker (a worker that dies mid-part loses nothing: the scheduler
    reschedules it); a part that fails every try raises FarmError with
    rpbrt's message. With ``reuse`` each worker parses a scene once and
    renders all its parts of it in one ``rpbrt --serve-parts`` process.
    ``on_submitted`` hears the futures once submitted. With ``denoise``
    the parts record albedo and normal (``rpbrt --gbuffer``), and each
    joined frame is written as ``<stem>-noisy.exr`` and denoised into its
    output name (``rpbrt imgtool denoise``; Open Image Denoise must be on
    this machine: ``pip install pyoidn``).
    """
    if len(scenes) != len(outfiles):
        raise FarmError("one output file per scene is needed")
    local_rpbrt = find_rpbrt(rpbrt)
    if denoise and parts and parts[0].kind != "tile":
        raise FarmError("--denoise needs tiles (--tiles): sample ranges keep only the rgb film's "
                        "sums, not the albedo and normal")
    session = uuid.uuid4().hex
    futures = []
    meta: Dict[object, tuple] = {}
    for frame, scene in enumerate(scenes):
        if not os.path.isfile(scene):
            raise FarmError(f"{scene}: no such scene file")
        archive = None
        archive_id = None
        scene_ref = os.path.abspath(scene)
        if should_ship(scene, ship):
            folder = os.path.dirname(scene_ref)
            packed = pack_folder(folder)
            archive_id = hashlib.sha256(packed).hexdigest()
            # Sent once to every worker, not once per task.
            archive = client.scatter(packed, broadcast=True)
            scene_ref = os.path.relpath(scene_ref, folder)
        for part in parts:
            label = f"{os.path.basename(scene)}: {part.label()}"
            args = (*extra_args, "--gbuffer") if denoise else tuple(extra_args)
            spec = TaskSpec(worker_rpbrt, scene_ref, args, tuple(part.rpbrt_args()),
                            label, archive_id, reuse, session)
            fut = client.submit(
                render_part,
                spec,
                archive,
                retries=retries,
                pure=False,
                key=f"rpbrt-{frame}-{part.kind}-{part.index}-{os.getpid()}-{time.monotonic_ns()}",
            )
            futures.append(fut)
            meta[fut.key] = (frame, part, label)
    if on_submitted is not None:
        on_submitted(futures)

    from distributed import as_completed

    bar = Progress(len(futures), progress)
    results: Dict[int, Dict[int, bytes]] = {i: {} for i in range(len(scenes))}
    try:
        for fut in as_completed(futures):
            frame, part, label = meta[fut.key]
            try:
                data = fut.result()
            except RenderTaskError as e:
                raise FarmError(f"{e} (failed {retries + 1} times)") from None
            except Exception as e:  # a worker lost too often, a cancelled task
                raise FarmError(f"{label}: {type(e).__name__}: {e}") from None
            results[frame][part.index] = data
            bar.step(label)
    except BaseException:
        client.cancel(futures)
        raise
    finally:
        if reuse:
            try:
                client.run(close_session, session)
            except Exception:
                pass  # workers gone: their processes ended with them

    written = []
    for frame, outfile in enumerate(outfiles):
        with tempfile.TemporaryDirectory(prefix="rpbrt-farm-join-") as tmp:
            files = []
            for part in parts:
                p = os.path.join(tmp, f"part-{part.index:05d}.exr")
                with open(p, "wb") as f:
                    f.write(results[frame][part.index])
                files.append(p)
            joined = noisy_name(outfile) if denoise else outfile
            join_parts(local_rpbrt, parts[0].kind, files, joined)
        if denoise:
            denoise_frame(local_rpbrt, joined, outfile)
        written.append(outfile)
    return written
