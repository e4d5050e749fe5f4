"""What a batch has to do, streamed: its inputs walked lazily, their output names, and which
of them an earlier run has done already, decided a chunk of inputs at a time (a manifest
query per chunk, the files' metadata read by a pool of threads) while the first tasks run.
The client's memory is bounded by a chunk and the tasks in flight, not by the inputs.
"""

from __future__ import annotations

import fnmatch
import hashlib
import itertools
import os
import re
from collections import Counter
from collections.abc import Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

from .manifest import Manifest

#: Extensions a directory or a pattern picks up (files named one by one may have any).
MESH_EXTENSIONS = (".obj", ".ply", ".off", ".npz", ".stl", ".glb", ".gltf", ".3mf", ".dae", ".vtk", ".vtu")
CHUNK = 512
#: the suffix of the markers in OUTDIR/.hybridsub-tmp that name a task's temporary output
PENDING = ".pending"
_MAGIC = re.compile(r"[*?[]")


@dataclass(frozen=True)
class BatchInput:
    """One input file of a batch and the stem of its output name."""

    path: str  # absolute
    stem: str  # output name without extension, relative to OUTDIR, '/'-separated


@dataclass
class Chunk:
    """The plan of one chunk of inputs: ``jobs`` to run, ``(input, output name, reason, the
    earlier record when verifying)``; how many were skipped; why each job runs."""

    jobs: list[tuple[BatchInput, str, str, dict | None]] = field(default_factory=list)
    skipped: int = 0
    reasons: Counter = field(default_factory=Counter)


# ----------------------------------------------------------------------------------------------
# the inputs, walked lazily


def _within(path: str, folder: str) -> bool:
    return os.path.commonpath([path, folder]) == folder


def _walk(base: str, real_out: str, keep) -> Iterator[tuple[str, str]]:
    """``(path, path relative to base, '/'-separated)`` of the files below ``base`` that
    ``keep(relative parts)`` accepts, a folder's sorted files before its sorted subfolders, the
    output folder and links to folders not followed."""
    for root, dirs, names in os.walk(base):
        dirs[:] = sorted(d for d in dirs if not _within(os.path.realpath(os.path.join(root, d)), real_out))
        rel = os.path.relpath(root, base)
        prefix = [] if rel == "." else rel.replace(os.sep, "/").split("/")
        if not keep(prefix, None):
            dirs[:] = []
            continue
        folder, lead = root + os.sep, "/".join(prefix) + "/" if prefix else ""
        for n in sorted(names):
            if n.lower().endswith(MESH_EXTENSIONS) and keep(prefix, n):
                yield folder + n, lead + n


def _pattern_matcher(parts: list[str]):
    """``keep(folder parts, name)`` for the pattern's components below its fixed folder, as
    glob matches them: ``**`` any folders (none hidden), a hidden name only by a dot."""
    comps = [None if p == "**" else (p, re.compile(fnmatch.translate(p))) for p in parts]

    def match(c: int, names: list[str], partial: bool) -> bool:
        if len(names) == 0:
            return partial or all(x is None for x in comps[c:])
        if c == len(comps):
            return False
        if comps[c] is None:
            return (match(c + 1, names, partial)
                    or (not names[0].startswith(".") and match(c, names[1:], partial)))
        pat, rx = comps[c]
        if names[0].startswith(".") and not pat.startswith("."):
            return False
        return rx.match(names[0]) is not None and match(c + 1, names[1:], partial)

    def keep(prefix: list[str], name: str | None) -> bool:
        return match(0, prefix, True) if name is None else match(0, prefix + [name], False)

    return keep


