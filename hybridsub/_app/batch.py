"""Many mesh files subdivided on Dask: :func:`batch` and ``hybridsub batch``.

One task per mesh. The client walks the inputs and plans them a chunk at a time against the
manifest (``plan.py``, ``manifest.py``) while the first tasks already run, keeps a window of
tasks in flight that follows the cluster's threads, and records results in batches. Each
task carries a few paths and the options; the worker (``task.py``) runs the file pipeline
on its input (:func:`~hybridsub._app.pipeline.subdivide_file`, the code of ``hybridsub
subdivide``, so outputs equal the command's byte for byte), writes the output under a
temporary name, renames it, and sends back a small record. The decisions (names, the
manifest, resuming, exit codes) are in ``docs/batch.md``.
"""

from __future__ import annotations

import contextlib
import datetime
import hashlib
import json
import logging
import math
import os
import sqlite3
import time
import uuid
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

from .._input import check_options, count_of
from .._input.arrays import check_boundary
from .._rules import normalize_sharpness
from .._typing import LoopWeights, Scheme
from .._units import si
from .._version import __version__
from .manifest import (
    TMPDIR,
    Manifest,
    is_disk_full,
)
from .batch_plan import CHUNK, Chunk, Planner, clean_tmpdir, walk_inputs
from .task import run_task

__all__ = ["BatchSummary", "batch"]

FORMATS = ("obj", "ply", "npz")
INSTALL_HINT = "python -m pip install 'hybridsub[batch]'"
#: tasks in flight: this many per thread of the cluster, at least MIN_WINDOW; the threads are
#: asked for again every WINDOW_SECONDS, so workers that join later are kept busy too
PER_THREAD, MIN_WINDOW, WINDOW_SECONDS = 4, 16, 1.0
MAX_FAILURES = 1000  # failures a BatchSummary lists (all are in the manifest)
_RUN_AGAIN = "what finished is recorded in the manifest: run the same command again to finish"


def _import_dask():
    try:
        import distributed
    except ImportError as e:
        raise ImportError(f"hybridsub batch runs on Dask, which is not installed ({e}); install it with "
                          f"{INSTALL_HINT} (or python -m pip install 'dask[distributed]')") from None
    return distributed


# ----------------------------------------------------------------------------------------------
# the summary


