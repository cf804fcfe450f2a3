"""mjcffi.minimize.least_squares against an independent solver (scipy) and the official one.

scipy.optimize.least_squares (trust-region reflective) shares no code with
mjcffi.minimize, so agreeing on the minimizer checks the answer itself; the
official mujoco.minimize runs the same algorithm on the same mju_boxQP, so
there the whole trace must agree, bit for bit.
"""

import io

import numpy as np
import pytest

scipy_optimize = pytest.importorskip("scipy.optimize")

import mjcffi  # noqa: E402
from mjcffi import minimize  # noqa: E402

SILENT = minimize.Verbosity.SILENT


def rosenbrock(x):
    """Vectorized Rosenbrock residual: its minimum, 0, is at (1, 1)."""
    return np.stack([1 - x[0, :], 10 * (x[1, :] - x[0, :] ** 2)])


def rosenbrock_jacobian(x, r):
    del r
    return np.array([[-1.0, 0.0], [-20.0 * x[0, 0], 10.0]])


def scipy_solve(fun, x0, **kwargs):
    """scipy's solution, to its tightest tolerances, for a residual of one point."""
    result = scipy_optimize.least_squares(
        lambda v: fun(v[:, None])[:, 0], x0, xtol=1e-15, ftol=1e-15, gtol=1e-15,
        **kwargs)
    return result.x


def test_the_module_is_a_lazy_attribute():
    assert mjcffi.minimize is minimize
    assert minimize.Verbosity.ITER.value == 2
    assert minimize.Status.G_TOL.value == 5
    with pytest.raises(TypeError):
        minimize.Norm()  # abstract


def test_linear_problem_matches_the_normal_equations():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(8, 3))
    b = rng.normal(size=8)
    exact = np.linalg.lstsq(a, b, rcond=None)[0]

    def residual(x):
        return a @ x - b[:, None]

    # With its exact Jacobian one Gauss-Newton step solves a linear problem,
    # so the answer is good to rounding (A is well conditioned).
    x, _ = minimize.least_squares(np.zeros(3), residual, jacobian=lambda x, r: a,
                                  verbose=SILENT)
    np.testing.assert_allclose(x, exact, rtol=0, atol=1e-12)
    # Forward differences of a linear residual err by rounding only, about
    # 1e-16 / eps = 1e-8 relative, which bounds the error of the solution.
    x, _ = minimize.least_squares(np.zeros(3), residual, verbose=SILENT)
    np.testing.assert_allclose(x, exact, rtol=0, atol=1e-7)
    np.testing.assert_allclose(x, scipy_solve(residual, np.zeros(3)), rtol=0, atol=1e-7)


@pytest.mark.parametrize("x0", [(0.0, 0.0), (-1.2, 1.0), (3.0, -2.0)])
def test_rosenbrock_matches_scipy(x0):
    x, trace = minimize.least_squares(np.array(x0), rosenbrock, verbose=SILENT)
    # The minimum is isolated and the residual is zero there, so both solvers
    # converge quadratically to it: far below the 1e-8 asked here.
    np.testing.assert_allclose(x, scipy_solve(rosenbrock, np.array(x0)), rtol=0, atol=1e-8)
    np.testing.assert_allclose(x, [1.0, 1.0], rtol=0, atol=1e-8)
    assert trace[-1].objective < 1e-20
    objectives = [log.objective for log in trace]
    assert objectives == sorted(objectives, reverse=True)  # every step reduces


def test_optimum_on_a_bound_matches_scipy():
    lower, upper = np.array([-2.0, -2.0]), np.array([0.5, 2.0])
    x, trace = minimize.least_squares(np.zeros(2), rosenbrock, bounds=[lower, upper],
                                      verbose=minimize.Verbosity.FULLITER,
                                      output=io.StringIO())
    expected = scipy_solve(rosenbrock, np.zeros(2), bounds=(lower, upper))
    # scipy's interior method approaches the bound without landing on it;
    # 1e-7 leaves room for that, while the box QP lands on it exactly.
    np.testing.assert_allclose(x, expected, rtol=0, atol=1e-7)
    np.testing.assert_allclose(x, [0.5, 0.25], rtol=0, atol=1e-10)
    assert x[0] == upper[0]
    grad = trace[-1].grad.ravel()
    assert grad[0] < 0  # the gradient pushes against the active bound
    assert abs(grad[1]) < 1e-8


