"""Nonlinear least squares with box bounds, solved as a sequence of box-constrained QPs.

The interface of the official `mujoco.minimize`:

    from mjcffi import minimize
    x, trace = minimize.least_squares(x0, residual, bounds=[lower, upper])

`residual` is vectorized: it takes points as the columns of an (n, k) array and
returns their residuals as the columns of an (nr, k) float64 array.  At every
iteration the solver models `norm(residual(x + dx))` to second order
(Gauss-Newton), adds `mu * I` to the Hessian (Levenberg-Marquardt), and minimizes
the model within the bounds with MuJoCo's box-constrained QP solver `mju_boxQP`.
A step is taken once it meets Armijo's sufficient-decrease rule; `mu` then
follows the ratio of actual to predicted reduction, as in Fletcher (1971).
"""

import abc
import dataclasses
import enum
import time
from typing import Callable, List, Optional, Sequence, TextIO, Tuple, Union

import numpy as np

from ._errors import with_note
from ._functions import mju_boxQP  # generated; not among the overrides

__all__ = [
    "IterLog", "Norm", "Quadratic", "Status", "Verbosity",
    "check_jacobian", "check_norm", "jacobian_fd", "least_squares",
]

# A step must achieve this fraction of the reduction its slope promises (Armijo).
_ARMIJO_C1 = 1e-2
# check_jacobian's tolerance on |J - J_fd| relative to the sum of both |J|.
_JACOBIAN_RTOL = 1e-5


class Verbosity(enum.Enum):
    """How much least_squares prints: nothing, a summary, a line per iteration,
    or that and full logs (residual, Jacobian, gradient, step) in the trace."""

    SILENT = 0
    FINAL = 1
    ITER = 2
    FULLITER = 3


class Status(enum.Enum):
    """Why least_squares stopped."""

    FACTORIZATION_FAILED = 1
    NO_IMPROVEMENT = 2
    MAX_ITER = 3
    DX_TOL = 4
    G_TOL = 5


# the printed reasons (tests of user code look for these words)
_STATUS_TEXT = {
    Status.FACTORIZATION_FAILED: "factorization failed.",
    Status.NO_IMPROVEMENT: "insufficient reduction.",
    Status.MAX_ITER: "maximum iterations reached.",
    Status.DX_TOL: "norm(dx) < tol.",
    Status.G_TOL: "norm(gradient) < tol.",
}


@dataclasses.dataclass(frozen=True)
class IterLog:
    """One entry of the trace that least_squares returns.

    Attributes:
      candidate: the point (an n x 1 column) at which this iteration started.
      objective: norm(residual(candidate)).
      reduction: how much the step of this iteration reduced the objective.
      regularizer: the mu added to the Hessian's diagonal for that step.
      residual, jacobian, grad, step: the residual, its Jacobian, the gradient
        of the objective at the candidate and the step taken, all in the
        coordinates of x; recorded with Verbosity.FULLITER only.

    The last entry describes the point returned, with a zero reduction.
    """

    candidate: np.ndarray
    objective: np.float64
    reduction: np.float64
    regularizer: np.float64
    residual: Optional[np.ndarray] = None
    jacobian: Optional[np.ndarray] = None
    grad: Optional[np.ndarray] = None
    step: Optional[np.ndarray] = None


class Norm(abc.ABC):
    """A measure of the size of a residual vector: the objective is norm(r(x)).

    A subclass defines `value(r)`, the norm of a column vector r, and
    `grad_hess(r, proj)`, its gradient and Hessian with respect to r carried
    through `proj` (the Jacobian of r, nr x nx): `proj.T @ dnorm/dr` and
    `proj.T @ d2norm/dr2 @ proj`.  The norm does the projection itself so that
    a structured Hessian (diagonal, block sparse) never has to be formed.
    """

    @abc.abstractmethod
    def value(self, r: np.ndarray) -> np.float64:
        """The norm of the column vector r (nr x 1), a scalar."""

    @abc.abstractmethod
    def grad_hess(self, r: np.ndarray, proj: np.ndarray):
        """The projected gradient (nx x 1) and Hessian (nx x nx) at r (nr x 1).

        Returns `(proj.T @ g, proj.T @ H @ proj)`, g and H being the gradient
        and Hessian of the norm with respect to r, and proj an nr x nx matrix.
        """


class Quadratic(Norm):
    """Half the squared Euclidean norm, r.T @ r / 2: classical least squares."""

    def value(self, r: np.ndarray):
        """r.T @ r / 2."""
        return 0.5 * (r.T @ r).item()

    def grad_hess(self, r: np.ndarray, proj: np.ndarray):
        """(proj.T @ r, proj.T @ proj): the Hessian of the norm is the identity."""
        return proj.T @ r, proj.T @ proj


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


# ---------------------------------------------------------------------------
# the solver

_QUADRATIC = Quadratic()


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


# ---------------------------------------------------------------------------
# argument checks

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


# ---------------------------------------------------------------------------
# derivative checks

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
