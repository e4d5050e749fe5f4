"""The manifest of a batch: ``OUTDIR/hybridsub-manifest.sqlite``, one row per input and
options key, the output name each input owns, and the lock that keeps a second batch out.

SQLite in WAL mode: only the client writes it, results in one transaction per batch of
results; a rerun reads it in chunks of inputs (indexed by input), never whole. A JSON-lines
manifest of an earlier version is migrated once. The decisions are in ``docs/batch.md``.
"""

from __future__ import annotations

import errno
import json
import os
import sqlite3
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from urllib.parse import quote

MANIFEST = "hybridsub-manifest.sqlite"
LEGACY_MANIFEST = "hybridsub-manifest.jsonl"
LOCKFILE = "hybridsub-manifest.lock"
TMPDIR = ".hybridsub-tmp"
NO_LOCK_HINT = ("if no other batch writes to this folder, run with --no-lock (lock=False in Python), or write the "
                "outputs to a file system with locks")
#: flock's errors that mean "another process holds it" (the others: this file system has no locks)
_HELD = (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES)
_NO_LOCKS = (errno.ENOSYS, errno.EOPNOTSUPP, errno.ENOTSUP, errno.ENOLCK, errno.EINVAL)

#: columns of a mesh row, in order; ``notes`` and ``seconds`` hold JSON
COLUMNS = ("input", "options_key", "status", "reason", "output", "input_size", "input_mtime_ns", "input_sha256",
           "output_size", "output_sha256", "faces_in", "faces_out", "vertices_out", "features", "notes", "seconds",
           "worker", "error", "traceback", "run", "finished")
_JSON = ("notes", "seconds")
_SCHEMA = f"""
CREATE TABLE IF NOT EXISTS options (options_key TEXT PRIMARY KEY, options TEXT NOT NULL, hybridsub TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS names (input TEXT PRIMARY KEY, stem TEXT NOT NULL, stem_cf TEXT NOT NULL UNIQUE)
    WITHOUT ROWID;
CREATE TABLE IF NOT EXISTS meshes ({", ".join(COLUMNS)}, PRIMARY KEY (input, options_key)) WITHOUT ROWID;
CREATE INDEX IF NOT EXISTS meshes_by_status ON meshes (options_key, status);
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT);
"""


class LockError(RuntimeError):
    """OUTDIR is locked by another batch, or its file system cannot lock files."""


def _lock(path: str) -> int | None:
    """An fd holding an exclusive ``flock`` on ``path`` (None where there is no ``fcntl``)."""
    try:
        import fcntl
    except ImportError:  # Windows: no advisory locks; one batch per folder is then up to the user
        return None
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as e:
        os.close(fd)
        folder = os.path.dirname(path)
        if e.errno in _HELD:
            raise LockError(f"{folder} is locked: another hybridsub batch is writing to this folder; wait for it, "
                            "or use another output folder") from None
        if e.errno in _NO_LOCKS:
            raise LockError(f"{folder}: this file system has no file locks ({e.strerror}), so hybridsub cannot "
                            f"keep a second batch out; {NO_LOCK_HINT}") from None
        raise LockError(f"{folder}: cannot lock {os.path.basename(path)}: {e.strerror}") from None
    return fd