def test_the_residual_is_never_evaluated_outside_the_bounds():
    lower, upper = np.array([0.2, -1.0, 0.0]), np.array([0.7, 1.0, 1e-9])
    target = np.array([[1.0], [0.3], [-4.0]])  # two of three outside the box

    def residual(x):
        assert np.all(x >= lower[:, None]) and np.all(x <= upper[:, None])
        return np.vstack([x - target, x[:1] * x[1:2]])

    x, _ = minimize.least_squares(np.array([0.5, 0.0, 5e-10]), residual,
                                  bounds=[lower, upper], verbose=SILENT)
    expected = scipy_solve(residual, np.array([0.5, 0.0, 5e-10]), bounds=(lower, upper))
    np.testing.assert_allclose(x, expected, rtol=0, atol=1e-7)
    assert x[0] == upper[0] and x[2] == lower[2]


def test_a_step_onto_a_bound_lands_exactly_on_it():
    # 0.6 + (1.7 - 0.6) rounds to 1.7000000000000002: a step of `upper - x`
    # computed in floating point overshoots the bound (the official solver
    # evaluates the residual there); the step must land on 1.7 itself.
    upper = 1.7
    assert 0.6 + (upper - 0.6) > upper
    evaluated = []

    def residual(x):
        evaluated.append(x.max())
        return x - 10.0

    x, trace = minimize.least_squares(np.array([0.6]), residual,
                                      bounds=[np.array([-5.0]), np.array([upper])],
                                      verbose=SILENT)
    assert x[0] == upper and trace[1].candidate[0, 0] == upper
    assert max(evaluated) <= upper


def test_a_user_jacobian_gives_the_finite_difference_answer():
    x_fd, trace_fd = minimize.least_squares(np.zeros(2), rosenbrock, verbose=SILENT)
    x_jac, trace_jac = minimize.least_squares(np.zeros(2), rosenbrock,
                                              jacobian=rosenbrock_jacobian, verbose=SILENT)
    # both reach the exact minimum, where the residual vanishes
    np.testing.assert_allclose(x_jac, x_fd, rtol=0, atol=1e-10)
    # forward differences err by O(eps * curvature) ~ 1e-7 here
    x = np.array([[0.3], [-0.7]])
    jac_fd, n_res = minimize.jacobian_fd(rosenbrock, x, rosenbrock(x), np.float64(1.5e-8), 5)
    np.testing.assert_allclose(jac_fd, rosenbrock_jacobian(x, None), rtol=0, atol=1e-6)
    assert n_res == 5 + 2


def test_a_wrong_user_jacobian_is_caught():
    def wrong(x, r):
        return rosenbrock_jacobian(x, r) * [[1.0, 1.0], [1.0, 1.5]]

    out = io.StringIO()
    with pytest.raises(ValueError, match="Jacobian does not match") as info:
        minimize.least_squares(np.zeros(2), rosenbrock, jacobian=wrong,
                               check_derivatives=True, output=out)
    assert "at index (1, 1)" in info.value.__notes__[0]
    minimize.least_squares(np.zeros(2), rosenbrock, jacobian=rosenbrock_jacobian,
                           check_derivatives=True, output=out)
    assert "User-provided Jacobian matches finite-differences." in out.getvalue()


class SoftL1(minimize.Norm):
    """scipy's 'soft_l1' loss: sum(sqrt(1 + r**2) - 1)."""

    def value(self, r):
        return np.sum(np.sqrt(1 + r ** 2) - 1)

    def grad_hess(self, r, proj):
        s = np.sqrt(1 + r ** 2)
        return proj.T @ (r / s), proj.T @ (proj / s ** 3)


def test_a_robust_norm_matches_scipy_soft_l1():
    t = np.linspace(0, 1, 12)
    y = 2 * t + 1
    y[3] += 8  # an outlier the robust loss discounts

    def residual(x):
        return x[0] * t[:, None] + x[1] - y[:, None]

    x, _ = minimize.least_squares(np.zeros(2), residual, norm=SoftL1(),
                                  check_derivatives=True, output=io.StringIO(),
                                  verbose=SILENT)
    expected = scipy_solve(residual, np.zeros(2), loss="soft_l1")
    # the same smooth convex objective: both stop within gtol of its minimizer
    np.testing.assert_allclose(x, expected, rtol=0, atol=1e-6)
    plain, _ = minimize.least_squares(np.zeros(2), residual, verbose=SILENT)
    assert abs(x[1] - 1) < abs(plain[1] - 1)  # the outlier pulls it less


