"""The scheme's rules (OpenSubdiv's Sdc): weights and limit masks as functions of
neighbourhood numbers (valence, crease count, sharpness). No mesh.

Two namespaces: :mod:`.refinement` (the masks of one step; ``from .._rules import
refinement as R``) and :mod:`.limit` (limit and tangent masks). The sharpness conventions the
file formats share are exported here too.
"""

from . import limit, refinement
from .refinement import INFINITE_SHARPNESS, normalize_sharpness

__all__ = ["INFINITE_SHARPNESS", "limit", "normalize_sharpness", "refinement"]
