"""hybridsub batch on a real local Dask cluster (2 worker processes, shared by the tests): outputs
equal ``hybridsub subdivide``'s byte for byte, broken meshes are reported and the batch goes on,
the manifest is complete, and a killed worker, a killed run or a changed option costs only what
is unfinished or changed."""

import hashlib
import io
import json
import os
import shutil
import signal
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
from hybridsub._app.manifest import MANIFEST, TMPDIR, Manifest, assign_outputs, expand_inputs
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


def _records(outdir):
    with open(os.path.join(outdir, MANIFEST)) as fh:
        return [json.loads(line) for line in fh]


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
    assert _files(outdir) == outputs | {MANIFEST}
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
    assert records == seen  # the callback sees what the manifest holds, in its order
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
    stamps = {p: os.stat(os.path.join(outdir, p)).st_mtime_ns for p in _files(outdir) if p != MANIFEST}
    s2 = hybridsub.batch(root, outdir, scheduler=cluster, **KW)
    assert (s2.done, s2.skipped, s2.failed) == (0, len(good), len(BROKEN))
    assert stamps == {p: os.stat(os.path.join(outdir, p)).st_mtime_ns for p in stamps}
    again = _records(outdir)[len(records):]
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
    with pytest.raises(ValueError, match="uv_mode must be 'linear' or 'smooth'"):
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
    recs = _records(outdir)
    assert [r["reason"] for r in recs[8:]] == ["options changed"] * 8
    assert recs[0]["options_key"] != recs[8]["options_key"]
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
    s3 = hybridsub.batch(src, outdir, scheduler=cluster, **KW)
    assert (s3.done, s3.skipped) == (3, 5)
    new = {os.path.relpath(r["input"], src).replace(os.sep, "/"): r["reason"] for r in _records(outdir)[16:]}
    assert new == {deleted: "output missing", changed: "input changed", cut: "output changed"}
    s4 = hybridsub.batch(src, outdir, scheduler=cluster, verify=True, **KW)
    assert (s4.done, s4.skipped) == (1, 7)
    last = _records(outdir)[-1]
    assert last["input"] == os.path.join(src, altered) and last["reason"] == "verify: the output's checksum differs"
    for rel in set(rels) - {changed}:
        with open(os.path.join(outdir, _out(rel)), "rb") as fh:
            assert fh.read() == reference[rel]
    assert hybridsub.read_mesh(os.path.join(outdir, _out(changed))).faces.shape[0] > len(F)


# ----------------------------------------------------------------------------------------------
# faults


def test_killed_worker_mid_batch(collection, reference, cluster, tmp_path):
    """SIGKILL to a worker process while it runs tasks: Dask runs them again elsewhere, every
    output is written once and whole; the next call finds everything done."""
    root, good = collection
    outdir = str(tmp_path / "out")
    pids = cluster.run(os.getpid)
    killed = []

    def kill_one(rec):
        if len(killed) == 0 and rec["status"] == "done":
            busy = [w for w, keys in cluster.processing().items() if keys and w in pids]
            killed.append(busy[0] if busy else next(iter(pids)))
            os.kill(pids[killed[0]], signal.SIGKILL)

    s = hybridsub.batch(root, outdir, scheduler=cluster, on_result=kill_one, **KW)
    assert killed and (s.done, s.failed) == (len(good), len(BROKEN))
    tmp = os.path.join(outdir, TMPDIR)
    stray = os.listdir(tmp) if os.path.isdir(tmp) else []  # the killed task's file, if it had begun writing
    assert len(stray) <= 1
    cluster.wait_for_workers(2, timeout=120)
    s2 = hybridsub.batch(root, outdir, scheduler=cluster, **KW)
    assert (s2.done, s2.skipped) == (0, len(good))
    assert bool(stray) == any("temporary files" in n for n in s2.notes)
    _check_outputs(root, outdir, good, reference, _records(outdir))


def test_killed_run_resumes(collection, reference, cluster, tmp_path):
    """``hybridsub batch`` killed with SIGKILL (client, scheduler and workers) after a few meshes,
    a torn manifest line added: the rerun redoes only the unfinished meshes."""
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
            if os.path.exists(manifest) and open(manifest, "rb").read().count(b"\n") >= 4:
                break
            time.sleep(0.01)
        assert p.poll() is None, p.stderr.read().decode()
    finally:
        os.killpg(p.pid, signal.SIGKILL)
        p.wait()
    before = [json.loads(line) for line in open(manifest, "rb").read().splitlines()
              if line.endswith(b"}")]
    done_before = [r for r in before if r["status"] == "done"]
    assert 4 <= len(before) < len(good) // 2
    for r in done_before:  # what the manifest says is done is there, whole
        assert _sha(os.path.join(outdir, r["output"])) == r["output_sha256"]
    on_disk = {f for f in _files(outdir) - {MANIFEST} if not f.startswith(TMPDIR + "/")}
    # an output renamed into place whose record the killed client had not yet written may be there too
    assert on_disk >= {r["output"] for r in done_before} and len(on_disk) <= len(done_before) + 1
    stamps = {r["output"]: os.stat(os.path.join(outdir, r["output"])) for r in done_before}
    with open(manifest, "ab") as fh:
        fh.write(b'{"input": "' + root.encode() + b'/shapes/tet')

    s = hybridsub.batch(root, outdir, scheduler=cluster, **KW)
    assert (s.skipped, s.done) == (len(done_before), len(good) - len(done_before))
    assert any("torn last line" in n for n in s.notes)
    for out, st in stamps.items():  # not redone: the same file, untouched
        st2 = os.stat(os.path.join(outdir, out))
        assert (st2.st_ino, st2.st_mtime_ns) == (st.st_ino, st.st_mtime_ns)
    records = _records(outdir)  # every line whole again
    assert records[:len(before)] == before
    assert {r["input"] for r in records[len(before):]}.isdisjoint(r["input"] for r in done_before)
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