def test_a_residual_that_raises_passes_its_exception_through():
    class Broken(Exception):
        pass

    calls = []

    def residual(x):
        calls.append(x)
        if len(calls) > 2:
            raise Broken("model exploded")
        return rosenbrock(x)

    with pytest.raises(Broken, match="model exploded"):
        minimize.least_squares(np.zeros(2), residual, verbose=SILENT)


@pytest.mark.parametrize("bad, error, message", [
    (lambda x: rosenbrock(x).ravel(), ValueError, r"shape \(nr, 1\) .* got \(2,\)"),
    (lambda x: rosenbrock(x)[:, :1], ValueError, r"shape \(2, 2\) .* got \(2, 1\)"),
    (lambda x: rosenbrock(x).astype(np.float32), ValueError, "must return float64"),
    (lambda x: rosenbrock(x).tolist(), TypeError, "must return a NumPy array, not list"),
    (lambda x: rosenbrock(x) + np.nan, ValueError, "residual at x0 is not finite"),
])
def test_a_residual_of_the_wrong_kind_is_a_clear_error(bad, error, message):
    # the second case is right at one point and wrong for the n points of the
    # finite differences
    with pytest.raises(error, match=message):
        minimize.least_squares(np.zeros(2), bad, verbose=SILENT)


def test_a_jacobian_of_the_wrong_shape_is_a_clear_error():
    with pytest.raises(ValueError, match=r"jacobian must return an array of shape \(2, 2\)"):
        minimize.least_squares(np.zeros(2), rosenbrock, jacobian=lambda x, r: np.eye(3),
                               verbose=SILENT)


@pytest.mark.parametrize("kwargs, message", [
    (dict(bounds=[np.zeros(2)]), "bounds must have 2 elements."),
    (dict(bounds=[np.zeros(3), np.ones(3)]), "bounds must have the same size as x0."),
    (dict(bounds=[np.zeros(2), np.array([1.0, np.inf])]), "bounds must be finite."),
    (dict(bounds=[np.zeros(2), np.array([1.0, 0.0])]),
     "bounds[0] must be smaller than bounds[1]."),
    (dict(x0=np.array([np.nan, 0.0])), "x0 must be finite."),
    (dict(x0=np.zeros(0)), "x0 must not be empty."),
    (dict(x_scale=np.ones(3)), "x_scale array must have shape (2,), got (3,)."),
    (dict(x_scale=np.array([1.0, 0.0])), "x_scale must be positive and finite."),
    (dict(mu_factor=1.0), "mu_factor must be > 1."),
])
def test_bad_arguments_raise_value_error(kwargs, message):
    kwargs = {"x0": np.zeros(2), "residual": rosenbrock, "verbose": SILENT, **kwargs}
    with pytest.raises(ValueError) as info:
        minimize.least_squares(**kwargs)
    assert str(info.value) == message  # details go to notes


@pytest.mark.parametrize("name", ["eps", "mu_min", "mu_max", "mu_factor", "xtol", "gtol"])
def test_float_arguments_no_float_holds_or_that_are_no_numbers(name):
    kwargs = {"x0": np.zeros(2), "residual": rosenbrock, "verbose": SILENT}
    with pytest.raises(ValueError, match=f"^{name} is too large for a float64"):
        minimize.least_squares(**kwargs, **{name: 2**1100})
    for bad in ("1e-3", [1e-3], None):
        with pytest.raises(TypeError, match=f"^{name} must be a real number"):
            minimize.least_squares(**kwargs, **{name: bad})


def test_messages_of_bad_arguments_are_the_official_ones(mujoco):
    import mujoco.minimize as official
    for kwargs in [dict(bounds=[np.zeros(3), np.ones(3)]), dict(x0=np.array([np.nan, 0.0])),
                   dict(bounds=[np.zeros(2), np.array([1.0, 0.0])]), dict(x_scale="bogus")]:
        kwargs = {"x0": np.zeros(2), "residual": rosenbrock, "verbose": 0, **kwargs}
        with pytest.raises(ValueError) as ours:
            minimize.least_squares(**kwargs)
        with pytest.raises(ValueError) as theirs:
            official.least_squares(**kwargs)
        assert str(ours.value) == str(theirs.value)


