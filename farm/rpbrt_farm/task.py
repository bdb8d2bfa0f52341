"""The worker side: run the rpbrt binary on one part and return its EXR.

This module is imported on the workers, so it needs nothing but the
standard library there.
"""

from __future__ import annotations

import io
import os
import shutil
import subprocess
import tarfile
import tempfile
from dataclasses import dataclass
from typing import List, Optional


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
    #: The rpbrt flags selecting the part and the render options.
    args: List[str]
    #: A label for error messages.
    label: str


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
        for m in tar.getmembers():
            target = os.path.realpath(os.path.join(into, m.name))
            if not target.startswith(os.path.realpath(into) + os.sep):
                raise RenderTaskError(f"shipped scene has an unsafe path {m.name!r}")
            if not (m.isfile() or m.isdir()):
                raise RenderTaskError(f"shipped scene has a link or device {m.name!r}")
        tar.extractall(into)


def render_part(spec: TaskSpec, archive: Optional[bytes] = None) -> bytes:
    """Renders one part and returns the EXR's bytes; raises
    RenderTaskError with rpbrt's message when rpbrt fails."""
    rpbrt = _find_rpbrt(spec.rpbrt)
    with tempfile.TemporaryDirectory(prefix="rpbrt-farm-") as tmp:
        scene = spec.scene
        if archive is not None:
            scene_dir = os.path.join(tmp, "scene")
            os.mkdir(scene_dir)
            _unpack(archive, scene_dir)
            scene = os.path.join(scene_dir, spec.scene)
        out = os.path.join(tmp, "part.exr")
        cmd = [rpbrt, "--quiet", *spec.args, "--outfile", out, scene]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            msg = proc.stderr.strip() or f"exit status {proc.returncode}"
            raise RenderTaskError(f"{spec.label}: {msg}")
        with open(out, "rb") as f:
            return f.read()
