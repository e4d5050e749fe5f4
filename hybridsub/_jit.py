"""Compiling the kernels: Numba's on-disk cache, keyed on every source a kernel compiles in.

Numba's ``cache=True`` stamps a kernel's cache entry with its own file only. A kernel also
compiles in what it calls from other modules (the scheme's rules, the halfedge primitives,
constants), so with that stamp alone an edited rule would keep running its old compiled
copy until the kernel's own file changed. :func:`kernel` is ``njit(cache=True)`` with a
stamp that also covers the package modules the kernel's module imports from, followed
transitively: any edit to them recompiles the kernel on its next first call, and a warm
cache of unchanged sources loads as before.

>>> import hybridsub
>>> dependencies("hybridsub._topology._kernels")  # doctest: +NORMALIZE_WHITESPACE
('hybridsub._atomic', 'hybridsub._jit', 'hybridsub._prefetch', 'hybridsub._rules.step_rules',
 'hybridsub._topology._halfedge_kernels', 'hybridsub._topology._kernels')
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import os
import re
import sys
import types
import warnings

import numba
import numpy as np
from numba import njit
from numba.core.errors import NumbaPerformanceWarning

try:  # Numba's private cache classes: where they move, kernels fall back to plain cache=True
    from numba.core.caching import CompileResultCacheImpl, FunctionCache, NullCache, _CacheLocator
    from numba.core.dispatcher import Dispatcher
except ImportError:  # pragma: no cover - depends on the installed Numba
    _CacheLocator = None
try:
    from numba.core.cpu_options import ParallelOptions
except ImportError:  # pragma: no cover - depends on the installed Numba
    ParallelOptions = None

# ``from X import a, b`` (parenthesised over lines or not) and ``import X``, at a line's start.
_FROM = re.compile(r"^[ \t]*from[ \t]+([.\w]+)[ \t]+import[ \t]+(\([^)]*\)|[^\n#]*)", re.M)
_IMPORT = re.compile(r"^[ \t]*import[ \t]+([^\n#]*)", re.M)


def kernel(fn=None, **options):
    """``numba.njit(cache=True, **options)``, its cache keyed on the sources it compiles in.

    Use as ``@kernel`` or ``@kernel(inline="always")``. The cache lives where Numba puts it
    (``NUMBA_CACHE_DIR``, else ``__pycache__``); only the stamp that decides whether an entry
    is fresh differs (see :func:`dependencies`).

    Examples
    --------
    >>> from hybridsub._topology._halfedge_kernels import dest
    >>> type(dest._cache).__name__
    'DependencyKeyedCache'
    """
    if fn is None:
        return functools.partial(kernel, **options)
    if "parallel" in options and options["parallel"] is NO_PARFORS:
        options["parallel"] = serial_pipeline()
    quiet = NO_PARFORS is not None and options.get("parallel") is NO_PARFORS
    if not _keyed_cache_works():
        dispatcher = njit(cache=True, **options)(fn)
    else:
        dispatcher = njit(**options)(fn)
        if _CacheLocator is not None and isinstance(dispatcher, Dispatcher):  # not NUMBA_DISABLE_JIT
            dispatcher._cache = DependencyKeyedCache(dispatcher.py_func)  # as Dispatcher.enable_caching
    if quiet and hasattr(dispatcher, "compile"):
        dispatcher.compile = _quietly(dispatcher.compile)
    return dispatcher


@functools.lru_cache(maxsize=None)
def _keyed_cache_works() -> bool:
    """Whether Numba's private cache classes are where :class:`DependencyKeyedCache` expects
    them (checked on a throwaway dispatcher, once). Where not, every kernel is plain
    ``njit(cache=True)`` and a warning says that an edit to a rule module then needs
    ``__pycache__`` (or ``NUMBA_CACHE_DIR``) cleared: never an import failure."""
    if os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0"):
        return True
    works = _CacheLocator is not None
    if works:
        try:
            probe = njit(lambda: 0)
            works = isinstance(probe, Dispatcher) and isinstance(getattr(probe, "_cache", None), NullCache)
            DependencyKeyedCache(_probe_function)._impl.locator.get_source_stamp()
        except Exception:  # noqa: BLE001 - any change in Numba's internals
            works = False
    if not works:
        warnings.warn(f"hybridsub: numba {numba.__version__} keeps its kernel cache differently from the "
                      "versions hybridsub was tested with; kernels use plain cache=True, so after editing "
                      "hybridsub's sources clear the Numba cache (__pycache__ or NUMBA_CACHE_DIR)",
                      RuntimeWarning, stacklevel=3)
    return works


def _probe_function():
    return 0


class _CompileNotice(numba.core.event.Listener):
    """Says once per process, on stderr, that hybridsub's kernels are being compiled: the
    first call after an install (or after an edit of the sources) waits for it, and a
    silent wait of many seconds reads as a hang. ``HYBRIDSUB_COMPILE_NOTICE=0`` silences it.
    Each such compile also lets :mod:`hybridsub._compile_ahead` start (or switch) the helpers
    that compile the rest of the call's kernels ahead."""

    said = False

    def on_start(self, event):
        dispatcher = event.data.get("dispatcher")
        module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
        if not module.startswith("hybridsub."):
            return
        try:  # by name, not a ``from . import``: a kernel's cache stamp follows this module's imports
            importlib.import_module("hybridsub._compile_ahead").on_compile()
        except Exception:  # noqa: BLE001 - compiling ahead only saves time: never a failed call
            pass
        if _CompileNotice.said:
            return
        _CompileNotice.said = True
        if os.environ.get("HYBRIDSUB_COMPILE_NOTICE", "1") == "0":
            return
        _say(f"hybridsub: compiling its kernels for this machine, once (seconds for a first call; each "
             f"new kind of call compiles what it needs). Later runs load them from {_cache_home(dispatcher)} "
             f"(NUMBA_CACHE_DIR moves it); `hybridsub warmup` compiles all of them ahead.")

    def on_end(self, event):
        pass


