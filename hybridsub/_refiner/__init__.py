"""The refiner (OpenSubdiv's Far): the step loop, refinement matrices and applying them, the limit."""
