"""Fitting and multiresolution, above the surface and the refiner: ``fitting`` fits a control
mesh's refined or limit surface to points (squared-distance Gauss–Newton; the exact closest
points on a triangle mesh come from the surface layer, ``_surface.mesh_closest``, which the
projection's certificate uses too), ``multires`` is least-squares reverse subdivision with
details in local frames (``Refinement.decompose`` / ``reconstruct``). ``docs/fitting.md``
explains every decision taken here.
"""

from .._surface import ClosestPoints, closest_points
from .fitting import FitResult, fit
from .multires import MultiresDetails, decompose, reconstruct

__all__ = ["ClosestPoints", "FitResult", "MultiresDetails", "closest_points", "decompose", "fit", "reconstruct"]
