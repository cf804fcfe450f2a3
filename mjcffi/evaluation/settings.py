"""A setting of a model's options: what `accuracy` sweeps and `tune` searches."""

import dataclasses
from typing import Optional

from .._generated.enums import mjtCone, mjtDisableBit, mjtIntegrator, mjtJacobian, mjtSolver

INTEGRATOR_NAMES = {int(mjtIntegrator.mjINT_EULER): "Euler",
                    int(mjtIntegrator.mjINT_RK4): "RK4",
                    int(mjtIntegrator.mjINT_IMPLICIT): "implicit",
                    int(mjtIntegrator.mjINT_IMPLICITFAST): "implicitfast"}
SOLVER_NAMES = {int(mjtSolver.mjSOL_PGS): "PGS", int(mjtSolver.mjSOL_CG): "CG",
                int(mjtSolver.mjSOL_NEWTON): "Newton"}
CONE_NAMES = {int(mjtCone.mjCONE_PYRAMIDAL): "pyramidal", int(mjtCone.mjCONE_ELLIPTIC): "elliptic"}
JACOBIAN_NAMES = {int(mjtJacobian.mjJAC_DENSE): "dense", int(mjtJacobian.mjJAC_SPARSE): "sparse",
                  int(mjtJacobian.mjJAC_AUTO): "auto"}

# the MjOption fields a Setting may hold, beside integrator and timestep
SOLVER_FIELDS = ("solver", "iterations", "tolerance", "ls_iterations", "noslip_iterations",
                 "cone", "jacobian")
_SHORT = {"solver": "solver", "iterations": "iter", "tolerance": "tol", "ls_iterations": "ls",
          "noslip_iterations": "noslip", "cone": "cone", "jacobian": "jac"}
_NAMES = {"solver": SOLVER_NAMES, "cone": CONE_NAMES, "jacobian": JACOBIAN_NAMES}


@dataclasses.dataclass(frozen=True)
class Setting:
    """Integrator, timestep and solver options; None keeps the model's own value.

    `disable` adds mjtDisableBit bits; `enable_stages` clears them (a stage switched back on).
    """

    integrator: int
    timestep: float
    solver: Optional[int] = None
    iterations: Optional[int] = None
    tolerance: Optional[float] = None
    ls_iterations: Optional[int] = None
    noslip_iterations: Optional[int] = None
    cone: Optional[int] = None
    jacobian: Optional[int] = None
    disable: int = 0
    enable_stages: int = 0

    @classmethod
    def of(cls, m):
        """The model's own setting, every field filled in."""
        o = m.opt
        return cls(int(o.integrator), float(o.timestep), int(o.solver), int(o.iterations),
                   float(o.tolerance), int(o.ls_iterations), int(o.noslip_iterations),
                   int(o.cone), int(o.jacobian))

    def apply(self, m, base_disable=None):
        """Write this setting into `m.opt` (disable flags on top of `base_disable`, default
        the model's own)."""
        base = int(m.opt.disableflags) if base_disable is None else int(base_disable)
        m.opt.integrator = int(self.integrator)
        m.opt.timestep = float(self.timestep)
        for name in SOLVER_FIELDS:
            value = getattr(self, name)
            if value is not None:
                setattr(m.opt, name, value)
        m.opt.disableflags = (base | self.disable) & ~self.enable_stages

    def replace(self, **changes):
        return dataclasses.replace(self, **changes)

    def changes(self, original):
        """{field: (original value, this value)} for the fields that differ from `original`."""
        out = {}
        for f in ("integrator", "timestep") + SOLVER_FIELDS:
            mine, theirs = getattr(self, f), getattr(original, f)
            if mine is not None and mine != theirs:
                out[f] = (theirs, mine)
        return out

    def label(self, original=None):
        """A short name: integrator, dt, then the solver fields that are set (or, given
        `original`, only those that differ from it) and the stages switched on or off."""
        parts = [INTEGRATOR_NAMES[int(self.integrator)], f"dt={self.timestep:g}"]
        for f in SOLVER_FIELDS:
            value = getattr(self, f)
            if value is None or (original is not None and value == getattr(original, f)):
                continue
            parts.append(f"{_SHORT[f]}={value_name(f, value)}")
        if self.enable_stages:
            parts.append("+" + "+".join(flag_names(self.enable_stages)))
        if self.disable:
            parts.append("-" + "-".join(flag_names(self.disable)))
        return " ".join(parts)


def value_name(field, value):
    """How a field's value reads: enum names for solver, cone, jacobian and integrator."""
    if field == "integrator":
        return INTEGRATOR_NAMES[int(value)]
    if field in _NAMES:
        return _NAMES[field][int(value)]
    return f"{value:g}" if isinstance(value, float) else str(value)


def flag_names(bits):
    """The lower-case stage names of mjtDisableBit `bits` ('contact', 'constraint', ...)."""
    return [f.name[len("mjDSBL_"):].lower() for f in mjtDisableBit
            if f.name != "mjNDISABLE" and bits & f]