@dataclass
class Manifest:
    """The manifest of ``outdir``, open. ``readonly``: the dry run's and ``--status``'s view
    (no lock, nothing written; a JSON-lines manifest is migrated into memory). ``lock=False``:
    no ``flock``, and SQLite without locks (for file systems that have none)."""

    outdir: str
    readonly: bool = False
    lock: bool = True
    durable: bool = False
    notes: list[str] = field(default_factory=list)

    def __post_init__(self):
        self.path = os.path.join(self.outdir, MANIFEST)
        self._lockfd = None
        self._new_owners: dict[str, str] = {}  # the dry run's names (nothing is written): stem_cf → input
        self._new_stems: dict[str, str] = {}  # input → stem
        self._dedupe_table = False
        if not self.readonly and self.lock:
            self._lockfd = _lock(os.path.join(self.outdir, LOCKFILE))
        try:
            self.db = self._connect()
        except BaseException:
            self._unlock()
            raise

    def _connect(self) -> sqlite3.Connection:
        legacy = os.path.join(self.outdir, LEGACY_MANIFEST)
        exists = os.path.exists(self.path)
        uri = f"file:{quote(self.path)}" + ("" if self.lock or self.readonly else "?vfs=unix-none")
        if self.readonly and not exists:
            uri = "file::memory:"
        try:  # a read-only view opens read-write too (never writing), so that closing it removes the WAL files
            db = sqlite3.connect(uri, uri=True, isolation_level=None, check_same_thread=False)
            if self.readonly and exists:
                db.execute("SELECT count(*) FROM sqlite_master").fetchone()
        except sqlite3.OperationalError:
            if not (self.readonly and exists):
                raise
            db = sqlite3.connect(f"file:{quote(self.path)}?mode=ro", uri=True, isolation_level=None,
                                 check_same_thread=False)
        db.execute("PRAGMA busy_timeout = 30000")
        if not self.readonly:
            if not self.lock:
                db.execute("PRAGMA locking_mode = EXCLUSIVE")  # WAL without shared memory
            db.execute("PRAGMA journal_mode = WAL")
            db.execute(f"PRAGMA synchronous = {'FULL' if self.durable else 'NORMAL'}")
        if not exists:
            db.executescript(_SCHEMA)
        if os.path.exists(legacy) and (not exists or not self.readonly):
            self._migrate(db, legacy)
        return db

    def _migrate(self, db: sqlite3.Connection, legacy: str) -> None:
        """Read the JSON-lines manifest of hybridsub < 0.2 once: its last record of each
        (input, options key) becomes a row, each input keeps its output name; the file is then
        renamed ``….jsonl.migrated`` (kept in memory only, for a read-only view)."""
        if db.execute("SELECT 1 FROM meta WHERE key = 'migrated'").fetchone():
            os.replace(legacy, legacy + ".migrated")  # migrated, renaming interrupted
            return
        n = bad = 0
        db.execute("BEGIN")
        with open(legacy, "rb") as fh:
            for line in fh:
                try:
                    rec = json.loads(line)
                    rec["input"], rec["options_key"]
                except (ValueError, KeyError, TypeError):
                    bad += line.strip() != b""
                    continue
                if isinstance(rec.get("options"), dict):
                    db.execute("INSERT OR IGNORE INTO options VALUES (?, ?, ?)",
                               (rec["options_key"], json.dumps(rec["options"]), rec.get("hybridsub", "")))
                self._put_name(db, rec)
                db.execute(_UPSERT, _row(rec))
                n += 1
        db.execute("INSERT INTO meta VALUES ('migrated', ?)", (LEGACY_MANIFEST,))
        db.execute("COMMIT")
        if not self.readonly:
            os.replace(legacy, legacy + ".migrated")
        self.notes.append(f"migrated {n:,} records of {LEGACY_MANIFEST} into {MANIFEST}"
                          + (f" ({bad:,} unreadable lines skipped)" if bad else "")
                          + ("" if self.readonly else f"; the old file is kept as {LEGACY_MANIFEST}.migrated"))

    @staticmethod
    def _put_name(db, rec: dict) -> None:
        out = rec.get("output")
        if isinstance(out, str):
            stem = os.path.splitext(out)[0]
            db.execute("INSERT OR REPLACE INTO names VALUES (?, ?, ?)", (rec["input"], stem, stem.casefold()))

    # ------------------------------------------------------------------------------------------
    # reading, a chunk of inputs at a time

    def lookup(self, inputs: list[str], key: str) -> tuple[dict[str, tuple], dict[str, str], set[str]]:
        """For ``inputs``: what planning needs of their rows under ``key``, ``input → (status,
        input_size, input_mtime_ns, output, output_size)``; the stems they own; and, of those
        without such a row, the ones with a row under another key."""
        marks = ",".join("?" * len(inputs))
        rows = {r[0]: r[1:] for r in self.db.execute(
            "SELECT input, status, input_size, input_mtime_ns, output, output_size FROM meshes "
            f"WHERE options_key = ? AND input IN ({marks})", [key, *inputs])}
        stems = dict(self.db.execute(f"SELECT input, stem FROM names WHERE input IN ({marks})", inputs))
        if self._new_stems:
            stems.update((p, self._new_stems[p]) for p in inputs if p in self._new_stems)
        seen = set()
        if len(rows) < len(inputs):
            rest = [p for p in inputs if p not in rows]
            seen = {r[0] for r in self.db.execute(
                f"SELECT DISTINCT input FROM meshes WHERE input IN ({','.join('?' * len(rest))})", rest)}
        return rows, stems, seen

    def record_of(self, path: str, key: str) -> dict | None:
        """The row of input ``path`` under options ``key``, as a record."""
        row = self.db.execute(f"SELECT {', '.join(COLUMNS)} FROM meshes WHERE input = ? AND options_key = ?",
                              (path, key)).fetchone()
        return _record(row) if row else None

    def owner(self, stem: str) -> str | None:
        """The input that owns the output stem (compared without case), if any."""
        cf = stem.casefold()
        if cf in self._new_owners:
            return self._new_owners[cf]
        row = self.db.execute("SELECT input FROM names WHERE stem_cf = ?", (cf,)).fetchone()
        return row[0] if row else None

    def first_seen(self, items: list) -> list:
        """The ``items`` (with a ``path``) whose path this run has not met before (a file given
        twice, by two INPUTS), remembered in a temporary table, not in memory."""
        if not self._dedupe_table:
            self.db.execute("CREATE TEMP TABLE IF NOT EXISTS run_inputs (input TEXT PRIMARY KEY) WITHOUT ROWID")
            self._dedupe_table = True
        keep = []
        for it in items:
            if self.db.execute("INSERT OR IGNORE INTO temp.run_inputs VALUES (?)", (it.path,)).rowcount:
                keep.append(it)
        return keep

    def take_names(self, names: Iterable[tuple[str, str]]) -> None:
        """Record that each input owns its stem, ``(input, stem)``, in one transaction."""
        rows = [(p, s, s.casefold()) for p, s in names]
        if self.readonly:
            for p, s, cf in rows:
                self._new_owners[cf] = p
                self._new_stems[p] = s
            return
        with self.db:
            self.db.executemany("INSERT OR REPLACE INTO names VALUES (?, ?, ?)", rows)

    def records(self, key: str | None = None, status: str | None = None) -> Iterator[dict]:
        """Every row (of options ``key``, of ``status``) as a record, streamed, in input order."""
        where = " AND ".join(w for w, v in (("m.options_key = ?", key), ("m.status = ?", status)) if v is not None)
        args = [v for v in (key, status) if v is not None]
        cur = self.db.execute(f"SELECT {', '.join('m.' + c for c in COLUMNS)}, o.options, o.hybridsub FROM meshes m "
                              f"LEFT JOIN options o USING (options_key){' WHERE ' + where if where else ''} "
                              "ORDER BY m.input, m.options_key", args)
        for row in cur:
            rec = _record(row[:len(COLUMNS)])
            rec["options"] = json.loads(row[-2]) if row[-2] else None
            rec["hybridsub"] = row[-1]
            yield rec

    def counts(self) -> list[tuple[str, dict, str, dict[str, int], int, str]]:
        """Per options key: (key, options, hybridsub version, rows by status, output faces of the
        done meshes, last finished)."""
        out = {}
        for key, opts, version in self.db.execute("SELECT options_key, options, hybridsub FROM options"):
            out[key] = [key, json.loads(opts), version, {}, 0, ""]
        for key, status, n, faces, last in self.db.execute(
                "SELECT options_key, status, count(*), total(faces_out), max(finished) FROM meshes "
                "GROUP BY options_key, status"):
            entry = out.setdefault(key, [key, {}, "", {}, 0, ""])
            entry[3][status] = n
            entry[4] += int(faces) if status == "done" else 0
            entry[5] = max(entry[5], last or "")
        return [tuple(v) for v in out.values() if v[3]]

    # ------------------------------------------------------------------------------------------
    # writing

    def add_options(self, key: str, options: dict, version: str) -> None:
        if not self.readonly:
            with self.db:
                self.db.execute("INSERT OR IGNORE INTO options VALUES (?, ?, ?)", (key, json.dumps(options), version))

    def record(self, records: list[dict]) -> None:
        """Write ``records`` (one row each, replacing the input's row of that options key) in one
        transaction."""
        if records and not self.readonly:
            with self.db:
                self.db.executemany(_UPSERT, [_row(r) for r in records])

    def close(self) -> None:
        try:
            self.db.close()
        finally:
            self._unlock()

    def _unlock(self) -> None:
        if self._lockfd is not None:
            os.close(self._lockfd)  # releases the lock
            self._lockfd = None


