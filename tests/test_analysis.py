"""Smoothness analysis: the project's local matrices against the paper's closed forms."""

import numpy as np
import pytest

from hybridsub._rules import step_rules as R
from hybridsub import analysis
from hybridsub._topology.level import build_level


def _same_multiset(a, b, tol=1e-10):
    a, b = list(np.asarray(a, complex)), list(np.asarray(b, complex))
    assert len(a) == len(b)
    for x in a:
        i = int(np.argmin([abs(x - y) for y in b]))
        assert abs(x - b[i]) < tol, (x, b[i])
        b.pop(i)


@pytest.mark.parametrize("n", range(3, 21))
def test_sqrt3_spectrum_is_the_papers_eq7(n):
    M2 = analysis.subdivision_matrix(n, "sqrt3", steps=2)
    ev = analysis.eigenvalues(M2)
    a = R.kobbelt_alpha(n)
    eq7 = np.r_[9, (2 - 3 * a) ** 2, 2 + 2 * np.cos(2 * np.pi * np.arange(1, n) / n)] / 9
    _same_multiset(ev, eq7)
    _same_multiset(ev, analysis.closed_form_spectrum(n, "sqrt3"))
    # one step: the ring turns by π/n, the spectrum is complex, its moduli the square roots
    ev1 = analysis.eigenvalues(analysis.subdivision_matrix(n, "sqrt3", steps=1))
    _same_multiset(ev1, analysis.closed_form_spectrum(n, "sqrt3", steps=1))
    _same_multiset(np.abs(ev1) ** 2, np.abs(ev))
    # condition (8), and Kobbelt's choice of α_n: the centre's eigenvalue is λ₂²
    c = analysis.check_smoothness(n, "sqrt3")
    assert c.condition8 and c.condition9 and c.crease_tangent is None
    lam2 = (2 + 2 * np.cos(2 * np.pi / n)) / 9
    assert np.isclose(c.subdominant[0], lam2) and np.isclose((2 - 3 * a) ** 2 / 9, lam2 ** 2)
    assert not analysis.check_smoothness(n, "sqrt3", steps=1).condition9  # complex pair


@pytest.mark.parametrize("weights", ["loop", "warren"])
@pytest.mark.parametrize("n", range(3, 21))
def test_loop_spectrum_is_the_papers_eq10(n, weights):
    M = analysis.subdivision_matrix(n, "loop", loop_weights=weights)
    ev = analysis.eigenvalues(M)
    _same_multiset(ev, analysis.closed_form_spectrum(n, "loop", loop_weights=weights))
    eq10 = (3 + 2 * np.cos(2 * np.pi / n)) / 8
    assert np.allclose(ev[1:3], eq10)  # the sub-dominant pair
    assert np.isclose(ev[3], (3 + 2 * np.cos(4 * np.pi / n)) / 8) or np.isclose(ev[3], 5 / 8 - n * R.loop_beta(n, weights))
    c = analysis.check_smoothness(n, "loop", loop_weights=weights)
    assert c.condition8 and c.condition9
    if weights == "loop":  # Loop's β_n makes the centre's eigenvalue λ₂²
        assert np.isclose(5 / 8 - n * R.loop_beta(n), eq10 ** 2)


@pytest.mark.parametrize("n", [3, 4, 6, 9, 12])
def test_bigger_neighbourhoods_keep_the_subdominant_pair(n):
    for scheme, steps in (("loop", 1), ("sqrt3", 2)):
        one = analysis.eigenvalues(analysis.subdivision_matrix(n, scheme, steps=steps))
        for rings in (2, 3):
            ev = analysis.eigenvalues(analysis.subdivision_matrix(n, scheme, steps=steps, rings=rings))
            assert len(ev) == 1 + n * rings * (rings + 1) // 2
            np.testing.assert_allclose(np.abs(ev[:3]), np.abs(one[:3]), atol=1e-12)
            assert np.abs(ev[3]) < np.abs(ev[2]) - 1e-9  # the outer rings add only smaller eigenvalues


@pytest.mark.parametrize("scheme", ["loop", "sqrt3"])
@pytest.mark.parametrize("k", range(1, 13))
def test_crease_spectra(scheme, k):
    steps = 2 if scheme == "sqrt3" else 1
    ev = analysis.eigenvalues(analysis.subdivision_matrix(k, scheme, steps=steps, crease=True))
    _same_multiset(ev, analysis.closed_form_spectrum(k, scheme, crease=True), tol=1e-7)
    c = analysis.check_smoothness(k, scheme, crease=True)
    # The crease tangent (1/2; 1/3 per two √3 steps) is sub-dominant up to 5 faces; at 6 it ties
    # with the second sector mode, from 7 on both sector modes win: no tangent plane at the vertex.
    assert c.crease_tangent == (k <= 5)


