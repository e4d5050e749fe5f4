"""The worker's side of a batch: one task subdivides one file (:func:`run_task`), with the
code of ``hybridsub subdivide``, writes the output under a temporary name beside it, renames
it, and returns a small record for the client to put in the manifest."""

from __future__ import annotations

import hashlib
import os
import time
import traceback
import uuid

from .._errors import MeshError
from .._version import __version__
from .manifest import is_disk_full
from .pipeline import FileOptions, PipelineError, subdivide_file
from .batch_plan import PENDING

_CHUNK = 1 << 20


def file_options(options: dict, **changes) -> FileOptions:
    """The pipeline's options of one task: the batch's ``options`` (the format aside: it is the
    output's extension), no messages, and ``changes``."""
    return FileOptions(**{k: v for k, v in options.items() if k != "format"}, quiet=True, **changes)


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
    record says ``"status": "failed"`` and why (and ``"no_space": True`` for a full disk)."""
    t0 = time.perf_counter()
    src, dst = job["input"], job["output_path"]
    rec = {"input": src, "input_size": None, "input_mtime_ns": None, "input_sha256": None,
           "options": job["options"], "options_key": job["options_key"], "hybridsub": __version__,
           "output": job["output"], "output_size": None, "output_sha256": None, "status": "failed",
           "reason": job["reason"], "faces_in": None, "faces_out": None, "vertices_out": None,
           "features": None, "notes": [], "seconds": None, "worker": "", "error": None}
    tmp = marker = None
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
        tmp, marker = _temporary(job, dst)
        res = subdivide_file(file_options(job["options"], force=job["force"], memory_limit=memory_limit), src, dst,
                             write_to=tmp)
        t = time.perf_counter()
        if job.get("fsync"):
            with open(tmp, "rb+") as fh:
                os.fsync(fh.fileno())
        rec["output_sha256"] = _sha256(tmp)
        rec["output_size"] = os.path.getsize(tmp)
        if os.stat(src).st_mtime_ns != st.st_mtime_ns:
            raise PipelineError(f"{src}: the file changed while it was being read")
        os.replace(tmp, dst)
        tmp = None
        rec.update(status="done", faces_in=res.faces_in, faces_out=res.faces_out, vertices_out=res.vertices_out,
                   features=res.features, notes=res.notes)
        rec["seconds"] = {"read": round(res.seconds_read, 6), "refine": round(res.seconds_refine, 6),
                          "write": round(res.seconds_write + time.perf_counter() - t, 6)}
    except (PipelineError, MeshError, ValueError, TypeError) as e:
        rec["error"] = str(e)
    except OSError as e:
        where = dst if e.filename is not None and e.filename == tmp else e.filename  # the name the user knows
        rec["error"] = f"{where}: {e.strerror}" if where and e.strerror else str(e)
        if is_disk_full(e):
            rec["no_space"] = True
    except MemoryError:
        rec["error"] = f"{src}: out of memory; use fewer levels"
    except (Exception, SystemExit) as e:  # a bug (or a library's sys.exit): recorded, the worker and the batch go on
        rec["error"] = f"{src}: internal error: {type(e).__name__}: {e}"
        rec["traceback"] = traceback.format_exc()
    finally:
        for path in (tmp, marker):
            if path is not None and os.path.exists(path):
                os.remove(path)
        rec["seconds"] = dict(rec["seconds"] or {}, total=round(time.perf_counter() - t0, 6))
    return rec


def _temporary(job: dict, dst: str) -> tuple[str, str]:
    """(temporary output, its marker): the output is written beside DST under a hidden name
    (so an OBJ names its ``.mtl`` relative to DST's folder, as ``subdivide`` does); the marker
    in OUTDIR/.hybridsub-tmp names it, for the next run to remove if this task is killed."""
    name = uuid.uuid4().hex
    folder = os.path.dirname(dst)
    os.makedirs(folder, exist_ok=True)
    tmp = os.path.join(folder, f".hybridsub-{name}.{job['options']['format']}")
    marker = os.path.join(job["tmpdir"], name + PENDING)
    with open(marker, "w", encoding="utf-8", errors="surrogateescape") as fh:
        fh.write(os.path.relpath(tmp, os.path.dirname(job["tmpdir"])).replace(os.sep, "/"))
    return tmp, marker


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
