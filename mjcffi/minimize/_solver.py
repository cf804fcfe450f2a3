"""least_squares: Levenberg-Marquardt iterations, each step a box-constrained QP for mju_boxQP."""

import dataclasses
import time
from typing import Callable, List, Optional, Sequence, TextIO, Tuple, Union

import numpy as np

from .._functions import mju_boxQP  # generated; not among the overrides
from ._checks import (
    _as_matrix, _checked_residual, _grad_hess, _resolve_bounds, _resolve_scale,
    _real, _starting_point,
)
from ._derivatives import _check_norm, _compare_jacobian, jacobian_fd
from ._types import _STATUS_TEXT, IterLog, Norm, Quadratic, Status, Verbosity

# A step must achieve this fraction of the reduction its slope promises (Armijo).
_ARMIJO_C1 = 1e-2

_QUADRATIC = Quadratic()


def least_squares(
    x0: np.ndarray,
    residual: Callable[[np.ndarray], np.ndarray],
    bounds: Optional[Sequence[np.ndarray]] = None,
    jacobian: Optional[Callable[[np.ndarray, np.ndarray], np.ndarray]] = None,
    norm: Optional[Norm] = None,
    eps: float = np.finfo(np.float64).eps ** 0.5,
    mu_min: float = 1e-6,
    mu_max: float = 1e8,
    mu_factor: float = 10.0 ** 0.1,
    xtol: float = 1e-8,
    gtol: float = 1e-8,
    max_iter: int = 100,
    verbose: Union[Verbosity, int] = Verbosity.ITER,
    output: Optional[TextIO] = None,
    iter_callback: Optional[Callable[[List[IterLog]], None]] = None,
    check_derivatives: bool = False,
    x_scale: Optional[Union[float, np.ndarray, str]] = None,
) -> Tuple[np.ndarray, List[IterLog]]:
    """Minimize norm(residual(x)) subject to bounds[0] <= x <= bounds[1].

    Args:
      x0: starting point, any shape; it is clipped into the bounds.
      residual: vectorized residual: points as the columns of an (n, k) array
        in, their residuals as the columns of an (nr, k) float64 array out.
      bounds: optional [lower, upper], each of x0's size, finite, lower < upper.
      jacobian: optional `jacobian(x, r)` returning the (nr, n) Jacobian of the
        residual at the column x whose residual is r; by default the residual
        is finite-differenced (n extra points per iteration, in one call).
      norm: the Norm measuring the residual; None (default) is Quadratic().
      eps: relative step of the finite differences.
      mu_min, mu_max: least nonzero and largest regularizer mu.
      mu_factor: factor (> 1) by which mu grows; it shrinks faster, by this
        factor to the power 2**k after k consecutive decreases.
      xtol: stop when |dx| < xtol * (xtol + |x|).
      gtol: stop when the gradient, less its components held by an active
        bound, has a norm <= gtol.
      max_iter: most iterations.
      verbose: a Verbosity, or its int value.
      output: text stream for messages (default: standard output).
      iter_callback: called with the trace after each new entry.
      check_derivatives: compare a user `jacobian` and a non-Quadratic norm's
        gradient and Hessian with finite differences at x0 before the first
        step, raising ValueError on a mismatch.
      x_scale: solve for z = x / D instead of x, as scipy's x_scale does: a
        positive scalar or an array of n positive entries is D itself, 'jac'
        recomputes D_i = 1 / |J[:, i]| at each iteration, and None or 1.0 is
        no scaling.  mu and its limits then apply to the scaled problem.

    Returns:
      (x, trace): the best point found, shaped as x0, and a list of IterLog,
      one per iteration and one for x.

    Raises:
      ValueError: on bad arguments, a residual or Jacobian of the wrong shape
        or dtype, a nonfinite residual at x0, or a failed derivative check.
      TypeError: if the residual returns something other than a NumPy array.

    Whatever `residual`, `jacobian` or `norm` raise passes through unchanged.
    """
    verbosity = Verbosity(verbose).value
    eps, mu_min, mu_max, mu_factor, xtol, gtol = (_real(name, value) for name, value in (
        ("eps", eps), ("mu_min", mu_min), ("mu_max", mu_max), ("mu_factor", mu_factor),
        ("xtol", xtol), ("gtol", gtol)))
    norm = _QUADRATIC if norm is None else norm
    x = _starting_point(x0)
    n = x.shape[0]
    scale, adaptive = _resolve_scale(x_scale, n)
    if mu_factor <= 1:
        raise ValueError("mu_factor must be > 1.")
    box = None if bounds is None else _resolve_bounds(bounds, n)
    if box is not None:
        np.clip(x, box[0], box[1], out=x)
    if not np.all(np.isfinite(x)):
        raise ValueError("x0 must be finite.")

    problem = _Problem(residual, jacobian, n, box, np.float64(eps))
    say = _Printer(output, verbosity)
    mu = _Regularizer(mu_min, mu_max, mu_factor)
    solver = _Solver(problem, norm, mu, say, box)
    started = time.perf_counter()
    x, r, status, trace = solver.run(
        x, scale, adaptive, xtol, gtol, max_iter, iter_callback, check_derivatives)
    _finish(problem, norm, x, r, mu.value, verbosity, trace, iter_callback)
    say.summary(status, trace, problem, time.perf_counter() - started)
    return x.reshape(np.shape(x0)), trace


