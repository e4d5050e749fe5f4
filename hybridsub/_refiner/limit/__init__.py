"""The limit surface: where the refined meshes converge to, and its normals.

``plan`` decides which stationary mask (``_rules.limit``) applies at every vertex and sector
of a level, on the sectors the topology layer cuts (``_topology.vertex_sectors``);
``normals`` turns tangent masks and control fans into sector normals; ``local`` refines the
stars of the vertices without a stationary mask until their rows and normals settle; ``api``
holds the public functions. ``docs/limit.md`` explains every decision taken here.
"""

from .api import limit_matrix, limit_normals, limit_positions

__all__ = ["limit_matrix", "limit_normals", "limit_positions"]
