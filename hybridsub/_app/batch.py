"""Many mesh files subdivided on Dask: :func:`batch` and ``hybridsub batch``.

One task per mesh. The client expands the inputs, decides which are already done (the
manifest), and sends each task a few paths and the options; the worker reads the input,
runs the file pipeline on it (:func:`~hybridsub._app.pipeline.subdivide_file`, the code of
``hybridsub subdivide``, so outputs equal the command's byte for byte), writes the output
under a temporary name, renames it, and sends back a small record. The client alone appends
records to the manifest (``manifest.py``). The decisions (names, the manifest, resuming, exit
codes) are in ``docs/batch.md``.
"""

from __future__ import annotations

import datetime
import hashlib
import logging
import math
import os
import time
import traceback
import uuid
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

from .._errors import MeshError
from .._input import check_options, count_of
from .._rules import normalize_sharpness
from .._typing import LoopWeights, Scheme
from .._units import si
from .._version import __version__
from .manifest import TMPDIR, Manifest, assign_outputs, clean_tmpdir, expand_inputs, options_key, plan_item
from .pipeline import FileOptions, PipelineError, subdivide_file

__all__ = ["batch", "BatchSummary"]

FORMATS = ("obj", "ply", "npz")
INSTALL_HINT = "python -m pip install 'hybridsub[batch]'"
_CHUNK = 1 << 20


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
    """What one :func:`batch` call did.

    Attributes
    ----------
    total : int
        Input files found.
    done, skipped, failed : int
        Meshes subdivided in this call; found done by an earlier call with the same options
        (not redone); failed (``failures`` says why).
    output_faces : int
        Faces written in this call.
    seconds : float
        Wall time of the call, cluster start included.
    outdir, manifest : str
        The output folder and the manifest (JSON lines) in it.
    failures : list of (str, str)
        ``(input path, error)`` of every failed mesh.
    cluster : str
        Where it ran (``"local cluster, 2 workers"`` or the scheduler's address).
    notes : list of str
        What the run found and dealt with (a torn manifest line, stray temporary files).

    Examples
    --------
    >>> s = BatchSummary(total=3, done=2, skipped=0, failed=1, output_faces=1200, seconds=2.0,
    ...                  outdir="out", manifest="out/hybridsub-manifest.jsonl",
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

    @property
    def ok(self) -> bool:
        """True when no mesh failed."""
        return self.failed == 0

    def table(self, max_failures: int = 10) -> str:
        """The final table ``hybridsub batch`` prints, failures listed (at most ``max_failures``)."""
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

    def failure_lines(self, max_failures: int = 10) -> list[str]:
        """``failed: ERROR`` for the first ``max_failures`` failures, and how many more there are."""
        lines = [f"failed: {err if err.startswith(path) else f'{path}: {err}'}"
                 for path, err in self.failures[:max_failures]]
        if len(self.failures) > max_failures:
            lines.append(f"… and {len(self.failures) - max_failures:,} more failures (see the manifest)")
        return lines

    def __str__(self) -> str:
        return self.table()


# ----------------------------------------------------------------------------------------------
# the task (runs on a worker)


def _sha256(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        while chunk := fh.read(_CHUNK):
            h.update(chunk)
    return h.hexdigest()


def _worker_settings() -> tuple[str, int | None]:
    """This worker's address and memory limit; Numba's threads for this task set to the
    worker process's share (its threads run one task each)."""
    try:
        from distributed import get_worker

        worker = get_worker()
    except (ImportError, ValueError):
        return "", None
    import numba

    nthreads = getattr(getattr(worker, "state", None), "nthreads", None) or 1
    numba.set_num_threads(max(1, numba.config.NUMBA_NUM_THREADS // nthreads))
    limit = getattr(getattr(worker, "memory_manager", None), "memory_limit", None)
    return worker.address, int(limit) if limit else None


def run_task(job: dict) -> dict:
    """Subdivide one file: the worker's side of a batch. Never raises for a bad mesh: the
    record says ``"status": "failed"`` and why."""
    t0 = time.perf_counter()
    src, dst = job["input"], job["output_path"]
    rec = {"input": src, "input_size": None, "input_mtime_ns": None, "input_sha256": None,
           "options": job["options"], "options_key": job["options_key"], "hybridsub": __version__,
           "output": job["output"], "output_size": None, "output_sha256": None, "status": "failed",
           "reason": job["reason"], "faces_in": None, "faces_out": None, "vertices_out": None,
           "features": None, "notes": [], "seconds": None, "worker": "", "error": None}
    tmp = None
    try:
        rec["worker"], memory_limit = _worker_settings()
        if __version__ != job["hybridsub"]:
            raise PipelineError(f"this worker has hybridsub {__version__}, the client {job['hybridsub']}: install the "
                           "same version everywhere")
        st = os.stat(src)
        rec["input_size"], rec["input_mtime_ns"] = st.st_size, st.st_mtime_ns
        rec["input_sha256"] = _sha256(src)
        expect = job.get("verify")
        if expect is not None:
            why = _verify(rec, expect, dst)
            if why is None:
                rec["status"] = "skipped"
                return rec
            rec["reason"] = why
        tmp = os.path.join(job["tmpdir"], f"{uuid.uuid4().hex}.{job['options']['format']}")
        res = subdivide_file(file_options(job["options"], force=job["force"], memory_limit=memory_limit), src, dst,
                             write_to=tmp)
        t = time.perf_counter()
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        rec["output_sha256"] = _sha256(tmp)
        rec["output_size"] = os.path.getsize(tmp)
        if os.stat(src).st_mtime_ns != st.st_mtime_ns:
            raise PipelineError(f"{src}: the file changed while it was being read")
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        os.replace(tmp, dst)
        tmp = None
        rec.update(status="done", faces_in=res.faces_in, faces_out=res.faces_out, vertices_out=res.vertices_out,
                   features=res.features, notes=res.notes)
        rec["seconds"] = {"read": round(res.seconds_read, 6), "refine": round(res.seconds_refine, 6),
                          "write": round(res.seconds_write + time.perf_counter() - t, 6)}
    except (PipelineError, MeshError, ValueError, TypeError) as e:
        rec["error"] = str(e)
    except OSError as e:
        rec["error"] = f"{e.filename}: {e.strerror}" if e.filename and e.strerror else str(e)
    except MemoryError:
        rec["error"] = f"{src}: out of memory; use fewer levels"
    except Exception as e:  # a bug: recorded with its traceback, the batch goes on
        rec["error"] = f"{src}: internal error: {type(e).__name__}: {e}"
        rec["traceback"] = traceback.format_exc()
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.remove(tmp)
        rec["seconds"] = dict(rec["seconds"] or {}, total=round(time.perf_counter() - t0, 6))
    return rec


def _verify(rec: dict, expect: dict, dst: str) -> str | None:
    """None when the input's content and the output file are what ``expect`` recorded; else why not."""
    if rec["input_sha256"] != expect.get("input_sha256"):
        return "verify: the input's checksum differs"
    if not os.path.isfile(dst):
        return "verify: the output is missing"
    if os.path.getsize(dst) != expect.get("output_size") or _sha256(dst) != expect.get("output_sha256"):
        return "verify: the output's checksum differs"
    for k in ("output_size", "output_sha256", "faces_in", "faces_out", "vertices_out", "features"):
        rec[k] = expect.get(k)
    return None


# ----------------------------------------------------------------------------------------------
# the client


def batch_options(levels, scheme, feature_angle, feature_sharpness, loop_weights, fmt, ignore_tags, triangulate,
                  weld, uv_mode) -> dict:
    """The options of a batch, checked, as the manifest records them (and its key hashes them)."""
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
    if uv_mode not in (None, "linear", "smooth"):
        raise ValueError(f"uv_mode must be 'linear' or 'smooth', got {uv_mode!r}")
    return {"levels": levels, "scheme": scheme, "feature_angle": feature_angle,
            "feature_sharpness": feature_sharpness, "loop_weights": loop_weights, "format": fmt,
            "ignore_tags": bool(ignore_tags), "triangulate": bool(triangulate), "weld": bool(weld), "uv_mode": uv_mode}



def file_options(options: dict, **changes) -> FileOptions:
    """The pipeline's options of one task: the batch's ``options`` (the format aside: it is the
    output's extension), no messages, and ``changes``."""
    return FileOptions(**{k: v for k, v in options.items() if k != "format"}, quiet=True, **changes)


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


def batch(inputs: str | os.PathLike | Iterable[str | os.PathLike], outdir: str | os.PathLike, *, levels: int = 1,
          scheme: Scheme = "hybrid", feature_angle: float | None = None, feature_sharpness: float | None = None,
          format: str = "obj", loop_weights: LoopWeights = "loop", ignore_tags: bool = False,
          triangulate: bool = False, weld: bool = False, uv_mode: str | None = None, force: bool = False,
          scheduler=None, workers: int | None = None, verify: bool = False, progress: bool = False,
          on_result: Callable[[dict], None] | None = None) -> BatchSummary:
    """Subdivide many mesh files on Dask, one task per mesh, resuming where an earlier call stopped.

    Each worker reads its input and writes its output itself (nothing large goes through the
    scheduler) with the code of ``hybridsub subdivide``, so every output equals that
    command's output byte for byte. Outputs are written under a temporary name and renamed;
    a manifest of JSON lines, ``OUTDIR/hybridsub-manifest.jsonl``, gets one record per mesh
    as it finishes. A later call with the same inputs and options skips what is done and
    redoes the rest. A mesh that fails is recorded with its error and the batch goes on.
    See ``docs/batch.md``.

    Parameters
    ----------
    inputs : path, glob pattern, or an iterable of them
        Mesh files (any format :func:`read_mesh` reads), folders (walked, for the extensions
        ``.obj .ply .off .npz .stl .glb .gltf .3mf .dae .vtk .vtu``) and glob patterns (``**`` allowed).
    outdir : path
        The output folder. Outputs mirror the inputs' names below their folder or pattern.
    levels, scheme, feature_angle, feature_sharpness, loop_weights, uv_mode
        As for ``hybridsub subdivide`` (``--feature-sharpness``, ``--uv-mode``; ``uv_mode=None``:
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
        cluster of ``workers`` processes, one thread each, started and stopped here.
    workers : int, optional
        Processes of the local cluster (default: the cores this process may use).
    verify : bool
        Before skipping a mesh done earlier, have a worker check the SHA-256 of its input and
        output against the manifest (reads both files); otherwise sizes and times are compared.
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
        Another batch is writing to ``outdir``, or the cluster went away (rerun to finish).

    Examples
    --------
    >>> import hybridsub, tempfile, os
    >>> V, F = hybridsub.load_example()
    >>> d = tempfile.mkdtemp()
    >>> hybridsub.write_mesh(os.path.join(d, "in", "fandisk.obj"), V, F)
    >>> s = hybridsub.batch(os.path.join(d, "in"), os.path.join(d, "out"), levels=1,
    ...                     feature_angle=30, workers=1)
    >>> s.done, s.failed, sorted(os.listdir(os.path.join(d, "out")))
    (1, 0, ['fandisk.obj', 'hybridsub-manifest.jsonl'])
    """
    from .progress import BatchProgress

    t_start = time.perf_counter()
    options = batch_options(levels, scheme, feature_angle, feature_sharpness, loop_weights, format, ignore_tags,
                       triangulate, weld, uv_mode)
    key = options_key(options, __version__)
    outdir = os.path.abspath(os.fspath(outdir))
    if os.path.exists(outdir) and not os.path.isdir(outdir):
        raise ValueError(f"{outdir}: the output folder is a file")
    if workers is not None:
        if scheduler is not None:
            raise ValueError("workers= starts a local cluster; it cannot be combined with scheduler=")
        if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
            raise ValueError(f"workers must be a positive integer, got {workers!r}")
    _import_dask()
    items, left_out = expand_inputs(inputs, outdir)
    if not items:
        raise ValueError("no inputs given: name mesh files, folders or glob patterns")
    os.makedirs(outdir, exist_ok=True)
    manifest = Manifest(outdir)
    closers: list = []
    try:
        notes = list(manifest.notes)
        if left_out:
            notes.append(f"left out {left_out:,} files inside the output folder")
        tmpdir = os.path.join(outdir, TMPDIR)
        os.makedirs(tmpdir, exist_ok=True)
        stray = clean_tmpdir(tmpdir)
        if stray:
            notes.append(f"removed {stray} temporary files left by an interrupted run")
        owners, previous = manifest.owners()
        names = assign_outputs(items, format, owners, previous)
        seen_inputs = {path for path, _ in manifest.records}
        jobs, skipped = [], 0
        for item, name in zip(items, names):
            prev = manifest.records.get((item.path, key))
            skip, reason = plan_item(item, name, outdir, prev, item.path in seen_inputs, verify)
            if skip:
                skipped += 1
                continue
            jobs.append({"input": item.path, "output": name, "output_path": os.path.join(outdir, *name.split("/")),
                         "tmpdir": tmpdir, "options": options, "options_key": key, "hybridsub": __version__,
                         "force": bool(force), "reason": reason, "verify": prev if reason == "verify" else None})
        summary = BatchSummary(total=len(items), done=0, skipped=skipped, failed=0, output_faces=0, seconds=0.0,
                               outdir=outdir, manifest=manifest.path, notes=notes)
        bar = BatchProgress(len(items), enabled=progress)
        bar.update(skipped, 0, 0, time.perf_counter() - t_start)
        try:
            if jobs:
                client, closers, summary.cluster = _connect(scheduler, workers, quiet=not progress)
                _run(client, jobs, manifest, summary, bar, t_start, on_result)
        finally:
            bar.close()
    finally:
        for c in closers:
            c.close()
        try:
            os.rmdir(os.path.join(outdir, TMPDIR))  # when empty: every task finished or cleaned up
        except OSError:
            pass
        manifest.close()
    summary.seconds = time.perf_counter() - t_start
    return summary


def _run(client, jobs: list[dict], manifest: Manifest, summary: BatchSummary, bar, t_start: float,
         on_result) -> None:
    """Submit ``jobs`` keeping a bounded number in flight, record each result as it comes."""
    from distributed import CancelledError, KilledWorker, as_completed

    run_id = uuid.uuid4().hex[:12]
    try:
        threads = sum(client.nthreads().values())
    except Exception:  # a scheduler that answers slowly: the floor below is enough
        threads = 0
    window = max(64, 4 * threads)
    pending = iter(enumerate(jobs))
    inflight: dict = {}  # key → (future, job)
    ac = as_completed(loop=client.loop)

    def submit(n: int) -> None:
        for i, job in pending:
            fut = client.submit(run_task, job, key=f"hybridsub-subdivide-{run_id}-{i}", pure=False)
            inflight[fut.key] = fut, job
            ac.add(fut)
            n -= 1
            if n == 0:
                return

    try:
        submit(window)
        for finished in ac.batches():
            records = []
            for fut in finished:
                job = inflight.pop(fut.key)[1]
                try:  # a result lost with its worker since is computed again, and waited for here
                    rec = fut.result()
                except CancelledError:
                    raise RuntimeError(f"Dask cancelled the task for {job['input']}: the connection to the "
                                       "scheduler was lost, or the scheduler restarted; what finished is in "
                                       f"{manifest.path}: run again to finish") from None
                except Exception as e:  # run_task never raises: this came from the cluster
                    rec = failed_on_cluster(job, e, KilledWorker)
                fut.release()
                rec["run"] = run_id
                rec["finished"] = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="milliseconds")
                records.append(rec)
            submit(len(finished))
            manifest.append([r for r in records if r["status"] != "skipped"])
            for rec in records:
                if rec["status"] == "done":
                    summary.done += 1
                    summary.output_faces += rec["faces_out"]
                elif rec["status"] == "skipped":
                    summary.skipped += 1
                else:
                    summary.failed += 1
                    summary.failures.append((rec["input"], rec["error"]))
            bar.update(summary.done + summary.skipped, summary.failed, summary.output_faces,
                       time.perf_counter() - t_start)
            if on_result is not None:
                for rec in records:
                    on_result(rec)
    finally:
        if inflight:  # stopped early: what has not finished is not recorded, and runs again next time
            client.cancel([fut for fut, _ in inflight.values()])
        ac.clear()


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
