"""hybridsub: subdivision surfaces that keep their sharp features.

The hybrid √3–Loop scheme of Abd El-Latif (2014) — Kobbelt's √3 on smooth faces, Loop's
1-to-4 split on sharp faces, creases split instead of flipped — and its two parents,
Kobbelt's √3 and Loop with creases, as sparse refinement matrices.

>>> import numpy as np, hybridsub
>>> V, F = hybridsub.load_example()
>>> V2, F2 = hybridsub.subdivide(V, F, levels=1, scheme="sqrt3")
>>> len(F2) == 3 * len(F)
True
"""

from ._errors import MeshError, OutputTooLargeError
from ._input import Features, detect_features
from ._refiner import (FaceVaryingRefinement, FitResult, LimitSurface, MultiresDetails, Refinement, RefinementStep,
                       fit, get_memory_limit, limit_matrix, limit_normals, limit_positions, refine,
                       refine_face_varying, seam_edges, set_memory_limit, subdivide, subdivide_face_varying)
from ._io import TaggedMesh, load_example, read_mesh, write_mesh
from ._app.batch import BatchSummary, batch
from ._app.interop import subdivide_mesh
from . import analysis

__all__ = [
    "subdivide", "refine", "Refinement", "RefinementStep", "detect_features", "Features", "MeshError",
    "OutputTooLargeError", "set_memory_limit", "get_memory_limit", "load_example", "subdivide_mesh",
    "read_mesh", "write_mesh", "TaggedMesh", "subdivide_face_varying", "refine_face_varying",
    "FaceVaryingRefinement", "seam_edges", "limit_matrix", "limit_positions", "limit_normals", "LimitSurface",
    "analysis", "batch", "BatchSummary", "MultiresDetails", "fit", "FitResult",
]
from ._version import __version__ as __version__
