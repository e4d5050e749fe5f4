"""pytest-benchmark suites: ``pytest benchmarks/ --benchmark-only``.

The project's own ``python -m pytest`` does not collect this folder (``testpaths`` and
``--ignore=benchmarks`` in pyproject.toml); naming it on the command line does.
"""

# Scripts and helpers, not test modules: keep --doctest-modules from importing them.
collect_ignore = ["compare.py", "scaling.py", "_bench.py"]
