"""The bilateral block's operator: its inverse or pseudo-inverse chosen as the condition number
by SVD chooses, with the SVD skipped where the 1-norm bounds settle the choice.

The reference rule (the SVD's condition number against 1e12, then ``np.linalg.inv`` or
``np.linalg.pinv(rcond=1e-12)``) is written here again, compiled like the kernel, and the kernel
must return its operator to the bit on blocks whose condition spans the limit: well and badly
conditioned Delassus-like blocks (symmetric positive definite, and with the small asymmetry of
the reference's iteration matrix), exactly singular and rank-deficient ones.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

from clearbench.ref_solver.dense_kernels import (
    BILATERAL_CONDITION_LIMIT,
    bilateral_block_operator,
    bilateral_operator_dense,
)
from clearbench.ref_solver.fc3d_nsgs import bilateral_solve_operator


@njit(cache=False)
def _by_svd(block):
    condition = np.linalg.cond(block)
    if math.isfinite(condition) and condition < 1e12:
        return np.linalg.inv(block), False
    return np.linalg.pinv(block, rcond=1e-12), True


def _block(rng, n, condition, asymmetry=0.0):
    """An (n, n) block Q diag(s) Q^T with singular values from 1 down to 1 / condition, plus
    ``asymmetry`` times a random matrix of unit entries."""
    q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    s = np.geomspace(1.0, 1.0 / condition, n)
    return q @ np.diag(s) @ q.T + asymmetry * rng.standard_normal((n, n))


CONDITIONS = [1e2, 1e8, 1e10, 1e11, 3e11, 9e11, 1.1e12, 3e12, 1e13, 1e14, 1e16, 1e20]


@pytest.mark.parametrize("n", [1, 2, 5, 12, 30])
@pytest.mark.parametrize("condition", CONDITIONS)
def test_the_operator_is_the_svd_rules_to_the_bit(n, condition):
    rng = np.random.default_rng(int(condition) % 1000 + n)
    for asymmetry in (0.0, 5e-6 / condition):
        block = _block(rng, n, condition if n > 1 else 1.0, asymmetry)
        expected, expected_pseudo = _by_svd(block)
        operator, pseudo = bilateral_block_operator(block)
        assert pseudo == expected_pseudo
        np.testing.assert_array_equal(operator, expected)


@pytest.mark.parametrize("block", [
    np.zeros((3, 3)),
    np.ones((4, 4)),
    np.array([[1.0, 2.0], [2.0, 4.0]]),
    np.diag([1.0, 1.0, 0.0]),
    np.diag([1.0, 1e-13]),
], ids=["zero", "rank-one", "dependent-rows", "zero-pivot", "below-rcond"])
def test_singular_and_non_finite_blocks_take_the_pseudo_inverse_as_before(block):
    expected, expected_pseudo = _by_svd(block)
    operator, pseudo = bilateral_block_operator(block)
    assert pseudo and expected_pseudo
    np.testing.assert_array_equal(operator, expected)


def test_a_non_finite_block_is_refused_as_before():
    """The step refuses a non-finite W before any solve; the kernel, reached anyway, raises as
    the SVD rule did rather than return an operator."""
    block = np.full((2, 2), np.nan)
    with pytest.raises(np.linalg.LinAlgError):
        _by_svd(block)
    with pytest.raises(np.linalg.LinAlgError):
        bilateral_block_operator(block)


def test_every_caller_takes_the_one_operator():
    """The compiled solvers' (``bilateral_operator_dense``, the leading block of W) and the
    Python path's (``bilateral_solve_operator``) are the same kernel's result."""
    rng = np.random.default_rng(7)
    W = _block(rng, 9, 1e3)
    expected, _ = bilateral_block_operator(np.ascontiguousarray(W[:4, :4]))
    np.testing.assert_array_equal(bilateral_operator_dense(W, 4), expected)
    np.testing.assert_array_equal(bilateral_solve_operator(W[:4, :4]), expected)
    assert bilateral_operator_dense(W, 0).shape == (0, 0)
    assert bilateral_solve_operator(np.zeros((0, 0))).shape == (0, 0)
    assert BILATERAL_CONDITION_LIMIT == 1e12  # the rule's limit, as the test's reference
