"""mcfbench.matrices against the textbook formulas, computed here with numpy: the cotangent
stiffness and the consistent (A/12, A/6) and lumped (A/3) mass matrices of the hat basis."""

import numpy as np
import pytest
import scipy.sparse as sp

import mcfbench


def reference(V, F):
    """(M, K, M_lumped) as dense arrays, one triangle at a time."""
    n = len(V)
    M, K, L = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    for f in F:
        p = V[f]
        area = 0.5 * np.linalg.norm(np.cross(p[1] - p[0], p[2] - p[0]))
        for k in range(3):
            i, j, o = f[k], f[(k + 1) % 3], f[(k + 2) % 3]
            # The angle at o faces the edge (i, j): K_ij -= cot/2, K_ii, K_jj += cot/2.
            a, b = V[i] - V[o], V[j] - V[o]
            half_cot = 0.5 * a.dot(b) / np.linalg.norm(np.cross(a, b))
            K[i, j] -= half_cot
            K[j, i] -= half_cot
            K[i, i] += half_cot
            K[j, j] += half_cot
            M[i, j] += area / 12
            M[j, i] += area / 12
            M[i, i] += area / 6
            L[i, i] += area / 3
    return M, K, L


@pytest.fixture(scope="module")
def mesh():
    return mcfbench.load_mesh("cgal:cow")


def close(A, B):
    # Sums of a few terms in another order: equal to rounding, far below 1e-12 of the largest.
    return np.abs(A - B).max() <= 1e-12 * np.abs(B).max()


def test_hat_matrices_are_the_cotangent_stiffness_and_the_consistent_mass():
    V, F = mcfbench.load_mesh("icosphere:level=2")
    M, K = mcfbench.matrices(V, F)
    assert sp.issparse(M) and sp.issparse(K) and M.shape == K.shape == (len(V), len(V))
    Mr, Kr, Lr = reference(V, F)
    assert close(M.toarray(), Mr) and close(K.toarray(), Kr)
    Ml, Kl = mcfbench.matrices(V, F, mass="lumped")
    assert close(Ml.toarray(), Lr) and close(Kl.toarray(), Kr)


def test_a_spec_gives_the_matrices_of_the_mesh_it_loads(mesh):
    V, F = mesh
    M, K = mcfbench.matrices(mesh="cgal:cow")
    M2, K2 = mcfbench.matrices(V, F)
    assert (M != M2).nnz == 0 and (K != K2).nnz == 0
    # Constants are in K's kernel; M sums to the area.
    assert np.abs(K @ np.ones(len(V))).max() < 1e-10 * abs(K).max()
    p = V[F]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
    assert abs(M.sum() - area) < 1e-12 * area


def test_octree_matrices_are_symmetric_and_reproduce_the_area(mesh):
    V, F = mesh
    M, K = mcfbench.matrices(V, F, basis="octree", depth=5)
    assert M.shape[0] != len(V)  # the octree's functions
    assert abs(M - M.T).max() == 0 and abs(K - K.T).max() == 0
    p = V[F]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
    # The B-splines sum to one on the surface (a partition of unity), so M's entries sum to its
    # area and constants are in K's kernel, up to rounding.
    assert abs(M.sum() - area) < 1e-12 * area
    assert np.abs(K @ np.ones(M.shape[0])).max() < 1e-12 * abs(K).max()


def test_bad_options_and_arrays_raise():
    V, F = mcfbench.load_mesh("icosphere:level=1")
    with pytest.raises(ValueError, match='unknown value "quadratic"'):
        mcfbench.matrices(V, F, mass="quadratic")
    with pytest.raises(ValueError, match="give V and F, or a mesh spec"):
        mcfbench.matrices()
    with pytest.raises(ValueError, match="F: expected an m x 3 array"):
        mcfbench.matrices(V, F[:, :2])
