"""The reduced system's uncoupled columns (issue 41): a column with nothing but its diagonal is
solved, factorised and inverted as the 1 × 1 block it is, the dense Cholesky runs on the rest."""

import numpy as np
import pytest

from hsgeo.adjust.schur import _coupled, _spd_inverse, _spd_solve


def _spd_with_isolated(n=40, isolated=(0, 7, 8, 39), seed=3):
    """A symmetric positive definite matrix whose ``isolated`` columns have only a diagonal."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    S = A @ A.T + n * np.eye(n)
    iso = list(isolated)
    S[iso, :] = 0.0
    S[:, iso] = 0.0
    S[iso, iso] = rng.uniform(0.5, 50.0, len(iso))
    return S, np.array(iso)


def test_coupled_columns_are_found():
    S, iso = _spd_with_isolated()
    keep = _coupled(S)
    assert keep is not None
    assert np.array_equal(np.setdiff1d(np.arange(S.shape[0]), keep), iso)
    full = np.ones((5, 5)) + 5 * np.eye(5)
    assert _coupled(full) is None


def test_solve_and_inverse_equal_the_dense_ones():
    S, _ = _spd_with_isolated()
    rhs = np.random.default_rng(4).standard_normal(S.shape[0])
    np.testing.assert_allclose(_spd_solve(S, rhs), np.linalg.solve(S, rhs), rtol=1e-12)
    np.testing.assert_allclose(_spd_inverse(S, 1e-11), np.linalg.inv(S), rtol=1e-10, atol=1e-15)


def test_every_column_isolated():
    d = np.array([2.0, 3.0, 4.0])
    S = np.diag(d)
    assert _coupled(S).size == 0
    np.testing.assert_array_equal(_spd_solve(S, np.ones(3)), 1.0 / d)
    np.testing.assert_allclose(_spd_inverse(S, 1e-11), np.diag(1.0 / d))


def test_a_zero_diagonal_or_a_singular_block_is_refused():
    S, iso = _spd_with_isolated()
    Z = S.copy()
    Z[iso[0], iso[0]] = 0.0
    with pytest.raises(np.linalg.LinAlgError):
        _spd_solve(Z, np.ones(S.shape[0]))
    # the coupled block made indefinite (an eigenvalue of the opposite sign): Cholesky fails,
    # the eigenvalues decide (singular)
    B = S.copy()
    keep = _coupled(S)
    v = np.zeros(S.shape[0])
    v[keep] = np.random.default_rng(5).standard_normal(keep.size)
    B -= 2.0 * np.outer(B @ v, B @ v) / (v @ B @ v)  # v's Rayleigh quotient turned negative
    with pytest.raises(np.linalg.LinAlgError):
        _spd_solve(B, np.ones(S.shape[0]))
    with pytest.raises(np.linalg.LinAlgError, match="singular"):
        _spd_inverse(B, 1e-11)
