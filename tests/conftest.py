import os
import sys

import numpy as np
import pytest
from hypothesis import settings

# The property tests draw the same examples on every run (a green suite stays green until the
# code changes); HYBRIDSUB_EXPLORE=1 draws fresh ones, to hunt for new counterexamples
# (with HYBRIDSUB_PROPERTY_SCALE=10 for ten times as many).
settings.register_profile("repeatable", derandomize=True, print_blob=True)
settings.register_profile("explore", derandomize=False, print_blob=True)
settings.load_profile("explore" if os.environ.get("HYBRIDSUB_EXPLORE") == "1" else "repeatable")

# No helpers compiling ahead (hybridsub/_compile_ahead.py): the tests that want them say so.
os.environ["HYBRIDSUB_COMPILE_AHEAD"] = "0"

DATA = os.path.join(os.path.dirname(__file__), "data")
sys.path.insert(0, os.path.dirname(__file__))


@pytest.fixture(autouse=True)
def _no_shared_patch_tables(monkeypatch):
    """Each test starts without the patch tables surfaces share (``_TABLES`` in
    hybridsub/_surface/surface.py), as a fresh process does: what one test's surfaces made,
    or set on their tables, does not reach another test."""
    import hybridsub._surface.surface as surface

    monkeypatch.setattr(surface, "_TABLES", {})


def load_mesh(name: str):
    """(V, F) of tests/data/NAME.off, exactly as stored (no merging, no reordering)."""
    from hybridsub._io import read_off

    return read_off(os.path.join(DATA, f"{name}.off"))


@pytest.fixture(scope="session")
def mesh():
    return load_mesh
