"""Finite-difference Jacobians, and checks of user derivatives against them."""

from typing import Callable, List, Optional, TextIO, Tuple

import numpy as np

from .._support.errors import with_note
from ._checks import _checked_residual
from ._types import Norm

# check_jacobian's tolerance on |J - J_fd| relative to the sum of both |J|.
_JACOBIAN_RTOL = 1e-5


def jacobian_fd(
    residual: Callable[[np.ndarray], np.ndarray],
    x: np.ndarray,
    r: np.ndarray,
    eps: np.float64,
    n_res: int,
    bounds: Optional[List[np.ndarray]] = None,
) -> Tuple[np.ndarray, int]:
    """Forward-difference Jacobian of a vectorized residual at x, inside bounds.

    Args:
      residual: vectorized residual function (see least_squares).
      x: the point, an (n, 1) column.
      r: residual(x), (nr, 1).
      eps: relative step: coordinate i moves by eps * max(1, |x_i|).
      n_res: residual evaluations so far.
      bounds: optional [lower, upper]: steps go toward the interior (away from
        the nearer bound) and are clipped to the box, so that the residual is
        never evaluated outside it.

    Returns:
      (jac, n_res): the (nr, n) Jacobian, and n_res plus the n points evaluated
      (in one call of `residual`).
    """
    x = np.asarray(x, dtype=np.float64)
    n = x.size
    x = x.reshape(n, 1)
    direction = np.ones((n, 1))
    if bounds is not None:
        lower, upper = (np.asarray(b, dtype=np.float64).reshape(n, 1) for b in bounds)
        # step down from the upper half; the midpoint may round onto `upper`
        middle = 0.5 * lower + 0.5 * upper
        direction[(x > middle) | (x == upper)] = -1.0
    points = x + np.diag((direction * eps * np.maximum(1.0, np.abs(x))).ravel())
    if bounds is not None:
        np.clip(points, lower, upper, out=points)
    # divide by the step actually taken, after rounding and clipping
    steps = points.diagonal() - x.ravel()
    values = _checked_residual(residual, points, np.shape(r)[0] if np.ndim(r) else None)
    return (values - r) / steps, n_res + n


def check_jacobian(
    residual: Callable[[np.ndarray], np.ndarray],
    x: np.ndarray,
    r: np.ndarray,
    jac: np.ndarray,
    eps: np.float64,
    n_res: int,
    bounds: Optional[List[np.ndarray]] = None,
    output: Optional[TextIO] = None,
    name: Optional[str] = "Jacobian",
) -> int:
    """Compare a user's Jacobian of `residual` at x with finite differences.

    Args:
      residual, x, r, eps, n_res, bounds: as for jacobian_fd.
      jac: the Jacobian to check, (nr, n).
      output: text stream for the confirmation (default: standard output).
      name: what `jac` is, for the messages.

    Returns:
      n_res, updated with the evaluations made.

    Raises:
      ValueError: if either Jacobian is not finite, or an entry differs by more
        than 1e-5 times the sum of the absolute entries of both.
    """
    n_res = _compare_jacobian(residual, x, r, jac, eps, n_res, bounds, name)
    print(f"User-provided {name} matches finite-differences.", file=output)
    return n_res


def check_norm(
    r: np.ndarray,
    norm: Norm,
    eps: np.float64,
    output: Optional[TextIO] = None,
):
    """Check a norm's gradient and Hessian at r against finite differences.

    The Hessian must be finite, symmetric and positive semidefinite; the
    gradient must match finite differences of `norm.value`, and the Hessian
    finite differences of the gradient (as check_jacobian compares them).

    Args:
      r: the residual column (nr x 1) at which to check.
      norm: the Norm to check.
      eps: relative finite-difference step.
      output: text stream for the confirmations (default: standard output).

    Raises:
      ValueError: naming the check that failed.
    """
    for line in _check_norm(r, norm, eps):
        print(line, file=output)


def _compare_jacobian(residual, x, r, jac, eps, n_res, bounds, name):
    """check_jacobian without the printing; returns n_res."""
    jac = np.asarray(jac, dtype=np.float64)
    # NaN compares false, so a NaN entry would otherwise pass the comparison
    if not np.all(np.isfinite(jac)):
        raise ValueError(f"User-provided {name} must contain only finite values.")
    jac_fd, n_res = jacobian_fd(residual, x, r, eps, n_res, bounds)
    if not np.all(np.isfinite(jac_fd)):
        raise ValueError(f"Finite-difference {name} must contain only finite values.")
    if jac.shape != jac_fd.shape:
        raise ValueError(f"User-provided {name} has shape {jac.shape}; finite "
                         f"differences give {jac_fd.shape}.")
    scale = np.abs(jac).sum() + np.abs(jac_fd).sum() + 1e-8
    error = np.abs(jac - jac_fd) / scale
    if np.any(error > _JACOBIAN_RTOL):
        worst = np.unravel_index(np.argmax(error), error.shape)
        raise with_note(ValueError(f"User-provided {name} does not match finite-differences "
                                   "to a relative tolerance of 1e-5."),
                        f"largest relative difference {error[worst]:.3g} at index "
                        f"{tuple(int(i) for i in worst)}: {jac[worst]!r} against "
                        f"{jac_fd[worst]!r} by finite differences")
    return n_res


def _check_norm(r, norm, eps):
    """check_norm without the printing: yields each confirmation as its check passes."""
    r = np.asarray(r, dtype=np.float64)
    eye = np.eye(r.size)
    value = np.atleast_2d(norm.value(r))
    grad, hess = norm.grad_hess(r, eye)
    hess = np.asarray(hess, dtype=np.float64)
    # a nonfinite Hessian would fail the tests below with a misleading message
    if not np.all(np.isfinite(hess)):
        raise ValueError("User-provided norm Hessian must contain only finite values.")
    if not np.allclose(hess, hess.T):
        raise ValueError("User-provided norm Hessian is not symmetric.")
    eigenvalues = np.linalg.eigvalsh(0.5 * (hess + hess.T))
    # allow the rounding error of a semidefinite Hessian's zero eigenvalues
    if eigenvalues[0] < -r.size * np.finfo(np.float64).eps * max(1.0, eigenvalues[-1]):
        raise ValueError("User-provided norm Hessian is not positive definite. "
                         f"Minimum eigenvalue is {eigenvalues[0]:<.4g}")

    def values(columns):
        return np.hstack([np.atleast_2d(norm.value(columns[:, j:j + 1]))
                          for j in range(columns.shape[1])])

    def gradients(columns):
        return np.hstack([np.asarray(norm.grad_hess(columns[:, j:j + 1], eye)[0],
                                     dtype=np.float64).reshape(-1, 1)
                          for j in range(columns.shape[1])])

    grad = np.asarray(grad, dtype=np.float64).reshape(-1, 1)
    for function, point_value, derivative, name in (
            (values, value, grad.T, "norm gradient"),
            (gradients, grad, hess, "norm Hessian")):
        _compare_jacobian(function, r, point_value, derivative, eps, 0, None, name)
        yield f"User-provided {name} matches finite-differences."