def _expand(arg: str, real_out: str) -> tuple[str, Iterator[tuple[str, str]]]:
    """(the base the output names are relative to, the files of one INPUT: absolute path, path
    relative to the base)."""
    if os.path.exists(arg) and _within(os.path.realpath(arg), real_out):
        raise ValueError(f"{arg}: the input lies inside the output folder; write to another folder")
    if _MAGIC.search(arg) and not os.path.exists(arg):
        parts = arg.replace(os.sep, "/").split("/")
        i = next(i for i, p in enumerate(parts) if _MAGIC.search(p))
        fixed = "/".join(parts[:i])
        base = fixed if fixed else ("/" if arg.startswith("/") else ".")
        if os.path.isdir(base) and _within(os.path.realpath(base), real_out):
            raise ValueError(f"the pattern {arg!r} looks inside the output folder; write to another folder")
        files = _walk(os.path.abspath(base), real_out, _pattern_matcher(parts[i:])) if os.path.isdir(base) \
            else iter(())
        return base, _first(files, f"the pattern {arg!r} matches no mesh file ({', '.join(MESH_EXTENSIONS)}; "
                                   "the output folder is not searched)")
    if os.path.isdir(arg):
        files = _walk(os.path.abspath(arg), real_out, lambda prefix, name: True)
        return arg, _first(files, f"{arg}: the folder holds no mesh file ({', '.join(MESH_EXTENSIONS)})")
    if os.path.exists(arg):
        return os.path.dirname(arg) or ".", iter([(os.path.abspath(arg), os.path.basename(arg))])
    raise FileNotFoundError(f"{arg}: no such file or directory")


def _first(files: Iterator[tuple[str, str]], empty: str) -> Iterator[tuple[str, str]]:
    """``files`` with its first item fetched now: a folder or pattern without any fails early."""
    first = next(files, None)
    if first is None:
        raise FileNotFoundError(empty)
    return itertools.chain([first], files)


def walk_inputs(inputs: Iterable[str | os.PathLike], outdir: str) -> Iterator[BatchInput]:
    """The files of the INPUTS, lazily, in order (folders and patterns walked sorted), each with
    its output stem: a file's base name, or its path below the folder or the pattern's fixed
    folder. Every INPUT is checked now (missing, inside ``outdir``, no mesh file); ``outdir``
    is never walked. A file given twice comes twice (the planner keeps the first)."""
    real_out = os.path.realpath(outdir)
    if isinstance(inputs, (str, os.PathLike)):
        inputs = [inputs]
    expanded = [_expand(os.fspath(arg), real_out) for arg in inputs]

    def items():
        for _, files in expanded:
            for path, rel in files:
                yield BatchInput(path, rel[:len(rel) - len(os.path.splitext(rel)[1])])

    return items()


# ----------------------------------------------------------------------------------------------
# the plan, a chunk at a time


