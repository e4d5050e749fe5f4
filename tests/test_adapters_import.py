"""Import cost: ``import hybridsub`` (and using it) imports neither PyTorch nor JAX nor CuPy,
and ``hybridsub.cupy`` imports CuPy only when called."""

import subprocess
import sys

CHECK = """
import sys, hybridsub, hybridsub.cupy
V, F = hybridsub.load_example()
hybridsub.subdivide(V, F, levels=1)
hybridsub.refine(F, levels=1).apply(V)
print(sorted(m for m in ("torch", "jax", "jaxlib", "cupy") if m in sys.modules))
"""


def test_no_adapter_library_imported():
    out = subprocess.run([sys.executable, "-c", CHECK], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
