"""The application layer: the file pipeline, the command line, batch runs, progress, reports
and figures, and trimesh interop. It sits on top: nothing below imports it, and the public
package imports its entry points from the modules themselves (``batch`` is both a module and
the function in it)."""