class _Regularizer:
    """The Levenberg-Marquardt mu: raised gently, lowered ever faster."""

    def __init__(self, mu_min, mu_max, factor):
        self.min, self.max, self.factor = mu_min, mu_max, factor
        self.value = np.float64(0.0)  # start as pure Gauss-Newton
        self.decreases = 0  # consecutive decreases

    def increase(self):
        self.value = max(self.min, self.factor * self.value)
        self.decreases = 0

    def decrease(self):
        lowered = self.value * (1 / self.factor) ** (2 ** self.decreases)
        self.value = 0.0 if lowered < self.min else lowered
        self.decreases += 1

    @property
    def exhausted(self):
        return self.value >= self.max


class _Problem:
    """The residual and its Jacobian, with shape checks, counts and timings."""

    def __init__(self, residual, jacobian, n, box, eps):
        self.residual_fn, self.jacobian_fn = residual, jacobian
        self.n, self.box, self.eps = n, box, eps
        self.nr = None  # set by the first evaluation
        self.n_res = self.n_jac = 0
        self.t_res = self.t_jac = 0.0

    def residual(self, x):
        start = time.perf_counter()
        r = _checked_residual(self.residual_fn, x, self.nr)
        self.t_res += time.perf_counter() - start
        self.n_res += x.shape[1]
        self.nr = r.shape[0]
        return r

    def jacobian(self, x, r):
        """The Jacobian at x: the user's, or finite differences."""
        start = time.perf_counter()
        if self.jacobian_fn is None:
            jac, self.n_res = jacobian_fd(
                self.residual_fn, x, r, self.eps, self.n_res, self.box)
            self.t_res += time.perf_counter() - start
            return jac
        jac = _as_matrix(self.jacobian_fn(x, r), (self.nr, self.n), "jacobian")
        self.t_jac += time.perf_counter() - start
        self.n_jac += 1
        return jac


class _Solver:
    """The iterations of least_squares."""

    def __init__(self, problem, norm, mu, say, box):
        self.problem, self.norm, self.mu, self.say, self.box = problem, norm, mu, say, box
        # mju_boxQP's workspace; its solution doubles as the next warm start
        self.dz = np.zeros((problem.n, 1))
        self.scratch = np.zeros((problem.n, problem.n + 7))
        self.eye = np.eye(problem.n)

    def run(self, x, scale, adaptive, xtol, gtol, max_iter, callback, check):
        problem, norm, say = self.problem, self.norm, self.say
        r = problem.residual(x)
        if not np.all(np.isfinite(r)):
            raise ValueError("the residual at x0 is not finite.")
        trace = []
        for i in range(max_iter):
            y = norm.value(r)
            jac = problem.jacobian(x, r)
            if i == 0 and check:
                self._check_derivatives(x, r, jac)
            if adaptive:
                scale = 1.0 / np.maximum(np.linalg.norm(jac, axis=0), problem.eps)[:, None]
            grad, hess = _grad_hess(norm, r, jac * scale.T, problem.n)
            g_norm = np.linalg.norm(self._free(x, grad))
            if g_norm <= gtol:
                if g_norm == 0:
                    say.note("Gradient norm is zero: exact minimum found?")
                return x, r, Status.G_TOL, trace
            status, xnew, rnew, reduction = self._line_search(x, y, grad, hess, scale)
            if status is not None:
                return x, r, status, trace
            ratio = self._ratio(reduction, grad, hess)
            step = scale * self.dz
            dx_norm = np.linalg.norm(step)
            say.iteration(i, y, self.mu.value, ratio, dx_norm, reduction)
            self._record(trace, callback, x, y, reduction, r, jac, grad / scale, step)
            if dx_norm < xtol * (xtol + np.linalg.norm(x)):
                return xnew, rnew, Status.DX_TOL, trace
            if ratio > 0.75:
                self.mu.decrease()
            elif ratio < 0.25:
                self.mu.increase()
            x, r = xnew, rnew
        return x, r, Status.MAX_ITER, trace

    def _record(self, trace, callback, x, y, reduction, r, jac, grad, step):
        """Log an iteration (in full with FULLITER) and call the user's callback."""
        log = IterLog(candidate=x, objective=y, reduction=reduction,
                      regularizer=self.mu.value)
        if self.say.full:
            log = dataclasses.replace(log, residual=r, jacobian=jac, grad=grad, step=step)
        trace.append(log)
        if callback is not None:
            callback(trace)

    def _check_derivatives(self, x, r, jac):
        problem = self.problem
        if problem.jacobian_fn is not None:
            problem.n_res = _compare_jacobian(
                problem.residual_fn, x, r, jac, problem.eps, problem.n_res,
                self.box, "Jacobian")
            self.say.check("User-provided Jacobian matches finite-differences.")
        if not isinstance(self.norm, Quadratic):
            for line in _check_norm(r, self.norm, problem.eps):
                self.say.check(line)

    def _free(self, x, grad):
        """The gradient less the components that an active bound holds."""
        if self.box is None:
            return grad
        lower, upper = self.box
        held = ((x == lower) & (grad > 0)) | ((x == upper) & (grad < 0))
        return grad[~held]

    def _line_search(self, x, y, grad, hess, scale):
        """Raise mu until a step passes Armijo's rule.

        Returns (status, xnew, rnew, reduction); status is None on success.
        """
        mu = self.mu
        dlower = dupper = None
        if self.box is not None:
            dlower, dupper = ((bound - x) / scale for bound in self.box)
        while True:
            if not self._solve_qp(hess, grad, dlower, dupper):
                return Status.FACTORIZATION_FAILED, None, None, 0.0
            xnew = self._step(x, scale, dlower, dupper)
            rnew = self.problem.residual(xnew)
            ynew = self.norm.value(rnew)
            reduction = y - ynew
            # a nonfinite objective is a failed trial, not a reduction
            if np.isfinite(ynew) and reduction + _ARMIJO_C1 * (grad.T @ self.dz).item() >= 0:
                return None, xnew, rnew, reduction
            if mu.exhausted:
                return Status.NO_IMPROVEMENT, None, None, 0.0
            mu.increase()

    def _solve_qp(self, hess, grad, dlower, dupper):
        """Solve the regularized QP into self.dz, raising mu until H + mu*I factors."""
        while mju_boxQP(self.dz, self.scratch, None, hess + self.mu.value * self.eye,
                        grad, dlower, dupper) < 0:
            if self.mu.exhausted:
                return False
            self.mu.increase()
        return True

    def _step(self, x, scale, dlower, dupper):
        """x + scale * dz, landing exactly on a bound where the QP made it active.

        x + (lower - x) need not round to lower; snapping keeps the bound
        recognizable as active (x == lower) and the residual inside the box.
        """
        xnew = x + scale * self.dz
        if self.box is not None:
            lower, upper = self.box
            xnew = np.where(self.dz <= dlower, lower, xnew)
            xnew = np.where(self.dz >= dupper, upper, xnew)
            np.clip(xnew, lower, upper, out=xnew)
        return xnew

    def _ratio(self, reduction, grad, hess):
        """Actual over predicted reduction (the prediction leaves mu out)."""
        dz = self.dz
        predicted = -(grad.T @ dz + 0.5 * dz.T @ hess @ dz).item()
        if predicted > 0:
            return reduction / predicted
        if predicted == 0:
            self.say.note("Predicted reduction is zero: exact minimum found?")
        else:
            self.say.note("Predicted reduction is negative (rounding error?).")
        return 0.0


