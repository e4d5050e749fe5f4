"""No rough edges (issue 16): every broken file is one line `hybridsub: error: …`, exit 1, no
output file; writes are atomic; one defaults policy; summaries instead of arrays; a fast
start-up; the documentation site lists the whole API."""

import errno
import inspect
import os
import subprocess
import sys
import tomllib

import numpy as np
import pytest

import hybridsub
from conftest import DATA, load_mesh
from hybridsub import MeshError
from hybridsub._app import cli
from hybridsub._app.cli import main
from hybridsub._app.pipeline import FileOptions
from hybridsub._io import TaggedMesh, describe_tags, formats, read_mesh, write

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BROKEN = os.path.join(DATA, "broken")

# file in tests/data/broken -> what its one-line error says
BROKEN_FILES = {
    "nan.obj": "vertex 1 has a non-finite coordinate (nan)",
    "inf.off": "vertex 1 has a non-finite coordinate (inf)",
    "nan.ply": "vertex 1 has a non-finite coordinate (nan)",
    "two_coords.off": "the vertices have 2 coordinates; a vertex needs three (x y z)",
    "huge_index.obj": "face 1 holds a vertex index too large for any mesh (23 digits)",
    "huge_index.off": "face 1 holds a vertex index too large for any mesh (23 digits)",
    "zero_index.obj": "line 4: cannot read face 'f 0 1 2': OBJ indices count from 1",
    "index_past_end.obj": "face 0 refers to vertex 4, but there are only 3 (valid 1..3)",
    "negative_past_start.obj": "OBJ index -4 counts back past the first vertex (3 read so far)",
    "two_vertex_face.obj": "face 1 has only 2 vertices (1 such): a face needs at least three",
    "two_vertex_face.off": "face 1 has only 2 vertices (1 such): a face needs at least three",
    "truncated.stl": "not a triangle mesh",
    "garbage.stl": "",
    "not_utf8.stl": "",
}


def one_line_error(capsys, argv, out=None) -> str:
    assert main(argv) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) >= 1 and err[-1].startswith("hybridsub: error: "), err
    assert "Traceback" not in "\n".join(err)
    if out is not None:
        assert not os.path.exists(out)
        assert [f for f in os.listdir(os.path.dirname(out)) if "partial" in f] == []
    return err[-1]


@pytest.mark.parametrize("name", sorted(BROKEN_FILES))
def test_broken_files_fail_in_one_line_without_output(name, tmp_path, capsys):
    assert sorted(os.listdir(BROKEN)) == sorted(BROKEN_FILES)  # every broken file is tested
    path = os.path.join(BROKEN, name)
    out = str(tmp_path / "out.obj")
    msg = one_line_error(capsys, ["subdivide", path, "-o", out, "-q"], out)
    assert msg.startswith(f"hybridsub: error: {path}: ") and BROKEN_FILES[name] in msg
    assert one_line_error(capsys, ["info", path]) == msg  # info refuses what it cannot read alike
    with pytest.raises(MeshError):
        read_mesh(path)


def test_stl_without_charset_normalizer(monkeypatch):
    """trimesh guesses the encoding of a damaged text STL with an optional module: its absence
    is the file's problem, said in one line, not a ModuleNotFoundError."""
    monkeypatch.setitem(sys.modules, "charset_normalizer", None)
    with pytest.raises(MeshError, match="not_utf8.stl: cannot read it as STL: the file is damaged or not STL"):
        read_mesh(os.path.join(BROKEN, "not_utf8.stl"))


# ----------------------------------------------------------------------------------------------
# atomic writes


def test_failed_write_leaves_nothing_and_keeps_the_old_file(tmp_path, monkeypatch, capsys):
    V, F = load_mesh("tetrahedron")
    mesh = TaggedMesh(V, F)
    out = tmp_path / "t.obj"
    write(str(out), mesh)
    before = out.read_bytes()

    def disk_full(path, m, folder=None):
        with open(path, "w") as fh:
            fh.write("v 0 0 0\n")  # a partial file, then the disk is full
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), path)

    monkeypatch.setattr(formats, "write_obj", disk_full)
    with pytest.raises(OSError) as e:
        write(str(out), TaggedMesh(V * 2, F))
    assert e.value.filename == str(out) and e.value.errno == errno.ENOSPC  # named as the caller named it
    assert out.read_bytes() == before and os.listdir(tmp_path) == ["t.obj"]
    msg = one_line_error(capsys, ["subdivide", os.path.join(DATA, "tetrahedron.off"), "-o", str(tmp_path / "n.obj"),
                                  "-q"], str(tmp_path / "n.obj"))
    assert msg == f"hybridsub: error: {tmp_path / 'n.obj'}: No space left on device"


