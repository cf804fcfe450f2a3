"""The vocabulary of least_squares: its verbosity, stop reasons, trace entries and norms."""

import abc
import dataclasses
import enum
from typing import Optional

import numpy as np


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
