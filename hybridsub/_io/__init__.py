"""Mesh files: the data model (:class:`TaggedMesh`), one module per format, welding and tag
lists. Other layers import from here, never from the modules inside.

mesh.py           TaggedMesh, as_tagged, describe_tags, the tag conventions of files
formats.py        read_mesh / write_mesh / write / check_writable: the format by the file's extension
obj.py, ply.py, off.py, npz.py, trimesh_formats.py, meshio_formats.py: one module per
                  format or library (off.py also read_off, the examples' plain loader)
convert.py        trimesh.Trimesh and pyvista.PolyData as TaggedMesh (write_mesh(path, mesh))
tables.py         polygons read as triangles, index checks, rows written as text
weld.py           classes, weld
tagfiles.py       the command line's tag lists (read_edge_file, read_list_file)
examples.py       the shipped example meshes (example_path, load_example)
"""

from .examples import example_path, load_example
from .formats import check_writable, read_mesh, write, write_mesh
from .convert import TAG_NAMES, kind_of, triangles_of
from .mesh import METADATA_KEY, TaggedMesh, corner_tags, describe_tags
from .off import read_off
from .tagfiles import read_edge_file, read_list_file
from .weld import classes, weld

__all__ = ["METADATA_KEY", "TAG_NAMES", "TaggedMesh", "check_writable", "classes", "corner_tags", "kind_of", "triangles_of",
           "describe_tags", "example_path", "load_example", "read_edge_file",
           "read_list_file", "read_mesh", "read_off", "weld", "write", "write_mesh"]
