"""The worker side: render one part with the rpbrt binary and return its EXR.

By default a worker keeps one ``rpbrt --serve-parts`` process per scene
(and per set of render options): the scene is parsed and its BVH built once
per worker, and every part that worker gets is a line on that process's
stdin. With ``reuse`` off, each part is a fresh ``rpbrt`` run.

This module is imported on the workers, so it needs nothing but the
standard library there.
"""

from __future__ import annotations

import atexit
import io
import os
import shutil
import subprocess
import tarfile
import tempfile
import threading
from dataclasses import dataclass
from typing import Dict, List, Optional, Tuple


class RenderTaskError(RuntimeError):
    """rpbrt failed on a part: the message carries rpbrt's own error."""


@dataclass(frozen=True)
class TaskSpec:
    """Everything a worker needs to render one part."""

    #: The rpbrt binary on the worker (None: found on the worker's PATH).
    rpbrt: Optional[str]
    #: The scene file: an absolute path (shared file system), or a path
    #: inside the shipped archive.
    scene: str
    #: Render options for every part of the frame (e.g. --spp 64).
    args: Tuple[str, ...]
    #: The flags selecting this part (--tile K/N or --spp-range A..B).
    part_args: Tuple[str, ...]
    #: A label for error messages.
    label: str
    #: Identifies the shipped archive (its digest), if the scene is shipped.
    archive_id: Optional[str] = None
    #: Keep one rpbrt process per scene on the worker (parse once).
    reuse: bool = True
    #: The render these parts belong to: processes are shared only within
    #: one render (a scene edited between renders is parsed anew) and
    #: closed by close_session when it ends.
    session: str = ""


def _find_rpbrt(path: Optional[str]) -> str:
    if path:
        if not os.path.isfile(path):
            raise RenderTaskError(f"rpbrt binary {path} not found on this worker")
        return path
    found = shutil.which("rpbrt")
    if found is None:
        raise RenderTaskError("no rpbrt binary on this worker's PATH (give --rpbrt)")
    return found


def _unpack(archive: bytes, into: str) -> None:
    with tarfile.open(fileobj=io.BytesIO(archive), mode="r:gz") as tar:
        root = os.path.realpath(into)
        for m in tar.getmembers():
            target = os.path.realpath(os.path.join(into, m.name))
            if not target.startswith(root + os.sep):
                raise RenderTaskError(f"shipped scene has an unsafe path {m.name!r}")
            if not (m.isfile() or m.isdir()):
                raise RenderTaskError(f"shipped scene has a link or device {m.name!r}")
        tar.extractall(into)


_lock = threading.Lock()
#: Shipped scenes unpacked in this worker process, by archive id.
_unpacked: Dict[str, str] = {}
#: Idle part servers, by (binary, scene, options).
_idle: Dict[tuple, List["_Server"]] = {}
_all_servers: List["_Server"] = []


def _scene_dir(archive: bytes, archive_id: Optional[str]) -> Tuple[str, bool]:
    """A folder holding the unpacked archive, and whether it is kept (to be
    reused by later parts) rather than to be removed after this part."""
    if archive_id is None:
        d = tempfile.mkdtemp(prefix="rpbrt-farm-scene-")
        _unpack(archive, d)
        return d, False
    with _lock:
        d = _unpacked.get(archive_id)
        if d is None:
            d = tempfile.mkdtemp(prefix="rpbrt-farm-scene-")
            _unpack(archive, d)
            _unpacked[archive_id] = d
        return d, True


class _Server:
    """One ``rpbrt --serve-parts`` process."""

    def __init__(self, cmd: List[str]):
        self.log = tempfile.TemporaryFile(mode="w+")
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=self.log, text=True, bufsize=1)

    def stderr_tail(self) -> str:
        self.log.flush()
        self.log.seek(0)
        return self.log.read()[-4000:].strip()

    def request(self, part_args: Tuple[str, ...], outfile: str) -> Optional[str]:
        """Renders a part; None when it worked, else rpbrt's message.
        Raises BrokenPipeError/EOFError when the process is gone."""
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write(" ".join(part_args) + " --outfile " + outfile + "\n")
        self.proc.stdin.flush()
        reply = self.proc.stdout.readline()
        if not reply:
            raise EOFError
        reply = reply.rstrip("\n")
        return None if reply == "ok" else reply.removeprefix("error: ")

    def close(self) -> None:
        try:
            if self.proc.stdin:
                self.proc.stdin.close()
            self.proc.wait(timeout=5)
        except Exception:
            self.proc.kill()
        self.log.close()


@atexit.register
def _shutdown() -> None:
    for s in _all_servers:
        s.close()
    for d in _unpacked.values():
        shutil.rmtree(d, ignore_errors=True)


def close_session(session: str) -> int:
    """Ends this worker's rpbrt processes of render ``session``; returns
    how many were closed (run on every worker when a render ends)."""
    with _lock:
        keys = [k for k in _idle if k[0] == session]
        servers = [s for k in keys for s in _idle.pop(k)]
        for s in servers:
            _all_servers.remove(s)
    for s in servers:
        s.close()
    return len(servers)


def _serve(rpbrt: str, scene: str, spec: TaskSpec, outfile: str) -> None:
    key = (spec.session, rpbrt, scene, spec.args)
    with _lock:
        pool = _idle.setdefault(key, [])
        server = pool.pop() if pool else None
    if server is None:
        server = _Server([rpbrt, "--quiet", *spec.args, "--serve-parts", scene])
        with _lock:
            _all_servers.append(server)
    try:
        msg = server.request(spec.part_args, outfile)
    except (BrokenPipeError, EOFError, OSError):
        server.proc.wait()
        tail = server.stderr_tail() or f"rpbrt exited with status {server.proc.returncode}"
        with _lock:
            _all_servers.remove(server)
        server.close()
        raise RenderTaskError(f"{spec.label}: {tail}") from None
    with _lock:
        _idle[key].append(server)
    if msg is not None:
        raise RenderTaskError(f"{spec.label}: {msg}")


def render_part(spec: TaskSpec, archive: Optional[bytes] = None) -> bytes:
    """Renders one part and returns the EXR's bytes; raises
    RenderTaskError with rpbrt's message when rpbrt fails."""
    rpbrt = _find_rpbrt(spec.rpbrt)
    keep_dir = True
    scene = spec.scene
    scene_dir = None
    if archive is not None:
        scene_dir, keep_dir = _scene_dir(archive, spec.archive_id if spec.reuse else None)
        scene = os.path.join(scene_dir, spec.scene)
    try:
        with tempfile.TemporaryDirectory(prefix="rpbrt-farm-") as tmp:
            out = os.path.join(tmp, "part.exr")
            if spec.reuse:
                _serve(rpbrt, scene, spec, out)
            else:
                cmd = [rpbrt, "--quiet", *spec.args, *spec.part_args, "--outfile", out, scene]
                proc = subprocess.run(cmd, capture_output=True, text=True)
                if proc.returncode != 0:
                    msg = proc.stderr.strip() or f"exit status {proc.returncode}"
                    raise RenderTaskError(f"{spec.label}: {msg}")
            with open(out, "rb") as f:
                return f.read()
    finally:
        if scene_dir is not None and not keep_dir:
            shutil.rmtree(scene_dir, ignore_errors=True)
