"""The application layer: the file pipeline, the command line, batch runs, progress, reports
and figures, and trimesh interop. It sits on top: nothing below imports it."""

from .batch import BatchSummary, batch
from .interop import subdivide_mesh

__all__ = ["BatchSummary", "batch", "subdivide_mesh"]