def _cache_home(dispatcher) -> str:
    """Where the compiled kernels go, in words."""
    if numba.config.CACHE_DIR:
        return numba.config.CACHE_DIR
    path = getattr(getattr(dispatcher, "_cache", None), "_cache_path", None)
    if not path:
        return "Numba's cache"
    if os.path.basename(path) == "__pycache__":
        return f"the __pycache__ folders in {os.path.dirname(os.path.dirname(path))}"
    return path


def _say(message: str) -> None:
    """``message`` on stderr, above a tqdm bar if one is drawn."""
    tqdm = sys.modules.get("tqdm")
    if tqdm is not None and getattr(tqdm, "tqdm", None) is not None:
        tqdm.tqdm.write(message, file=sys.stderr)
    else:
        print(message, file=sys.stderr, flush=True)


numba.core.event.register("numba:compile", _CompileNotice())


#: ``kernel(parallel=NO_PARFORS)``: Numba's parallel pipeline with every transformation off.
#: ``prange`` runs as ``range`` and nothing runs on threads, but the code is the parallel
#: pipeline's, which keeps arrays out of reference counting inside loops where Numba's plain
#: pipeline counts references of array views on every iteration (docs/performance.md,
#: "Kernel design"). The same operations, so the same bits. Used by the serial twins of
#: :func:`threaded_and_serial` (a step's kernels on one thread, the limit surface's walk),
#: a step's one-pass kernels and the limit surface's per-point kernels, whose outputs the
#: tests check bit for bit.
#: (An options object, not a dict: Numba empties a dict of parallel options as it reads it,
#: so a shared dict would leave every later kernel fully parallel.)
NO_PARFORS = None if ParallelOptions is None else ParallelOptions({
    "prange": False, "numpy": False, "reduction": False, "setitem": False, "stencil": False,
    "comprehension": False, "fusion": False, "inplace_binop": False})


#: The Numba releases on which :data:`NO_PARFORS` was checked to do what it says (``prange``
#: in order on the calling thread, no thread launched, the warning :func:`_quietly` drops):
#: ``tests/test_kernel_cache.py`` fails if a release changes any of it. Outside this range,
#: and with ``HYBRIDSUB_NO_PARFORS=0``, the serial kernels use Numba's plain pipeline
#: instead: the same results, slower loops.
NO_PARFORS_VERIFIED = ((0, 60), (0, 68))


def serial_pipeline():
    """What ``parallel=`` a serial kernel gets: :data:`NO_PARFORS` where it was verified
    (:data:`NO_PARFORS_VERIFIED`), else False.

    Examples
    --------
    >>> serial_pipeline() in (NO_PARFORS, False)
    True
    """
    if os.environ.get("HYBRIDSUB_NO_PARFORS", "1") == "0":
        return False
    version = tuple(int(part) for part in re.findall(r"\d+", numba.__version__)[:2])
    low, high = NO_PARFORS_VERIFIED
    return NO_PARFORS if NO_PARFORS is not None and low <= version <= high else False


def _quietly(compile_):
    """``compile_`` without Numba's warning that a parallel kernel found nothing to run on
    threads (true, and meant: see :data:`NO_PARFORS`)."""
    @functools.wraps(compile_)
    def compile(sig):
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="(?s).*'parallel=True' was specified but no transformation",
                                    category=NumbaPerformanceWarning)
            return compile_(sig)
    return compile


def threaded_and_serial(fn):
    """Compile a kernel written with ``prange`` twice: threaded, and serial (``prange`` runs
    as ``range``, :data:`NO_PARFORS`). The serial twin is a copy of the function under its
    own name, so the two have separate on-disk caches. Returns ``(threaded, serial)``."""
    serial = types.FunctionType(fn.__code__, fn.__globals__, fn.__name__ + "_serial", fn.__defaults__,
                                fn.__closure__)
    serial.__qualname__ = fn.__qualname__ + "_serial"
    serial.__doc__ = fn.__doc__
    return kernel(parallel=True)(fn), kernel(parallel=NO_PARFORS)(serial)