@dataclass
class BatchSummary:
    """What one :func:`batch` call did (or, for a dry run, would do).

    Attributes
    ----------
    total : int
        Input files found.
    done, skipped, failed : int
        Meshes subdivided in this call; found done by an earlier call with the same options
        (not redone); failed (``failures`` says why). A dry run counts what would run in
        ``reasons`` and leaves ``done`` and ``failed`` at 0.
    output_faces : int
        Faces written in this call.
    seconds : float
        Wall time of the call, cluster start included.
    outdir, manifest : str
        The output folder and the manifest (SQLite) in it.
    failures : list of (str, str)
        ``(input path, error)`` of every failed mesh.
    cluster : str
        Where it ran (``"a local cluster of 2 workers"`` or the scheduler's address).
    notes : list of str
        What the run found and dealt with (a migrated manifest, stray temporary files).
    reasons : dict of str to int
        Why the meshes that ran (or would run) did: ``new``, ``failed before``, ``input
        changed``, … (``docs/batch.md``).
    dry_run : bool
        Nothing was run or written: :func:`batch` with ``dry_run=True``.

    Examples
    --------
    >>> s = BatchSummary(total=3, done=2, skipped=0, failed=1, output_faces=1200, seconds=2.0,
    ...                  outdir="out", manifest="out/hybridsub-manifest.sqlite",
    ...                  failures=[("bad.obj", "bad.obj: face 0 has 4 vertices")])
    >>> s.ok
    False
    >>> print(s.table().splitlines()[1])
      done              2   1,200 output faces
    """

    total: int
    done: int
    skipped: int
    failed: int
    output_faces: int
    seconds: float
    outdir: str
    manifest: str
    failures: list[tuple[str, str]] = field(default_factory=list)
    cluster: str = ""
    notes: list[str] = field(default_factory=list)
    reasons: dict[str, int] = field(default_factory=dict)
    dry_run: bool = False

    @property
    def ok(self) -> bool:
        """True when no mesh failed."""
        return self.failed == 0

    def table(self, max_failures: int = 10) -> str:
        """The final table ``hybridsub batch`` prints, failures listed (at most ``max_failures``)."""
        if self.dry_run:
            return self._dry_table()
        rate = ""
        if self.seconds > 0 and self.done:
            rate = f"   {self.done / self.seconds:.1f} meshes/s, {si(self.output_faces / self.seconds)} faces/s"
        where = f" on {self.cluster}" if self.cluster else ""
        lines = [f"hybridsub batch: {self.total:,} meshes → {self.outdir}{where}",
                 f"  done       {self.done:>8,}   {self.output_faces:,} output faces",
                 f"  skipped    {self.skipped:>8,}   done before with the same options",
                 f"  failed     {self.failed:>8,}" + (f"   listed in {self.manifest}" if self.failed else ""),
                 f"  wall time  {self.seconds:>6.2f} s{rate}"]
        lines += [f"note: {n}" for n in self.notes]
        return "\n".join(lines + self.failure_lines(max_failures))

    def _dry_table(self) -> str:
        new = self.reasons.get("new", 0)
        redo = sum(self.reasons.values()) - new
        why = ", ".join(f"{n:,} {r}" for r, n in sorted(self.reasons.items(), key=lambda x: -x[1]) if r != "new")
        lines = [f"hybridsub batch --dry-run: {self.total:,} meshes → {self.outdir} (nothing run or written)",
                 f"  would do   {new:>8,}   new",
                 f"  would redo {redo:>8,}" + (f"   {why}" if why else ""),
                 f"  would skip {self.skipped:>8,}   done before with the same options",
                 f"  planned in {self.seconds:>6.2f} s"]
        return "\n".join(lines + [f"note: {n}" for n in self.notes])

    def failure_lines(self, max_failures: int = 10) -> list[str]:
        """``failed: ERROR`` for the first ``max_failures`` failures, and how many more there are."""
        lines = [f"failed: {err if err.startswith(path) else f'{path}: {err}'}"
                 for path, err in self.failures[:max_failures]]
        if len(self.failures) > max_failures:
            lines.append(f"… and {len(self.failures) - max_failures:,} more failures "
                         "(hybridsub batch --status OUTDIR lists them all)")
        return lines

    def __str__(self) -> str:
        return self.table()


# ----------------------------------------------------------------------------------------------
# the client


def batch_options(levels, scheme, feature_angle, feature_sharpness, loop_weights, fmt, ignore_tags, triangulate,
                  weld, uv_mode, boundary="edge_only") -> dict:
    """The options of a batch, checked, as the manifest records them (and its key hashes them;
    ``boundary`` only when it is not the default, so a default batch keeps its key)."""
    levels = check_options(scheme, levels, loop_weights)
    if fmt not in FORMATS:
        raise ValueError(f"format must be one of {FORMATS}, got {fmt!r}")
    if feature_angle is not None:
        if isinstance(feature_angle, bool) or not isinstance(feature_angle, (int, float)) \
                or not 0 <= feature_angle <= 180:
            raise ValueError(f"feature_angle must be an angle between 0 and 180 degrees, got {feature_angle!r}")
        if scheme == "sqrt3":
            raise ValueError("feature_angle needs scheme 'hybrid' or 'loop': Kobbelt's √3 takes no feature tags")
        feature_angle = float(feature_angle)
    if feature_sharpness is not None:
        if isinstance(feature_sharpness, bool) or not isinstance(feature_sharpness, (int, float)) \
                or not feature_sharpness > 0:
            raise ValueError("feature_sharpness must be a number > 0 (inf: infinitely sharp), "
                             f"got {feature_sharpness!r}")
        if feature_angle is None:
            raise ValueError("feature_sharpness sets the sharpness of detected creases: give feature_angle too")
        feature_sharpness = float(normalize_sharpness(feature_sharpness))
        feature_sharpness = None if math.isinf(feature_sharpness) else feature_sharpness  # JSON has no inf
    names = ("linear", "smooth", "none", "corners_only", "corners_plus1", "corners_plus2", "boundaries", "all")
    if uv_mode not in (None,) + names:
        raise ValueError(f"uv_mode must be one of {names}, got {uv_mode!r}")
    out = {"levels": levels, "scheme": scheme, "feature_angle": feature_angle,
           "feature_sharpness": feature_sharpness, "loop_weights": loop_weights, "format": fmt,
           "ignore_tags": bool(ignore_tags), "triangulate": bool(triangulate), "weld": bool(weld), "uv_mode": uv_mode}
    if check_boundary(boundary) != "edge_only":
        out["boundary"] = boundary
    return out



