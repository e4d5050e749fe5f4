"""Mesh files: the data model (:class:`TaggedMesh`), one module per format, welding and tag
lists. Other layers import from here, never from the modules inside."""

from .examples import example_path, load_example, read_off
from .mesh import (TaggedMesh, classes, describe_tags, read_edge_file, read_list_file, read_mesh, weld, write,
                   write_mesh)

__all__ = ["TaggedMesh", "classes", "describe_tags", "example_path", "load_example", "read_edge_file",
           "read_list_file", "read_mesh", "read_off", "weld", "write", "write_mesh"]
