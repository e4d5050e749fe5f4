"""The refiner (OpenSubdiv's Far): the one step loop, refinement matrices and applying them
(or the stencils applied directly on the fast path), the memory budget, and the parameter
chart of a refinement (where each refined vertex lies over the input). Other layers import
from here, never from the modules inside; the limit surface (``_surface``) and fitting
(``_fit``) sit above it."""

from .budget import (cgroup_memory_limit, get_memory_limit, memory_source, physical_memory, predict_levels,
                     set_memory_limit)
from .chart import (EQUILATERAL, FaceCharts, barycentric, child_shapes, glue, glue_maps, matrix_supports,
                    onto_input_faces, plan_supports, vertex_origins)
from .facevarying import FaceVaryingRefinement, refine_face_varying, seam_edges, subdivide_face_varying
from .fastpath import (LevelOutput, WalkedLevel, subdivide, subdivide_face_varying_levels, subdivide_levels, walk_data,
                       walk_to)
from .refinement import Refinement, RefinementStep, refine, refinement_of, without_holes
from .sharpness import SharpnessSteps, Slopes, sharpness_steps
from .stencils import (CodedStencils, apply_coded, apply_matrix, coded_stencils, in_read_order,
                       step_matrix)

__all__ = ["apply_coded", "apply_matrix", "barycentric", "cgroup_memory_limit", "child_shapes", "coded_stencils",
           "CodedStencils", "EQUILATERAL", "FaceCharts", "FaceVaryingRefinement", "get_memory_limit", "glue", "glue_maps",
           "in_read_order", "LevelOutput", "matrix_supports", "memory_source", "onto_input_faces", "physical_memory",
           "plan_supports", "predict_levels", "refine", "refine_face_varying", "Refinement", "refinement_of", "without_holes",
           "RefinementStep", "seam_edges", "set_memory_limit", "sharpness_steps", "SharpnessSteps", "Slopes",
           "step_matrix", "subdivide", "subdivide_face_varying", "subdivide_face_varying_levels", "subdivide_levels",
           "vertex_origins", "walk_data", "WalkedLevel", "walk_to"]
