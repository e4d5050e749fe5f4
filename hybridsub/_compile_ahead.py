"""Compiling ahead: while a first call compiles its kernels, helper processes compile the rest.

Private. A first call on an empty kernel cache compiles each kernel as it reaches it, one
after the other, on one core. The kernels a kind of call needs are known ahead: the lists in
``data/kernel_signatures.json``, one per job (``"limit surface/hybrid"``, ``"refine/loop"``,
…), each kernel with the argument types it was compiled for: first what only larger calls
compile (the threaded twins), then the rest in the order a first call compiles them. On the
first compile of a process, :func:`on_compile` names the job from the call stack (the
outermost public entry point, its ``scheme`` and tags) and starts helper processes
(``python -m hybridsub._compile_ahead JOB PARENT_PID I N``) that compile that job's list from
its end, into the same on-disk cache; a later compile under another entry
point (``detect_features`` first, then ``LimitSurface``) ends them and starts that job's.
The call walks the list from the start; what a helper has written by the time the call
reaches it is loaded, not compiled. On two cores, cold first calls take 8–47 % less wall
time (docs/performance.md, "First call").

The results do not change: a kernel loaded from the cache is the one the call would have
compiled. Helpers run only in a process's main interpreter (not in multiprocessing workers),
with at least two usable cores (one helper per further core, three at most), at a lower
priority, and end when the process exits or their parent is gone. ``HYBRIDSUB_COMPILE_AHEAD=0``
turns them off; the tests do.

``python -m hybridsub._compile_ahead --record [JOB ...]`` writes the lists again (each job's
call run in a fresh process on an empty cache, every compile recorded): run it after adding
kernels or changing what a call compiles (``tests/test_compile_ahead.py`` fails where a
listed kernel is gone, and, slow, where a listed call compiles a kernel its list lacks).

>>> sig = (numba.types.int64[:, ::1], numba.types.float64)
>>> encode(sig)
[['array', 'int64', 2, 'C', False], ['scalar', 'float64']]
>>> decode(encode(sig)) == sig
True
"""

from __future__ import annotations

import atexit
import functools
import importlib
import json
import multiprocessing
import os
import subprocess
import sys
import tempfile
from collections.abc import Sequence

import numba
import numpy as np
from numba.core import types

#: The lists of kernels per job, shipped with the package.
SIGNATURES = os.path.join(os.path.dirname(__file__), "data", "kernel_signatures.json")
#: The job of a first compile that no entry point on the stack names (``detect_features``, …).
DEFAULT_JOB = "subdivide/hybrid"
#: Helpers at most, whatever the number of cores.
MOST_HELPERS = 3
SCHEMES = ("hybrid", "loop", "sqrt3")

#: Public entry points, by (module, function name), and the job each names. A method of
#: ``LimitSurface`` counts as ``"limit surface"``.
ENTRY_POINTS = {
    **{("hybridsub._refiner.fastpath", "subdivide"): "subdivide",
       ("hybridsub._refiner.facevarying", "subdivide_face_varying"): "subdivide",
       ("hybridsub._refiner.refinement", "refine"): "refine",
       ("hybridsub._refiner.facevarying", "refine_face_varying"): "refine",
       ("hybridsub._surface.adaptive", "subdivide_adaptive"): "adaptive",
       ("hybridsub._surface.adaptive", "refine_adaptive"): "adaptive",
       ("hybridsub._fit.fitting", "fit"): "fit"},
    **{("hybridsub._surface.vertex_limit", name): "limit positions"
       for name in ("limit_positions", "limit_normals", "limit_matrix", "limit_mesh", "limit_tangents")},
}
SURFACE_MODULE = "hybridsub._surface.surface"
#: The arguments whose presence makes a call tagged (creases or corners: other kernels).
TAG_ARGUMENTS = ("sharp_edges", "sharp_faces", "corners", "feature_angle")