def _default_workers() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def local_cluster(workers: int, *, quiet: bool = True, **kwargs):
    """(cluster, client): ``workers`` processes of one thread each, each with its share of the
    cores for Numba's threads, and glibc's own malloc trimming. (Dask sets
    ``MALLOC_TRIM_THRESHOLD_=65536`` in its workers, which turns glibc's adaptive thresholds
    off: every array above 128 KiB becomes a fresh mmap whose pages fault on first touch, and
    each mesh took 1.4x as long.) ``kwargs`` go to ``LocalCluster``."""
    import dask

    distributed = _import_dask()
    threads = max(1, _default_workers() // workers)
    with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}):
        cluster = distributed.LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
            silence_logs=logging.CRITICAL if quiet else logging.ERROR,
            env={"NUMBA_NUM_THREADS": str(threads)}, **kwargs)
    try:
        return cluster, distributed.Client(cluster, set_as_default=False)
    except BaseException:
        cluster.close()
        raise


def _connect(scheduler, workers: int | None, quiet: bool):
    """(client, things to close, description)."""
    distributed = _import_dask()
    if isinstance(scheduler, distributed.Client):
        return scheduler, [], f"the scheduler at {scheduler.scheduler.address}"
    if scheduler is not None:
        client = distributed.Client(scheduler, set_as_default=False)
        return client, [client], f"the scheduler at {scheduler}"
    n = _default_workers() if workers is None else workers
    cluster, client = local_cluster(n, quiet=quiet)
    return client, [client, cluster], f"a local cluster of {count_of(n, 'worker')}"


