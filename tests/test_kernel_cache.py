"""A rule change must reach the compiled kernels, even with a warm Numba cache.

Numba's ``cache=True`` keys a kernel's cache entry on the kernel's own file; the rules it
compiles in live elsewhere (``_rules``), so an edited rule used to keep running its old
compiled copy. ``hybridsub._jit.kernel`` keys the entry on every package module the kernel
imports from. These tests edit sources in a temporary copy and run fresh processes: the
edited code with a warm cache must give what it gives with an empty one.
"""

import importlib
import importlib.util
import os
import pkgutil
import shutil
import subprocess
import sys
import textwrap

import numba
import pytest
from numba.core.caching import NullCache

import hybridsub
from hybridsub._jit import DependencyKeyedCache, dependencies


def _run(code: str, cwd, cache_dir) -> str:
    """stdout of ``python -c code`` in ``cwd`` (imports from there first, then this hybridsub),
    Numba caching into ``cache_dir``; no ``.pyc`` written, so an edit is never masked by one."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache_dir), PYTHONDONTWRITEBYTECODE="1",
               PYTHONPATH=os.pathsep.join([str(cwd), os.path.dirname(os.path.dirname(hybridsub.__file__))]))
    r = subprocess.run([sys.executable, "-c", code], cwd=cwd, env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-2000:]
    return r.stdout.strip()


def _edit(path, old: str, new: str) -> None:
    with open(path, encoding="utf-8") as f:
        text = f.read()
    assert text.count(old) == 1, old
    with open(path, "w", encoding="utf-8") as f:
        f.write(text.replace(old, new))


_ADAPTERS = {"hybridsub.torch": "torch", "hybridsub.jax": "jax", "hybridsub.cupy": "cupy"}


def _package_modules():
    for info in pkgutil.walk_packages(hybridsub.__path__, "hybridsub."):
        if info.name.endswith("__main__"):
            continue
        try:
            yield importlib.import_module(info.name)
        except ImportError:  # an adapter without its library (its extra not installed)
            if info.name not in _ADAPTERS or importlib.util.find_spec(_ADAPTERS[info.name]) is not None:
                raise


def test_every_cached_kernel_is_keyed_on_the_modules_it_compiles_in():
    """A kernel whose module imports from another package module must not be cached on its
    own file alone (a plain ``njit(cache=True)`` there would bring stale kernels back)."""
    checked = 0
    for module in _package_modules():
        own = [obj for obj in vars(module).values()
               if isinstance(obj, numba.core.registry.CPUDispatcher) and obj.py_func.__module__ == module.__name__]
        needs_key = len(dependencies(module.__name__)) > 1
        for obj in own:
            if isinstance(obj._cache, NullCache):
                continue
            checked += 1
            if needs_key:
                assert isinstance(obj._cache, DependencyKeyedCache), f"{module.__name__}.{obj.__name__}"
    assert checked > 20


def test_kernels_depend_on_the_rules_they_compile_in():
    rules = "hybridsub._rules.step_rules"
    halfedges = "hybridsub._topology._halfedge_kernels"
    assert {rules, halfedges} <= set(dependencies("hybridsub._topology._kernels"))
    assert {rules, halfedges} <= set(dependencies("hybridsub._refiner._stencil_kernels"))
    assert halfedges in dependencies("hybridsub._topology._sector_kernels")


PACKAGE = {
    "__init__.py": "",
    "rules.py": """
        from numba import njit

        SCALE = 2.0


        @njit(cache=True)
        def weight():
            return 0.375
        """,
    "kernels.py": """
        from numba import njit

        from hybridsub._jit import kernel

        from .rules import SCALE, weight


        @kernel
        def keyed(x):
            return SCALE * weight() * x


        @njit(cache=True)
        def plain(x):
            return SCALE * weight() * x
        """,
}

CALL = ("from rulepkg.kernels import keyed, plain\n"
        "print(keyed(1.0), plain(1.0), keyed.stats.cache_hits[keyed.signatures[0]])")


@pytest.mark.slow  # subprocesses / a cluster / figures: ~4-11 s; .ci/run runs the slow tests
def test_an_edited_rule_recompiles_a_warm_kernel(tmp_path):
    """A small package: ``keyed`` (``hybridsub._jit.kernel``) and ``plain`` (Numba's own cache)
    both compile in a rule and a constant from another module. After the rule is edited,
    ``keyed`` computes with the new rule; ``plain`` still runs its stale copy, which is what
    this test would catch if the keying broke."""
    src = tmp_path / "src"
    (src / "rulepkg").mkdir(parents=True)
    for name, text in PACKAGE.items():
        (src / "rulepkg" / name).write_text(textwrap.dedent(text))
    cache = tmp_path / "cache"
    assert _run(CALL, src, cache) == "0.75 0.75 0"
    assert _run(CALL, src, cache) == "0.75 0.75 1"  # warm: loaded, not compiled
    _edit(src / "rulepkg" / "rules.py", "return 0.375", "return 0.5")
    assert _run(CALL, src, cache) == "1.0 0.75 0"  # keyed recompiles; plain is stale
    _edit(src / "rulepkg" / "rules.py", "SCALE = 2.0", "SCALE = 4.0")
    assert _run(CALL, src, cache) == "2.0 0.75 0"

OUTPUTS = """
import hashlib, numpy as np, hybridsub
assert hybridsub.__file__.startswith({root!r}), hybridsub.__file__
V, F = hybridsub.load_example()
feat = hybridsub.detect_features(V, F, angle=30)
h = hashlib.sha256()
for scheme in ("hybrid", "loop"):
    V2, F2 = hybridsub.subdivide(V, F, feat.sharp_edges, levels=2, scheme=scheme, corners=feat.corners,
                                 sharpness=np.full(len(feat.sharp_edges), 1.5))
    S = hybridsub.refine(F, feat.sharp_edges, levels=1, n_vertices=len(V), scheme=scheme).matrix
    for a in (V2, F2, S.data, S.indices, S.indptr):
        h.update(np.ascontiguousarray(a).tobytes())
print(h.hexdigest())
"""


@pytest.mark.slow
def test_an_edited_rule_changes_the_package_as_an_empty_cache_does(tmp_path):
    """The package copied, run with a cache; Loop's 3/8 edge weight and the smooth vertex mask
    edited; run again with that warm cache and with an empty one: the same bits (and not the
    unedited ones)."""
    src = tmp_path / "src"
    shutil.copytree(os.path.dirname(hybridsub.__file__), src / "hybridsub",
                    ignore=shutil.ignore_patterns("__pycache__"))
    code = OUTPUTS.format(root=str(src))
    warm = tmp_path / "warm"
    before = _run(code, src, warm)
    rules = src / "hybridsub" / "_rules" / "step_rules.py"
    _edit(rules, "(1.0 - s) * 0.375", "(1.0 - s) * 0.4")
    _edit(rules, "return 1.0 - n * smooth_w, smooth_w, 0.0, 0.0",
          "return 1.0 - n * (0.5 * smooth_w), 0.5 * smooth_w, 0.0, 0.0")
    edited_warm = _run(code, src, warm)
    edited_cold = _run(code, src, tmp_path / "empty")
    assert edited_warm == edited_cold != before


def test_kernels_without_parfors_compile_quietly_and_run_serially():
    """``kernel(parallel=NO_PARFORS)``: Numba's parallel pipeline with nothing on threads,
    compiled without its warning that nothing runs on threads; ``prange`` runs in order."""
    import warnings

    import numpy as np

    from hybridsub._jit import NO_PARFORS, kernel

    def running_sum(x):
        out = np.empty_like(x)
        acc = 0.0
        for i in numba.prange(len(x)):  # in order, or the running sum would be wrong
            acc += x[i]
            out[i] = acc
        return out

    quiet = kernel(parallel=NO_PARFORS)(running_sum)
    quiet._cache = NullCache()  # a test function: nothing on disk
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert quiet(np.arange(5.0)).tolist() == [0.0, 1.0, 3.0, 6.0, 10.0]
    loud = [str(w.message) for w in caught if "parallel=True" in str(w.message)]
    assert not loud, loud


def test_kernels_fall_back_to_plain_caching_where_numbas_internals_moved(tmp_path):
    """Should a Numba release rename the private cache classes ``_jit`` builds on, ``import
    hybridsub`` still works: every kernel is plain ``njit(cache=True)``, with one warning."""
    code = textwrap.dedent("""
        import warnings
        import numba.core.caching as caching
        del caching._CacheLocator
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            import hybridsub
            from hybridsub._topology import _halfedge_kernels as H
        import numpy as np
        said = [str(w.message) for w in caught if "plain cache=True" in str(w.message)]
        print(len(said), type(H.far_twins._cache).__name__, H.far_twins(np.zeros(6, np.int64)))
    """)
    assert _run(code, tmp_path, tmp_path / "cache") == "1 FunctionCache False"


def test_no_parfors_is_what_it_says_on_this_numba():
    """``NO_PARFORS`` leans on undocumented behaviour (a ``ParallelOptions`` object as
    ``parallel=``, and the text of a warning): on the Numba installed, within the verified
    range, it must still compile Numba's parallel pipeline with no thread launched and give
    exactly the warning that ``_quietly`` drops. A release that changes either fails here."""
    import warnings

    import numpy as np

    from hybridsub._jit import NO_PARFORS, NO_PARFORS_VERIFIED, serial_pipeline

    version = tuple(int(p) for p in numba.__version__.split(".")[:2])
    low, high = NO_PARFORS_VERIFIED
    assert low <= version <= high, (f"numba {numba.__version__} is outside the range NO_PARFORS was verified "
                                    f"on {NO_PARFORS_VERIFIED}: check it and widen the range, or drop it")
    assert serial_pipeline() is NO_PARFORS

    def scaled(x):
        out = np.empty_like(x)
        for i in numba.prange(len(x)):
            out[i] = 2.0 * x[i]
        return out

    raw = numba.njit(parallel=NO_PARFORS)(scaled)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert raw(np.arange(3.0)).tolist() == [0.0, 2.0, 4.0]
    import re

    pattern = "(?s).*'parallel=True' was specified but no transformation"
    assert any(re.match(pattern, str(w.message)) for w in caught), [str(w.message) for w in caught]
    llvm = "".join(raw.inspect_llvm().values())
    assert "do_scheduling" not in llvm  # nothing is handed to Numba's thread pool
    threaded = numba.njit(parallel=True)(scaled)
    threaded(np.arange(3.0))
    assert "do_scheduling" in "".join(threaded.inspect_llvm().values())  # the marker still means threads


def test_no_parfors_switch_off_gives_the_plain_pipeline(monkeypatch):
    from hybridsub._jit import serial_pipeline

    monkeypatch.setenv("HYBRIDSUB_NO_PARFORS", "0")
    assert serial_pipeline() is False