_UPSERT = f"INSERT OR REPLACE INTO meshes VALUES ({', '.join('?' * len(COLUMNS))})"


def _row(rec: dict) -> tuple:
    return tuple(json.dumps(rec.get(c)) if c in _JSON else rec.get(c) for c in COLUMNS)


def _record(row) -> dict:
    rec = dict(zip(COLUMNS, row))
    for c in _JSON:
        rec[c] = json.loads(rec[c]) if rec[c] is not None else None
    return rec


def is_disk_full(exc: BaseException) -> bool:
    """True for the errors of a full disk or an exceeded quota (the OS's, and SQLite's)."""
    if isinstance(exc, OSError):
        return exc.errno in (errno.ENOSPC, errno.EDQUOT)
    return isinstance(exc, sqlite3.OperationalError) and getattr(exc, "sqlite_errorcode", None) == sqlite3.SQLITE_FULL


# ----------------------------------------------------------------------------------------------
# --status


def status_report(outdir: str | os.PathLike, max_failures: int = 20) -> tuple[str, int]:
    """(the text ``hybridsub batch --status OUTDIR`` prints, how many meshes failed): per options
    key the meshes done and failed, and the failures' messages."""
    outdir = os.path.abspath(os.fspath(outdir))
    if not (os.path.exists(os.path.join(outdir, MANIFEST)) or os.path.exists(os.path.join(outdir, LEGACY_MANIFEST))):
        raise FileNotFoundError(f"{outdir}: no batch manifest here ({MANIFEST})")
    m = Manifest(outdir, readonly=True)
    try:
        lines = [f"hybridsub batch --status: {m.path}"] + [f"note: {n}" for n in m.notes]
        failed_total = 0
        for key, options, version, by_status, faces, last in sorted(m.counts(), key=lambda c: c[5], reverse=True):
            opts = ", ".join(f"{k} {v}" for k, v in options.items() if v not in (None, False))
            lines.append(f"options {key}: {opts or '?'}; hybridsub {version or '?'}; last finished {last or '-'}")
            lines.append(f"  done     {by_status.get('done', 0):>10,}   {faces:,} output faces")
            failed = by_status.get("failed", 0)
            failed_total += failed
            lines.append(f"  failed   {failed:>10,}")
            for k, rec in enumerate(m.records(key, "failed")):
                if k == max_failures:
                    lines.append(f"  … and {failed - max_failures:,} more failures")
                    break
                err = rec["error"] or "?"
                lines.append(f"  failed: {err if err.startswith(rec['input']) else rec['input'] + ': ' + err}")
        if len(lines) == 1 + len(m.notes):
            lines.append("  (no meshes recorded yet)")
        return "\n".join(lines), failed_total
    finally:
        m.close()
