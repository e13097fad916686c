"""The compiled core's QZ (``kinelab.core._blas.ggev``, LAPACK's dggev), which the general 6R elimination calls
instead of ``scipy.linalg.lapack.dggev`` (whose package import, 0.15–0.3 s, fell inside a first pose's budget)."""

import numpy as np
import pytest
import scipy.linalg.lapack

from kinelab.core import _blas


def _complex(v, alphai):
    out = v.astype(complex)
    first = np.flatnonzero(alphai > 0)
    out[:, first] = v[:, first] + 1j * v[:, first + 1]
    out[:, first + 1] = np.conj(out[:, first])
    return out


@pytest.mark.parametrize("n", [1, 3, 8, 12])
def test_the_pencils_eigenpairs_hold_and_match_scipys_dggev(n):
    rng = np.random.default_rng(n)
    A, B = rng.normal(size=(n, n)), rng.normal(size=(n, n))
    A0, B0 = A.copy(), B.copy()
    alphar, alphai, beta, vl, vr, info = _blas.ggev(A, B)
    assert info == 0 and np.array_equal(A, A0) and np.array_equal(B, B0)  # the inputs are left as they were
    alpha, V, W = alphar + 1j * alphai, _complex(vr, alphai), _complex(vl, alphai)
    for k in range(n):  # β A v = α B v and β wᴴ A = α wᴴ B, to rounding
        scale = (abs(beta[k]) * np.linalg.norm(A) + abs(alpha[k]) * np.linalg.norm(B)) * np.linalg.norm(V[:, k])
        assert np.linalg.norm(beta[k] * A @ V[:, k] - alpha[k] * B @ V[:, k]) <= 1e-12 * scale
        scale = (abs(beta[k]) * np.linalg.norm(A) + abs(alpha[k]) * np.linalg.norm(B)) * np.linalg.norm(W[:, k])
        assert np.linalg.norm(beta[k] * W[:, k].conj() @ A - alpha[k] * W[:, k].conj() @ B) <= 1e-12 * scale
    theirs = scipy.linalg.lapack.dggev(A, B, 1, 1)
    for ours, reference in zip((alphar, alphai, beta, vl, vr), theirs[:5], strict=True):
        np.testing.assert_allclose(ours, reference, rtol=1e-10, atol=1e-12)


def test_a_non_square_pencil_is_refused_by_name():
    with pytest.raises(ValueError, match="two n × n matrices"):
        _blas.ggev(np.zeros((2, 3)), np.zeros((2, 3)))
