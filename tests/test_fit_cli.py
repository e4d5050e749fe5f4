"""`hybridsub fit` and `hybridsub decompose` on files."""

import numpy as np

import hybridsub
from hybridsub._app.cli import main
from test_fit import CREASES, EDGE, FC, VC


def test_fit_and_decompose_commands(tmp_path, capsys):
    rng = np.random.default_rng(9)
    ctrl = tmp_path / "control.obj"
    start = VC + 0.03 * EDGE * rng.normal(size=VC.shape)
    hybridsub.write_mesh(ctrl, start, FC, sharp_edges=CREASES)
    r = hybridsub.refine(FC, CREASES, levels=2)
    target = tmp_path / "target.xyz"
    np.savetxt(target, r.apply(VC))
    out = tmp_path / "fitted.obj"
    assert main(["fit", str(ctrl), str(target), "-o", str(out), "--levels", "2", "--max-iterations", "8"]) == 0
    err = capsys.readouterr().err
    assert "iteration   0" in err and "converged" in err
    m = hybridsub.read_mesh(out)
    assert len(m.sharp_edges) == len(CREASES)                    # tags written back
    assert np.abs(m.vertices - VC).max() < 1e-6                  # the OBJ's printed precision
    fine = tmp_path / "fine.obj"
    X = r.apply(VC) + 0.01 * rng.normal(size=(r.n_vertices, 3))
    hybridsub.write_mesh(fine, X, r.faces)
    coarse_out = tmp_path / "coarse.obj"
    assert main(["decompose", str(ctrl), str(fine), "-o", str(coarse_out), "--levels", "2", "-q"]) == 0
    c = hybridsub.read_mesh(coarse_out).vertices
    d = np.load(tmp_path / "coarse.details.npz")
    assert d["level2"].shape == (r.n_vertices, 3) and bool(d["local_frames"])
    assert np.abs(c - r.decompose(hybridsub.read_mesh(fine).vertices)[0]).max() < 1e-6
    assert main(["decompose", str(ctrl), str(fine), "-o", str(coarse_out), "--levels", "1"]) == 1
    assert "must be that refinement" in capsys.readouterr().err


def test_fit_command_uses_every_tag_of_the_control_file(tmp_path):
    """Semi-sharp creases and corners in the control file shape the fitted surface: the command's
    result is the Python fit given the same tags (it once passed the crease edges alone)."""
    rng = np.random.default_rng(4)
    sharpness = np.full(len(CREASES), 1.5)
    corners = np.array([0])
    r = hybridsub.refine(FC, CREASES, levels=1, sharpness=sharpness, corners=corners)
    target = tmp_path / "target.npy"
    np.save(target, r.apply(VC))
    start = VC + 0.03 * EDGE * rng.normal(size=VC.shape)
    ctrl = tmp_path / "control.ply"
    hybridsub.write_mesh(ctrl, start, FC, sharp_edges=CREASES, sharpness=sharpness, corners=corners)
    out = tmp_path / "fitted.npz"
    assert main(["fit", str(ctrl), str(target), "-o", str(out), "--levels", "1", "--max-iterations", "6", "-q"]) == 0
    m = hybridsub.read_mesh(ctrl)
    want = hybridsub.fit(FC, r.apply(VC), m.sharp_edges, sharpness=m.sharpness, corners=m.corners, V0=m.vertices,
                         levels=1, max_iterations=6)
    assert np.abs(hybridsub.read_mesh(out).vertices - want.vertices).max() < 1e-12
