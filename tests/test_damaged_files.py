"""Damaged mesh files: every reader's failure is one MeshError naming the file and what is
wrong, and whatever a reader lets through passes the one check of its output (indices in range,
counts as declared, finite numbers) — never another exception, never meshio's SystemExit.

The cases of issue 31 one by one, then a seeded fuzz over the shipped small meshes written in
every format and mutated (byte flips, truncation, numbers replaced by huge counts, NaN, inf,
negative indices): a few seconds in the default run, ``HYBRIDSUB_FILE_FUZZ=N`` mutations per
format under ``-m slow``.
"""

import os
import random
import re
import struct
import subprocess
import sys
import warnings
import zipfile

import meshio
import numpy as np
import pytest

import hybridsub
from hybridsub import MeshError
from hybridsub._io import TaggedMesh, read_off, write

DATA = os.path.join(os.path.dirname(__file__), "data")


def _expect(path, *words):
    """read_mesh(path) raises one MeshError naming the file and each of ``words``."""
    with pytest.raises(MeshError) as e:
        hybridsub.read_mesh(path)
    msg = str(e.value)
    assert str(path) in msg, msg
    for w in words:
        assert w in msg, msg
    return msg


def _plain(tmp_path, ext, binary=False):
    V, F = read_off(os.path.join(DATA, "octahedron.off"))
    path = tmp_path / f"plain.{ext}"
    meshio.Mesh(V, [("triangle", F)]).write(path, binary=binary)
    return path


# ----------------------------------------------------------------------------------------------
# meshio: SystemExit, indices as the file has them, cells it drops


