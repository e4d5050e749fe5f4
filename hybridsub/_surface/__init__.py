"""The limit surface (OpenSubdiv's Bfr), above the refiner: where the refined meshes converge
to, its normals, and the surface at any point.

``mask_plan`` decides which stationary mask (``_rules.limit``) applies at every vertex and sector
of a level, on the sectors the topology layer cuts (``_topology.vertex_sectors``);
``normals`` turns tangent masks and control fans into sector normals; ``local`` refines the
stars of the vertices without a stationary mask until their rows and normals settle; ``vertex_limit``
holds the public functions. ``descent`` follows any point of the surface down the refinement
(exact local refinement), ``surface`` is :class:`LimitSurface` on top of it, ``project`` its
closest points, certified on the exact closest points of a refined level (``mesh_closest``,
Numba kernels in ``_closest_kernels``; fitting uses them too). ``adaptive`` refines only where
the output is not yet within a tolerance of the surface (the engine is the refiner's).
``docs/limit.md`` explains every decision taken here.
"""

from .vertex_limit import LimitMesh, limit_matrix, limit_mesh, limit_normals, limit_positions, limit_tangents
from .surface import LimitSurface
from .adaptive import AdaptiveWarning, refine_adaptive, subdivide_adaptive
from .mesh_closest import ClosestPoints, Footpoints, closest_points

__all__ = ["AdaptiveWarning", "ClosestPoints", "Footpoints", "LimitMesh", "LimitSurface", "closest_points",
           "limit_matrix", "limit_mesh", "limit_normals", "limit_positions", "limit_tangents", "refine_adaptive", "subdivide_adaptive"]
