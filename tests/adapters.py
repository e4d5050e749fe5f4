"""The optional adapters' libraries (torch, jax) for the tests that need them.

``adapter(name)`` skips the calling module where the library is not installed (a plain
``pip install ".[test]"``), except under ``HYBRIDSUB_REQUIRE_ADAPTERS=1`` (CI, which installs
the ``torch`` and ``jax`` extras): there a missing library is an error, not a skip.
"""

import importlib
import os

import pytest

REQUIRED = os.environ.get("HYBRIDSUB_REQUIRE_ADAPTERS") == "1"


def adapter(name: str):
    if REQUIRED:
        return importlib.import_module(name)
    return pytest.importorskip(name)