def test_unwritable_format_leaves_no_file(tmp_path, capsys):
    out = str(tmp_path / "x.xyz")
    msg = one_line_error(capsys, ["subdivide", os.path.join(DATA, "tetrahedron.off"), "-o", out, "-q"], out)
    assert f"{out}: cannot write a mesh in this format (trimesh could not write it" in msg and ".partial" not in msg
    assert os.listdir(tmp_path) == []


def test_written_file_has_ordinary_permissions(tmp_path):
    V, F = load_mesh("tetrahedron")
    write(str(tmp_path / "t.ply"), TaggedMesh(V, F))
    mask = os.umask(0)
    os.umask(mask)
    assert os.stat(tmp_path / "t.ply").st_mode & 0o777 == 0o666 & ~mask


# ----------------------------------------------------------------------------------------------
# the Python API


def test_levels_given_where_sharp_edges_go():
    V, F = load_mesh("tetrahedron")
    with pytest.raises(TypeError, match=r"got the number 2: .* levels comes after it — pass levels=2 by keyword"):
        hybridsub.subdivide(V, F, 2)
    with pytest.raises(TypeError, match="pass levels=1 by keyword"):
        hybridsub.refine(F, 1)


def test_feature_angle_with_cut_on_an_inconsistently_oriented_mesh():
    """Features are detected on the cut mesh: an octahedron with one face flipped, every
    dihedral angle 109.5°, is all creases and corners, as if they were given."""
    V, F = load_mesh("octahedron")
    F = F.copy()
    F[0] = F[0, ::-1]
    with pytest.raises(MeshError, match="not consistently oriented"):
        hybridsub.subdivide(V, F, levels=1, feature_angle=30)
    V2, F2 = hybridsub.subdivide(V, F, levels=1, feature_angle=30, non_manifold="cut")
    edges = np.unique(np.sort(np.vstack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1), axis=0)
    V3, F3 = hybridsub.subdivide(V, F, edges, levels=1, corners=np.arange(len(V)), non_manifold="cut")
    assert np.array_equal(F2, F3) and np.array_equal(V2, V3)
    V4, F4 = hybridsub.subdivide(V, F, levels=1, non_manifold="cut")  # without features: smooth, fewer faces
    assert len(F4) < len(F2)


def test_load_example_names_the_examples():
    with pytest.raises(ValueError, match="no example mesh named 'x'; the examples are: 'cube', 'fandisk', 'icosahedron'"):
        hybridsub.load_example("x")


def test_reprs_are_summaries():
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, 30)
    r = hybridsub.refine(F, feat.sharp_edges, levels=2, corners=feat.corners)
    assert repr(feat) == "Features(722 sharp edges, 0 boundary edges, 23 corners)"
    assert repr(r) == ("<Refinement: 2 levels from 6,475 vertices: 123,734 faces, 61,869 vertices; 2,888 creases, "
                       "23 corners>")
    assert repr(r.steps[0]).startswith("<RefinementStep: from 6,475 vertices: 40,282 faces, 20,143 vertices")
    m = TaggedMesh(V, F, corners=np.array([3]))
    assert repr(m) == "<TaggedMesh: 6,475 vertices, 12,946 triangles; 0 creases, 1 corner>"
    fv = hybridsub.refine_face_varying(F, F, levels=1)
    assert len(repr(fv)) < 400 and "array" not in repr(fv)


def test_counts_in_words(tmp_path):
    m = TaggedMesh(np.eye(3), np.array([[0, 1, 2]]), sharp_edges=np.array([[0, 1]]), corners=np.array([2]))
    assert describe_tags(m) == "1 crease, 1 corner"
    quad = tmp_path / "q.off"
    quad.write_text("OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")
    assert read_mesh(quad, triangulate=True).notes == ("triangulated 1 polygon into 2 triangles",)


