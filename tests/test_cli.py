"""The command line end to end (subprocesses), its pieces in-process, and the engines behind it:
level counts (info), level-by-level refinement (progress), the renderer (compare)."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import hybridsub
from conftest import DATA, load_mesh
from hybridsub import read_mesh
from hybridsub._app.cli import main
from hybridsub._app.report import mesh_report
from hybridsub._refiner import predict_levels
from hybridsub._app.progress import ProgressBar, refine_by_level

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(*args, env=None):
    """``python -m hybridsub ARGS`` from the worktree, as a user would run it."""
    return subprocess.run([sys.executable, "-m", "hybridsub", *map(str, args)], cwd=ROOT, capture_output=True,
                          text=True, timeout=300, env=env)


def off(name):
    return os.path.join(DATA, f"{name}.off")


def _write(path, text):
    with open(path, "w") as fh:
        fh.write(text)
    return str(path)


# ----------------------------------------------------------------------------------------------
# end to end, in a subprocess


@pytest.mark.slow  # two subprocesses, ~3 s; .ci/run runs the slow tests
def test_subdivide_writes_tags_that_the_next_run_uses(tmp_path, capsys):
    """cube-meshed, creases at 30°: two runs of one level through an OBJ with tags give what one
    run of two levels gives, and the file holds the propagated tags."""
    out1, out2, out12 = tmp_path / "l1.obj", tmp_path / "l2.obj", tmp_path / "l12.ply"
    r = run("subdivide", off("cube-meshed"), "-o", out1, "--levels", 1, "--feature-angle", 30)
    assert r.returncode == 0, r.stderr
    assert "features: 192 creases, 8 corners — from dihedral angle > 30°" in r.stderr
    assert r.stdout == ""
    assert "\r" not in r.stderr  # no progress bar when stderr is not a terminal
    assert main(["subdivide", str(out1), "-o", str(out2), "--levels", "1"]) == 0
    assert "features: 384 creases, 8 corners — from tags in l1.obj" in capsys.readouterr().err
    assert main(["subdivide", off("cube-meshed"), "-o", str(out12), "--levels", "2", "--feature-angle", "30",
                 "-q"]) == 0
    V, F = load_mesh("cube-meshed")
    feat = hybridsub.detect_features(V, F, 30)
    ref = hybridsub.refine(F, feat.sharp_edges, 2, n_vertices=len(V), corners=feat.corners)
    V2 = ref.apply(V)
    for path in (out2, out12):
        m = read_mesh(path)
        assert np.array_equal(m.faces, ref.faces)
        assert np.allclose(m.vertices, V2, atol=1e-15, rtol=0)
        assert np.array_equal(m.sharp_edges, ref.sharp_edges) and np.array_equal(m.corners, ref.corners)
    assert capsys.readouterr().err == ""  # -q
    import trimesh

    for path in (out2, out12):  # valid meshes for other tools too
        t = trimesh.load(path, process=False)
        assert isinstance(t, trimesh.Trimesh) and t.is_watertight and len(t.faces) == len(ref.faces)


def test_error_messages(tmp_path, capsys):
    """One line naming the problem and exit code 1 (the first case through a real process, the
    others in-process: same code); a bad command line is exit code 2."""
    r = run("subdivide", tmp_path / "missing.obj", "-o", tmp_path / "x.obj")
    assert r.returncode == 1 and r.stdout == ""
    assert r.stderr == f"hybridsub: error: {tmp_path / 'missing.obj'}: no such file\n"
    quad = _write(tmp_path / "quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    nm = _write(tmp_path / "nm.off", "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 -1 0\n3 0 1 2\n3 1 0 3\n3 0 1 4\n")
    cases = [
        (quad, "quad.obj: face 0 has 4 vertices (1 of 1 faces are not triangles): hybridsub subdivides triangle "
               "meshes; triangulate it first (--triangulate"),
        (nm, "nm.off: edge (0, 1) is shared by 3 faces [0, 1, 2]: the mesh is not edge-manifold"),
    ]
    for path, needle in cases:
        for command in (["subdivide", path, "-o", str(tmp_path / "x.obj")], ["compare", path, "-o",
                                                                                str(tmp_path / "x.png")]):
            assert main(command) == 1
            last = capsys.readouterr().err.strip().splitlines()[-1]
            assert last.startswith("hybridsub: error: ") and needle in last, last
    assert main(["subdivide", quad, "-o", str(tmp_path / "x.obj"), "--triangulate", "--levels", "1"]) == 0
    capsys.readouterr()
    r = run("subdivide", off("tetrahedron"), "-o", tmp_path / "x.obj", "--levels", "two")
    assert r.returncode == 2 and "--levels: must be a non-negative integer" in r.stderr
    assert main(["info", nm]) == 0  # info describes what subdivide refuses
    out = capsys.readouterr().out
    assert "1 non-manifold edge (in 3+ faces; at vertices 0–1)" in out and "refuses this mesh" in out


@pytest.mark.slow  # subprocesses / a cluster / figures: ~4-11 s; .ci/run runs the slow tests
def test_compare_writes_the_figure(tmp_path):
    fig = tmp_path / "cmp.png"
    r = run("compare", off("cube-meshed"), "-o", fig, "--levels", 1, "--size", "640x300", "--view", "30,25",
            "--feature-angle", 30)
    assert r.returncode == 0, r.stderr
    assert "features: 192 creases, 8 corners — from dihedral angle > 30°" in r.stderr  # asked for, never guessed
    assert "faces: input 1,728, Kobbelt √3 5,184, hybrid √3–Loop 5,568, Loop 6,912" in r.stderr
    data = fig.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
    import matplotlib.image

    img = matplotlib.image.imread(fig)
    assert img.shape[:2] == (300, 640)
    rgb = img[..., :3]
    panel = [rgb[:230, k * 160:(k + 1) * 160] for k in range(4)]
    red = (panel[0][..., 0] > 0.7) & (panel[0][..., 1] < 0.3) & (panel[0][..., 2] < 0.3)
    assert red.sum() > 200  # the input's creases, in red
    for p in panel[1:]:
        assert ((p[..., 0] > 0.7) & (p[..., 1] < 0.3)).sum() == 0  # no red on the results
        assert (p.std(axis=2) < 0.05).mean() > 0.2 and (p.sum(axis=2) < 2.8).sum() > 2000  # a grey shape
    assert np.abs(panel[1] - panel[2]).max() > 0.1  # √3 rounds the cube's creases, hybrid keeps them


def test_demo_runs_without_arguments(tmp_path):
    r = run("demo", "-o", tmp_path / "d")  # one level by default, as everywhere
    assert r.returncode == 0, r.stderr
    assert f"wrote 4 files to {tmp_path / 'd'}" in r.stdout
    for name in ("fandisk.hybrid.L1.obj", "fandisk.sqrt3.L1.obj", "fandisk.loop.L1.obj", "fandisk_compare.png"):
        assert (tmp_path / "d" / name).stat().st_size > 1000
        assert name in r.stdout
    m = read_mesh(tmp_path / "d" / "fandisk.hybrid.L1.obj")
    assert len(m.faces) == 40282 and len(m.sharp_edges) == 2 * 722


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="needs a pseudo-terminal")
@pytest.mark.slow  # a subprocess on a pseudo-terminal, ~2 s; .ci/run runs the slow tests
def test_progress_bar_on_a_terminal(tmp_path):
    import pty

    master, slave = pty.openpty()
    p = subprocess.Popen([sys.executable, "-m", "hybridsub", "subdivide", off("cube-meshed"), "-o",
                          tmp_path / "p.obj", "--levels", "3"], cwd=ROOT, stdout=subprocess.PIPE, stderr=slave)
    os.close(slave)
    out = b""
    while True:
        try:
            chunk = os.read(master, 4096)
        except OSError:
            break
        if not chunk:
            break
        out += chunk
    p.wait(timeout=300)
    os.close(master)
    text = out.decode()
    assert p.returncode == 0, text
    for level, faces in ((1, "5,184"), (2, "15,552"), (3, "46,656")):
        assert f"level {level}/3: {faces} faces" in text
    assert "faces/s" in text and "\r" in text and "100%" in text


# ----------------------------------------------------------------------------------------------
# in-process: options and messages


def test_features_line_without_tags(tmp_path, capsys):
    assert main(["subdivide", off("mesh_with_border"), "-o", str(tmp_path / "a.obj"), "--levels", "1"]) == 0
    err = capsys.readouterr().err
    assert err.splitlines()[0] == ("features: boundary only (80 boundary edges kept as creases); --feature-angle 30 "
                                   "would detect creases")
    assert main(["subdivide", off("icosahedron"), "-o", str(tmp_path / "b.obj"), "--levels", "1"]) == 0
    assert capsys.readouterr().err.startswith("features: none (a closed mesh without tags: smooth everywhere)")
    assert main(["subdivide", off("mesh_with_border"), "-o", str(tmp_path / "c.obj"), "--levels", "1",
                 "--scheme", "sqrt3"]) == 0
    assert "80 boundary edges follow Kobbelt's boundary rule" in capsys.readouterr().err


def test_tag_files(tmp_path, capsys):
    V, F = load_mesh("icosahedron")
    edges = _write(tmp_path / "e.txt", "# creases\n0 1\n1 9 1.5\n9, 0\n")
    faces = _write(tmp_path / "f.txt", "3 4\n5\n")
    corners = _write(tmp_path / "c.txt", "7\n")
    out = tmp_path / "o.obj"
    assert main(["subdivide", off("icosahedron"), "-o", str(out), "--levels", "2", "--sharp-edges", edges,
                 "--sharp-faces", faces, "--corners", corners]) == 0
    err = capsys.readouterr().err
    assert "features: 3 creases (1 semi-sharp), 1 corner, 3 sharp faces — from e.txt + f.txt + c.txt" in err
    r = hybridsub.refine(F, [[0, 1], [1, 9], [9, 0]], 2, n_vertices=len(V), sharpness=[np.inf, 1.5, np.inf],
                         sharp_faces=[3, 4, 5], corners=[7])
    m = read_mesh(out)
    assert np.array_equal(m.faces, r.faces) and np.allclose(m.vertices, r.apply(V), atol=1e-15)
    assert np.array_equal(m.sharp_edges, r.sharp_edges) and np.array_equal(m.sharpness, r.sharpness)
    assert np.array_equal(m.sharp_faces, r.sharp_faces) and m.corners.tolist() == [7]
    # --ignore-tags drops the file's tags; --no-tags writes none
    assert main(["subdivide", str(out), "-o", str(tmp_path / "p.obj"), "--levels", "1", "--ignore-tags",
                 "--no-tags"]) == 0
    assert not read_mesh(tmp_path / "p.obj").has_tags
    capsys.readouterr()


def test_feature_sharpness_makes_detected_creases_semi_sharp(tmp_path, capsys):
    """--feature-sharpness 1.5: the detected creases get s = 1.5 and no corner tags; after one
    level the file holds their children with s = 0.5, after two none are left."""
    V, F = load_mesh("cube-meshed")
    feat = hybridsub.detect_features(V, F, 30)
    s = np.full(len(feat.sharp_edges), 1.5)
    for levels in (1, 2):
        out = tmp_path / f"s{levels}.obj"
        assert main(["subdivide", off("cube-meshed"), "-o", str(out), "--levels", str(levels),
                     "--feature-angle", "30", "--feature-sharpness", "1.5"]) == 0
        assert "features: 192 creases (192 semi-sharp), 0 corners — from dihedral angle > 30°, sharpness 1.5" in \
            capsys.readouterr().err
        ref = hybridsub.refine(F, feat.sharp_edges, levels, n_vertices=len(V), sharpness=s)
        m = read_mesh(out)
        assert np.array_equal(m.faces, ref.faces) and np.allclose(m.vertices, ref.apply(V), atol=1e-15, rtol=0)
        assert np.array_equal(m.sharp_edges, ref.sharp_edges) and np.array_equal(m.sharpness, ref.sharpness)
        assert m.sharpness.tolist() == ([0.5] * 384 if levels == 1 else []) and len(m.corners) == 0
    # 10 or more is infinite: the same as no --feature-sharpness
    assert main(["subdivide", off("cube-meshed"), "-o", str(tmp_path / "i.obj"), "--levels", "1",
                 "--feature-angle", "30", "--feature-sharpness", "10", "-q"]) == 0
    ref = hybridsub.refine(F, feat.sharp_edges, 1, n_vertices=len(V), corners=feat.corners)
    assert np.array_equal(read_mesh(tmp_path / "i.obj").corners, ref.corners)


@pytest.mark.parametrize("args,needle", [
    (["--feature-sharpness", "2"], "--feature-sharpness sets the sharpness of detected creases: give "
                                   "--feature-angle too"),
    (["--scheme", "sqrt3", "--feature-sharpness", "2"], "--feature-sharpness needs --scheme hybrid or loop"),
    (["--sharp-edges", "E"], "e.txt: edge 0 = (0, 5) is not an edge of"),
    (["--sharp-edges", "N"], "n.txt: edge 1 = (0, 2) has sharpness -1; give 0 for no crease"),  # opposite corners of the octahedron
    (["--corners", "C"], "c.txt: vertex 99 does not exist"),
    (["--scheme", "sqrt3", "--feature-angle", "30"], "--feature-angle needs --scheme hybrid or loop"),
    (["--feature-angle", "200"], None),
    (["--feature-sharpness", "0"], None),
    (["--feature-sharpness", "x"], None),
])
def test_option_errors(tmp_path, capsys, args, needle):
    _write(tmp_path / "e.txt", "0 5\n")
    _write(tmp_path / "c.txt", "99\n")
    _write(tmp_path / "n.txt", "0 1 2\n0 2 -1\n")
    files = {"E": "e.txt", "C": "c.txt", "N": "n.txt"}
    args = [str(tmp_path / files[a]) if a in files else a for a in args]
    if needle is None:  # argparse: exit code 2
        with pytest.raises(SystemExit) as e:
            main(["subdivide", off("octahedron"), "-o", str(tmp_path / "x.obj"), *args])
        expected = {"200": "must be between 0 and 180 degrees, got 200", "0": "must be greater than 0, got 0",
                    "x": "must be a number (inf: infinitely sharp), got 'x'"}[args[-1]]
        assert e.value.code == 2 and expected in capsys.readouterr().err
        return
    assert main(["subdivide", off("octahedron"), "-o", str(tmp_path / "x.obj"), *args]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("hybridsub: error: ") and needle in err[-1]


@pytest.mark.parametrize("ext", ["ply", "off", "stl", "glb"])
def test_output_formats(tmp_path, capsys, ext):
    out = tmp_path / f"o.{ext}"
    assert main(["subdivide", off("cube-meshed"), "-o", str(out), "--levels", "1", "--feature-angle", "30"]) == 0
    err = capsys.readouterr().err
    m = read_mesh(out)
    assert len(m.faces) == 5568
    if ext == "ply":
        assert len(m.sharp_edges) == 384 and "with its 384 creases, 8 corners" in err
    else:
        assert f".{ext} files cannot hold the 384 creases, 8 corners; write .obj or .ply" in err


def test_colors_are_refined(tmp_path, capsys):
    V, F = load_mesh("octahedron")
    colors = (V - V.min(0)) / np.ptp(V, 0)
    hybridsub.write_mesh(tmp_path / "c.ply", V, F, vertex_colors=colors)
    assert main(["subdivide", str(tmp_path / "c.ply"), "-o", str(tmp_path / "o.obj"), "--levels", "2", "-q"]) == 0
    m = read_mesh(tmp_path / "o.obj")
    c0 = read_mesh(tmp_path / "c.ply").vertex_colors
    assert np.allclose(m.vertex_colors[:, :3], hybridsub.refine(F, levels=2).apply(c0[:, :3]))
    assert capsys.readouterr().err == ""


def test_info(capsys):
    assert main(["info", off("elephant-with-holes"), "--feature-angle", "40", "--levels", "3"]) == 0
    out = capsys.readouterr().out
    assert "2,798 vertices, 4,463 triangles, 7,371 edges" in out
    assert "106 loops, 1,353 edges" in out and "Euler characteristic -110, genus 3" in out
    assert "edge-manifold, consistently oriented" in out
    assert "valence       2:" in out
    V, F = load_mesh("elephant-with-holes")
    feat = hybridsub.detect_features(V, F, 40)
    r = hybridsub.refine(F, feat.sharp_edges, 3, n_vertices=len(V), corners=feat.corners)
    for k, st in enumerate(r.steps, 1):
        assert f"{k} {len(st.faces):>12,} {st.n_vertices:>12,}" in out
    assert main(["info", off("tetrahedron"), "--json", "--scheme", "loop", "--levels", "2"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert [p["faces"] for p in d["levels"]] == [16, 64] and d["report"]["genus"] == 0
    assert d["report"]["valence"] == {"3": 4}


def test_memory_guard(tmp_path, capsys, monkeypatch):
    from hybridsub._app import pipeline
    from hybridsub._app.pipeline import FileOptions

    monkeypatch.setattr(pipeline, "physical_memory", lambda: 50_000_000)
    assert main(["subdivide", off("cube-meshed"), "-o", str(tmp_path / "x.obj"), "--levels", "6"]) == 1
    err = capsys.readouterr().err
    assert "would need about" in err and "this machine has 50.0 MB" in err and "--force" in err
    # a batch task checks against its Dask worker's memory limit where that is smaller
    pred = [{"peak_bytes": 30_000_000, "faces": 1000}]
    with pytest.raises(pipeline.PipelineError, match="the Dask worker's memory limit is 20.0 MB"):
        pipeline.check_memory(FileOptions(force=False, memory_limit=20_000_000), pred, "3 levels")
    pipeline.check_memory(FileOptions(force=False, memory_limit=90_000_000), pred, "3 levels")  # RAM: 50 MB
    pipeline.check_memory(FileOptions(force=True, memory_limit=20_000_000), pred, "3 levels")


# ----------------------------------------------------------------------------------------------
# info's counts, the level-by-level run, the progress bar


def _tags(V, F, seed):
    rng = np.random.default_rng(seed)
    feat = hybridsub.detect_features(V, F, 30)
    E = feat.sharp_edges
    s = np.where(rng.random(len(E)) < 0.5, rng.uniform(0.2, 3.5, len(E)), np.inf)
    return E, s, rng.random(len(F)) < 0.1, feat.corners


@pytest.mark.parametrize("name", ["cube-meshed", "mesh_with_border", "elephant-with-holes", "tetrahedron"])
def test_predicted_counts_are_exact(name):
    V, F = load_mesh(name)
    E, s, sf, C = _tags(V, F, 0)
    for scheme, kw in [("sqrt3", {}), ("loop", dict(sharp_edges=E, sharpness=s)), ("hybrid", dict(sharp_edges=E)),
                       ("hybrid", dict(sharp_edges=E, sharpness=s, sharp_faces=sf)), ("hybrid", {})]:
        levels = 4 if len(F) < 2000 else 3
        pred = predict_levels(F, len(V), levels, scheme=scheme, **kw)
        r = hybridsub.refine(F, kw.get("sharp_edges"), levels, n_vertices=len(V), scheme=scheme,
                             sharpness=kw.get("sharpness"), sharp_faces=kw.get("sharp_faces"))
        assert [(p["faces"], p["vertices"]) for p in pred] == [(len(st.faces), st.n_vertices) for st in r.steps]
        for p, st in zip(pred, r.steps):
            assert st.matrix.nnz <= p["nnz"] <= 2.6 * st.matrix.nnz  # an upper bound, and not a loose one


@pytest.mark.parametrize("name", ["mesh_with_border", "cube-meshed"])
@pytest.mark.parametrize("scheme", ["sqrt3", "hybrid", "loop"])
def test_level_by_level_is_one_call(name, scheme):
    V, F = load_mesh(name)
    E, s, sf, C = _tags(V, F, 1)
    kw = {} if scheme == "sqrt3" else dict(sharp_edges=E, sharpness=s, sharp_faces=np.flatnonzero(sf), corners=C)
    for levels in (1, 2, 3):
        r = hybridsub.refine(F, kw.get("sharp_edges"), levels, n_vertices=len(V), scheme=scheme,
                             sharpness=kw.get("sharpness"), sharp_faces=kw.get("sharp_faces"),
                             corners=kw.get("corners"))
        calls = []
        res = refine_by_level(V, F, levels, scheme=scheme, on_level=lambda done, *_: calls.append(done), **kw)
        assert np.array_equal(res.faces, r.faces) and np.array_equal(res.face_parent, r.face_parent)
        assert np.array_equal(res.X, r.apply(V))  # the fast path and the matrices agree bit for bit
        assert np.array_equal(res.sharp_edges, r.sharp_edges) and np.array_equal(res.sharpness, r.sharpness)
        assert calls == list(range(1, levels + 1))  # one report per level, Kobbelt's parity kept in one pass


def test_progress_bar_text():
    import io

    buf = io.StringIO()
    bar = ProgressBar([100, 300, 900], "hybrid", enabled=True, stream=buf)
    bar.update(1, 3, 100, 0.5)
    bar.update(3, 3, 900, 0.001)
    bar.close()
    text = buf.getvalue()
    assert "level 1/3: 100 faces, 200 faces/s; next 300" in text
    assert "level 3/3: 900 faces, 900.0 k faces/s" in text and " 100%" in text and text.endswith("\n")
    quiet = io.StringIO()
    bar = ProgressBar([100], "hybrid", enabled=False, stream=quiet)
    bar.update(1, 1, 100, 1.0)
    bar.close()
    assert quiet.getvalue() == ""


def test_mesh_report_on_broken_meshes():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0, -1, 0], [5, 5, 5]], float)
    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])  # edge 0-1 in three faces; vertex 5 unused
    rep = mesh_report(V, F)
    assert rep["nonmanifold_edges"] == 1 and rep["nonmanifold_edge_examples"] == [[0, 1]]
    assert rep["unreferenced_vertices"] == 1 and rep["genus"] is None
    F2 = np.array([[0, 1, 2], [0, 1, 3]])  # both run 0→1
    rep = mesh_report(V, F2)
    assert rep["misoriented_edges"] == 1 and rep["misoriented_edge_examples"] == [[0, 1]]
    # a bow-tie: two triangles sharing only vertex 0
    V3 = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [-1, 0, 0], [-1, -1, 0]], float)
    rep = mesh_report(V3, np.array([[0, 1, 2], [0, 3, 4]]))
    assert rep["nonmanifold_vertices"] == 1 and rep["nonmanifold_vertex_examples"] == [0]
    assert rep["boundary_loops"] == 1 and rep["components"] == 2


# ----------------------------------------------------------------------------------------------
# the renderer


def test_renderer_hides_what_is_behind():
    from hybridsub._app.render import render, view_rotation

    # two squares facing the camera (+z); the second nearer, overlapping the first's upper right
    V = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0],
                  [0, -0.5, 0.5], [2, -0.5, 0.5], [2, 1.5, 0.5], [0, 1.5, 0.5]], float)
    F = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    # the far square's diagonal, drawn as a line: x = (X - 0.5) * 28.16 + 60, y = 40 - (Y - 0.25) * 28.16
    img = render(V, F, view_rotation(0, 0), 120, 80, outline=False, lines=np.array([[0, 2]]))
    assert img.shape == (80, 120, 3) and img.dtype == np.uint8
    assert (img[0, 0] == 255).all() and (img[40, 60] < 250).all()  # background; a lit face

    def red(y, x):
        patch = img[y - 1:y + 2, x - 1:x + 2].astype(int)
        return bool(((patch[..., 0] > 150) & (patch[..., 1] < 90)).any())

    assert red(61, 32)  # (-0.5, -0.5): only the far square is there, the line shows
    assert not red(33, 60)  # (0.5, 0.5): the near square covers the line
    swapped = V.copy()
    swapped[4:, 2] = -0.5  # put the second square behind: now the line shows there too
    img = render(swapped, F, view_rotation(0, 0), 120, 80, outline=False, lines=np.array([[0, 2]]))
    assert red(33, 60)


def test_renderer_draws_a_texture_from_face_varying_uvs():
    """A square facing the camera, two triangles with their own UV indices (a seam on the
    diagonal, the UVs continuous across it): a 2 × 2 checkerboard lands in the four quarters."""
    from hybridsub._app.render import render, view_rotation

    V = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float)
    F = np.array([[0, 1, 2], [0, 2, 3]])
    UV = np.array([[0, 0], [1, 0], [1, 1], [0, 0], [1, 1], [0, 1]], float)
    FUV = np.array([[0, 1, 2], [3, 4, 5]])

    def image(uv):
        odd = (np.floor(uv[:, 0] * 2) + np.floor(uv[:, 1] * 2)) % 2 == 1
        return np.where(odd[:, None], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])

    img = render(V, F, view_rotation(0, 0), 100, 100, outline=False, texture=(UV, FUV, image)).astype(int)
    blue = lambda y, x: img[y, x, 2] > 2 * img[y, x, 0]  # noqa: E731
    assert not blue(70, 30) and blue(70, 70) and blue(30, 30) and not blue(30, 70)  # (u, v) = image (x, up)
    assert (img[2, 2] == 255).all()


# ----------------------------------------------------------------------------------------------
# textured OBJ: vt and f v/vt, seams refined face-varying

def _textured_bunny(tmp_path):
    d = np.load(os.path.join(DATA, "bunny10k_textured.fvar_linear.L1.npz"))
    V, F, UV, FUV = d["V_in"], d["F_in"], d["UV_in"], d["FUV_in"]
    path = tmp_path / "bunny.obj"
    hybridsub.write_mesh(path, V, F, uv=UV, face_uv=FUV)
    return str(path), V, F, UV, FUV


@pytest.mark.slow  # subprocesses / a cluster / figures: ~4-11 s; .ci/run runs the slow tests
def test_textured_obj_round_trips(tmp_path, capsys):
    """vt and f v/vt in, seams refined face-varying, vt and f v/vt out: what
    subdivide_face_varying gives, to the bit (OBJ floats are written as repr)."""
    path, V, F, UV, FUV = _textured_bunny(tmp_path)
    out = tmp_path / "b2.obj"
    r = run("subdivide", path, "-o", out, "--levels", 2)
    assert r.returncode == 0, r.stderr
    assert "dropped" not in r.stderr
    m = read_mesh(out)
    V2, F2, UV2, FUV2 = hybridsub.subdivide_face_varying(V, F, UV, FUV, levels=2)
    assert np.array_equal(m.vertices, V2) and np.array_equal(m.faces, F2)
    assert np.array_equal(m.uv, UV2) and np.array_equal(m.face_uv, FUV2)
    # smooth UVs with Loop; one level, then one more from the written file, is two levels
    for k, target in ((1, "s1.obj"), (2, "s2.obj")):
        assert main(["subdivide", path, "-o", str(tmp_path / target), "--levels", str(k), "--scheme", "loop",
                     "--uv-mode", "smooth", "-q"]) == 0
    assert main(["subdivide", str(tmp_path / "s1.obj"), "-o", str(tmp_path / "s11.obj"), "--levels", "1",
                 "--scheme", "loop", "--uv-mode", "smooth", "-q"]) == 0
    V2, F2, UV2, FUV2 = hybridsub.subdivide_face_varying(V, F, UV, FUV, levels=2, scheme="loop", uv_mode="smooth")
    for name in ("s2.obj", "s11.obj"):
        m = read_mesh(tmp_path / name)
        assert np.array_equal(m.faces, F2) and np.array_equal(m.face_uv, FUV2), name
        assert np.allclose(m.vertices, V2, atol=1e-13, rtol=0) and np.allclose(m.uv, UV2, atol=1e-13, rtol=0)
    assert np.array_equal(read_mesh(tmp_path / "s2.obj").uv, UV2)  # one run: to the bit
    assert capsys.readouterr().err == ""
    for mode in ("corners_plus1", "boundaries"):
        assert main(["subdivide", path, "-o", str(tmp_path / f"{mode}.obj"), "--levels", "2", "--scheme", "loop",
                     "--uv-interpolation", mode, "-q"]) == 0
        _, _, UV2, FUV2 = hybridsub.subdivide_face_varying(V, F, UV, FUV, levels=2, scheme="loop",
                                                           uv_interpolation=mode)
        m = read_mesh(tmp_path / f"{mode}.obj")
        assert np.array_equal(m.uv, UV2) and np.array_equal(m.face_uv, FUV2), mode


def test_textured_obj_with_sqrt3_and_other_formats(tmp_path, capsys):
    path, V, F, UV, FUV = _textured_bunny(tmp_path)
    assert main(["subdivide", path, "-o", str(tmp_path / "k.obj"), "--levels", "1", "--scheme", "sqrt3"]) == 0
    err = capsys.readouterr().err
    assert "note: texture coordinates dropped: Kobbelt's √3 cannot keep UV seams (use --scheme hybrid" in err
    m = read_mesh(tmp_path / "k.obj")
    assert m.uv is None and len(m.faces) == 3 * len(F)
    assert main(["subdivide", path, "-o", str(tmp_path / "k.obj"), "--scheme", "sqrt3", "--uv-mode", "smooth"]) == 1
    assert "--uv-mode needs --scheme hybrid or loop" in capsys.readouterr().err
    # PLY keeps the seams as per-face texcoords (float32)
    assert main(["subdivide", path, "-o", str(tmp_path / "b.ply"), "--levels", "1", "-q"]) == 0
    m = read_mesh(tmp_path / "b.ply")
    V1, F1, UV1, FUV1 = hybridsub.subdivide_face_varying(V, F, UV, FUV, levels=1)
    assert np.array_equal(m.faces, F1) and np.allclose(m.uv[m.face_uv], UV1[FUV1], atol=1e-6, rtol=0)


def test_textured_counts_are_predicted():
    """The counts info and the progress bar use include the split seams: exact with UVs, and
    without them (compare) the plain refinement's."""
    from hybridsub._app.pipeline import FileFeatures as Features, predict_file_levels as _predict

    d = np.load(os.path.join(DATA, "bunny10k_textured.fvar_linear.L1.npz"))
    m = hybridsub.TaggedMesh(d["V_in"], d["F_in"], uv=d["UV_in"], face_uv=d["FUV_in"])
    none = Features(np.empty((0, 2), np.int64), np.empty(0), np.empty(0, np.int64), np.empty(0, np.int64), "")
    for scheme in ("hybrid", "loop"):
        r = hybridsub.refine(d["F_in"], levels=3, scheme=scheme, uv_faces=d["FUV_in"])
        pred = _predict(m, 3, scheme, none)
        assert [(p["faces"], p["vertices"]) for p in pred] == [(len(s.faces), s.n_vertices) for s in r.steps]
    plain = _predict(m, 3, "hybrid", none, uv=False)
    r = hybridsub.refine(d["F_in"], levels=3)
    assert [(p["faces"], p["vertices"]) for p in plain] == [(len(s.faces), s.n_vertices) for s in r.steps]
    assert plain[-1]["faces"] < _predict(m, 3, "hybrid", none)[-1]["faces"]
