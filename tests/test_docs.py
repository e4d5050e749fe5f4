"""Every Python block of the README and of docs/ runs as written, on the shipped data.

The blocks of one page run in order in one namespace (a page reads as one session), in a
temporary folder holding the files the page's shell commands make (:data:`SETUP`). A block
written as a session (``>>>``) runs as a doctest: its printed results must be what the page
shows. A block whose info string says ``python no-run`` (code that needs what a test machine
lacks: a GPU) is skipped; the text around it says why.
"""

import doctest
import os
import pathlib
import re

import matplotlib
import numpy as np
import pytest

import hybridsub

ROOT = pathlib.Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
_BLOCK = re.compile(r"^```(python[^\n]*)\n(.*?)^```", re.M | re.S)


def python_blocks(page: pathlib.Path) -> list[tuple[int, str]]:
    """(line, code) of each block of ``page`` to run."""
    text = page.read_text(encoding="utf-8")
    blocks = []
    for match in _BLOCK.finditer(text):
        if "no-run" in match[1]:
            continue
        blocks.append((text[:match.start()].count("\n") + 2, match[2]))
    return blocks


def _usage_files():
    """usage.md's shell session: fandisk.off subdivided to fandisk.L3.obj by the command line,
    and the textured bunny of the tests as an OBJ."""
    from hybridsub._app.cli import main

    V, F = hybridsub.load_example()
    hybridsub.write_mesh("fandisk.off", V, F)
    assert main(["subdivide", "fandisk.off", "-o", "fandisk.L3.obj", "--levels", "3", "--feature-angle", "30",
                 "-q"]) == 0
    d = np.load(ROOT / "tests" / "data" / "bunny10k_textured.fvar_linear.L1.npz")
    hybridsub.write_mesh("bunny10k_textured.obj", d["V_in"], d["F_in"], uv=d["UV_in"], face_uv=d["FUV_in"])


#: What a page's shell commands made before its Python blocks, by page.
SETUP = {"usage.md": _usage_files}

#: Pages whose blocks start worker processes (a local Dask cluster), fit surfaces to
#: thousands of points, refine fandisk to a tolerance or run 300 steps of gradient descent:
#: run with ``-m slow``.
SLOW = {"adaptive.md", "batch.md", "fitting.md", "differentiable.md"}


@pytest.mark.parametrize("page", [pytest.param(p, marks=pytest.mark.slow) if p.name in SLOW else p
                                  for p in PAGES if python_blocks(p)], ids=lambda p: getattr(p, "name", p))
def test_the_python_blocks_of_a_page_run(page, tmp_path, monkeypatch):
    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    if page.name in SETUP:
        SETUP[page.name]()
    namespace = {"__name__": "__main__"}  # as a script run by hand
    for line, code in python_blocks(page):
        where = f"{page.relative_to(ROOT)}, the block at line {line}"
        if code.lstrip().startswith(">>>"):
            test = doctest.DocTestParser().get_doctest(code, namespace, where, str(page), line)
            runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
            out = []
            runner.run(test, out=out.append, clear_globs=False)
            namespace.update(test.globs)  # a DocTest runs in a copy
            assert runner.failures == 0, f"{where}:\n" + "".join(out)
            continue
        try:
            exec(compile(code, where, "exec"), namespace)
        except Exception as e:
            raise AssertionError(f"{where}: {type(e).__name__}: {e}") from e