# ----------------------------------------------------------------------------------------------
# one defaults policy


def test_one_level_by_default_everywhere():
    parser = cli.build_parser()
    commands = parser._subparsers._group_actions[0].choices
    for name, sub in commands.items():
        levels = [a for a in sub._actions if a.dest == "levels"]
        if levels and name == "fit":  # fit's surface is the limit surface unless a level is given, as in Python
            assert levels[0].default is None and inspect.signature(hybridsub.fit).parameters["levels"].default is None
        elif levels and not levels[0].required:  # (decompose must be told the fine mesh's level)
            assert levels[0].default == 1, name
    for f in (hybridsub.subdivide, hybridsub.refine, hybridsub.subdivide_mesh, hybridsub.batch,
              hybridsub.subdivide_face_varying):
        assert inspect.signature(f).parameters["levels"].default == 1, f.__name__
    assert FileOptions().levels == 1


def test_compare_detects_no_creases_unasked(tmp_path, capsys, monkeypatch):
    """compare uses the features subdivide would (none here), and says how to ask for them."""
    from hybridsub._app import figure

    seen = {}

    def panels(V, F, levels, **tags):
        seen.update(tags)
        raise MeshError("stop here")

    monkeypatch.setattr(figure, "compare_panels", panels)
    assert main(["compare", os.path.join(DATA, "cube-meshed.off"), "-o", str(tmp_path / "c.png")]) == 1
    assert len(seen["sharp_edges"]) == 0 and len(seen["corners"]) == 0
    assert "--feature-angle 30 would detect creases" in capsys.readouterr().err


def test_loop_outputs_carry_no_sharp_faces(tmp_path):
    src = os.path.join(DATA, "tetrahedron.off")
    assert main(["subdivide", src, "-o", str(tmp_path / "l.obj"), "--scheme", "loop", "-q"]) == 0
    assert "sharpface" not in (tmp_path / "l.obj").read_text()
    (tmp_path / "sf.txt").write_text("0\n")
    assert main(["subdivide", src, "-o", str(tmp_path / "h.ply"), "--sharp-faces", str(tmp_path / "sf.txt"), "-q"]) == 0
    assert len(read_mesh(tmp_path / "h.ply").sharp_faces) == 4  # hybrid: the sharp face's four children


# ----------------------------------------------------------------------------------------------
# start-up and the documentation site


def _modules_after(code: str) -> set:
    out = subprocess.run([sys.executable, "-c", code + "\nimport sys; print(' '.join(sorted(sys.modules)))"],
                         cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return set(out.stdout.split())


def test_help_loads_nothing_heavy():
    mods = _modules_after("import contextlib, io\nfrom hybridsub.__main__ import main\n"
                          "with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):\n"
                          "    main(['--help'])")
    assert not {"numpy", "scipy", "numba", "trimesh"} & mods


def test_a_small_run_loads_only_what_it_needs(tmp_path):
    out = tmp_path / "t.obj"
    mods = _modules_after(f"from hybridsub._app.cli import main\n"
                          f"assert main(['subdivide', {os.path.join(DATA, 'tetrahedron.off')!r}, '-o', {str(out)!r}, "
                          "'-q']) == 0")
    assert not {"trimesh", "matplotlib", "dask", "scipy.sparse.csgraph"} & mods
    assert out.exists()


def test_docs_site_lists_the_api_and_is_linked():
    api = open(os.path.join(ROOT, "docs", "api.rst")).read()
    for name in hybridsub.__all__:
        assert f"hybridsub.{name}" in api, name
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as fh:
        project = tomllib.load(fh)["project"]
    assert project["urls"]["Documentation"] == cli.DOCS_URL
    assert cli.DOCS_URL in cli.build_parser().format_help()
    assert {"sphinx", "numpydoc", "myst-parser"} <= {d.split(">")[0] for d in project["optional-dependencies"]["docs"]}
    guide = open(os.path.join(ROOT, "docs", "index.md")).read()
    pages = {p[:-3] for p in os.listdir(os.path.join(ROOT, "docs")) if p.endswith(".md") and p != "index.md"}
    assert all(f"\n{p}\n" in guide for p in pages)  # every page is in the guide's table of contents
