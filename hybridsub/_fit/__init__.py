"""Fitting and multiresolution, above the surface and the refiner: ``fitting`` fits a control
mesh's refined or limit surface to points (squared-distance Gauss–Newton), ``closest`` finds
exact closest points on a triangle mesh, ``multires`` is least-squares reverse subdivision
with details in local frames (``Refinement.decompose`` / ``reconstruct``). ``docs/fitting.md``
explains every decision taken here.
"""

from .closest import ClosestPoints, closest_points
from .fitting import FitResult, fit
from .multires import MultiresDetails, decompose, reconstruct

__all__ = ["ClosestPoints", "FitResult", "MultiresDetails", "closest_points", "decompose", "fit", "reconstruct"]
