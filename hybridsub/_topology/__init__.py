"""Topology and tags (OpenSubdiv's Vtr): halfedges, levels, step plans, emission. No positions."""