def options_key(options: dict, version: str) -> str:
    """What makes two runs' outputs of one input the same: the options and hybridsub's version."""
    text = json.dumps(dict(options, hybridsub=version), sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def batch(inputs: str | os.PathLike | Iterable[str | os.PathLike], outdir: str | os.PathLike, *, levels: int = 1,
          scheme: Scheme = "hybrid", feature_angle: float | None = None, feature_sharpness: float | None = None,
          format: str = "obj", loop_weights: LoopWeights = "loop", ignore_tags: bool = False,
          triangulate: bool = False, weld: bool = False, uv_mode: str | None = None, boundary: str = "edge_only",
          force: bool = False,
          scheduler=None, workers: int | None = None, verify: bool = False, dry_run: bool = False,
          lock: bool = True, fsync: bool = False, progress: bool = False,
          on_result: Callable[[dict], None] | None = None) -> BatchSummary:
    """Subdivide many mesh files on Dask, one task per mesh, resuming where an earlier call stopped.

    Each worker reads its input and writes its output itself (nothing large goes through the
    scheduler) with the code of ``hybridsub subdivide``, so every output equals that
    command's output byte for byte. Outputs are written under a temporary name and renamed; a
    manifest, ``OUTDIR/hybridsub-manifest.sqlite`` (SQLite), gets one row per mesh and options
    as results come. A later call with the same inputs and options skips what is done and
    redoes the rest. A mesh that fails is recorded with its error and the batch goes on. The
    inputs are walked and planned a chunk at a time while the first tasks run, so the client's
    memory does not grow with the number of inputs. See ``docs/batch.md``.

    Parameters
    ----------
    inputs : path, glob pattern, or an iterable of them
        Mesh files (any format :func:`read_mesh` reads), folders (walked, for the extensions
        ``.obj .ply .off .npz .stl .glb .gltf .3mf .dae .vtk .vtu``) and glob patterns (``**`` allowed).
    outdir : path
        The output folder. Outputs mirror the inputs' names below their folder or pattern.
    levels, scheme, feature_angle, feature_sharpness, loop_weights, uv_mode, boundary
        As for ``hybridsub subdivide`` (``--feature-sharpness``, ``--uv-mode``, ``--boundary``; ``uv_mode=None``:
        UVs with seams refined linearly, or dropped with a note under ``"sqrt3"``). Tags stored in OBJ, PLY and
        NPZ inputs are used, and propagated into OBJ, PLY and NPZ outputs.
    format : {"obj", "ply", "npz"}
        The output format (``docs/formats.md``).
    ignore_tags, triangulate, weld : bool
        As the command's ``--ignore-tags``, ``--triangulate``, ``--weld``.
    force : bool
        Run meshes whose memory estimate exceeds 80% of their worker's memory limit.
    scheduler : str or distributed.Client, optional
        A scheduler address (``"tcp://host:8786"``) or a connected client. Default: a local
        cluster of ``workers`` processes, one thread each, started (only if there is work) and
        stopped here.
    workers : int, optional
        Processes of the local cluster (default: the cores this process may use).
    verify : bool
        Before skipping a mesh done earlier, have a worker check the SHA-256 of its input and
        output against the manifest (reads both files); otherwise sizes and times are compared.
    dry_run : bool
        Only say what would be done, redone and skipped (``BatchSummary.reasons``): no cluster,
        nothing written, no lock taken.
    lock : bool
        Lock OUTDIR against a second batch (``flock``). ``False`` for a file system without
        locks, when nothing else writes to OUTDIR.
    fsync : bool
        Flush each output and each manifest transaction to the disk before recording it
        (survives a power loss, at a few ms per mesh); a killed process loses nothing either way.
    progress : bool
        Draw a progress bar on stderr.
    on_result : callable, optional
        Called with each record right after it is written to the manifest (in this process).
        An exception it raises stops the batch: unfinished tasks are cancelled.

    Returns
    -------
    BatchSummary

    Raises
    ------
    ImportError
        Dask is not installed (``pip install 'hybridsub[batch]'``).
    FileNotFoundError
        An input that does not exist, or a folder or pattern without mesh files.
    ValueError
        A bad option, no inputs, or an input inside ``outdir``.
    OSError
        The scheduler cannot be reached (Dask's ``TimeoutError``).
    RuntimeError
        Another batch is writing to ``outdir`` or its file system has no locks, the cluster
        went away, or the disk is full (each says to run again once mended).

    Examples
    --------
    >>> import hybridsub, tempfile, os
    >>> V, F = hybridsub.load_example()
    >>> d = tempfile.mkdtemp()
    >>> hybridsub.write_mesh(os.path.join(d, "in", "fandisk.obj"), V, F)
    >>> s = hybridsub.batch(os.path.join(d, "in"), os.path.join(d, "out"), levels=1,
    ...                     feature_angle=30, workers=1)
    >>> s.done, s.failed, "fandisk.obj" in os.listdir(os.path.join(d, "out"))
    (1, 0, True)
    """
    t_start = time.perf_counter()
    options = batch_options(levels, scheme, feature_angle, feature_sharpness, loop_weights, format, ignore_tags,
                            triangulate, weld, uv_mode, boundary)
    key = options_key(options, __version__)
    outdir = os.path.abspath(os.fspath(outdir))
    if os.path.exists(outdir) and not os.path.isdir(outdir):
        raise ValueError(f"{outdir}: the output folder is a file")
    if workers is not None:
        if scheduler is not None:
            raise ValueError("workers= starts a local cluster; it cannot be combined with scheduler=")
        if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
            raise ValueError(f"workers must be a positive integer, got {workers!r}")
    if not dry_run:
        _import_dask()
    inputs = [inputs] if isinstance(inputs, (str, os.PathLike)) else list(inputs)
    if not inputs:
        raise ValueError("no inputs given: name mesh files, folders or glob patterns")
    items = walk_inputs(inputs, outdir)
    try:
        with quiet_dask():
            return _batch(items, len(inputs) > 1, outdir, options, key, dict(
                force=bool(force), scheduler=scheduler, workers=workers, verify=verify, dry_run=dry_run, lock=lock,
                fsync=fsync, progress=progress, on_result=on_result), t_start)
    except (OSError, sqlite3.Error) as e:
        if is_disk_full(e):
            raise RuntimeError(f"{outdir}: the disk is full ({_strerror(e)}); free some space, then "
                               f"{_RUN_AGAIN}") from None
        raise


def _strerror(e: BaseException) -> str:
    return f"{e.filename}: {e.strerror}" if getattr(e, "filename", None) and getattr(e, "strerror", None) else str(e)


def _batch(items, dedupe: bool, outdir: str, options: dict, key: str, kw: dict, t_start: float) -> BatchSummary:
    from .progress import BatchProgress

    dry = kw["dry_run"]
    if not dry:
        os.makedirs(outdir, exist_ok=True)
    manifest = Manifest(outdir, readonly=dry, lock=kw["lock"], durable=kw["fsync"])
    planner = Planner(manifest, key, options["format"], outdir, kw["verify"], dedupe)
    summary = BatchSummary(total=0, done=0, skipped=0, failed=0, output_faces=0, seconds=0.0, outdir=outdir,
                           manifest=manifest.path, notes=manifest.notes, dry_run=dry)
    tmpdir = os.path.join(outdir, TMPDIR)
    closers: list = []
    try:
        if not dry:
            manifest.add_options(key, options, __version__)
            os.makedirs(tmpdir, exist_ok=True)
            stray = clean_tmpdir(outdir, tmpdir)
            if stray:
                summary.notes.append(f"removed {stray} temporary files left by an interrupted run")
        chunks = planner.chunks(items)
        if dry:
            for chunk in chunks:
                _count(summary, chunk)
        else:
            bar = BatchProgress(0, enabled=kw["progress"])
            run_id = uuid.uuid4().hex[:12]

            def job(item, name, reason, prev) -> dict:
                return {"input": item.path, "output": name, "output_path": os.path.join(outdir, *name.split("/")),
                        "tmpdir": tmpdir, "options": options, "options_key": key, "hybridsub": __version__,
                        "force": kw["force"], "fsync": kw["fsync"], "reason": reason, "verify": prev}

            def connect():
                client, close, summary.cluster = _connect(kw["scheduler"], kw["workers"], not kw["progress"])
                closers.extend(close)
                return client

            try:
                _run(connect, chunks, job, run_id, manifest, summary, bar, t_start, kw["on_result"])
            finally:
                bar.close()
    finally:
        planner.close()
        for c in closers:
            with contextlib.suppress(Exception):
                c.close()
        with contextlib.suppress(OSError):
            os.rmdir(tmpdir)  # when empty: every task finished or cleaned up
        manifest.close()
    summary.seconds = time.perf_counter() - t_start
    return summary


def _count(summary: BatchSummary, chunk: Chunk) -> None:
    summary.total += len(chunk.jobs) + chunk.skipped
    summary.skipped += chunk.skipped
    for r, n in chunk.reasons.items():
        summary.reasons[r] = summary.reasons.get(r, 0) + n


# ----------------------------------------------------------------------------------------------
# the run: plan, submit, gather


class Window:
    """How many tasks to keep in flight: ``PER_THREAD`` per thread the cluster has now (asked
    again every ``WINDOW_SECONDS``), at least ``MIN_WINDOW``."""

    def __init__(self, client, clock=time.monotonic):
        self.client, self.clock = client, clock
        self.threads, self.asked = 0, -math.inf

    def size(self) -> int:
        now = self.clock()
        if now - self.asked >= WINDOW_SECONDS:
            self.asked = now
            with contextlib.suppress(Exception):  # a scheduler slow to answer: keep the last count
                self.threads = sum(self.client.nthreads().values())
        return max(MIN_WINDOW, PER_THREAD * self.threads)


def _run(connect, chunks: Iterator[Chunk] | None, job, run_id: str, manifest: Manifest, summary: BatchSummary,
         bar, t_start: float, on_result) -> None:
    """Plan a chunk whenever the window has room, submit what is planned, and record the results
    in batches; the cluster starts (in the background, planning on) once there is work."""
    from distributed import as_completed

    pending: deque = deque()  # planned, not yet submitted: (input, name, reason, earlier record)
    inflight: dict = {}  # key → job
    starting = client = window = ac = None
    submitted = 0
    pool = ThreadPoolExecutor(1, thread_name_prefix="hybridsub-connect")

    def room() -> int:
        return (window.size() if window else 4 * CHUNK) - len(inflight) - len(pending)

    try:
        while True:
            if chunks is not None and room() > 0:
                chunk = next(chunks, None)
                if chunk is None:
                    chunks = None
                else:
                    _count(summary, chunk)
                    pending.extend(chunk.jobs)
                if pending and starting is None:
                    starting = pool.submit(connect)
            if client is None and starting is not None and (starting.done() or chunks is None or room() <= 0):
                client = starting.result()
                window, ac = Window(client), as_completed(loop=client.loop)
            if client is not None and pending:
                jobs = [job(*pending.popleft()) for _ in range(min(len(pending), window.size() - len(inflight)))]
                keys = [f"hybridsub-subdivide-{run_id}-{submitted + i}" for i in range(len(jobs))]
                submitted += len(jobs)
                futures = client.map(run_task, jobs, key=keys, pure=False) if jobs else []
                inflight.update((fut.key, j) for fut, j in zip(futures, jobs))
                ac.update(futures)
            if chunks is not None and room() > 0:  # more to plan: gather only what is ready
                finished = ac.next_batch(block=False) if ac is not None and ac.has_ready() else []
            elif inflight:
                finished = ac.next_batch(block=True)
            elif chunks is None and not pending:
                break
            else:
                continue
            if finished:
                _gather(finished, inflight, run_id, manifest, summary, on_result)
            bar.update(summary.done + summary.skipped, summary.failed, summary.output_faces,
                       time.perf_counter() - t_start, total=summary.total, planning=chunks is not None)
    finally:
        if inflight:  # stopped early: what has not finished is not recorded, and runs again next time
            with contextlib.suppress(Exception):
                client.cancel(list(inflight))
        if ac is not None:
            ac.clear()
        pool.shutdown(wait=True)


def _gather(finished, inflight: dict, run_id: str, manifest: Manifest, summary: BatchSummary, on_result) -> None:
    """Record a batch of finished tasks in one manifest transaction, count them, and stop the
    batch when the disk is full."""
    from distributed import CancelledError, KilledWorker

    records, full = [], None
    for fut in finished:
        job = inflight.pop(fut.key)
        try:  # a result lost with its worker since is computed again, and waited for here
            rec = fut.result()
        except CancelledError:
            raise RuntimeError(f"Dask cancelled the task for {job['input']}: the connection to the scheduler was "
                               f"lost, or the scheduler restarted; {_RUN_AGAIN}") from None
        except Exception as e:  # run_task never raises: this came from the cluster
            rec = failed_on_cluster(job, e, KilledWorker)
        fut.release()
        if rec.pop("no_space", False):
            full = rec["error"]
        rec["run"] = run_id
        rec["finished"] = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="milliseconds")
        records.append(rec)
    manifest.record([r for r in records if r["status"] != "skipped"])
    for rec in records:
        if rec["status"] == "done":
            summary.done += 1
            summary.output_faces += rec["faces_out"]
        elif rec["status"] == "skipped":
            summary.skipped += 1
        else:
            summary.failed += 1
            if len(summary.failures) < MAX_FAILURES:
                summary.failures.append((rec["input"], rec["error"]))
    if full is not None:
        raise RuntimeError(f"{summary.outdir}: the disk is full ({full}); free some space, then {_RUN_AGAIN}")
    if on_result is not None:
        for rec in records:
            on_result(rec)


