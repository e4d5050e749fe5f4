"""The files of a batch: its inputs expanded, their output names, the manifest, and which
meshes an earlier run has done already.

The manifest, ``OUTDIR/hybridsub-manifest.jsonl``, has one JSON record per mesh and run;
only the client writes it, and it is locked while a batch runs. The decisions (names,
resuming) are in ``docs/batch.md``.
"""

from __future__ import annotations

import glob
import hashlib
import json
import os
import re
from collections.abc import Iterable
from dataclasses import dataclass

MANIFEST = "hybridsub-manifest.jsonl"
TMPDIR = ".hybridsub-tmp"
#: Extensions a directory or a pattern picks up (files named one by one may have any).
MESH_EXTENSIONS = (".obj", ".ply", ".off", ".npz", ".stl", ".glb", ".gltf", ".3mf", ".dae", ".vtk", ".vtu")
_MAGIC = re.compile(r"[*?[]")


# ----------------------------------------------------------------------------------------------
# inputs and output names


@dataclass(frozen=True)
class BatchInput:
    """One input file of a batch and the stem of its output name."""

    path: str  # absolute
    stem: str  # output name without extension, relative to OUTDIR, '/'-separated


def _within(path: str, folder: str) -> bool:
    return os.path.commonpath([path, folder]) == folder


def expand_inputs(inputs: Iterable[str | os.PathLike], outdir: str) -> tuple[list[BatchInput], int]:
    """Files of the INPUTS in order (directories walked, patterns expanded, both sorted), each
    once, with its output stem: a file's base name, or the path below the directory or the
    pattern's fixed folder. ``outdir`` is not walked, and files a pattern finds in it are left
    out (returns how many); an INPUT inside it is an error."""
    real_out = os.path.realpath(outdir)
    seen: set[str] = set()
    found: list[BatchInput] = []
    left_out = 0
    if isinstance(inputs, (str, os.PathLike)):
        inputs = [inputs]
    for arg in inputs:
        arg = os.fspath(arg)
        if os.path.exists(arg) and _within(os.path.realpath(arg), real_out):
            raise ValueError(f"{arg}: the input lies inside the output folder {outdir}; write to another folder")
        if _MAGIC.search(arg) and not os.path.exists(arg):
            parts = arg.replace(os.sep, "/").split("/")
            fixed = "/".join(parts[:next(i for i, p in enumerate(parts) if _MAGIC.search(p))])
            base = fixed if fixed else "."
            if arg.startswith("/") and not fixed:
                base = "/"
            files = sorted(f for f in glob.glob(arg, recursive=True)
                           if os.path.isfile(f) and f.lower().endswith(MESH_EXTENSIONS))
            if not files:
                raise FileNotFoundError(f"the pattern {arg!r} matches no mesh file ({', '.join(MESH_EXTENSIONS)})")
            kept = [f for f in files if not _within(os.path.realpath(f), real_out)]
            if not kept:
                raise ValueError(f"the pattern {arg!r} matches only files inside the output folder {outdir}; "
                                 "write to another folder")
            left_out += len(files) - len(kept)
            files = kept
        elif os.path.isdir(arg):
            base = arg
            files = []
            for root, dirs, names in os.walk(arg):
                dirs[:] = sorted(d for d in dirs if not _within(os.path.realpath(os.path.join(root, d)), real_out))
                files += [os.path.join(root, n) for n in sorted(names) if n.lower().endswith(MESH_EXTENSIONS)]
            if not files:
                raise FileNotFoundError(f"{arg}: the folder holds no mesh file ({', '.join(MESH_EXTENSIONS)})")
        elif os.path.exists(arg):
            base, files = os.path.dirname(arg) or ".", [arg]
        else:
            raise FileNotFoundError(f"{arg}: no such file or directory")
        for f in files:
            path = os.path.abspath(f)
            if path in seen:
                continue
            seen.add(path)
            rel = os.path.relpath(f, base).replace(os.sep, "/")
            if rel.startswith("../") or rel == "..":
                rel = os.path.basename(f)
            found.append(BatchInput(path, os.path.splitext(rel)[0]))
    return found, left_out


