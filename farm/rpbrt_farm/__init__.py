"""rpbrt-farm: one rpbrt frame rendered across a Dask cluster.

The frame is split into tiles (``rpbrt --tile K/N``) or into ranges of pixel
samples (``rpbrt --spp-range A..B``); each part is a Dask task that runs the
``rpbrt`` binary on a worker and returns the part's EXR; the client joins the
parts with ``rpbrt imgtool assemble`` or ``rpbrt imgtool merge``, which give
exactly the image one ``rpbrt`` run makes.
"""

from .plan import Part, plan_frame
from .render import FarmError, render_frames

__all__ = ["FarmError", "Part", "plan_frame", "render_frames"]