#: What ``--record`` runs per job, in a fresh process (``scheme`` filled in; ``V, F``: the
#: example, ``E, C``: its 30° creases and corners, or None where the job is untagged).
RECIPES = {
    "subdivide": """
hybridsub.subdivide(V, F, E, levels=2, scheme=scheme, corners=C)
""",
    "refine": """
r = hybridsub.refine(F, E, levels=2, scheme=scheme, corners=C)
r.apply(V)
""",
    "limit positions": """
hybridsub.limit_positions(V, F, E, levels=1, scheme=scheme, corners=C)
hybridsub.limit_normals(V, F, E, levels=1, scheme=scheme, corners=C)
""",
    "limit surface": """
s = hybridsub.LimitSurface(V, F, E, scheme=scheme, corners=C)
rng = np.random.default_rng(0)
face, bary = rng.integers(0, len(F), 200), rng.dirichlet(np.ones(3), 200)
s.evaluate(face, bary)
s.evaluate(face, bary, derivatives=True)
""",
    "adaptive": """
hybridsub.subdivide_adaptive(V, F, E, tolerance="0.1%", scheme=scheme, corners=C)
""",
    "fit": """
r = hybridsub.refine(F, E, levels=1, scheme=scheme, corners=C)
hybridsub.fit(F, r.apply(V), E, corners=C, V0=V, scheme=scheme, levels=1, max_iterations=2)
""",
}
#: What ``--record`` runs after the recipe: larger calls of the same kind, whose extra kernels
#: (the threaded twins, from ``PARALLEL_MIN`` faces or points on) go first in the list, where
#: the helpers, working from its end, reach them last: a small first call does not wait for them.
LARGER = {
    "subdivide": "hybridsub.subdivide(V, F, E, levels=3, scheme=scheme, corners=C)",
    "refine": "hybridsub.refine(F, E, levels=3, scheme=scheme, corners=C).apply(V)",
    "limit positions": """
hybridsub.limit_positions(V, F, E, levels=2, scheme=scheme, corners=C)
hybridsub.limit_normals(V, F, E, levels=2, scheme=scheme, corners=C)
""",
    "limit surface": """
face, bary = rng.integers(0, len(F), 20000), rng.dirichlet(np.ones(3), 20000)
s.evaluate(face, bary, derivatives=True)
""",
}
#: ``"JOB/SCHEME"`` with creases and corners, ``"JOB/SCHEME untagged"`` without (√3: never tagged).
VARIANTS = ("hybrid", "hybrid untagged", "loop", "loop untagged", "sqrt3")
JOBS = tuple(f"{job}/{variant}" for job in RECIPES for variant in VARIANTS if job != "fit") + ("fit/hybrid",)

#: Jobs a process starts helpers for at most (the first, then switches to later entry points).
MOST_JOBS = 8

_helpers: list[subprocess.Popen] = []
_job: str | None = None
_jobs_started = 0


# ---------------------------------------------------------------------------------------------
# argument types as JSON


def encode(args: Sequence[types.Type]) -> list | None:
    """A kernel signature's argument types as JSON-able lists, or None where one of them has
    no encoding here (the helpers then skip that kernel)."""
    out = []
    for t in args:
        e = _encode_one(t)
        if e is None:
            return None
        out.append(e)
    return out


def _encode_one(t: types.Type):
    if isinstance(t, types.Array) and isinstance(t.dtype, (types.Integer, types.Float, types.Boolean)):
        return ["array", str(t.dtype), t.ndim, t.layout, not t.mutable]
    if isinstance(t, (types.Integer, types.Float, types.Boolean)):
        return ["scalar", str(t)]  # NumPy's names: int64, float32, bool
    if isinstance(t, types.NoneType):
        return ["none"]
    if isinstance(t, types.UniTuple):
        inner = _encode_one(t.dtype)
        return None if inner is None else ["unituple", inner, t.count]
    if isinstance(t, types.Tuple):
        inner = [_encode_one(x) for x in t.types]
        return None if any(x is None for x in inner) else ["tuple", inner]
    return None


def decode(encoded: Sequence) -> tuple[types.Type, ...]:
    """The argument types that :func:`encode` wrote."""
    return tuple(_decode_one(e) for e in encoded)


def _decode_one(e) -> types.Type:
    kind = e[0]
    if kind == "array":
        return types.Array(numba.from_dtype(np.dtype(e[1])), int(e[2]), e[3], readonly=bool(e[4]))
    if kind == "scalar":
        return numba.from_dtype(np.dtype(e[1]))
    if kind == "none":
        return types.none
    if kind == "unituple":
        return types.UniTuple(_decode_one(e[1]), int(e[2]))
    if kind == "tuple":
        return types.Tuple([_decode_one(x) for x in e[1]])
    raise ValueError(f"unknown encoded type {e!r}")


def find_kernel(module: str, qualname: str):
    """The dispatcher of ``module`` whose Python function is ``qualname``, or None."""
    try:
        mod = importlib.import_module(module)
    except ImportError:
        return None
    for value in vars(mod).values():
        if getattr(getattr(value, "py_func", None), "__qualname__", None) == qualname and hasattr(value, "compile"):
            return value
    return None


def load_lists(path: str | None = None) -> dict[str, list]:
    """The shipped lists (or those at ``path``): job → [[module, qualname, encoded args], …],
    in first-call order. Stored once per kernel: ``{"kernels": [entry, …], "jobs": {job:
    [index, …]}}``."""
    try:
        with open(path or SIGNATURES, encoding="utf-8") as f:
            stored = json.load(f)
        kernels = stored["kernels"]
        return {job: [kernels[i] for i in indices] for job, indices in stored["jobs"].items()}
    except (OSError, ValueError, KeyError, TypeError, IndexError):
        return {}


