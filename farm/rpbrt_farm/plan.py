"""What each task renders: the rpbrt arguments of every part of a frame."""

from __future__ import annotations

from dataclasses import dataclass
from typing import List, Optional


@dataclass(frozen=True)
class Part:
    """One task's share of a frame."""

    #: "tile" or "range".
    kind: str
    #: Index of the part within its frame (0-based).
    index: int
    #: How many parts the frame has.
    count: int
    #: For ranges: samples [start, end) of every pixel.
    start: int = 0
    end: int = 0

    def rpbrt_args(self) -> List[str]:
        """The rpbrt flags that select this part."""
        if self.kind == "tile":
            return ["--tile", f"{self.index}/{self.count}"]
        return ["--spp-range", f"{self.start}..{self.end}"]

    def label(self) -> str:
        """A short name for messages and file names."""
        if self.kind == "tile":
            return f"tile {self.index}/{self.count}"
        return f"samples {self.start}..{self.end}"


def plan_frame(tiles: Optional[int], ranges: Optional[int], spp: Optional[int]) -> List[Part]:
    """The parts of one frame: ``tiles`` tiles, or ``ranges`` sample ranges of
    ``spp`` samples per pixel split as evenly as integers allow."""
    if (tiles is None) == (ranges is None):
        raise ValueError("give either a number of tiles or a number of sample ranges")
    if tiles is not None:
        if tiles < 1:
            raise ValueError(f"--tiles must be at least 1, got {tiles}")
        return [Part("tile", k, tiles) for k in range(tiles)]
    assert ranges is not None
    if spp is None:
        raise ValueError("--ranges needs --spp: the farm must know the samples per pixel to split")
    if ranges < 1 or spp < ranges:
        raise ValueError(f"cannot split {spp} samples per pixel into {ranges} ranges")
    bounds = [k * spp // ranges for k in range(ranges + 1)]
    return [Part("range", k, ranges, bounds[k], bounds[k + 1]) for k in range(ranges)]
