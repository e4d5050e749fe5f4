"""The input gate: user arrays and options checked once, with errors that name the problem,
and the features detected on them. Other layers import from here, never from the modules
inside."""

from .arrays import (SCHEMES, as_corner_mask, as_face_mask, as_faces, as_sharp_edges, as_vertices, check_options,
                     count_of)
from .features import Features, detect_features

__all__ = ["Features", "SCHEMES", "as_corner_mask", "as_face_mask", "as_faces", "as_sharp_edges", "as_vertices",
           "check_options", "count_of", "detect_features"]
