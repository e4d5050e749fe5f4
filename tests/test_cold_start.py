"""The first call after an install: a notice while kernels compile, and ``hybridsub warmup``
compiling everything ahead, so that no later call compiles."""

import os
import subprocess
import sys
import textwrap
import types

import pytest

import hybridsub
from hybridsub._jit import _CompileNotice

_COUNT_COMPILES = textwrap.dedent("""
    import sys
    from numba.core import event
    compiled = []
    class Count(event.Listener):
        def on_start(self, ev):
            compiled.append(ev.data["dispatcher"].py_func.__module__ + "." + ev.data["dispatcher"].py_func.__name__)
        def on_end(self, ev):
            pass
    event.register("numba:compile", Count())
""")

_USER_CALLS = textwrap.dedent("""
    import numpy as np
    import hybridsub
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, angle=30)
    V2, F2 = hybridsub.subdivide(V, F, feat.sharp_edges, levels=2, corners=feat.corners)
    r = hybridsub.refine(F, feat.sharp_edges, levels=2, corners=feat.corners)
    r.apply(V); r.matrix
    hybridsub.subdivide(V, F, levels=2, scheme="sqrt3")
    hybridsub.limit_positions(V, F, feat.sharp_edges, corners=feat.corners, levels=1)
    s = hybridsub.LimitSurface(V, F, feat.sharp_edges, corners=feat.corners)
    s.evaluate(np.arange(10), np.full((10, 3), 1 / 3))
""")


def _python(code, cache_dir):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache_dir))
    env.pop("HYBRIDSUB_COMPILE_NOTICE", None)
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=1800)


def _event(module):
    fn = types.SimpleNamespace(__module__=module)
    return types.SimpleNamespace(data={"dispatcher": types.SimpleNamespace(py_func=fn, _cache=None)})


def test_the_compile_notice_is_said_once_and_only_for_hybridsubs_kernels(monkeypatch, capsys):
    monkeypatch.setattr(_CompileNotice, "said", False)
    monkeypatch.delenv("HYBRIDSUB_COMPILE_NOTICE", raising=False)
    notice = _CompileNotice()
    notice.on_start(_event("someone_else"))
    assert capsys.readouterr().err == ""  # a user's own Numba function: not ours to announce
    notice.on_start(_event("hybridsub._topology._kernels"))
    notice.on_start(_event("hybridsub._refiner._stencil_kernels"))
    err = capsys.readouterr().err
    assert err.count("hybridsub: compiling its kernels") == 1 and "hybridsub warmup" in err
    monkeypatch.setattr(_CompileNotice, "said", False)
    monkeypatch.setenv("HYBRIDSUB_COMPILE_NOTICE", "0")
    notice.on_start(_event("hybridsub._topology._kernels"))
    assert capsys.readouterr().err == ""


def test_warmup_is_a_command():
    from hybridsub._app.cli import build_parser

    a = build_parser().parse_args(["warmup", "-q"])
    assert a.func.__name__ == "cmd_warmup" and a.quiet


@pytest.mark.slow
def test_after_warmup_no_call_compiles(tmp_path):
    """In a fresh cache: the first call says once that it compiles; after ``hybridsub
    warmup`` the calls of a first session compile nothing and say nothing."""
    cache = tmp_path / "numba"
    first = _python("import hybridsub; V, F = hybridsub.load_example(); hybridsub.subdivide(V, F, levels=1)", cache)
    assert first.returncode == 0, first.stderr[-2000:]
    assert first.stderr.count("hybridsub: compiling its kernels") == 1
    warm = subprocess.run([sys.executable, "-m", "hybridsub", "warmup", "-q"], capture_output=True, text=True,
                          env=dict(os.environ, NUMBA_CACHE_DIR=str(cache)), timeout=1800)
    assert warm.returncode == 0, warm.stderr[-2000:]
    after = _python(_COUNT_COMPILES + _USER_CALLS + textwrap.dedent("""
        ours = [c for c in compiled if c.startswith("hybridsub.")]
        print(len(ours), ours[:5])
    """), cache)
    assert after.returncode == 0, after.stderr[-2000:]
    assert after.stdout.startswith("0 "), after.stdout
    assert "compiling" not in after.stderr
