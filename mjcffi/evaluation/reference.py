"""The fine reference every setting is compared with."""

from .._generated.enums import mjtIntegrator, mjtSolver
from .settings import Setting

REF_FACTOR = 100          # the reference timestep is the model's own divided by this
REF_TOLERANCE = 1e-12
REF_ITERATIONS = 100
REF_LS_ITERATIONS = 50


def reference_setting(m, tight_solver=True, timestep=None):
    """RK4 at the model's timestep (or `timestep`) / REF_FACTOR, and with `tight_solver`
    Newton run to a tolerance of 1e-12.

    The constraint problem MuJoCo solves is convex with one solution, so Newton at a tight
    tolerance finds the same forces PGS or CG would converge to, only sooner.  The cone and
    noslip stay the model's own: they change the physics, not only the precision.
    """
    dt = (m.opt.timestep if timestep is None else timestep) / REF_FACTOR
    if not tight_solver:
        return Setting(int(mjtIntegrator.mjINT_RK4), dt)
    return Setting(int(mjtIntegrator.mjINT_RK4), dt, solver=int(mjtSolver.mjSOL_NEWTON),
                   iterations=max(int(m.opt.iterations), REF_ITERATIONS),
                   tolerance=REF_TOLERANCE,
                   ls_iterations=max(int(m.opt.ls_iterations), REF_LS_ITERATIONS))