class Planner:
    """Plans chunks of inputs against the manifest: names each input's output (an input keeps
    the stem it owns; a new one takes its own stem unless another input owns it, compared
    without case, and then ``STEM-HASH``), reads the metadata of the inputs and outputs an
    earlier run did (``threads`` at a time), and decides what runs and why."""

    def __init__(self, manifest: Manifest, key: str, fmt: str, outdir: str, verify: bool, dedupe: bool,
                 threads: int = 8, chunk: int = CHUNK):
        self.manifest, self.key, self.fmt, self.outdir, self.verify = manifest, key, fmt, outdir, verify
        self.chunk, self.threads = chunk, threads
        self.dedupe = dedupe
        self.pool = ThreadPoolExecutor(threads, thread_name_prefix="hybridsub-stat") if threads > 1 else None

    def close(self) -> None:
        if self.pool is not None:
            self.pool.shutdown(cancel_futures=True)

    def chunks(self, items: Iterator[BatchInput]) -> Iterator[Chunk]:
        while batch := list(itertools.islice(items, self.chunk)):
            if self.dedupe:
                batch = self.manifest.first_seen(batch)
            yield self.plan(batch)

    def plan(self, batch: list[BatchInput]) -> Chunk:
        paths = [it.path for it in batch]
        rows, stems, seen = self.manifest.lookup(paths, self.key)
        new: dict[str, str] = {}  # casefolded stem → input, taken in this chunk
        for it in batch:
            if it.path not in stems:
                stems[it.path] = self._free_stem(it, new)
                new[stems[it.path].casefold()] = it.path
        if new:
            self.manifest.take_names((p, stems[p]) for p in new.values())
        names = [f"{stems[p]}.{self.fmt}" for p in paths]
        done = [i for i, p in enumerate(paths) if p in rows and rows[p][0] == "done"]
        out_prefix = self.outdir + os.sep
        st = self._stat([paths[i] for i in done] + [out_prefix + names[i].replace("/", os.sep) for i in done])
        st_in, st_out = dict(zip(done, st[:len(done)])), dict(zip(done, st[len(done):]))
        out = Chunk()
        for i, it in enumerate(batch):
            skip, reason = decide(rows.get(it.path), names[i], st_in.get(i), st_out.get(i), it.path in seen,
                                  self.verify)
            if skip:
                out.skipped += 1
            else:
                prev = self.manifest.record_of(it.path, self.key) if reason == "verify" else None
                out.jobs.append((it, names[i], reason, prev))
                out.reasons[reason] += 1
        return out

    def _free_stem(self, it: BatchInput, new: dict[str, str]) -> str:
        stem = it.stem
        digest = hashlib.sha1(it.path.encode("utf-8", "surrogateescape")).hexdigest()
        for width in (8, 16, 40):
            owner = new.get(stem.casefold()) or self.manifest.owner(stem)
            if owner is None or owner == it.path:
                break
            stem = f"{it.stem}-{digest[:width]}"
        return stem

    def _stat(self, paths: list[str]) -> list[tuple[int, int] | None]:
        if self.pool is None or len(paths) < 4 * self.threads:
            return _stat_all(paths)
        step = -(-len(paths) // self.threads)
        parts = self.pool.map(_stat_all, [paths[k:k + step] for k in range(0, len(paths), step)])
        return [s for part in parts for s in part]


def _stat_all(paths: list[str]) -> list[tuple[int, int] | None]:
    out = []
    for p in paths:
        try:
            st = os.stat(p)
            out.append((st.st_size, st.st_mtime_ns))
        except OSError:
            out.append(None)
    return out


def decide(prev: tuple | None, output: str, st_in, st_out, seen_input: bool, verify: bool) -> tuple[bool, str]:
    """(skip, reason): whether an input is done already (its row under these options, ``(status,
    input_size, input_mtime_ns, output, output_size)``, and the ``(size, mtime_ns)`` of it and of
    its output now), and why it runs otherwise."""
    if prev is None:
        return False, "options changed" if seen_input else "new"
    status, in_size, in_mtime, prev_output, out_size = prev
    if status != "done":
        return False, "failed before"
    if st_in is None or st_in != (in_size, in_mtime):
        return False, "input changed"
    if prev_output != output:
        return False, "output name changed"
    if st_out is None:
        return False, "output missing"
    if st_out[0] != out_size:
        return False, "output changed"
    return not verify, "verify"  # skip, or have a worker compare checksums


def clean_tmpdir(outdir: str, tmpdir: str) -> int:
    """Remove what killed tasks left: each marker ``*.pending`` in ``tmpdir`` names the temporary
    output (relative to ``outdir``) a task was writing; both go, and anything else in ``tmpdir``
    (an earlier version wrote its temporary files there). Returns how many temporary files."""
    removed = 0
    for entry in os.scandir(tmpdir):
        if not entry.is_file(follow_symlinks=False):
            continue
        try:
            if entry.name.endswith(PENDING):
                with open(entry.path, encoding="utf-8", errors="surrogateescape") as fh:
                    tmp = fh.read(4096)
                if tmp and not os.path.isabs(tmp) and ".." not in tmp.split("/"):
                    os.remove(os.path.join(outdir, *tmp.split("/")))
                    removed += 1
            else:
                removed += 1
        except FileNotFoundError:  # the task had not begun writing, or it is finishing right now
            pass
        try:
            os.remove(entry.path)
        except FileNotFoundError:
            pass
    return removed
