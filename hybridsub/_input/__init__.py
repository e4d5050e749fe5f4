"""The input gate: user arrays and options checked once, with errors that name the problem,
the features detected on them, and the frozen description of one refinement
(:class:`RefineInput`) that every layer below takes. Other layers import from here, never
from the modules inside."""

from .arrays import (SCHEMES, UV_MODES, as_corner_mask, as_corner_sharpness, as_data, as_face_mask, as_faces, as_sharp_edges,
                     as_uv_values, as_vertices, check_options, count, count_of, tag_counts, writable)
from .features import Features, detect_features, merge_detected, merge_edges
from .gate import RefineInput, UVInput, open_gate

__all__ = ["Features", "RefineInput", "SCHEMES", "UVInput", "UV_MODES", "as_corner_mask", "as_corner_sharpness", "as_data",
           "as_face_mask", "as_faces", "as_sharp_edges", "as_uv_values", "as_vertices", "check_options", "count", "count_of",
           "detect_features", "merge_detected", "merge_edges", "open_gate", "tag_counts", "writable"]
