"""Compiling ahead (hybridsub/_compile_ahead.py): the shipped kernel lists resolve and encode
faithfully, the job is named from the call stack, and a helper's cache makes the call it
compiled for load every kernel instead of compiling one (slow: fresh processes, empty caches)."""

import json
import multiprocessing
import os
import subprocess
import sys

import numba
import pytest

from hybridsub import _compile_ahead as ahead


def test_every_job_has_a_list_of_kernels_that_exist():
    lists = ahead.load_lists()
    assert set(lists) == set(ahead.JOBS)
    for job, entries in lists.items():
        assert len(entries) >= 5, job
        for module, qualname, encoded in entries:
            dispatcher = ahead.find_kernel(module, qualname)
            assert dispatcher is not None, f"{job}: {module}.{qualname} is gone: run python -m hybridsub._compile_ahead --record"
            assert ahead.encode(ahead.decode(encoded)) == encoded


def test_encoding_keeps_what_dispatch_looks_at():
    t = numba.types
    sig = (t.float64[:, ::1], t.int32[::1], t.Array(t.boolean, 1, "A", readonly=True), t.float32, t.int64,
           t.boolean, t.none, t.UniTuple(t.int64, 3), t.Tuple([t.float64, t.int64[:]]))
    assert ahead.decode(ahead.encode(sig)) == sig
    assert ahead.encode((t.float64, t.unicode_type)) is None  # not encoded: the helpers skip it


def test_the_outermost_entry_point_names_the_job():
    def entry(module, name):
        scope = {"__name__": module}
        exec(f"def {name}(inner, sharp_edges=None, *, scheme=None, corners=None, feature_angle=None):\n"
             "    return inner()", scope)
        return scope[name]

    adaptive = entry("hybridsub._surface.adaptive", "subdivide_adaptive")
    refine = entry("hybridsub._refiner.refinement", "refine")
    fit = entry("hybridsub._fit.fitting", "fit")
    edges = [[0, 1]]
    assert adaptive(ahead.job_on_stack, edges, scheme="loop") == "adaptive/loop"
    assert adaptive(ahead.job_on_stack, [], scheme="loop") == "adaptive/loop untagged"
    assert adaptive(ahead.job_on_stack, scheme="loop", corners=[3]) == "adaptive/loop"
    assert adaptive(ahead.job_on_stack, scheme="hybrid", feature_angle=30.0) == "adaptive/hybrid"
    assert adaptive(ahead.job_on_stack, edges, scheme="sqrt3") == "adaptive/sqrt3"
    assert adaptive(lambda: refine(ahead.job_on_stack, scheme="sqrt3"), edges, scheme="loop") == "adaptive/loop"
    assert refine(ahead.job_on_stack) == "refine/hybrid untagged"  # the default scheme
    assert fit(lambda: refine(ahead.job_on_stack, edges, scheme="loop")) == "fit/hybrid"
    assert ahead.job_on_stack() is None  # no entry point on the stack
    assert all(job in ahead.JOBS for job in ("adaptive/loop untagged", "refine/hybrid untagged", ahead.DEFAULT_JOB))


class _FakeHelper:
    started: list = []

    def __init__(self, args, **kw):
        self.args, self.ended = args, False
        _FakeHelper.started.append(self)

    def poll(self):
        return 0 if self.ended else None

    def terminate(self):
        self.ended = True

    def wait(self, timeout=None):
        return 0


def test_helpers_follow_the_entry_point_that_compiles(monkeypatch):
    monkeypatch.setattr(ahead.subprocess, "Popen", _FakeHelper)
    monkeypatch.setattr(ahead, "helpers_wanted", lambda: 2)
    monkeypatch.setattr(ahead, "_helpers", [])
    monkeypatch.setattr(ahead, "_job", None)
    monkeypatch.setattr(ahead, "_jobs_started", 0)
    _FakeHelper.started = []
    scope = {"__name__": "hybridsub._surface.adaptive", "on_compile": ahead.on_compile}
    exec("def subdivide_adaptive(sharp_edges=None, scheme='loop'):\n    on_compile()", scope)

    ahead.on_compile()  # a first compile outside any entry point (detect_features, a file's check)
    ahead.on_compile()
    first = list(_FakeHelper.started)
    assert [h.args[3:4] + h.args[5:] for h in first] == [[ahead.DEFAULT_JOB, "0", "2"], [ahead.DEFAULT_JOB, "1", "2"]]
    scope["subdivide_adaptive"]([[0, 1]])  # then the call itself: its own list, the first helpers ended
    assert all(h.ended for h in first)
    assert [h.args[3] for h in _FakeHelper.started[2:]] == ["adaptive/loop", "adaptive/loop"]
    ahead.on_compile()  # no entry point again: the helpers go on with the call's list
    scope["subdivide_adaptive"]([[0, 1]])
    assert len(_FakeHelper.started) == 4 and not any(h.ended for h in _FakeHelper.started[2:])
    ahead.switch_off()
    assert all(h.ended for h in _FakeHelper.started)
    scope["subdivide_adaptive"]([], scheme="hybrid")
    assert len(_FakeHelper.started) == 4