def test_damaged_vtk_and_vtu_are_mesh_errors_not_system_exit(tmp_path, capfd):
    for ext in ("vtk", "vtu"):
        path = _plain(tmp_path, ext)
        text = path.read_text()
        path.write_text(text[:len(text) // 3] + "garbage 12 x\n")
        _expect(path, "meshio cannot read it")
    # meshio's own printing (its reason, its "Couldn't read file") is in the error, not on the terminal
    out, err = capfd.readouterr()
    assert "Couldn't read" not in out + err


@pytest.mark.parametrize("index", ["999999999999", "-1"])
def test_vtk_face_index_out_of_range_names_the_cell(tmp_path, index):
    path = _plain(tmp_path, "vtk")
    text = path.read_text()
    head, tail = text.split("CONNECTIVITY vtktypeint64\n")
    rows = tail.split("\n")
    rows[4] = index  # cell 1's second point
    path.write_text(head + "CONNECTIVITY vtktypeint64\n" + "\n".join(rows))
    _expect(path, "triangle cell 1", f"point {index}", "only 6")


def test_vtu_face_index_out_of_range_names_the_cell(tmp_path):
    path = _plain(tmp_path, "vtu")
    text = path.read_text()
    j = text.index('Name="connectivity"')
    k = text.index(">", j) + 1
    body = text[k:text.index("<", k)]
    values = body.split()
    values[7] = "999999999999"
    path.write_text(text[:k] + "\n" + "\n".join(values) + "\n" + text[k + len(body):])
    _expect(path, "triangle cell 2", "point 999999999999")


def test_cells_of_unknown_type_are_refused_not_dropped(tmp_path):
    path = _plain(tmp_path, "vtk")
    text = path.read_text()
    i = text.index("CELL_TYPES")
    rows = text[i:].split("\n")
    rows[2], rows[4] = "99", "98"
    path.write_text(text[:i] + "\n".join(rows))
    _expect(path, "2 cells", "98, 99")
    path = _plain(tmp_path, "vtu")
    text = path.read_text()
    k = text.index(">", text.index('Name="types"')) + 1
    body = text[k:text.index("<", k)]
    path.write_text(text[:k] + body.replace("5", "99", 3) + text[k + len(body):])
    _expect(path, "3 cells", "type 99")


def test_batch_worker_reports_the_mesh_error(tmp_path):
    """A damaged VTK in a batch: the task's record names the file and meshio's reason (the
    worker lived: no SystemExit, no 'out of memory')."""
    from hybridsub._app import batch as _batch, task as _task
    from hybridsub._app.manifest import TMPDIR

    src = _plain(tmp_path, "vtk")
    src.write_text(src.read_text()[:200])
    os.makedirs(tmp_path / TMPDIR)
    job = {"input": str(src), "output": "out/t.obj", "output_path": str(tmp_path / "out" / "t.obj"),
           "tmpdir": str(tmp_path / TMPDIR), "options": _batch.batch_options(1, "hybrid", None, None, "loop", "obj",
                                                                             False, False, False, None),
           "options_key": "k", "hybridsub": hybridsub.__version__, "force": False, "reason": "new", "verify": None}
    rec = _task.run_task(job)
    assert rec["status"] == "failed" and "meshio cannot read it" in rec["error"] and str(src) in rec["error"]
    assert "memory" not in rec["error"] and "traceback" not in rec


def test_worker_survives_a_library_calling_exit(tmp_path, monkeypatch):
    from hybridsub._app import batch as _batch, task as _task
    from hybridsub._app.manifest import TMPDIR

    src = tmp_path / "t.off"
    src.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    os.makedirs(tmp_path / TMPDIR)
    job = {"input": str(src), "output": "out/t.obj", "output_path": str(tmp_path / "out" / "t.obj"),
           "tmpdir": str(tmp_path / TMPDIR), "options": _batch.batch_options(1, "hybrid", None, None, "loop", "obj",
                                                                             False, False, False, None),
           "options_key": "k", "hybridsub": hybridsub.__version__, "force": False, "reason": "new", "verify": None}

    def exits(*a, **k):
        sys.exit(1)

    monkeypatch.setattr(_task, "subdivide_file", exits)
    rec = _task.run_task(job)
    assert rec["status"] == "failed" and "SystemExit" in rec["error"]


# ----------------------------------------------------------------------------------------------
# PLY


_PLY = "ply\nformat ascii 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\nproperty float z\n" \
       "element face {nf}\nproperty list uchar int vertex_indices\nend_header\n"
_ROWS = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"


def test_ascii_ply_value_not_a_number_names_the_file(tmp_path):
    path = tmp_path / "t.ply"
    path.write_text(_PLY.format(nv=3, nf=1) + "0 0 0\n1 0$1 0\n0 1 0\n3 0 1 2\n")
    _expect(path, "element 'vertex'", "not a number")
    path.write_text(_PLY.format(nv=3, nf=1) + "0 0 0\n1 0 0\n0 1 0\n3 0 x 2\n")
    _expect(path, "element 'face' row 0", "not a number")


def test_ascii_ply_short_row_and_odd_list_counts(tmp_path):
    path = tmp_path / "t.ply"
    path.write_text(_PLY.format(nv=3, nf=2) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0\n")  # ply.py's IndexError
    _expect(path, "element 'face' row 1", "a list of 3 values")
    for count in ("inf", "nan", "-2", "2.5", "1e30"):
        path.write_text(_PLY.format(nv=3, nf=1) + f"0 0 0\n1 0 0\n0 1 0\n{count} 0 1 2\n")
        _expect(path, "element 'face' row 0")
    path.write_text(_PLY.format(nv=3, nf=1) + "0 0 0\n1 0 0\n0 1 0\n3 0 nan 2\n")
    _expect(path, "vertex_indices is nan")


@pytest.mark.parametrize("count", ["99999999999999999999999", "inf", "-3", "1e30"])
def test_ply_huge_or_odd_element_counts(tmp_path, count):
    for binary in (False, True):
        path = tmp_path / f"t{binary}.ply"
        write(str(path), TaggedMesh(np.eye(3), np.array([[0, 1, 2]])), binary=binary)
        raw = path.read_bytes()
        path.write_bytes(raw.replace(b"element face 1", b"element face " + count.encode(), 1))
        _expect(path)


# ----------------------------------------------------------------------------------------------
# NPZ


def _npy(header: str, data: bytes = b"") -> bytes:
    h = header.encode("latin1")
    h += b" " * (63 - (10 + len(h)) % 64) + b"\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(h)) + h + data


def _npz(path, vertices_header, faces=np.array([[0, 1, 2]], np.int64)):
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("vertices.npy", _npy(vertices_header, np.eye(3).tobytes()))
        z.writestr("faces.npy", _npy(f"{{'descr': '<i8', 'fortran_order': False, 'shape': {faces.shape}, }}",
                                     faces.tobytes()))


def test_npz_damaged_header_and_huge_shape(tmp_path, capsys):
    path = tmp_path / "tok.npz"
    _npz(path, "{'descr': '<f8', 'fortran_order': False, 'shape': ((3, 3), }")  # numpy: tokenize.TokenError
    _expect(path, "'vertices'", "cannot be read")
    path = tmp_path / "huge.npz"
    _npz(path, "{'descr': '<f8', 'fortran_order': False, 'shape': (999999999999999, 3), }")  # numpy: 21 PiB
    _expect(path, "'vertices'", "(999999999999999, 3)", "200 bytes")
    # the command line says what is wrong with the file, not "out of memory; use fewer levels"
    from hybridsub._app.cli import main

    assert main(["info", str(path)]) == 1
    err = capsys.readouterr().err
    assert "memory" not in err and "999999999999999" in err


def test_npz_sharpness_without_sharp_edges_names_the_file(tmp_path):
    path = tmp_path / "t.npz"
    np.savez(path, vertices=np.eye(3), faces=[[0, 1, 2]], sharpness=[2.0])
    _expect(path, "sharpness")


# ----------------------------------------------------------------------------------------------
# the one check of every reader's output


def test_check_read_refuses_what_a_reader_might_let_through():
    from hybridsub._io.mesh import check_read

    V, F = np.eye(3), np.array([[0, 1, 2]])
    bad = [
        (TaggedMesh(V, np.array([[0, 1, -1]])), "face 0 refers to vertex -1"),
        (TaggedMesh(V, F, sharp_edges=np.array([[0, 7]]), sharpness=np.array([np.inf])), "crease 0 refers to vertex 7"),
        (TaggedMesh(V, F, sharp_edges=np.array([[0, 1]]), sharpness=np.array([np.nan])), "sharpness nan"),
        (TaggedMesh(V, F, sharp_edges=np.array([[0, 1]]), sharpness=np.empty(0)), "0 sharpness values"),
        (TaggedMesh(V, F, corners=np.array([3])), "corner 0 refers to vertex 3"),
        (TaggedMesh(V, F, sharp_faces=np.array([1])), "sharp face 0 refers to face 1"),
        (TaggedMesh(V, F, vertex_colors=np.ones((2, 3))), "vertex colours"),
        (TaggedMesh(V, F, uv=np.zeros((3, 2)), face_uv=np.array([[0, 1, 5]])), "refers to UV 5"),
        (TaggedMesh(V, F, uv=np.full((3, 2), np.inf), face_uv=F), "texture coordinate 0 is not finite"),
        (TaggedMesh(V, F.astype(float)), "not triangles of vertex indices"),
    ]
    for mesh, words in bad:
        with pytest.raises(MeshError, match=re.escape(words)):
            check_read("t.vtk", mesh)


# ----------------------------------------------------------------------------------------------
# fuzz: mutated files in every format


def _bases(folder) -> dict[str, bytes]:
    """The small shipped meshes, with tags, written in every format hybridsub reads (two of PLY and
    VTK: ASCII and binary): name -> bytes."""
    out = {}
    for mesh_name in ("tetrahedron", "octahedron"):
        V, F = read_off(os.path.join(DATA, f"{mesh_name}.off"))
        m = TaggedMesh(V, F, sharp_edges=np.array([[F[0, 0], F[0, 1]], [F[0, 1], F[0, 2]]]),
                       sharpness=np.array([np.inf, 2.0]), corners=np.array([F[1, 2]]), sharp_faces=np.array([1]),
                       uv=V[:, :2].copy(), face_uv=F.copy())
        for name, binary in (("obj", True), ("ply", False), ("bin.ply", True), ("off", True), ("stl", True),
                             ("vtk", True), ("vtu", True), ("npz", True)):
            path = os.path.join(folder, f"{mesh_name}.{name}")
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                write(path, m, binary=binary)
            out[f"{mesh_name}.{name}"] = open(path, "rb").read()
        path = os.path.join(folder, f"{mesh_name}.ascii.vtk")
        meshio.Mesh(V, [("triangle", F), ("line", m.sharp_edges)],
                    cell_data={"sharpness": [np.zeros(len(F)), np.array([10.0, 2.0])]}).write(path, binary=False)
        out[f"{mesh_name}.ascii.vtk"] = open(path, "rb").read()
    return out


_NUMBER = re.compile(rb"-?\d+(\.\d+)?(e[-+]?\d+)?")
_ODD = [b"999999999999", b"-1", b"-5", b"nan", b"inf", b"-inf", b"1e308", b"1e400", b"0", b"3.5",
        b"99999999999999999999999", b"2147483648", b"18446744073709551616", b""]


def _mutate(raw: bytes, rng: random.Random) -> bytes:
    b = bytearray(raw)
    kind = rng.randrange(5)
    if kind == 0:  # flipped bits
        for _ in range(rng.randint(1, 6)):
            i = rng.randrange(len(b))
            b[i] ^= 1 << rng.randrange(8)
    elif kind == 1:  # cut short
        del b[rng.randrange(len(b)):]
    elif kind == 2:  # a run of bytes overwritten or duplicated
        i = rng.randrange(len(b))
        j = min(len(b), i + rng.randint(1, 64))
        b[i:j] = bytes(rng.randrange(256) for _ in range(j - i)) if rng.random() < 0.5 else b[i:j] * 2
    else:  # a number (a count, an index, a coordinate) replaced by an odd one
        found = list(_NUMBER.finditer(bytes(b)))
        for _ in range(rng.randint(1, 2)):
            if found:
                m = rng.choice(found)
                b[m.start():m.end()] = rng.choice(_ODD)
                found = list(_NUMBER.finditer(bytes(b)))
    return bytes(b)


def _valid(m: TaggedMesh) -> None:
    """What a mesh read from any file satisfies: checked here independently of the reader's check."""
    n, nf = len(m.vertices), len(m.faces)
    assert m.vertices.shape == (n, 3) and np.isfinite(m.vertices).all() and nf > 0
    assert m.faces.shape == (nf, 3) and m.faces.dtype.kind in "iu" and 0 <= m.faces.min() and m.faces.max() < n
    assert m.sharp_edges.shape == (len(m.sharpness), 2)
    if len(m.sharp_edges):
        assert 0 <= m.sharp_edges.min() and m.sharp_edges.max() < n and (m.sharpness > 0).all()
    assert all(0 <= c < n for c in m.corners) and all(0 <= f < nf for f in m.sharp_faces)
    if m.uv is not None:
        assert np.isfinite(m.uv).all() and m.face_uv.shape == m.faces.shape
        assert 0 <= m.face_uv.min() and m.face_uv.max() < len(m.uv)
    if m.vertex_colors is not None:
        assert m.vertex_colors.shape[0] == n and np.isfinite(m.vertex_colors).all()


def _fuzz(tmp_path, per_format: int, seed: int) -> dict:
    rng = random.Random(seed)
    bases = _bases(str(tmp_path))
    outcomes = {"error": 0, "mesh": 0}
    for name, raw in sorted(bases.items()):
        ext = name.split(".", 1)[1].rsplit(".", 1)[-1]
        for t in range(per_format):
            path = tmp_path / f"m{t}.{ext}"
            path.write_bytes(_mutate(raw, rng))
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    m = hybridsub.read_mesh(path)
            except MeshError as e:
                assert str(path) in str(e)
                outcomes["error"] += 1
            except BaseException as e:  # noqa: B036 - SystemExit and KeyboardInterrupt-likes included
                raise AssertionError(f"{name} mutation {t} (seed {seed}): {type(e).__name__}: {e}") from e
            else:
                _valid(m)
                outcomes["mesh"] += 1
    return outcomes


def test_fuzzed_files_give_mesh_errors_or_valid_meshes(tmp_path, capfd):
    out = _fuzz(tmp_path, 25, seed=0)
    assert out["error"] > 100 and out["mesh"] > 10  # the mutations reach both outcomes
    assert "Couldn't read" not in "".join(capfd.readouterr())


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_fuzzed_files_long(tmp_path, seed):
    _fuzz(tmp_path, int(os.environ.get("HYBRIDSUB_FILE_FUZZ", "400")), seed)


def test_tags_written_to_a_format_that_loses_them_are_reported(tmp_path):
    """Medit's .mesh takes line cells but not their sharpness: written as triangles, and the tags
    reported dropped (a UserWarning), where VTK and VTU keep them."""
    V, F = read_off(os.path.join(DATA, "octahedron.off"))
    kw = dict(sharp_edges=[[0, 1]], corners=[3], sharp_faces=[2])
    with pytest.warns(UserWarning, match="cannot hold 1 crease, 1 corner, 1 sharp face"):
        hybridsub.write_mesh(tmp_path / "t.mesh", V, F, **kw)
    assert len(hybridsub.read_mesh(tmp_path / "t.mesh").faces) == len(F)
    for ext in ("vtk", "vtu"):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            hybridsub.write_mesh(tmp_path / f"t.{ext}", V, F, **kw)
        m = hybridsub.read_mesh(tmp_path / f"t.{ext}")
        assert m.sharp_edges.tolist() == [[0, 1]] and m.corners.tolist() == [3] and m.sharp_faces.tolist() == [2]
