"""hybridsub batch on a real local Dask cluster (2 worker processes, shared by the tests): outputs
equal ``hybridsub subdivide``'s byte for byte, broken meshes are reported and the batch goes on,
the manifest is complete, and a killed worker, a killed run or a changed option costs only what
is unfinished or changed."""

import contextlib
import errno
import hashlib
import io
import json
import logging
import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import time
from types import SimpleNamespace

import numpy as np
import pytest
from distributed import KilledWorker

import hybridsub
from conftest import DATA
from hybridsub._app import batch as _batch
from hybridsub._app import task as _task
from hybridsub._app.manifest import LEGACY_MANIFEST, LOCKFILE, MANIFEST, TMPDIR, LockError, Manifest
from hybridsub._app.batch_plan import Planner, walk_inputs
from hybridsub._app.cli import main
from hybridsub._app.progress import BatchProgress
from strategies import grid, sphere_hull, torus

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OPTS = ["--levels", "2", "--feature-angle", "30"]
KW = dict(levels=2, feature_angle=30)

# broken inputs and what their error must say
BROKEN = {
    "broken/garbage.obj": "not a triangle mesh",
    "broken/fin.off": "is shared by 3 faces",
    "broken/range.obj": "face 1 refers to vertex 9, but there are only 3 (valid 1..3)",
    "broken/quad.obj": "has 4 vertices",
    "broken/truncated.ply": "truncated.ply",
    "broken/nofaces.npz": "needs arrays 'vertices' and 'faces'",
    "broken/empty.off": "not an OFF file",
}


