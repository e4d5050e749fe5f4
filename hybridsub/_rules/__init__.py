"""The scheme's rules (OpenSubdiv's Sdc): weights and limit masks as functions of
neighbourhood numbers (valence, crease count, sharpness). No mesh.

Two namespaces: :mod:`.step_rules` (the masks of one step; ``from .._rules import
step_rules as R``) and :mod:`.limit` (limit and tangent masks). The sharpness conventions the
file formats share are exported here too.
"""

from . import limit, step_rules
from .step_rules import INFINITE_SHARPNESS, normalize_sharpness

__all__ = ["INFINITE_SHARPNESS", "limit", "normalize_sharpness", "step_rules"]
