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

from ._derivatives import check_jacobian, check_norm, jacobian_fd
from ._solver import least_squares
from ._types import IterLog, Norm, Quadratic, Status, Verbosity

__all__ = [
    "IterLog", "Norm", "Quadratic", "Status", "Verbosity",
    "check_jacobian", "check_norm", "jacobian_fd", "least_squares",
]