def _text(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as fh:
        fh.write(text)


def _make_collection(root):
    """42 meshes in nested folders, every format hybridsub writes, tags in some files, two files
    named part.obj in different folders and a part.ply beside one; 7 of them broken."""
    rng = np.random.default_rng(8)
    good = []

    def put(rel, V, F, **tags):
        hybridsub.write_mesh(os.path.join(root, rel), V, F, **tags)
        good.append(rel)

    for name in ("cube-meshed", "elephant-with-holes", "icosahedron", "mesh_with_border", "octahedron",
                 "tetrahedron"):
        os.makedirs(os.path.join(root, "shapes"), exist_ok=True)
        shutil.copy(os.path.join(DATA, f"{name}.off"), os.path.join(root, "shapes", f"{name}.off"))
        good.append(f"shapes/{name}.off")
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, 45)
    put("cad/fandisk.obj", V, F, sharp_edges=feat.sharp_edges, corners=feat.corners)
    s = np.where(np.arange(len(feat.sharp_edges)) % 3 == 0, 2.5, np.inf)
    put("cad/fandisk-semisharp.ply", V, F, sharp_edges=feat.sharp_edges, sharpness=s)
    formats = ("obj", "ply", "off", "npz")
    for i in range(10):
        V, F = sphere_hull(int(rng.integers(40, 120)), rng)
        colors = rng.random((len(V), 3)) if i == 3 else None
        put(f"spheres/s{i:02d}.{formats[i % 4]}", V, F, vertex_colors=colors)
    for i in range(8):
        nu, nv = int(rng.integers(5, 12)), int(rng.integers(4, 9))
        V, F = torus(nu, nv, rng.random((nu, nv)) < 0.5)
        V = V + 0.01 * rng.standard_normal(V.shape)
        put(f"tori/t{i}.{formats[(i + 1) % 4]}", V, F)
    for i in range(6):
        nx, ny = int(rng.integers(3, 9)), int(rng.integers(3, 9))
        V, F = grid(nx, ny, rng.random((nx, ny)) < 0.5, z=rng.random((nx + 1, ny + 1)))
        put(f"grids/g{i}.{formats[(i + 2) % 4]}", V, F)
    for rel, seed in (("set1/part.obj", 1), ("set2/part.obj", 2), ("set1/part.ply", 3)):
        V, F = sphere_hull(30 + seed, np.random.default_rng(seed))
        put(rel, V, F)
    _text(os.path.join(root, "broken/garbage.obj"), "this is not a mesh\n")
    _text(os.path.join(root, "broken/fin.off"),
          "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 -1 0\n3 0 1 2\n3 1 0 3\n3 0 1 4\n")
    _text(os.path.join(root, "broken/range.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 9\n")
    _text(os.path.join(root, "broken/quad.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    _text(os.path.join(root, "broken/empty.off"), "")
    hybridsub.write_mesh(os.path.join(root, "broken/truncated.ply"), *sphere_hull(50, rng))
    with open(os.path.join(root, "broken/truncated.ply"), "r+b") as fh:
        fh.truncate(os.path.getsize(fh.name) // 2)
    np.savez(os.path.join(root, "broken/nofaces.npz"), vertices=np.eye(3))
    return sorted(good)


def _sha(path):
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()


def _records(outdir, key=None):
    """The manifest's rows (of options ``key``), in input order."""
    m = Manifest(str(outdir), readonly=True)
    try:
        return list(m.records(key))
    finally:
        m.close()


def _same(seen, records):
    """The records on_result saw are the manifest's rows (which hold every field)."""
    rows = {(r["input"], r["options_key"]): r for r in records}
    assert len(seen) == len(rows)
    for rec in seen:
        row = rows[rec["input"], rec["options_key"]]
        assert {k: row[k] for k in rec} == rec


def _count_rows(path):
    with contextlib.closing(sqlite3.connect(path, timeout=5)) as db:
        try:
            return db.execute("SELECT count(*) FROM meshes").fetchone()[0]
        except sqlite3.OperationalError:  # not created yet
            return 0


def _files(outdir):
    """Every file below outdir, relative, '/'-separated."""
    out = set()
    for root, _, names in os.walk(outdir):
        out |= {os.path.relpath(os.path.join(root, n), outdir).replace(os.sep, "/") for n in names}
    return out


def _out(rel, fmt="obj"):
    return f"{os.path.splitext(rel)[0]}.{fmt}"


@pytest.fixture(scope="module")
def collection(tmp_path_factory):
    root = str(tmp_path_factory.mktemp("meshes"))
    return root, _make_collection(root)


@pytest.fixture(scope="module")
def reference(collection, tmp_path_factory):
    """Each good input's output as ``hybridsub subdivide IN -o OUT --levels 2 --feature-angle 30``
    writes it, run here in this process: bytes by input name."""
    root, good = collection
    d = tmp_path_factory.mktemp("reference")
    ref = {}
    for rel in good:
        out = os.path.join(d, rel.replace("/", "_") + ".obj")
        assert main(["subdivide", os.path.join(root, rel), "-o", out, *OPTS, "-q"]) == 0
        with open(out, "rb") as fh:
            ref[rel] = fh.read()
    return ref


@pytest.fixture(scope="module")
def client():
    cluster, c = _batch.local_cluster(2, memory_limit="2GB")  # what batch(workers=2) starts, with less memory
    with cluster, c:
        yield c


@pytest.fixture
def cluster(client):
    client.wait_for_workers(2, timeout=120)  # a test that kills a worker leaves its restart behind
    return client


def _check_outputs(root, outdir, good, reference, records):
    """Each good input has exactly one done record naming one output, whose bytes are the
    reference's and whose size and checksum the record gives; nothing else lies in outdir but
    the manifest."""
    done = {}
    for r in records:
        if r["status"] == "done":
            rel = os.path.relpath(r["input"], root).replace(os.sep, "/")
            assert rel not in done, f"{rel} done twice"
            done[rel] = r
    assert sorted(done) == good
    outputs = set()
    for rel, r in done.items():
        path = os.path.join(outdir, r["output"])
        with open(path, "rb") as fh:
            data = fh.read()
        assert data == reference[rel], rel
        assert r["output_size"] == len(data) and r["output_sha256"] == hashlib.sha256(data).hexdigest()
        outputs.add(r["output"])
    assert len(outputs) == len(good)
    assert _files(outdir) == outputs | {MANIFEST, LOCKFILE}  # the WAL files go when the batch ends
    assert not os.path.exists(os.path.join(outdir, TMPDIR))  # removed once empty
    return done


# ----------------------------------------------------------------------------------------------
# a whole batch


def test_batch_equals_subdivide_and_reports_broken_meshes(collection, reference, cluster, tmp_path):
    root, good = collection
    outdir = str(tmp_path / "out")
    seen = []
    s = hybridsub.batch(root, outdir, scheduler=cluster, on_result=seen.append, **KW)
    assert (s.total, s.done, s.skipped, s.failed) == (len(good) + len(BROKEN), len(good), 0, len(BROKEN))
    assert not s.ok and s.manifest == os.path.join(outdir, MANIFEST)
    records = _records(outdir)
    _same(seen, records)  # the callback sees what the manifest holds
    assert len(records) == s.total
    done = _check_outputs(root, outdir, good, reference, records)
    assert s.output_faces == sum(r["faces_out"] for r in done.values())

    # names: mirrored below the input folder; set1/part.ply comes after set1/part.obj, which has
    # its name, so it takes a hash of its path
    digest = hashlib.sha1(os.path.join(root, "set1", "part.ply").encode()).hexdigest()[:8]
    assert {rel: r["output"] for rel, r in done.items()} == \
        {rel: f"set1/part-{digest}.obj" if rel == "set1/part.ply" else _out(rel) for rel in good}

    # the manifest is complete
    for r in records:
        src = r["input"]
        assert r["options"] == dict(levels=2, scheme="hybrid", feature_angle=30.0, feature_sharpness=None,
                                    loop_weights="loop", format="obj", ignore_tags=False, triangulate=False,
                                    weld=False, uv_mode=None)
        assert r["options_key"] == records[0]["options_key"] and r["hybridsub"] == hybridsub.__version__
        assert r["input_size"] == os.path.getsize(src) and r["input_sha256"] == _sha(src)
        assert r["input_mtime_ns"] == os.stat(src).st_mtime_ns
        assert r["reason"] == "new" and r["worker"].startswith("tcp://") and r["finished"]
        assert r["seconds"]["total"] > 0
        if r["status"] == "done":
            assert r["error"] is None and r["faces_out"] > r["faces_in"] > 0
            assert r["seconds"]["refine"] > 0 and r["features"]
    failed = {os.path.relpath(r["input"], root).replace(os.sep, "/"): r["error"]
              for r in records if r["status"] == "failed"}
    assert sorted(failed) == sorted(BROKEN)
    for rel, err in failed.items():
        assert err.startswith(os.path.join(root, rel)) and BROKEN[rel] in err, err
    assert sorted(s.failures) == sorted((os.path.join(root, rel), e) for rel, e in failed.items())

    # the arrays are subdivide's, bit for bit (the file's tags merged with the detected ones)
    for rel in ("shapes/mesh_with_border.off", "cad/fandisk.obj", "spheres/s03.npz"):
        m = hybridsub.read_mesh(os.path.join(root, rel))
        V2, F2 = hybridsub.subdivide(m.vertices, m.faces, m.sharp_edges, 2, corners=m.corners, feature_angle=30)
        out = hybridsub.read_mesh(os.path.join(outdir, _out(rel)))
        assert np.array_equal(out.faces, F2) and np.array_equal(out.vertices, V2)
    assert hybridsub.read_mesh(os.path.join(outdir, "spheres/s03.obj")).vertex_colors is not None

    # the same call again: nothing redone, nothing rewritten, the failures tried again
    stamps = {p: os.stat(os.path.join(outdir, p)).st_mtime_ns for p in _files(outdir) - {MANIFEST, LOCKFILE}}
    s2 = hybridsub.batch(root, outdir, scheduler=cluster, **KW)
    assert (s2.done, s2.skipped, s2.failed) == (0, len(good), len(BROKEN))
    assert stamps == {p: os.stat(os.path.join(outdir, p)).st_mtime_ns for p in stamps}
    after = _records(outdir)
    assert len(after) == len(records)  # one row per input and options: rows replaced, never appended
    again = [r for r in after if r["run"] != records[0]["run"]]
    assert len(again) == len(BROKEN) and all(r["reason"] == "failed before" for r in again)


def test_semi_sharp_features_and_smooth_uvs_as_subdivide(cluster, tmp_path):
    """--feature-sharpness and --uv-mode travel to the workers: a textured OBJ (seams) and the
    CAD cube come out as 'hybridsub subdivide' writes them with the same options, byte for byte;
    the options are part of what makes a mesh done."""
    src = tmp_path / "in"
    src.mkdir()
    d = np.load(os.path.join(DATA, "bunny10k_textured.fvar_linear.L1.npz"))
    hybridsub.write_mesh(src / "bunny.obj", d["V_in"], d["F_in"], uv=d["UV_in"], face_uv=d["FUV_in"])
    shutil.copy(os.path.join(DATA, "cube-meshed.off"), src / "cube.off")
    opts = ["--levels", "1", "--feature-angle", "30", "--feature-sharpness", "1.5", "--uv-mode", "smooth"]
    ref = {}
    for name in ("bunny", "cube"):
        out = tmp_path / f"{name}.ref.obj"
        assert main(["subdivide", str(src / f"{name}.{'obj' if name == 'bunny' else 'off'}"), "-o", str(out),
                     *opts, "-q"]) == 0
        ref[name] = out.read_bytes()
    outdir = tmp_path / "out"
    kw = dict(levels=1, feature_angle=30, feature_sharpness=1.5, uv_mode="smooth")
    s = hybridsub.batch(str(src), str(outdir), scheduler=cluster, **kw)
    assert (s.done, s.failed) == (2, 0)
    for name in ("bunny", "cube"):
        assert (outdir / f"{name}.obj").read_bytes() == ref[name], name
    assert b"t crease 2/1/0" in ref["cube"] and b" 0.5\n" in ref["cube"]  # children of s = 1.5
    assert b"vt " in ref["bunny"]
    rec = _records(str(outdir))[-1]
    assert rec["options"]["feature_sharpness"] == 1.5 and rec["options"]["uv_mode"] == "smooth"
    s = hybridsub.batch(str(src), str(outdir), scheduler=cluster, **dict(kw, uv_mode="linear"))
    assert (s.done, s.skipped) == (2, 0)  # other options: redone
    with pytest.raises(ValueError, match="feature_sharpness sets the sharpness of detected creases"):
        hybridsub.batch(str(src), str(outdir), scheduler=cluster, feature_sharpness=2)
    with pytest.raises(ValueError, match="feature_sharpness must be a number > 0"):
        hybridsub.batch(str(src), str(outdir), scheduler=cluster, feature_angle=30, feature_sharpness=0)
    with pytest.raises(ValueError, match="uv_mode must be one of"):
        hybridsub.batch(str(src), str(outdir), scheduler=cluster, uv_mode="cubic")


def test_changed_option_deleted_output_changed_input(collection, reference, cluster, tmp_path):
    """levels changed: everything redone; then only the deleted output, the changed input, the
    output cut short and (with verify) the output altered at the same size."""
    root, good = collection
    src = str(tmp_path / "in")
    for rel in good[:8]:
        os.makedirs(os.path.dirname(os.path.join(src, rel)), exist_ok=True)
        shutil.copy2(os.path.join(root, rel), os.path.join(src, rel))
    rels = sorted(os.path.relpath(os.path.join(r, n), src).replace(os.sep, "/")
                  for r, _, ns in os.walk(src) for n in ns)
    outdir = str(tmp_path / "out")
    s1 = hybridsub.batch(src, outdir, scheduler=cluster, levels=1, feature_angle=30)
    assert (s1.done, s1.skipped, s1.failed) == (8, 0, 0)
    s2 = hybridsub.batch(src, outdir, scheduler=cluster, **KW)
    assert (s2.done, s2.skipped) == (8, 0)
    by_key = {}
    for r in _records(outdir):
        by_key.setdefault(r["options_key"], []).append(r["reason"])
    assert sorted(by_key.values()) == [["new"] * 8, ["options changed"] * 8]  # one row per input and options
    for rel in rels:
        with open(os.path.join(outdir, _out(rel)), "rb") as fh:
            assert fh.read() == reference[rel]

    deleted, changed, cut, altered = rels[0], rels[1], rels[2], rels[3]
    os.remove(os.path.join(outdir, _out(deleted)))
    V, F = sphere_hull(60, np.random.default_rng(5))
    os.remove(os.path.join(src, changed))
    hybridsub.write_mesh(os.path.join(src, changed), V, F)
    with open(os.path.join(outdir, _out(cut)), "r+b") as fh:
        fh.truncate(100)
    path = os.path.join(outdir, _out(altered))
    with open(path, "r+b") as fh:  # same size, one byte different: only a checksum sees it
        fh.seek(-2, os.SEEK_END)
        fh.write(b"9" if fh.read(1) != b"9" else b"8")
    got = []
    s3 = hybridsub.batch(src, outdir, scheduler=cluster, on_result=got.append, **KW)
    assert (s3.done, s3.skipped) == (3, 5)
    new = {os.path.relpath(r["input"], src).replace(os.sep, "/"): r["reason"] for r in got}
    assert new == {deleted: "output missing", changed: "input changed", cut: "output changed"}
    got = []
    s4 = hybridsub.batch(src, outdir, scheduler=cluster, verify=True, on_result=got.append, **KW)
    assert (s4.done, s4.skipped) == (1, 7)
    last = [r for r in got if r["status"] != "skipped"][-1]
    assert last["input"] == os.path.join(src, altered) and last["reason"] == "verify: the output's checksum differs"
    for rel in set(rels) - {changed}:
        with open(os.path.join(outdir, _out(rel)), "rb") as fh:
            assert fh.read() == reference[rel]
    assert hybridsub.read_mesh(os.path.join(outdir, _out(changed))).faces.shape[0] > len(F)


# ----------------------------------------------------------------------------------------------
# faults


@pytest.mark.slow  # subprocesses: ~4 s; .ci/run runs the slow tests
def test_killed_worker_mid_batch(collection, reference, cluster, tmp_path, capfd, caplog):
    """SIGKILL to a worker process while it runs tasks: Dask runs them again elsewhere, every
    output is written once and whole, and none of Dask's warnings or tracebacks reach the user
    (``distributed.client`` and the nanny log at their own levels); the next call finds
    everything done."""
    root, good = collection
    outdir = str(tmp_path / "out")
    pids = cluster.run(os.getpid)
    killed = []

    def kill_one(rec):
        if len(killed) == 0 and rec["status"] == "done":
            busy = [w for w, keys in cluster.processing().items() if keys and w in pids]
            killed.append(busy[0] if busy else next(iter(pids)))
            os.kill(pids[killed[0]], signal.SIGKILL)

    capfd.readouterr()
    caplog.clear()
    s = hybridsub.batch(root, outdir, scheduler=cluster, on_result=kill_one, **KW)
    assert killed and (s.done, s.failed) == (len(good), len(BROKEN))
    err = capfd.readouterr().err
    assert "distributed." not in err and "Traceback" not in err, err
    noise = [r for r in caplog.records if r.name.split(".")[0] in ("distributed", "tornado", "asyncio")
             and r.levelno >= logging.WARNING]
    assert noise == [], [r.getMessage() for r in noise]
    assert not logging.getLogger("distributed.client").disabled  # restored after
    tmp = os.path.join(outdir, TMPDIR)
    stray = os.listdir(tmp) if os.path.isdir(tmp) else []  # the killed task's marker, if it had begun
    assert len(stray) <= 1
    hidden = {f for f in _files(outdir) if os.path.basename(f).startswith(".hybridsub-")}  # its temporary output
    assert len(hidden) <= len(stray)
    cluster.wait_for_workers(2, timeout=120)
    s2 = hybridsub.batch(root, outdir, scheduler=cluster, **KW)
    assert (s2.done, s2.skipped) == (0, len(good))
    assert bool(hidden) == any("temporary files" in n for n in s2.notes)
    _check_outputs(root, outdir, good, reference, _records(outdir))


@pytest.mark.slow  # subprocesses / a cluster / figures: ~4-11 s; .ci/run runs the slow tests
def test_killed_run_resumes(collection, reference, cluster, tmp_path):
    """``hybridsub batch`` killed with SIGKILL (client, scheduler and workers) after a few meshes,
    the manifest's WAL left behind: the rerun redoes only the unfinished meshes."""
    root, good = collection
    outdir = str(tmp_path / "out")
    manifest = os.path.join(outdir, MANIFEST)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([ROOT, os.environ.get("PYTHONPATH", "")]))
    p = subprocess.Popen([sys.executable, "-m", "hybridsub", "batch", root, "-o", outdir, *OPTS, "--workers", "1",
                          "-q"], cwd=ROOT, env=env, start_new_session=True, stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and p.poll() is None:
            if os.path.exists(manifest) and _count_rows(manifest) >= 4:
                break
            time.sleep(0.01)
        assert p.poll() is None, p.stderr.read().decode()
    finally:
        os.killpg(p.pid, signal.SIGKILL)
        p.wait()
    assert os.path.exists(manifest + "-wal")  # killed: not checkpointed
    before = _records(outdir)
    done_before = [r for r in before if r["status"] == "done"]
    assert 4 <= len(before) < len(good) // 2
    for r in done_before:  # what the manifest says is done is there, whole
        assert _sha(os.path.join(outdir, r["output"])) == r["output_sha256"]
    on_disk = {f for f in _files(outdir) if not f.startswith((TMPDIR + "/", "hybridsub-manifest"))
               and not os.path.basename(f).startswith(".hybridsub-")}
    # an output renamed into place whose record the killed client had not yet written may be there too
    assert on_disk >= {r["output"] for r in done_before} and len(on_disk) <= len(done_before) + 1
    stamps = {r["output"]: os.stat(os.path.join(outdir, r["output"])) for r in done_before}

    s = hybridsub.batch(root, outdir, scheduler=cluster, **KW)
    assert (s.skipped, s.done) == (len(done_before), len(good) - len(done_before))
    for out, st in stamps.items():  # not redone: the same file, untouched
        st2 = os.stat(os.path.join(outdir, out))
        assert (st2.st_ino, st2.st_mtime_ns) == (st.st_ino, st.st_mtime_ns)
    records = _records(outdir)
    rows = {r["input"]: r for r in records}
    assert all(rows[r["input"]] == r for r in done_before)  # their rows untouched
    _check_outputs(root, outdir, good, reference, records)


def test_stopping_after_k_results_and_resuming(collection, reference, cluster, tmp_path):
    """An exception from on_result stops the batch (as Ctrl-C would): what finished is recorded,
    the rest is cancelled; the next call does only the rest."""
    root, good = collection
    outdir = str(tmp_path / "out")

    def stop(rec):
        if len(_records(outdir)) >= 5:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        hybridsub.batch(root, outdir, scheduler=cluster, on_result=stop, **KW)
    first = _records(outdir)
    assert 5 <= len(first) < len(good)
    s = hybridsub.batch(root, outdir, scheduler=cluster, **KW)
    n_done = sum(r["status"] == "done" for r in first)
    assert (s.skipped, s.done) == (n_done, len(good) - n_done)
    _check_outputs(root, outdir, good, reference, _records(outdir))


def test_local_cluster_settings(cluster):
    """Each worker has its share of the cores for Numba, and glibc's malloc trimming (not Dask's
    MALLOC_TRIM_THRESHOLD_, which made each mesh 1.4x slower)."""
    cores = len(os.sched_getaffinity(0))
    env = cluster.run(lambda: (os.environ.get("NUMBA_NUM_THREADS"), os.environ.get("MALLOC_TRIM_THRESHOLD_")))
    assert sorted(env.values()) == [(str(max(1, cores // 2)), os.environ.get("MALLOC_TRIM_THRESHOLD_"))] * 2


def test_memory_guard_uses_the_worker_limit(cluster, tmp_path):
    """7 levels of fandisk would need more than the test cluster's 2 GB per worker: the mesh fails
    before allocating, naming the limit, and the batch goes on."""
    V, F = hybridsub.load_example()
    hybridsub.write_mesh(tmp_path / "in" / "big.obj", V, F)
    hybridsub.write_mesh(tmp_path / "in" / "small.obj", np.eye(3), [[0, 1, 2]])
    s = hybridsub.batch(tmp_path / "in", tmp_path / "out", scheduler=cluster, levels=7)
    assert (s.done, s.failed) == (1, 1)
    assert "would need about" in s.failures[0][1] and "the Dask worker's memory limit is 2.0 GB" in s.failures[0][1]


# ----------------------------------------------------------------------------------------------
# formats, the command line, the local cluster


@pytest.mark.slow  # subprocesses / a cluster / figures: ~4-11 s; .ci/run runs the slow tests
def test_cli_local_cluster_ply_and_npz(collection, tmp_path, capsys):
    """``hybridsub batch`` starting its own cluster, PLY and NPZ outputs equal to ``subdivide``'s,
    exit code 1 for a failed mesh, 0 when all are done or skipped."""
    root, good = collection
    picks = [os.path.join(root, rel) for rel in ("cad/fandisk-semisharp.ply", "spheres/s03.npz", "tori/t0.ply")]
    for fmt in ("ply", "npz"):
        outdir = str(tmp_path / fmt)
        rc = main(["batch", *picks, os.path.join(root, "broken", "quad.obj"), "-o", outdir, "--format", fmt, *OPTS,
                   "--workers", "2"])
        err = capsys.readouterr().err
        assert rc == 1, err
        assert "local cluster of 2 workers" in err and "\r" not in err
        assert f"failed: {os.path.join(root, 'broken', 'quad.obj')}: face 0 has 4 vertices" in err
        for p in picks:
            ref = str(tmp_path / f"ref.{fmt}")
            assert main(["subdivide", p, "-o", ref, *OPTS, "-q"]) == 0
            out = os.path.join(outdir, os.path.splitext(os.path.basename(p))[0] + "." + fmt)
            with open(out, "rb") as a, open(ref, "rb") as b:
                assert a.read() == b.read(), out
    for name in ("fandisk-semisharp", "s03"):  # the same mesh, tags and colours in both formats
        a = hybridsub.read_mesh(os.path.join(str(tmp_path / "npz"), f"{name}.npz"))
        b = hybridsub.read_mesh(os.path.join(str(tmp_path / "ply"), f"{name}.ply"))
        for k in ("vertices", "faces", "sharp_edges", "sharpness", "corners"):
            assert np.array_equal(getattr(a, k), getattr(b, k)), k
    assert np.allclose(a.vertex_colors, b.vertex_colors, atol=0.5 / 255)  # PLY keeps them as bytes
    assert main(["batch", *picks, "-o", str(tmp_path / "npz"), "--format", "npz", *OPTS, "--workers", "1", "-q"]) == 0
    assert capsys.readouterr().err == ""


def test_usage_errors(collection, tmp_path, capsys):
    root, good = collection
    mesh = os.path.join(root, good[0])
    for argv in (["--workers", "0"], ["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], ["--format", "stl"],
                 ["--levels", "-1"], ["--feature-angle", "200"]):
        with pytest.raises(SystemExit) as e:
            main(["batch", mesh, "-o", str(tmp_path / "o"), *argv])
        assert e.value.code == 2
    capsys.readouterr()
    cases = [
        ([str(tmp_path / "missing.obj")], f"{tmp_path / 'missing.obj'}: no such file or directory"),
        ([str(tmp_path / "*.obj")], "matches no mesh file"),
        ([str(tmp_path)], "the folder holds no mesh file"),
        ([mesh, "--scheme", "sqrt3", "--feature-angle", "30"], "feature_angle needs scheme 'hybrid' or 'loop'"),
    ]
    for argv, msg in cases:
        assert main(["batch", *argv, "-o", str(tmp_path / "o")]) == 1
        err = capsys.readouterr().err
        assert err.startswith("hybridsub: error: ") and msg in err, err
    with pytest.raises(ValueError, match="format must be one of"):
        hybridsub.batch(mesh, tmp_path / "o", format="stl")
    with pytest.raises(ValueError, match="inside the output folder"):
        hybridsub.batch(mesh, os.path.dirname(mesh))
    with pytest.raises(ValueError, match="workers must be a positive integer"):
        hybridsub.batch(mesh, tmp_path / "o", workers=0)
    with pytest.raises(ValueError, match="no inputs given"):
        hybridsub.batch([], tmp_path / "o")
    assert not os.path.exists(tmp_path / "o")  # nothing made for a batch that cannot run
    lock = Manifest(str(tmp_path))  # another batch holds the folder
    try:
        with pytest.raises(RuntimeError, match="another hybridsub batch is writing to this folder"):
            hybridsub.batch(mesh, tmp_path)
        assert main(["batch", mesh, "-o", str(tmp_path)]) == 1
        assert "is locked" in capsys.readouterr().err
    finally:
        lock.close()


def test_without_dask_says_how_to_install(collection, tmp_path, monkeypatch, capsys):
    root, good = collection
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed → ImportError
    assert main(["batch", os.path.join(root, good[0]), "-o", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("hybridsub: error: hybridsub batch runs on Dask, which is not installed")
    assert "python -m pip install 'hybridsub[batch]'" in err
    with pytest.raises(ImportError, match=r"hybridsub\[batch\]"):
        hybridsub.batch(root, tmp_path / "o")
    assert not os.path.exists(tmp_path / "o")


# ----------------------------------------------------------------------------------------------
# the pieces


def _plan_names(manifest, items, fmt="obj"):
    planner = Planner(manifest, "k", fmt, manifest.outdir, verify=False, dedupe=True, threads=1)
    return [name for _, name, _, _ in planner.plan(manifest.first_seen(items)).jobs]


def test_inputs_and_output_names(tmp_path, monkeypatch):
    for rel in ("d/a/x.obj", "d/b/x.obj", "d/b/x.ply", "d/b/notes.txt", "d/out/old.obj", "e/X.obj", "e/x.off",
                "d/.hidden/h.obj", "d/b/.h.obj", "d/b/deep/y.obj"):
        _text(str(tmp_path / rel), "")
    monkeypatch.chdir(tmp_path)
    items = list(walk_inputs(["d", "d/a/x.obj", "e/*.o*"], "d/out"))
    # a folder's files before its subfolders, both sorted; hidden files taken from a folder
    assert [(os.path.relpath(i.path), i.stem) for i in items] == [
        ("d/.hidden/h.obj", ".hidden/h"), ("d/a/x.obj", "a/x"), ("d/b/.h.obj", "b/.h"), ("d/b/x.obj", "b/x"),
        ("d/b/x.ply", "b/x"), ("d/b/deep/y.obj", "b/deep/y"), ("d/a/x.obj", "x"), ("e/X.obj", "X"),
        ("e/x.off", "x")]
    for inside in ("d/out/old.obj", "d/out", "d/out/*.obj"):
        with pytest.raises(ValueError, match="inside the output folder"):
            walk_inputs([inside], "d/out" if inside != "d/out" else "d")
    # patterns as glob matches them: ** any folders but hidden ones, * not across '/', d/out not searched
    assert [i.stem for i in walk_inputs(["d/**/*.obj"], "d/out")] == ["a/x", "b/x", "b/deep/y"]
    assert [i.stem for i in walk_inputs(["d/*/x.*"], "d/out")] == ["a/x", "b/x", "b/x"]
    assert [i.stem for i in walk_inputs(["d/b/.*"], "d/out")] == [".h"]
    with pytest.raises(FileNotFoundError, match="matches no mesh file"):
        walk_inputs(["d/*.stl"], "d/out")
    with pytest.raises(FileNotFoundError, match="no such file"):
        walk_inputs(["d", "nothing.obj"], "d/out")  # every INPUT is checked before anything runs

    picked = [items[k] for k in (1, 3, 4, 7, 8, 6)]  # d/a/x, d/b/x.obj, d/b/x.ply, e/X, e/x, d/a/x again
    h = [hashlib.sha1(i.path.encode()).hexdigest()[:8] for i in picked]
    m = Manifest(str(tmp_path / "o1"), readonly=True)  # nothing written: names kept in memory
    try:
        # first come keeps the name; the next takes a hash of its path; names differing in case collide;
        # a file given twice is planned once
        assert _plan_names(m, picked) == ["a/x.obj", "b/x.obj", f"b/x-{h[2]}.obj", "X.obj", f"x-{h[4]}.obj"]
    finally:
        m.close()
    assert not os.path.exists(tmp_path / "o1")
    os.makedirs(tmp_path / "o2")
    for run, fmt, names in (([picked[2]], "ply", ["b/x.ply"]),  # an earlier run named only d/b/x.ply, b/x:
                            (picked[:3], "obj", ["a/x.obj", f"b/x-{h[1]}.obj", "b/x.obj"])):  # it keeps the name
        m = Manifest(str(tmp_path / "o2"))
        try:
            assert _plan_names(m, run, fmt) == names
        finally:
            m.close()


def test_manifest_migrated_from_json_lines(tmp_path):
    """A JSON-lines manifest of an earlier version is read once: the last record of each key wins,
    unreadable and torn lines are skipped, each input keeps its output name; the old file is
    renamed. A read-only view (dry run, --status) migrates into memory and renames nothing."""
    path = tmp_path / LEGACY_MANIFEST
    good = {"input": "/a.obj", "options_key": "k", "status": "done", "output": "sub/a.obj", "options": {"levels": 1},
            "hybridsub": "0.1.0", "notes": ["n"], "seconds": {"total": 1.5}}
    path.write_text(json.dumps(good) + "\nnot json\n" + json.dumps(dict(good, status="failed", error="e")) + "\n"
                    + json.dumps(dict(good, input="/b.obj", output="b.obj")) + '\n{"inp')
    view = Manifest(str(tmp_path), readonly=True)
    try:
        assert [r["input"] for r in view.records()] == ["/a.obj", "/b.obj"]
    finally:
        view.close()
    assert path.exists() and not (tmp_path / MANIFEST).exists()
    m = Manifest(str(tmp_path))
    try:
        recs = list(m.records())
        assert recs[0] == dict(recs[0], input="/a.obj", status="failed", error="e", output="sub/a.obj",
                               options={"levels": 1}, hybridsub="0.1.0", notes=["n"], seconds={"total": 1.5})
        assert m.notes == [f"migrated 3 records of {LEGACY_MANIFEST} into {MANIFEST} (2 unreadable lines skipped); "
                           f"the old file is kept as {LEGACY_MANIFEST}.migrated"]
        assert m.owner("SUB/A") == "/a.obj" and m.owner("b") == "/b.obj" and m.owner("c") is None
        m.record([dict(good, input="/c.obj", output="c.obj")])
    finally:
        m.close()
    assert not path.exists() and (tmp_path / (LEGACY_MANIFEST + ".migrated")).exists()
    m = Manifest(str(tmp_path))  # read once: the next open finds only the database
    try:
        assert m.notes == [] and [r["input"] for r in m.records()] == ["/a.obj", "/b.obj", "/c.obj"]
    finally:
        m.close()


def test_lock_held_or_missing(tmp_path, monkeypatch, capsys):
    """flock's errors: EWOULDBLOCK is another batch; ENOSYS/EOPNOTSUPP/ENOLCK (Lustre without -o flock,
    some NFS setups) is a file system without locks, with the fallback named; lock=False runs
    without flock, and SQLite without locks."""
    import fcntl

    def failing(code):
        def flock(fd, op):
            raise OSError(code, os.strerror(code))
        return flock

    for code in (errno.EWOULDBLOCK, errno.ENOSYS, errno.EOPNOTSUPP, errno.ENOLCK, errno.EIO):
        monkeypatch.setattr(fcntl, "flock", failing(code))
        with pytest.raises(LockError) as e:
            Manifest(str(tmp_path))
        msg = str(e.value)
        if code == errno.EWOULDBLOCK:
            assert "another hybridsub batch is writing to this folder" in msg
        elif code == errno.EIO:
            assert "cannot lock" in msg and "another" not in msg
        else:
            assert "this file system has no file locks" in msg and "--no-lock" in msg, msg
    monkeypatch.setattr(fcntl, "flock", failing(errno.ENOSYS))
    m = Manifest(str(tmp_path), lock=False)  # flock is not called
    try:
        m.record([{"input": "/a.obj", "options_key": "k", "status": "done"}])
        assert [r["input"] for r in m.records()] == ["/a.obj"]
    finally:
        m.close()
    src = tmp_path / "in.obj"
    src.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert main(["batch", str(src), "-o", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("hybridsub: error: ") and "no file locks" in err and "--no-lock" in err
    assert main(["batch", str(src), "-o", str(tmp_path / "o"), "--no-lock", "--dry-run"]) == 0
    assert "would do          1   new" in capsys.readouterr().err


def test_progress_bar_and_killed_worker_record():
    buf = io.StringIO()
    bar = BatchProgress(10, enabled=True, stream=buf)
    bar.update(3, 1, 2_500_000, 2.0)
    bar.close()
    assert "4/10 meshes (1 failed), 1.2 M faces/s" in buf.getvalue() and buf.getvalue().endswith("\n")
    off = io.StringIO()
    BatchProgress(10, enabled=False, stream=off).update(3, 0, 10, 1.0)
    assert off.getvalue() == ""
    job = {"input": "/x.obj", "options": {}, "options_key": "k", "hybridsub": "0", "output": "x.obj", "reason": "new"}
    rec = _batch.failed_on_cluster(job, KilledWorker("key", SimpleNamespace(address="tcp://w"), 3), KilledWorker)
    assert rec["status"] == "failed" and rec["error"].startswith("/x.obj: the worker running it died")


def test_run_task_records_what_went_wrong(tmp_path, monkeypatch):
    """The task never raises: another hybridsub version on the worker, a bug (with its traceback)
    and a full disk (flagged, for the client to stop) become failed records, and no temporary
    file or marker stays behind."""
    src = tmp_path / "t.off"
    src.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    os.makedirs(tmp_path / TMPDIR)
    job = {"input": str(src), "output": "out/t.obj", "output_path": str(tmp_path / "out" / "t.obj"),
           "tmpdir": str(tmp_path / TMPDIR), "options": _batch.batch_options(1, "hybrid", None, None, "loop", "obj",
                                                                             False, False, False, None),
           "options_key": "k", "hybridsub": "0.0.1", "force": False, "reason": "new", "verify": None}
    rec = _task.run_task(job)
    assert rec["status"] == "failed" and "this worker has hybridsub" in rec["error"] and "0.0.1" in rec["error"]

    def broken(exc):
        def subdivide_file(a, src, dst, write_to=None):
            assert os.path.dirname(write_to) == os.path.dirname(dst)  # beside its output: OBJ's mtllib is right
            assert len(os.listdir(tmp_path / TMPDIR)) == 1  # the marker naming it
            with open(write_to, "w") as fh:
                fh.write("half a file")
            raise exc
        return subdivide_file

    monkeypatch.setattr(_task, "subdivide_file", broken(RuntimeError("boom")))
    rec = _task.run_task(dict(job, hybridsub=hybridsub.__version__))
    assert rec["status"] == "failed" and rec["error"] == f"{src}: internal error: RuntimeError: boom"
    assert "Traceback" in rec["traceback"] and os.listdir(tmp_path / TMPDIR) == []
    assert os.listdir(tmp_path / "out") == [] and "no_space" not in rec
    full = OSError(errno.ENOSPC, "No space left on device", str(tmp_path / "out" / "t.obj"))
    monkeypatch.setattr(_task, "subdivide_file", broken(full))
    rec = _task.run_task(dict(job, hybridsub=hybridsub.__version__))
    assert rec["no_space"] and rec["error"] == f"{tmp_path / 'out' / 't.obj'}: No space left on device"
    assert os.listdir(tmp_path / "out") == [] and os.listdir(tmp_path / TMPDIR) == []
    monkeypatch.undo()
    rec = _task.run_task(dict(job, hybridsub=hybridsub.__version__))
    assert rec["status"] == "done" and os.listdir(tmp_path / TMPDIR) == []
    assert rec["faces_out"] == len(hybridsub.read_mesh(tmp_path / "out" / "t.obj").faces) > 1
    assert _sha(tmp_path / "out" / "t.obj") == rec["output_sha256"]


# ----------------------------------------------------------------------------------------------
# the defects of issue 17, the dry run, --status, the window, memory


def test_obj_with_materials_names_its_mtl_as_subdivide(cluster, tmp_path):
    """The output is written beside its final name, so its 'mtllib' line and the copied library are
    byte for byte what 'hybridsub subdivide' writes (it was relative to the temporary folder)."""
    (tmp_path / "in" / "parts").mkdir(parents=True)
    (tmp_path / "in" / "mats.mtl").write_text("newmtl red\nKd 1 0 0\n")
    (tmp_path / "in" / "parts" / "a.obj").write_text(
        "mtllib ../mats.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nusemtl red\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n")
    ref = tmp_path / "ref" / "parts" / "a.obj"
    assert main(["subdivide", str(tmp_path / "in" / "parts" / "a.obj"), "-o", str(ref), "--levels", "1", "-q"]) == 0
    s = hybridsub.batch(tmp_path / "in", tmp_path / "out", scheduler=cluster, levels=1)
    assert (s.done, s.failed) == (1, 0)
    out = (tmp_path / "out" / "parts" / "a.obj").read_bytes()
    # the material library is copied beside the output, as subdivide does, not named relative to a temporary folder
    assert b"mtllib mats.mtl\n" in out and out == ref.read_bytes()
    assert (tmp_path / "out" / "parts" / "mats.mtl").read_text() == "newmtl red\nKd 1 0 0\n"


def _patch_full_disk():  # runs on the workers: the task for m3 finds the disk full
    real = _task.subdivide_file

    def full(opts, src, dst, write_to=None):
        if os.path.basename(src) == "m3.obj":
            with open(write_to, "w") as fh:
                fh.write("v 0")
            raise OSError(errno.ENOSPC, "No space left on device", write_to)
        return real(opts, src, dst, write_to)

    full.real = real
    _task.subdivide_file = full


def _unpatch_full_disk():
    _task.subdivide_file = getattr(_task.subdivide_file, "real", _task.subdivide_file)


def test_full_disk_stops_and_says_run_again(cluster, tmp_path, monkeypatch):
    """A worker's ENOSPC stops the batch with the hint (its mesh recorded as failed, no temporary
    file left); the manifest's own ENOSPC too; the rerun finishes."""
    for i in range(6):
        hybridsub.write_mesh(tmp_path / "in" / f"m{i}.obj", np.eye(3), [[0, 1, 2]])
    outdir = tmp_path / "out"
    cluster.run(_patch_full_disk)
    try:
        with pytest.raises(RuntimeError, match=r"the disk is full \(.*m3.obj: No space left on device\); free some "
                                               r"space, then .*run the same command again"):
            hybridsub.batch(tmp_path / "in", outdir, scheduler=cluster, levels=1)
    finally:
        cluster.run(_unpatch_full_disk)
    rows = {os.path.basename(r["input"]): r for r in _records(outdir)}
    assert rows["m3.obj"]["status"] == "failed" and "No space left" in rows["m3.obj"]["error"]
    assert not [f for f in _files(outdir) if ".hybridsub-" in f]

    def no_space(self, records):
        raise OSError(errno.ENOSPC, "No space left on device", self.path)

    monkeypatch.setattr(Manifest, "record", no_space)
    with pytest.raises(RuntimeError, match=r"hybridsub-manifest.sqlite: No space left on device\); free some space"):
        hybridsub.batch(tmp_path / "in", outdir, scheduler=cluster, levels=1)
    monkeypatch.undo()
    s = hybridsub.batch(tmp_path / "in", outdir, scheduler=cluster, levels=1)
    assert s.done + s.skipped == 6 and s.failed == 0 and s.reasons.get("failed before") == 1


def test_dry_run_and_status(tmp_path, capsys):
    """--dry-run plans without a cluster and writes nothing; --status reports the manifest."""
    for i in range(3):
        hybridsub.write_mesh(tmp_path / "in" / f"m{i}.obj", np.eye(3), [[0, 1, 2]])
    (tmp_path / "in" / "bad.obj").write_text("nothing\n")
    outdir = tmp_path / "out"
    assert main(["batch", str(tmp_path / "in"), "-o", str(outdir), "--dry-run"]) == 0
    assert "would do          4   new" in capsys.readouterr().err and not outdir.exists()
    key = _batch.options_key(_batch.batch_options(1, "hybrid", None, None, "loop", "obj", False, False, False, None),
                             hybridsub.__version__)
    os.makedirs(outdir)
    m = Manifest(str(outdir))
    try:  # as a run would leave it: m0 done, m1 done but its output deleted since, bad failed
        m.add_options(key, {"levels": 1}, hybridsub.__version__)
        for i, (name, status) in enumerate((("m0", "done"), ("m1", "done"), ("bad", "failed"))):
            src = str(tmp_path / "in" / f"{name}.obj")
            m.take_names([(src, name)])
            st = os.stat(src)
            if name == "m0":
                (outdir / "m0.obj").write_text("x")
            m.record([{"input": src, "options_key": key, "status": status, "output": f"{name}.obj",
                       "input_size": st.st_size, "input_mtime_ns": st.st_mtime_ns, "output_size": 1, "faces_out": 4,
                       "error": f"{src}: not a triangle mesh" if status == "failed" else None, "finished": f"t{i}"}])
    finally:
        m.close()
    assert main(["batch", str(tmp_path / "in"), "-o", str(outdir), "--dry-run"]) == 0
    err = capsys.readouterr().err
    assert "would do          1   new" in err and "would skip        1" in err
    assert "would redo        2   1 failed before, 1 output missing" in err or \
        "would redo        2   1 output missing, 1 failed before" in err, err
    assert main(["batch", "--status", str(outdir)]) == 1  # some mesh failed
    out = capsys.readouterr().out
    assert f"options {key}: levels 1;" in out and "last finished t2" in out
    assert "  done              2   8 output faces" in out and "  failed            1" in out
    assert f"failed: {tmp_path / 'in' / 'bad.obj'}: not a triangle mesh" in out
    for argv in (["--status", str(outdir), str(tmp_path / "in")], [str(tmp_path / "in")]):
        with pytest.raises(SystemExit) as e:
            main(["batch", *argv])
        assert e.value.code == 2
    assert main(["batch", "--status", str(tmp_path)]) == 1
    assert "no batch manifest here" in capsys.readouterr().err


def test_window_follows_the_cluster_threads():
    """Workers that join (autoscaling, dask-jobqueue) widen the window within a second."""
    clock = [0.0]
    client = SimpleNamespace(nthreads=lambda: {"w0": 1})
    w = _batch.Window(client, clock=lambda: clock[0])
    assert w.size() == _batch.MIN_WINDOW
    client.nthreads = lambda: {f"w{i}": 2 for i in range(100)}
    clock[0] = 0.5
    assert w.size() == _batch.MIN_WINDOW  # asked at most once a second
    clock[0] = 1.0
    assert w.size() == _batch.PER_THREAD * 200

    def lost():
        raise OSError("scheduler gone")

    client.nthreads = lost
    clock[0] = 2.0
    assert w.size() == _batch.PER_THREAD * 200  # the last count kept


def _done_manifest(root, n):
    """n inputs all done (as a run records them), and their outputs."""
    key = _batch.options_key(_batch.batch_options(1, "hybrid", None, None, "loop", "obj", False, False, False, None),
                             hybridsub.__version__)
    os.makedirs(os.path.join(root, "in"))
    os.makedirs(os.path.join(root, "out"))
    m = Manifest(os.path.join(root, "out"))
    try:
        rows, names = [], []
        for i in range(n):
            src = os.path.join(root, "in", f"m{i:05d}.obj")
            with open(src, "w") as fh:
                fh.write("v")
            with open(os.path.join(root, "out", f"m{i:05d}.obj"), "w") as fh:
                fh.write("vv")
            st = os.stat(src)
            names.append((src, f"m{i:05d}"))
            rows.append({"input": src, "options_key": key, "status": "done", "output": f"m{i:05d}.obj",
                         "input_size": 1, "input_mtime_ns": st.st_mtime_ns, "output_size": 2})
        m.take_names(names)
        m.record(rows)
    finally:
        m.close()


def test_rerun_memory_does_not_grow_with_inputs(tmp_path):
    """Planning streams: a rerun of 2,400 done inputs peaks at no more Python memory than one of
    600 (the JSON-lines manifest took 7.4 kB per input)."""
    import tracemalloc

    peaks = []
    for n in (600, 2400):
        root = str(tmp_path / str(n))
        _done_manifest(root, n)
        tracemalloc.start()
        s = hybridsub.batch(os.path.join(root, "in"), os.path.join(root, "out"), dry_run=True)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
        assert (s.total, s.skipped) == (n, n)
    # flat once a few planning chunks (512 inputs) are in flight; the JSON-lines manifest took 7.4 kB per input
    assert peaks[1] < 1024 * 2400 and peaks[1] - peaks[0] < 400 * 1800, peaks


def test_dask_logs_held_back_while_a_batch_runs(capfd):
    """Dask gives ``distributed.client`` its own level (so quieting ``distributed`` let its
    errors and tracebacks through when the scheduler died): every Dask logger is held at
    CRITICAL inside a batch, and restored after."""
    client_logger = logging.getLogger("distributed.client")
    before = client_logger.level
    assert before != logging.NOTSET  # Dask's configuration sets it: the reason for the fix
    with _batch.quiet_dask():
        try:
            raise ConnectionError("scheduler gone")
        except ConnectionError:
            client_logger.exception("the report stream closed")
        logging.getLogger("distributed.nanny").warning("Restarting worker")
        logging.getLogger("asyncio").error("Task exception was never retrieved")
    assert capfd.readouterr().err == ""
    assert client_logger.level == before and not client_logger.disabled


@pytest.mark.slow
def test_scheduler_killed_mid_batch_says_one_line(tmp_path):
    """A real scheduler SIGKILLed while ``hybridsub batch --scheduler`` runs: one line, exit 1, no
    Dask traceback; the rerun (on a new scheduler) finishes."""
    V, F = hybridsub.load_example()
    for i in range(30):
        hybridsub.write_mesh(tmp_path / "in" / f"m{i:02d}.obj", V, F)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([ROOT, os.environ.get("PYTHONPATH", "")]))

    def start_cluster():
        port = 20000 + os.getpid() % 20000
        sch = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--port", str(port),
                                "--dashboard-address", ":0"], env=env, start_new_session=True,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wk = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", f"tcp://127.0.0.1:{port}",
                               "--nthreads", "1"], env=env, start_new_session=True, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
        return f"tcp://127.0.0.1:{port}", [sch, wk]

    addr, procs = start_cluster()
    manifest = str(tmp_path / "out" / MANIFEST)
    try:
        p = subprocess.Popen([sys.executable, "-m", "hybridsub", "batch", str(tmp_path / "in"), "-o",
                              str(tmp_path / "out"), "--levels", "3", "--scheduler", addr, "-q"], cwd=ROOT, env=env,
                             stderr=subprocess.PIPE)
        deadline = time.monotonic() + 180
        while time.monotonic() < deadline and p.poll() is None and not (os.path.exists(manifest)
                                                                        and _count_rows(manifest) >= 2):
            time.sleep(0.05)
        os.killpg(procs[0].pid, signal.SIGKILL)
        err = p.communicate(timeout=120)[1].decode()
    finally:
        for q in procs:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(q.pid, signal.SIGKILL)
    assert p.returncode == 1 and err.count("\n") == 1, err
    assert err.startswith("hybridsub: error: Dask cancelled the task for") and "run the same command again" in err
    assert "Traceback" not in err and "distributed." not in err
