"""The refiner (OpenSubdiv's Far): the one step loop, refinement matrices and applying them
(or the stencils applied directly on the fast path), the memory budget, the limit surface.
Other layers import from here, never from the modules inside."""

from .budget import (cgroup_memory_limit, get_memory_limit, memory_source, physical_memory, predict_levels,
                     set_memory_limit)
from .facevarying import FaceVaryingRefinement, refine_face_varying, seam_edges, subdivide_face_varying
from .fastpath import LevelOutput, subdivide, subdivide_face_varying_levels, subdivide_levels, walk_data
from .fitting import FitResult, fit
from .limit import LimitSurface, limit_matrix, limit_normals, limit_positions
from .multires import MultiresDetails
from .refinement import Refinement, RefinementStep, refine, refinement_of

__all__ = ["FaceVaryingRefinement", "FitResult", "LevelOutput", "LimitSurface", "MultiresDetails", "Refinement",
           "RefinementStep", "cgroup_memory_limit", "fit", "get_memory_limit", "limit_matrix", "limit_normals",
           "limit_positions", "memory_source", "physical_memory", "predict_levels", "refine", "refine_face_varying",
           "refinement_of", "seam_edges", "set_memory_limit", "subdivide", "subdivide_face_varying",
           "subdivide_face_varying_levels", "subdivide_levels", "walk_data"]