def test_inputs_and_output_names(tmp_path, monkeypatch):
    for rel in ("d/a/x.obj", "d/b/x.obj", "d/b/x.ply", "d/b/notes.txt", "d/out/old.obj", "e/X.obj", "e/x.off"):
        _text(str(tmp_path / rel), "")
    monkeypatch.chdir(tmp_path)
    items, left_out = expand_inputs(["d", "d/a/x.obj", "e/*.o*"], "d/out")
    assert [(os.path.relpath(i.path), i.stem) for i in items] == [
        ("d/a/x.obj", "a/x"), ("d/b/x.obj", "b/x"), ("d/b/x.ply", "b/x"), ("e/X.obj", "X"), ("e/x.off", "x")]
    assert left_out == 0  # d/out is skipped while walking d, and not counted: it is the output folder
    for inside in ("d/out/old.obj", "d/out", "d/out/*.obj"):
        with pytest.raises(ValueError, match="inside the output folder"):
            expand_inputs([inside], "d/out" if inside != "d/out" else "d")
    items2, left = expand_inputs(["d/**/*.obj"], "d/out")
    assert [i.stem for i in items2] == ["a/x", "b/x"] and left == 1

    h = [hashlib.sha1(i.path.encode()).hexdigest()[:8] for i in items]
    # first come keeps the name; the next takes a hash of its path; names differing in case collide
    assert assign_outputs(items, "obj", {}, {}) == ["a/x.obj", "b/x.obj", f"b/x-{h[2]}.obj", "X.obj",
                                                    f"x-{h[4]}.obj"]
    # an earlier run named only d/b/x.ply, b/x.ply: it keeps the name, the new d/b/x.obj takes a hash
    again = assign_outputs(items, "obj", {"b/x.ply": items[2].path}, {items[2].path: "b/x.ply"})
    assert again[1:3] == [f"b/x-{h[1]}.obj", "b/x.obj"]


def test_manifest_torn_and_bad_lines(tmp_path):
    path = tmp_path / MANIFEST
    good = {"input": "/a.obj", "options_key": "k", "status": "done", "output": "a.obj"}
    path.write_text(json.dumps(good) + "\nnot json\n" + json.dumps(dict(good, status="failed")) + '\n{"inp')
    m = Manifest(str(tmp_path))
    try:
        assert m.records == {("/a.obj", "k"): dict(good, status="failed")}  # the last record of a key wins
        assert m.notes == [f"cut off a torn last line of {MANIFEST} (5 bytes)",
                           f"skipped 1 unreadable lines of {MANIFEST}"]
        m.append([dict(good, input="/b.obj")])
    finally:
        m.close()
    lines = path.read_text().splitlines()
    assert len(lines) == 4 and json.loads(lines[-1])["input"] == "/b.obj"


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
    """The task never raises: another hybridsub version on the worker, and a bug (with its
    traceback), become failed records, and no temporary file stays behind."""
    src = tmp_path / "t.off"
    src.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    os.makedirs(tmp_path / "tmp")
    job = {"input": str(src), "output": "t.obj", "output_path": str(tmp_path / "out" / "t.obj"),
           "tmpdir": str(tmp_path / "tmp"), "options": _batch.batch_options(1, "hybrid", None, None, "loop", "obj",
                                                                           False, False, False, None),
           "options_key": "k", "hybridsub": "0.0.1", "force": False, "reason": "new", "verify": None}
    rec = _batch.run_task(job)
    assert rec["status"] == "failed" and "this worker has hybridsub" in rec["error"] and "0.0.1" in rec["error"]

    def broken(a, src, dst, write_to=None):
        with open(write_to, "w") as fh:
            fh.write("half a file")
        raise RuntimeError("boom")

    monkeypatch.setattr(_batch, "subdivide_file", broken)
    rec = _batch.run_task(dict(job, hybridsub=hybridsub.__version__))
    assert rec["status"] == "failed" and rec["error"] == f"{src}: internal error: RuntimeError: boom"
    assert "Traceback" in rec["traceback"] and os.listdir(tmp_path / "tmp") == []
    assert not os.path.exists(tmp_path / "out")
    monkeypatch.undo()
    rec = _batch.run_task(dict(job, hybridsub=hybridsub.__version__))
    assert rec["status"] == "done" and os.listdir(tmp_path / "tmp") == []
    assert rec["faces_out"] == len(hybridsub.read_mesh(tmp_path / "out" / "t.obj").faces) > 1
    assert _sha(tmp_path / "out" / "t.obj") == rec["output_sha256"]
