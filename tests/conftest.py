import os
import sys

import numpy as np
import pytest

DATA = os.path.join(os.path.dirname(__file__), "data")
sys.path.insert(0, os.path.dirname(__file__))


def load_mesh(name: str):
    """(V, F) of tests/data/NAME.off, exactly as stored (no merging, no reordering)."""
    from hybridsub._io import read_off

    return read_off(os.path.join(DATA, f"{name}.off"))


@pytest.fixture(scope="session")
def mesh():
    return load_mesh
