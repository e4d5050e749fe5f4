"""Doctests of the optional adapters (hybridsub/torch.py, hybridsub/jax.py) are collected only
where their library imports; with ``HYBRIDSUB_REQUIRE_ADAPTERS=1`` (CI) always, so that a
missing library fails there instead of skipping."""

import importlib.util
import os

os.environ["HYBRIDSUB_COMPILE_AHEAD"] = "0"  # no helpers compiling ahead (_compile_ahead.py)

collect_ignore = []
if os.environ.get("HYBRIDSUB_REQUIRE_ADAPTERS") != "1":
    collect_ignore += [f"{name}.py" for name in ("torch", "jax")
                       if importlib.util.find_spec(name) is None]