def _finish(problem, norm, x, r, mu, verbosity, trace, callback):
    """Append the entry of the final point, with its derivatives if FULLITER."""
    log = IterLog(candidate=x, objective=norm.value(r), reduction=np.float64(0.0),
                  regularizer=mu)
    if verbosity >= Verbosity.FULLITER.value:
        jac = problem.jacobian(x, r)
        grad, _ = _grad_hess(norm, r, jac, problem.n)
        log = dataclasses.replace(log, residual=r, jacobian=jac, grad=grad)
    trace.append(log)
    if callback is not None:
        callback(trace)


class _Printer:
    """least_squares' messages, as much of them as the verbosity asks."""

    def __init__(self, output, verbosity):
        self.output, self.verbosity = output, verbosity
        self.full = verbosity >= Verbosity.FULLITER.value

    def _print(self, text, level):
        if self.verbosity >= level:
            print(text, file=self.output)

    def note(self, text):
        self._print(text, Verbosity.FINAL.value)

    check = note

    def iteration(self, i, y, mu, ratio, dx_norm, reduction):
        log_mu = np.log10(mu) if mu > 0 else -np.inf
        self._print(
            f"iter: {i:<3d}  y: {y:<9.4g}  log10mu: {log_mu:>4.1f}  "
            f"ratio: {ratio:<7.2g}  dx: {dx_norm:<7.2g}  reduction: {reduction:<7.2g}",
            Verbosity.ITER.value)

    def summary(self, status, trace, problem, elapsed):
        if self.verbosity < Verbosity.FINAL.value:
            return
        text = (f"Terminated after {len(trace) - 1} iterations: {_STATUS_TEXT[status]} "
                f"y: {trace[-1].objective:<.4g}, Residual evals: {problem.n_res:d}")
        if problem.n_jac:
            text += f", Jacobian evals: {problem.n_jac:d}"
        print(text, file=self.output)
        if elapsed > 0:
            ms = elapsed <= 1
            text = (f"total time {elapsed * (1000 if ms else 1):<.1f}{'ms' if ms else 's'}"
                    f" of which residual {100 * problem.t_res / elapsed:<.1f}%")
            if problem.t_jac:
                text += f" Jacobian {100 * problem.t_jac / elapsed:<.1f}%"
            print(text, file=self.output)