# ---------------------------------------------------------------------------------------------
# the calling process


def job_on_stack(frame=None) -> str | None:
    """The job the running call belongs to: the outermost public entry point on the stack
    (:data:`ENTRY_POINTS`, or a method of ``LimitSurface``), its ``scheme`` and whether it
    was given creases or corners; None where no entry point is on the stack."""
    frame = frame if frame is not None else sys._getframe(1)
    found = None
    while frame is not None:
        module = frame.f_globals.get("__name__", "")
        job = ENTRY_POINTS.get((module, frame.f_code.co_name))
        owner = frame.f_locals.get("self")
        if job is None and module == SURFACE_MODULE and type(owner).__name__ == "LimitSurface":
            job = "limit surface"
        if job is not None:
            found = (job, frame.f_locals, owner)
        frame = frame.f_back
    if found is None:
        return None
    job, local, owner = found
    if job == "fit":
        return "fit/hybrid"
    scheme = local.get("scheme")
    if not isinstance(scheme, str):
        scheme = getattr(owner, "scheme", None)
    scheme = scheme if scheme in SCHEMES else "hybrid"
    if scheme == "sqrt3":
        return f"{job}/sqrt3"
    return f"{job}/{scheme}" if _tagged(local, owner) else f"{job}/{scheme} untagged"


def _tagged(local: dict, owner) -> bool:
    """Whether a call (its arguments, or the ``LimitSurface`` it runs on) has tags."""
    inp = getattr(owner, "_inp", None)
    if inp is not None and hasattr(inp, "sharp_edges"):
        return bool(len(inp.sharp_edges) or np.any(inp.corner))
    for name in TAG_ARGUMENTS:
        value = local.get(name)
        if value is None or value is Ellipsis:
            continue
        try:
            if len(value):
                return True
        except TypeError:  # a number: feature_angle, or a scalar mask
            return True
    return False


def helpers_wanted() -> int:
    """How many helpers a first compile starts here (0: off, or nowhere to run them)."""
    if os.environ.get("HYBRIDSUB_COMPILE_AHEAD", "1") == "0" or getattr(sys, "frozen", False):
        return 0
    if multiprocessing.parent_process() is not None or not os.path.basename(sys.executable or "").startswith("python"):
        return 0
    if os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0"):
        return 0
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    return max(0, min(cores - 1, MOST_HELPERS))