def test_array_like_arguments_are_accepted():
    x, _ = minimize.least_squares([0.0, 0.0], rosenbrock, bounds=[[-2, -2], [0.5, 2]],
                                  verbose=SILENT)
    np.testing.assert_allclose(x, [0.5, 0.25], rtol=0, atol=1e-10)


def test_shape_of_x0_is_kept():
    x, _ = minimize.least_squares(np.zeros((2, 1)), rosenbrock, verbose=SILENT)
    assert x.shape == (2, 1)


def test_silent_prints_nothing_even_when_checking(capsys):
    out = io.StringIO()
    minimize.least_squares(np.zeros(2), rosenbrock, jacobian=rosenbrock_jacobian,
                           norm=SoftL1(), check_derivatives=True, verbose=SILENT, output=out)
    assert out.getvalue() == "" and capsys.readouterr().out == ""


def test_full_iteration_logs():
    out = io.StringIO()
    seen = []
    x, trace = minimize.least_squares(np.zeros(2), rosenbrock, output=out,
                                      verbose=minimize.Verbosity.FULLITER,
                                      iter_callback=lambda t: seen.append(len(t)))
    assert seen == list(range(1, len(trace) + 1))
    for log in trace[:-1]:
        assert log.residual.shape == (2, 1) and log.jacobian.shape == (2, 2)
        assert log.grad.shape == (2, 1) and log.step.shape == (2, 1)
    for before, after in zip(trace, trace[1:]):
        np.testing.assert_allclose(before.candidate + before.step, after.candidate)
    assert trace[-1].reduction == 0 and trace[-1].step is None
    lines = out.getvalue().splitlines()
    assert lines[0].startswith("iter: 0 ")
    assert f"Terminated after {len(trace) - 1} iterations: norm(gradient) < tol." in lines[-2]


def test_max_iter_and_no_improvement_statuses():
    out = io.StringIO()
    _, trace = minimize.least_squares(np.zeros(2), rosenbrock, max_iter=3, output=out)
    assert len(trace) == 4 and "maximum iterations reached." in out.getvalue()

    def residual(x):  # undefined below 0, where every full step goes
        return np.where(x >= 0, x + 1, np.nan)

    out = io.StringIO()
    x, trace = minimize.least_squares(np.array([0.0]), residual, mu_max=1e-2, output=out)
    assert x == 0 and len(trace) == 1 and "insufficient reduction." in out.getvalue()


def test_check_norm_rejects_an_indefinite_hessian():
    class Saddle(minimize.Norm):
        def value(self, r):
            return 0.5 * (r[0, 0] ** 2 - r[1, 0] ** 2)

        def grad_hess(self, r, proj):
            h = np.diag([1.0, -1.0])
            return proj.T @ (h @ r), proj.T @ h @ proj

    with pytest.raises(ValueError, match="not positive definite. Minimum eigenvalue is -1"):
        minimize.check_norm(np.array([[1.0], [2.0]]), Saddle(), np.float64(1e-6))
    out = io.StringIO()
    minimize.check_norm(np.array([[1.0], [2.0]]), SoftL1(), np.float64(1e-6), output=out)
    assert out.getvalue().count("matches finite-differences.") == 2


@pytest.mark.parametrize("name, residual, x0, kwargs", [
    ("rosenbrock", rosenbrock, [0.0, 0.0], {}),
    ("bounded", rosenbrock, [0.0, 0.0],
     dict(bounds=[np.array([-2.0, -2.0]), np.array([0.5, 2.0])])),
    ("powell, x_scale='jac'",
     lambda x: np.stack([1e4 * x[0] * x[1] - 1, np.exp(-x[0]) + np.exp(-x[1]) - 1.0001]),
     [0.0, 1.0], dict(x_scale="jac")),
])
def test_same_trace_as_the_official(mujoco, name, residual, x0, kwargs):
    import mujoco.minimize as official
    x0 = np.array(x0)
    ours = minimize.least_squares(x0, residual, verbose=0, **kwargs)
    theirs = official.least_squares(x0, residual, verbose=0, **kwargs)
    # Same algorithm, same NumPy operations on the same values, same mju_boxQP
    # in the same libmujoco: the results are equal to the last bit.
    np.testing.assert_array_equal(ours[0], theirs[0])
    assert len(ours[1]) == len(theirs[1])
    for a, b in zip(ours[1], theirs[1]):
        np.testing.assert_array_equal(a.candidate, b.candidate)
        assert (a.objective, a.reduction, a.regularizer) == (
            b.objective, b.reduction, b.regularizer)
