"""hybridsub: subdivision surfaces that keep their sharp features.

The hybrid √3–Loop scheme of Abd El-Latif (2014) — Kobbelt's √3 on smooth faces, Loop's
1-to-4 split on sharp faces, creases split instead of flipped — and its two parents,
Kobbelt's √3 and Loop with creases, as sparse refinement matrices.

>>> import numpy as np, hybridsub
>>> V, F = hybridsub.load_example()
>>> V2, F2 = hybridsub.subdivide(V, F, levels=1, scheme="sqrt3")
>>> len(F2) == 3 * len(F)
True

The public names are imported on first use (PEP 562), so that ``hybridsub --help`` does not
load NumPy, SciPy and Numba; ``from hybridsub import subdivide`` works as usual.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from ._errors import MeshError, OutputTooLargeError
from ._version import __version__ as __version__

if TYPE_CHECKING:  # what type checkers and editors see; at run time, __getattr__ below
    from . import analysis
    from ._app.batch import BatchSummary, batch
    from ._app.interop import subdivide_mesh
    from ._input import Features, detect_features
    from ._io import TaggedMesh, load_example, read_mesh, write_mesh
    from ._jit import set_threads
    from ._fit import FitResult, MultiresDetails, fit
    from ._refiner import (FaceVaryingRefinement, Refinement, RefinementStep, get_memory_limit, refine,
                           refine_face_varying, seam_edges, set_memory_limit, subdivide, subdivide_face_varying)
    from ._surface import (AdaptiveWarning, LimitMesh, LimitSurface, limit_matrix, limit_mesh, limit_normals,
                           limit_positions, limit_tangents, refine_adaptive, subdivide_adaptive)

#: Where each public name lives (imported when first used).
_HOMES = {
    "._refiner": ("FaceVaryingRefinement", "Refinement", "RefinementStep", "get_memory_limit", "refine",
                  "refine_face_varying", "seam_edges", "set_memory_limit", "subdivide", "subdivide_face_varying"),
    "._surface": ("AdaptiveWarning", "LimitMesh", "LimitSurface", "limit_matrix", "limit_mesh", "limit_normals",
                  "limit_positions", "limit_tangents", "refine_adaptive", "subdivide_adaptive"),
    "._fit": ("FitResult", "MultiresDetails", "fit"),
    "._input": ("Features", "detect_features"),
    "._io": ("TaggedMesh", "load_example", "read_mesh", "write_mesh"),
    "._app.batch": ("BatchSummary", "batch"),
    "._app.interop": ("subdivide_mesh",),
    "._jit": ("set_threads",),
}
_HOME_OF = {name: home for home, names in _HOMES.items() for name in names}
_SUBMODULES = ("_app", "_io", "_refiner", "_surface", "_fit", "_input", "_topology", "_rules", "_jit", "_typing", "_units")

__all__ = [
    "subdivide", "refine", "Refinement", "RefinementStep", "detect_features", "Features", "MeshError",
    "OutputTooLargeError", "set_memory_limit", "get_memory_limit", "load_example", "subdivide_mesh",
    "read_mesh", "write_mesh", "TaggedMesh", "subdivide_face_varying", "refine_face_varying",
    "FaceVaryingRefinement", "seam_edges", "limit_matrix", "limit_positions", "limit_normals", "limit_tangents", "limit_mesh",
    "LimitMesh", "LimitSurface", "analysis", "batch", "BatchSummary", "set_threads", "MultiresDetails", "fit", "FitResult",
    "refine_adaptive", "subdivide_adaptive", "AdaptiveWarning",
]


def __getattr__(name: str) -> Any:
    if name == "analysis":
        value: Any = importlib.import_module(".analysis", __name__)
    elif name in _HOME_OF:
        value = getattr(importlib.import_module(_HOME_OF[name], __name__), name)
    elif name.startswith("_") and not name.startswith("__") and name in _SUBMODULES:
        value = importlib.import_module("." + name, __name__)  # hybridsub._io as an attribute, as before
    else:
        raise AttributeError(f"module 'hybridsub' has no attribute {name!r}")
    globals()[name] = value  # once imported, a plain module attribute
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
