"""The refiner (OpenSubdiv's Far): the one step loop, refinement matrices and applying them
(or the stencils applied directly on the fast path), the memory budget, and the parameter
chart of a refinement (where each refined vertex lies over the input). Other layers import
from here, never from the modules inside; the limit surface (``_surface``) and fitting
(``_fit``) sit above it."""

from .budget import (cgroup_memory_limit, get_memory_limit, memory_source, physical_memory, predict_levels,
                     set_memory_limit)
from .chart import (EQUILATERAL, FaceCharts, barycentric, child_shapes, glue, glue_maps, onto_input_faces, plan_supports,
                    vertex_origins)
from .facevarying import FaceVaryingRefinement, refine_face_varying, seam_edges, subdivide_face_varying
from .fastpath import LevelOutput, subdivide, subdivide_face_varying_levels, subdivide_levels, walk_data
from .refinement import Refinement, RefinementStep, refine, refinement_of
from .stencils import step_matrix

__all__ = ["EQUILATERAL", "FaceCharts", "FaceVaryingRefinement", "LevelOutput", "Refinement", "RefinementStep", "barycentric",
           "cgroup_memory_limit", "child_shapes", "get_memory_limit", "glue", "glue_maps", "memory_source",
           "onto_input_faces", "physical_memory", "plan_supports", "predict_levels", "refine", "refine_face_varying",
           "refinement_of", "seam_edges", "set_memory_limit", "step_matrix", "subdivide", "subdivide_face_varying",
           "subdivide_face_varying_levels", "subdivide_levels", "vertex_origins", "walk_data"]