def test_limit_surface_methods_name_their_scheme_and_tags():
    import hybridsub

    V, F = hybridsub.load_example("icosahedron")
    scope = {"__name__": ahead.SURFACE_MODULE, "job_on_stack": ahead.job_on_stack}
    exec("def evaluate(self):\n    return job_on_stack()", scope)
    assert scope["evaluate"](hybridsub.LimitSurface(V, F, scheme="sqrt3")) == "limit surface/sqrt3"
    assert scope["evaluate"](hybridsub.LimitSurface(V, F, scheme="loop")) == "limit surface/loop untagged"
    assert scope["evaluate"](hybridsub.LimitSurface(V, F, [[0, 1]], corners=[5])) == "limit surface/hybrid"


def test_switched_off(monkeypatch):
    monkeypatch.setenv("HYBRIDSUB_COMPILE_AHEAD", "0")
    assert ahead.helpers_wanted() == 0
    monkeypatch.setenv("HYBRIDSUB_COMPILE_AHEAD", "1")
    assert ahead.helpers_wanted() == max(0, min(len(os.sched_getaffinity(0)) - 1, ahead.MOST_HELPERS))
    monkeypatch.setenv("NUMBA_DISABLE_JIT", "1")
    assert ahead.helpers_wanted() == 0


def _wanted_in_worker(out):
    out.put(ahead.helpers_wanted())


def test_no_helpers_in_multiprocessing_workers(monkeypatch):
    monkeypatch.setenv("HYBRIDSUB_COMPILE_AHEAD", "1")
    ctx = multiprocessing.get_context("fork")
    out = ctx.Queue()
    worker = ctx.Process(target=_wanted_in_worker, args=(out,))
    worker.start()
    assert out.get(timeout=60) == 0
    worker.join(timeout=60)


def test_a_stale_entry_is_skipped(tmp_path, monkeypatch):
    lists = {"refine/hybrid": [["hybridsub._topology._halfedge_kernels", "no_such_kernel", [["scalar", "int64"]]],
                               ["hybridsub.no_such_module", "dest", []]]}
    path = tmp_path / "lists.json"
    path.write_text(json.dumps({"kernels": lists["refine/hybrid"], "jobs": {"refine/hybrid": [0, 1]}}))
    monkeypatch.setattr(ahead, "SIGNATURES", str(path))
    assert ahead.load_lists(str(path)) == lists
    assert ahead.compile_job("refine/hybrid") == 0
    assert ahead.load_lists(str(tmp_path / "missing.json")) == {}


# What a user's first call looks like, written here (not the recipes the lists were recorded
# from): other point counts and arguments than the recording's.
_CALLS = {
    "refine/loop": """
feat = hybridsub.detect_features(V, F, angle=30)
r = hybridsub.refine(F, feat.sharp_edges, levels=3, scheme="loop", corners=feat.corners)
r.apply(V)
""",
    "limit surface/hybrid": """
feat = hybridsub.detect_features(V, F, angle=30)
s = hybridsub.LimitSurface(V, F, feat.sharp_edges, corners=feat.corners)
s.evaluate(np.arange(100), np.full((100, 3), 1 / 3), derivatives=True)
s.normals(np.arange(0, 3000, 7), np.tile([0.2, 0.3, 0.5], (429, 1)))
""",
    "adaptive/hybrid untagged": """
hybridsub.subdivide_adaptive(V, F, tolerance="0.1%")
""",
}
_CALL = """
import numba, numpy as np, hybridsub
misses = []
class Count(numba.core.event.Listener):
    def on_start(self, event):
        fn = event.data["dispatcher"].py_func
        if fn.__module__.startswith("hybridsub."):
            misses.append(fn.__qualname__)
    def on_end(self, event):
        pass
numba.core.event.register("numba:compile", Count())
V, F = hybridsub.load_example()
{call}
print("compiled:", misses)
"""


@pytest.mark.slow
@pytest.mark.parametrize("job", sorted(_CALLS))
def test_what_a_helper_compiled_the_call_loads(tmp_path, job):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), HYBRIDSUB_COMPILE_AHEAD="0")
    helper = subprocess.run([sys.executable, "-m", "hybridsub._compile_ahead", job, str(os.getpid()), "0", "1"],
                            env=env, capture_output=True, text=True, timeout=600)
    assert helper.returncode == 0, helper.stderr
    call = subprocess.run([sys.executable, "-c", _CALL.format(call=_CALLS[job])], env=env,
                          capture_output=True, text=True, timeout=600)
    assert call.returncode == 0, call.stderr
    assert "compiled: []" in call.stdout, call.stdout  # every kernel loaded from the helper's cache


_FIRST = """
import json, hybridsub
from hybridsub import _compile_ahead
V, F = hybridsub.load_example("icosahedron")
hybridsub.subdivide(V, F, levels=1, scheme="sqrt3")
print(json.dumps([[p.args[3]] + p.args[5:] for p in _compile_ahead._helpers] + [[p.pid for p in _compile_ahead._helpers]]))
"""


@pytest.mark.slow
@pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="one core: no helper")
def test_a_first_compile_starts_helpers_that_end_with_the_process(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), HYBRIDSUB_COMPILE_AHEAD="1")
    out = subprocess.run([sys.executable, "-c", _FIRST], env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    *jobs, pids = json.loads(out.stdout.strip().splitlines()[-1])
    n = min(len(os.sched_getaffinity(0)) - 1, ahead.MOST_HELPERS)
    assert jobs == [["subdivide/sqrt3", str(i), str(n)] for i in range(n)]
    for pid in pids:  # ended at exit (and reaped: no process of that id is left running hybridsub)
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                assert b"hybridsub._compile_ahead" not in f.read()
        except FileNotFoundError:
            pass