def test_model_neighbourhood():
    for crease in (False, True):
        for n in (3, 5, 8):
            V, F, ring = analysis.model_neighbourhood(n, 3, crease=crease)
            lvl = build_level(F, len(V))  # consistently oriented, edge-manifold
            cnt = np.bincount(ring)
            assert cnt[0] == 1 and list(cnt[1:]) == [n * r + crease for r in (1, 2, 3)]
            assert lvl.valence[0] == n + crease
            inner = np.flatnonzero((ring >= 1) & (ring <= 2))
            if not crease:
                assert (lvl.valence[inner] == 6).all()
            tri = V[F]
            area = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[:, 2]
            assert (area > 0).all()


def _cross2(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _map_checks(P, F):
    tri = P[F]
    det = _cross2(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    key = np.sort(e, axis=1)
    _, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    b = e[cnt[inv.ravel()] == 1]
    enclosed = 0.5 * _cross2(P[b[:, 0]], P[b[:, 1]]).sum()
    return det, enclosed


@pytest.mark.parametrize("scheme", ["loop", "sqrt3"])
@pytest.mark.parametrize("n", [3, 4, 5, 7, 10, 16])
def test_characteristic_map_is_regular_and_injective(scheme, n):
    P, F, lam = analysis.characteristic_map(n, scheme, levels=3)
    det, enclosed = _map_checks(P, F)
    assert (det > 0).all()  # orientation kept everywhere: regular
    # no fold-over: the triangles exactly tile the region their boundary encloses
    assert np.isclose(0.5 * det.sum(), enclosed, rtol=1e-9)
    assert np.allclose(lam, (3 + 2 * np.cos(2 * np.pi / n)) / 8 if scheme == "loop"
                       else (2 + 2 * np.cos(2 * np.pi / n)) / 9)
    # centre at the origin, the map's rotational symmetry: the points' centroid is 0
    assert np.allclose(P.mean(axis=0), 0, atol=1e-9)


@pytest.mark.parametrize("k", [1, 2, 3, 4, 5, 8])
def test_crease_characteristic_map(k):
    P, F, lam = analysis.characteristic_map(k, "loop", levels=3, crease=True)
    det, enclosed = _map_checks(P, F)
    if k <= 5:
        assert (det > 0).all() and np.isclose(0.5 * det.sum(), enclosed, rtol=1e-9)
        assert np.isclose(min(lam), 0.5) or np.isclose(max(lam), 0.5)
    else:  # both eigenvectors vanish on the crease: the whole crease maps to one point
        assert not np.isclose(lam, 0.5).any()
        assert not (det > 1e-12 * np.abs(det).max()).all()


def test_bad_arguments():
    with pytest.raises(ValueError, match="valence >= 3"):
        analysis.subdivision_matrix(2, "loop")
    with pytest.raises(ValueError, match="scheme must be one of"):
        analysis.subdivision_matrix(5, "hybrid")
    with pytest.raises(ValueError, match="stationary over two steps"):
        analysis.subdivision_matrix(3, "sqrt3", crease=True, steps=1)
    with pytest.raises(TypeError, match="n must be an integer"):
        analysis.check_smoothness(4.5)
    with pytest.raises(ValueError, match="crease sector needs at least 1 face"):
        analysis.closed_form_spectrum(0, "loop", crease=True)


@pytest.mark.slow  # subprocesses / a cluster / figures: ~4-11 s; .ci/run runs the slow tests
def test_figure_script_runs(tmp_path):
    """docs/figures/make_figures.py, in its quick mode: the docs' figures can be regenerated."""
    pytest.importorskip("matplotlib")
    import importlib.util
    import os

    path = os.path.join(os.path.dirname(__file__), "..", "docs", "figures", "make_figures.py")
    spec = importlib.util.spec_from_file_location("make_figures", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    mod.main(["--out", str(tmp_path), "--quick"])
    made = sorted(p.name for p in tmp_path.iterdir())
    assert made == ["adaptive_fandisk.png", "analysis_charmaps.png", "analysis_spectra.png", "features_fandisk.png",
                    "limit_convergence.png", "limit_fandisk.png", "limit_octahedron.png", "options_cube.png",
                    "semisharp_cube.png", "textured_bunny.png"]
    assert all((tmp_path / m).stat().st_size > 5000 for m in made)