def on_compile() -> None:
    """Called by ``_jit``'s listener on each compile of a hybridsub kernel: start helpers for
    the job on the stack where none run for it. The first compile starts them (for
    :data:`DEFAULT_JOB` where no entry point is on the stack: ``detect_features`` or a file's
    check before ``subdivide``); a later compile under another entry point ends them and
    starts the new job's (:data:`MOST_JOBS` jobs per process at most)."""
    global _job, _jobs_started
    if _jobs_started >= MOST_JOBS:
        return
    job = job_on_stack()
    if job is None:
        if _job is not None:
            return
        job = DEFAULT_JOB
    if job == _job:
        return
    if _jobs_started == 0 and not helpers_wanted():
        _jobs_started = MOST_JOBS  # off for this process
        return
    lists = _lists()
    if job not in lists:
        return
    stop_helpers()
    _job = job
    _jobs_started += 1
    n = helpers_wanted()
    env = dict(os.environ, HYBRIDSUB_COMPILE_AHEAD="0", HYBRIDSUB_COMPILE_NOTICE="0")
    if numba.config.CACHE_DIR:
        env["NUMBA_CACHE_DIR"] = numba.config.CACHE_DIR
    # this copy of hybridsub first, wherever the caller's sys.path found it (a source checkout)
    home = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env["PYTHONPATH"] = os.pathsep.join([home] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
    for i in range(n):
        try:
            _helpers.append(subprocess.Popen(
                [sys.executable, "-m", "hybridsub._compile_ahead", job, str(os.getpid()), str(i), str(n)],
                env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                close_fds=True))
        except OSError:
            break
    if _jobs_started == 1:
        atexit.register(stop_helpers)


def switch_off() -> None:
    """No helpers from now on in this process (``hybridsub warmup`` compiles everything)."""
    global _jobs_started
    stop_helpers()
    _jobs_started = MOST_JOBS


@functools.lru_cache(maxsize=1)
def _lists() -> dict[str, list]:
    return load_lists()


def stop_helpers() -> None:
    """End the helpers still running (what they wrote to the cache stays)."""
    while _helpers:
        p = _helpers.pop()
        if p.poll() is None:
            p.terminate()
            try:
                p.wait(timeout=2)
            except subprocess.TimeoutExpired:
                p.kill()


# ---------------------------------------------------------------------------------------------
# the helper process


def compile_job(job: str, parent: int | None = None, part: int = 0, parts: int = 1) -> int:
    """Compile the kernels of ``job``'s list from its end, every ``parts``-th from the
    ``part``-th; stop early once ``parent`` is gone. Returns how many were compiled or loaded."""
    import hybridsub  # noqa: F401 - the kernels' modules import from it

    done = 0
    entries = load_lists().get(job, [])[::-1][part::parts]
    for module, qualname, encoded in entries:
        if parent is not None and os.getppid() != parent:
            break
        dispatcher = find_kernel(module, qualname)
        if dispatcher is None:
            continue
        try:
            dispatcher.compile(decode(encoded))
        except Exception:  # noqa: BLE001 - a stale entry: the call compiles it itself
            continue
        done += 1
    return done


# ---------------------------------------------------------------------------------------------
# recording the lists


def _record_child(job: str) -> None:
    """In a fresh process on an empty cache: run ``job``'s recipe, print what compiled."""
    import hybridsub

    seen: list = []

    class Recorder(numba.core.event.Listener):
        def on_start(self, event):
            dispatcher = event.data.get("dispatcher")
            fn = getattr(dispatcher, "py_func", None)
            if fn is None or not fn.__module__.startswith("hybridsub."):
                return
            encoded = encode(event.data.get("args", ()))
            entry = [fn.__module__, fn.__qualname__, encoded]
            if encoded is not None and find_kernel(fn.__module__, fn.__qualname__) is dispatcher and entry not in seen:
                seen.append(entry)

        def on_end(self, event):
            pass

    numba.core.event.register("numba:compile", Recorder())
    name, variant = job.split("/")
    scheme = variant.split()[0]
    V, F = hybridsub.load_example()
    if scheme == "sqrt3" or variant.endswith("untagged"):
        E, C = None, None
    else:
        feat = hybridsub.detect_features(V, F, angle=30)
        E, C = feat.sharp_edges, feat.corners
    scope = {"hybridsub": hybridsub, "np": np, "V": V, "F": F, "E": E, "C": C, "scheme": scheme}
    exec(RECIPES[name], scope)
    first = len(seen)
    exec(LARGER.get(name, ""), scope)
    print(json.dumps(seen[first:] + seen[:first]))


def record(path: str | None = None, jobs: Sequence[str] = JOBS) -> dict[str, list]:
    """Run each job's recipe in a fresh process on an empty cache; write the lists."""
    from concurrent.futures import ThreadPoolExecutor

    def one(job: str) -> list:
        with tempfile.TemporaryDirectory() as cache:
            env = dict(os.environ, NUMBA_CACHE_DIR=cache, HYBRIDSUB_COMPILE_AHEAD="0", HYBRIDSUB_COMPILE_NOTICE="0")
            out = subprocess.run([sys.executable, "-c", f"from hybridsub._compile_ahead import _record_child; "
                                  f"_record_child({job!r})"], env=env, check=True, capture_output=True, text=True)
        entries = json.loads(out.stdout.strip().splitlines()[-1])
        print(f"{job}: {len(entries)} kernels", file=sys.stderr, flush=True)
        return entries

    with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        lists = {**load_lists(path), **dict(zip(jobs, pool.map(one, jobs)))}
    lists = {job: lists[job] for job in JOBS if job in lists}
    kernels: list = []
    index: dict[str, int] = {}
    for entries in lists.values():
        for e in entries:
            index.setdefault(json.dumps(e), len(kernels))
            if len(kernels) < len(index):
                kernels.append(e)
    with open(path or SIGNATURES, "w", encoding="utf-8") as f:
        f.write('{"numba": ' + json.dumps(numba.__version__) + ',\n "kernels": [\n')
        f.write(",\n".join(f"  {json.dumps(e)}" for e in kernels))
        f.write('],\n "jobs": {\n')
        f.write(",\n".join(f"  {json.dumps(job)}: {json.dumps([index[json.dumps(e)] for e in entries])}"
                           for job, entries in lists.items()))
        f.write("\n }\n}\n")
    return lists


def _main(argv: list[str]) -> int:
    if argv[:1] == ["--record"]:
        record(jobs=argv[1:] or JOBS)
        return 0
    job, parent, part, parts = argv[0], int(argv[1]), int(argv[2]), int(argv[3])
    try:
        os.nice(10)
    except (AttributeError, OSError):
        pass
    compile_job(job, parent, part, parts)
    return 0


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1:]))