def set_threads(n: int | None = None) -> int:
    """Set how many threads the kernels use from now on; returns the number set.

    ``n``: 1 runs everything on one core; None (default) goes back to every thread Numba
    starts with (``NUMBA_NUM_THREADS``, by default one per core), the most ``n`` may be.
    Results do not depend on it: every kernel sums each output in the same order whatever
    the number of threads, so one thread and all give the same bits. Numba keeps the
    setting per calling thread (a thread started later begins with all of them); the
    command line's ``hybridsub --threads N`` sets it for the whole run.

    Examples
    --------
    >>> import hybridsub
    >>> hybridsub.set_threads(1)
    1
    >>> hybridsub.set_threads() >= 1
    True
    """
    most = numba.config.NUMBA_NUM_THREADS
    if n is None:
        n = most
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)):
        raise TypeError(f"threads must be an integer or None, got {n!r}")
    if not 1 <= n <= most:
        raise ValueError(f"threads must be between 1 and {most} (NUMBA_NUM_THREADS), got {n}")
    numba.set_num_threads(int(n))
    return int(n)


def dependencies(module: str) -> tuple[str, ...]:
    """The package modules whose sources a kernel of ``module`` may compile in, sorted:
    ``module`` itself and every module of its package it imports from, transitively.

    A name imported from a package (``from .._topology import dest``) counts as its defining
    module where it has one (functions, kernels), else as the package's ``__init__``. Imports
    are read from the source (``from X import ...`` and ``import X`` statements at a line's
    start), so constants count too; names reached otherwise (``importlib``) do not.
    """
    seen = {module}
    todo = [module]
    while todo:
        for dep in _imports(todo.pop()):
            if dep not in seen:
                seen.add(dep)
                todo.append(dep)
    return tuple(sorted(seen))


@functools.lru_cache(maxsize=None)
def _imports(module: str) -> tuple[str, ...]:
    """The modules of ``module``'s own top-level package that its source imports from."""
    path = _source(module)
    top = module.split(".", 1)[0]
    package = module if os.path.basename(path) == "__init__.py" else module.rpartition(".")[0]
    with open(path, encoding="utf-8") as f:
        text = f.read()
    found = set()
    for match in _FROM.finditer(text):
        try:
            base = importlib.util.resolve_name(match[1], package)
        except (ImportError, ValueError):
            continue
        if base == top or base.startswith(top + "."):
            names = match[2].strip("() \t\n").replace("\n", " ").split(",")
            found.update(_origin(base, name.split()[0]) for name in names if name.split())
    for match in _IMPORT.finditer(text):
        for name in match[1].split(","):
            name = name.split()[0] if name.split() else ""
            if name == top or name.startswith(top + "."):
                found.add(name)
    found.discard(module)
    return tuple(sorted(found))


def _origin(base: str, name: str) -> str:
    """The module that ``from base import name`` takes its code from."""
    if f"{base}.{name}" in sys.modules:
        return f"{base}.{name}"
    obj = getattr(sys.modules.get(base), name, None)
    where = getattr(getattr(obj, "py_func", obj), "__module__", None)  # constants have none
    top = base.split(".", 1)[0]
    if isinstance(where, str) and (where == top or where.startswith(top + ".")):
        return where
    return base


def _source(module: str) -> str:
    loaded = sys.modules.get(module)
    path = getattr(loaded, "__file__", None)
    if path is None:
        path = importlib.util.find_spec(module).origin
    return path


@functools.lru_cache(maxsize=None)
def _hash_file(path: str, mtime_ns: int, size: int) -> bytes:
    # mtime and size in the key: a file edited while the process runs is hashed again.
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).digest()


def _digest(path: str) -> bytes:
    st = os.stat(path)
    return _hash_file(path, st.st_mtime_ns, st.st_size)


if _CacheLocator is not None:
    class _DependencyStamp(_CacheLocator):
        """Numba's own locator for the function (cache directory, file names) with a source
        stamp that adds the contents of the modules in :func:`dependencies`."""

        def __init__(self, inner: _CacheLocator, module: str):
            self._inner = inner
            self._module = module

        def ensure_cache_path(self):
            self._inner.ensure_cache_path()

        def get_cache_path(self):
            return self._inner.get_cache_path()

        def get_disambiguator(self):
            return self._inner.get_disambiguator()

        def get_source_stamp(self):
            deps = tuple((name, _digest(_source(name))) for name in dependencies(self._module))
            return self._inner.get_source_stamp(), deps


    class _DependencyKeyedImpl(CompileResultCacheImpl):
        def __init__(self, py_func):
            super().__init__(py_func)
            self._locator = _DependencyStamp(self._locator, py_func.__module__)


    class DependencyKeyedCache(FunctionCache):
        """A Numba function cache whose entries go stale when any source in the kernel's
        :func:`dependencies` changes, not only the kernel's own file."""

        _impl_class = _DependencyKeyedImpl
else:  # pragma: no cover - depends on the installed Numba
    DependencyKeyedCache = None