def assign_outputs(items: list[BatchInput], fmt: str, owners: dict[str, str], previous: dict[str, str]) -> list[str]:
    """Output names (relative to OUTDIR) for ``items``, never two alike (compared without
    case). An input keeps the name the manifest gave it before (``previous``: input → output);
    a new input takes ``STEM.FMT`` unless another input has it, in this run or in the manifest
    (``owners``: casefolded name → input), and then ``STEM-HASH.FMT``, HASH from its path."""
    taken = dict(owners)
    names: list[str | None] = [None] * len(items)

    def free(name: str, path: str) -> bool:
        return taken.get(name.casefold(), path) == path

    for i, it in enumerate(items):
        prev = previous.get(it.path)
        if prev is not None:
            name = f"{os.path.splitext(prev)[0]}.{fmt}"
            if free(name, it.path):
                names[i] = name
                taken[name.casefold()] = it.path
    for i, it in enumerate(items):
        if names[i] is not None:
            continue
        name = f"{it.stem}.{fmt}"
        digest = hashlib.sha1(it.path.encode("utf-8", "surrogateescape")).hexdigest()
        for width in (8, 16, 40):
            if free(name, it.path):
                break
            name = f"{it.stem}-{digest[:width]}.{fmt}"
        names[i] = name
        taken[name.casefold()] = it.path
    return names


# ----------------------------------------------------------------------------------------------
# the manifest


class Manifest:
    """``OUTDIR/hybridsub-manifest.jsonl``, locked while a batch runs. Reading keeps the last
    record of each (input, options key); a torn last line (a killed writer) is cut off, other
    unreadable lines are skipped. ``append`` writes whole lines and fsyncs."""

    def __init__(self, outdir: str):
        self.path = os.path.join(outdir, MANIFEST)
        self.fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_APPEND, 0o644)
        try:
            self._lock()
            self.notes: list[str] = []
            self.records: dict[tuple[str, str], dict] = {}
            self._read()
        except BaseException:
            os.close(self.fd)
            raise

    def _lock(self) -> None:
        try:
            import fcntl
        except ImportError:  # Windows: no advisory locks; one batch per folder is then up to the user
            return
        try:
            fcntl.flock(self.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise RuntimeError(f"{self.path} is locked: another hybridsub batch is writing to this folder; "
                               "wait for it, or use another output folder") from None

    def _read(self) -> None:
        with open(self.path, "rb") as fh:
            data = fh.read()
        end = data.rfind(b"\n") + 1
        if end < len(data):  # a line without its newline: the writer was killed in the middle of it
            os.ftruncate(self.fd, end)
            self.notes.append(f"cut off a torn last line of {MANIFEST} ({len(data) - end} bytes)")
            data = data[:end]
        bad = 0
        for line in data.splitlines():
            try:
                rec = json.loads(line)
                key = (rec["input"], rec["options_key"])
            except (ValueError, KeyError, TypeError):
                bad += line.strip() != b""
                continue
            self.records[key] = rec
        if bad:
            self.notes.append(f"skipped {bad} unreadable lines of {MANIFEST}")

    def owners(self) -> tuple[dict[str, str], dict[str, str]]:
        """Casefolded output name → input, and input → its latest output name."""
        owners, previous = {}, {}
        for (path, _), rec in self.records.items():
            out = rec.get("output")
            if isinstance(out, str):
                owners[out.casefold()] = path
                previous[path] = out
        return owners, previous

    def append(self, records: list[dict]) -> None:
        if not records:
            return
        data = b"".join(json.dumps(r, ensure_ascii=False, allow_nan=False).encode() + b"\n" for r in records)
        view = memoryview(data)
        while view:
            view = view[os.write(self.fd, view):]
        os.fsync(self.fd)

    def close(self) -> None:
        os.close(self.fd)  # releases the lock


# ----------------------------------------------------------------------------------------------
# what is done already


def options_key(options: dict, version: str) -> str:
    """What makes two runs' outputs of one input the same: the options and hybridsub's version."""
    text = json.dumps(dict(options, hybridsub=version), sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def plan_item(item: BatchInput, output: str, outdir: str, prev: dict | None, seen_input: bool, verify: bool):
    """(skip, reason): whether ``item`` is done already, and why it must run otherwise."""
    if prev is None:
        return False, "options changed" if seen_input else "new"
    if prev.get("status") != "done":
        return False, "failed before"
    try:
        st = os.stat(item.path)
    except OSError:
        return False, "input changed"
    if (st.st_size, st.st_mtime_ns) != (prev.get("input_size"), prev.get("input_mtime_ns")):
        return False, "input changed"
    if prev.get("output") != output:
        return False, "output name changed"
    try:
        size = os.path.getsize(os.path.join(outdir, output))
    except OSError:
        return False, "output missing"
    if size != prev.get("output_size"):
        return False, "output changed"
    return not verify, "verify"  # skip, or have a worker compare checksums


def clean_tmpdir(tmpdir: str) -> int:
    """Remove what killed tasks left in OUTDIR/.hybridsub-tmp; returns how many files."""
    removed = 0
    for entry in os.scandir(tmpdir):
        if entry.is_file(follow_symlinks=False):
            try:
                os.remove(entry.path)
                removed += 1
            except FileNotFoundError:  # a task of an earlier, orphaned run finishing right now
                pass
    return removed
