"""Checks and conversions of the arguments and of what user functions return."""

import numpy as np

from .._support.errors import with_note


def _real(name, value):
    """A float argument as a Python float: TypeError for a non-number, ValueError for
    one no float holds (an int such as 2**1100)."""
    if isinstance(value, (str, bytes)) or not np.isscalar(value) and np.ndim(value) != 0:
        raise TypeError(f"{name} must be a real number, not {type(value).__name__}")
    try:
        return float(value)
    except OverflowError:
        raise ValueError(f"{name} is too large for a float64 (an int of "
                         f"{int(value).bit_length()} bits)") from None
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a real number, not {type(value).__name__}") from None


def _starting_point(x0):
    """x0 as a fresh float64 column."""
    x = np.array(x0, dtype=np.float64)
    if x.size == 0:
        raise with_note(ValueError("x0 must not be empty."),
                        f"x0 has shape {x.shape}")
    return x.reshape(x.size, 1)


def _resolve_scale(x_scale, n):
    """(D, adaptive): the (n, 1) scale, and whether 'jac' recomputes it."""
    if isinstance(x_scale, str):
        if x_scale != "jac":
            raise ValueError("x_scale must be None, 'jac', a positive scalar, or array, "
                             f"got {x_scale!r}.")
        return np.ones((n, 1)), True
    if x_scale is None:
        return np.ones((n, 1)), False
    scale = np.asarray(x_scale, dtype=np.float64)
    if scale.shape not in ((), (n,)):
        raise ValueError(f"x_scale array must have shape ({n},), got {scale.shape}.")
    if not np.all(np.isfinite(scale)) or np.any(scale <= 0):
        raise ValueError("x_scale must be positive and finite.")
    return np.broadcast_to(scale, (n,)).reshape(n, 1).copy(), False


def _resolve_bounds(bounds, n):
    """[lower, upper] as float64 columns, checked."""
    if len(bounds) != 2:
        raise ValueError("bounds must have 2 elements.")
    box = [np.array(b, dtype=np.float64) for b in bounds]
    if box[0].size != n or box[1].size != n:
        raise with_note(ValueError("bounds must have the same size as x0."),
                        f"x0 has {n} entries; the bounds have {box[0].size} and {box[1].size}")
    if not (np.all(np.isfinite(box[0])) and np.all(np.isfinite(box[1]))):
        raise ValueError("bounds must be finite.")
    lower, upper = (b.reshape(n, 1) for b in box)
    if not np.all(lower < upper):
        raise with_note(ValueError("bounds[0] must be smaller than bounds[1]."),
                        f"not so at indices {np.flatnonzero(lower >= upper).tolist()}")
    return [lower, upper]


def _checked_residual(residual, points, nr):
    """residual(points), checked to be a float64 (nr, k) array for k points."""
    r = residual(points)
    if not isinstance(r, np.ndarray):
        raise TypeError("residual function must return a NumPy array, "
                        f"not {type(r).__name__}.")
    if r.dtype != np.float64:
        raise with_note(ValueError("residual function must return float64 arrays."),
                        f"it returned {r.dtype}")
    k = points.shape[1]
    if r.ndim != 2 or r.shape[1] != k or (nr is not None and r.shape[0] != nr):
        rows = "nr" if nr is None else nr
        raise ValueError(
            f"residual function must return an array of shape ({rows}, {k}) for "
            f"points of shape {points.shape} (one column per point); got {r.shape}.")
    return r


def _as_matrix(value, shape, what):
    """A user function's matrix result as float64 of the expected shape."""
    try:
        matrix = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{what} must return a real array of shape {shape}.") from exc
    if matrix.shape != shape:
        raise ValueError(f"{what} must return an array of shape {shape}; "
                         f"got {matrix.shape}.")
    return matrix


def _grad_hess(norm, r, proj, n):
    """norm.grad_hess as an (n, 1) gradient and a C-contiguous (n, n) Hessian."""
    grad, hess = norm.grad_hess(r, proj)
    grad = np.asarray(grad, dtype=np.float64)
    if grad.size != n:
        raise ValueError(f"norm.grad_hess must return a gradient of {n} entries; "
                         f"got shape {grad.shape}.")
    hess = _as_matrix(hess, (n, n), "norm.grad_hess (Hessian)")
    return grad.reshape(n, 1), np.ascontiguousarray(hess)
