"""Topology and tags (OpenSubdiv's Vtr): halfedges, levels, step plans, emission of the next
level. Knows connectivity and tags, never positions or weights applied to data. Other
layers import from here, never from the modules inside."""

from .edges import (EdgeGroups, UndirectedEdges, edge_keys, group_halfedges, halfedge_ends, next_halfedge,
                    prev_halfedge, undirected_edges)
from .level import Level, StepPlan, build_level, child_creases, child_level, face_parents, plan_step, step_arguments

__all__ = ["EdgeGroups", "Level", "StepPlan", "UndirectedEdges", "build_level", "child_creases", "child_level",
           "edge_keys", "face_parents", "group_halfedges", "halfedge_ends", "next_halfedge", "plan_step",
           "prev_halfedge", "step_arguments", "undirected_edges"]