def failed_on_cluster(job: dict, exc: BaseException, killed_worker: type) -> dict:
    """The record of a task that raised on the cluster (run_task itself never raises)."""
    if isinstance(exc, killed_worker):
        why = (f"{job['input']}: the worker running it died each time it was tried ({exc}); "
               "out of memory? try fewer levels or more memory per worker")
    else:
        why = f"{job['input']}: the task failed on the cluster: {type(exc).__name__}: {exc}"
        if isinstance(exc, ImportError):
            why += " (is hybridsub installed on the workers?)"
    return {"input": job["input"], "options": job["options"], "options_key": job["options_key"],
            "hybridsub": job["hybridsub"], "output": job["output"], "status": "failed", "reason": job["reason"],
            "error": why}


#: loggers whose messages a batch keeps to itself: Dask logs a lost worker or scheduler as
#: warnings and tracebacks; the batch reports it in one line (or recovers)
_DASK_LOGGERS = ("distributed", "tornado", "asyncio")


@contextlib.contextmanager
def quiet_dask():
    """Dask's loggers silent while a batch runs, restored after: each existing one disabled
    (``distributed.client`` and others have their own level, so quieting ``distributed`` is
    not enough), and the top ones at CRITICAL for those created meanwhile."""
    loggers = [logging.getLogger(n) for n in list(logging.root.manager.loggerDict)
               if n.split(".")[0] in _DASK_LOGGERS]
    tops = [logging.getLogger(n) for n in _DASK_LOGGERS]
    disabled = [lg.disabled for lg in loggers]
    levels = [lg.level for lg in tops]
    for lg in loggers:
        lg.disabled = True
    for lg in tops:
        lg.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for lg, d in zip(loggers, disabled):
            lg.disabled = d
        for lg, level in zip(tops, levels):
            lg.setLevel(level)
