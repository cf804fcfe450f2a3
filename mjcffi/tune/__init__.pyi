from typing import Any, Literal, Mapping

import numpy as np

from ..evaluation.measures import Estimate
from ..evaluation.settings import Setting
from ..evaluation.timing import Speed
from ..model import MjModel

OBJECTIVES: tuple[str, ...]

class Stage:
    flag: int
    name: str
    reason: str
    def __init__(self, flag: int, name: str, reason: str) -> None: ...

def unneeded_stages(m: MjModel) -> list[Stage]: ...

class Change:
    name: str
    before: Any
    after: Any
    reason: str

class TuneError:
    local: dict[str, float]
    original_local: dict[str, float]
    budget: dict[str, float]
    stability: Any
    original_stability: Any
    local_bound: dict[str, float] | None
    original_bound: dict[str, float] | None
    bounded: bool
    reference_penetration: float
    divergence: Any

class Candidate:
    setting: Setting
    nstep: int
    estimates: dict[str, Estimate]
    speed: Speed | None
    status: str
    held_out: dict[str, Estimate] | None
    stability: Any
    divergence: Any
    reasons: dict[str, str]
    @property
    def error(self) -> dict[str, float]: ...
    @property
    def speedup(self) -> float | None: ...
    @property
    def measured(self) -> bool: ...
    def label(self, original: Setting) -> str: ...

class TuneResult:
    model: MjModel
    original: MjModel
    setting: Setting
    original_setting: Setting
    settings: dict[str, Change]
    outcome: Literal["faster", "original", "slower"]
    original_meets: bool
    speedup: float
    speed: Speed | None
    error: TuneError
    candidates: list[Candidate]
    budget_name: str
    objective: str
    control_period: float
    period_source: str
    wall_time: float
    evaluations: int
    timings: int
    disable_set: int
    def options(self) -> dict[str, Any]: ...
    def report(self, plot: str | None = ...) -> str: ...
    def write_xml(self, source: str, out_path: str) -> tuple[str, str]: ...
    def _repr_markdown_(self) -> str | None: ...
    def _repr_html_(self) -> str: ...

class BudgetError(ValueError):
    best: Candidate
    candidates: list[Candidate]

def tune(model: MjModel, budget: float | Mapping[str, float] | Literal["original"], *,
         control_period: float | None = ..., control: np.ndarray | None = ...,
         horizon: float | None = ..., states: np.ndarray | None = ...,
         objective: Literal["cheapest", "accurate"] = ..., nthread: int | None = ...,
         seed: int = ..., progress: bool = ..., ray: bool = ...) -> TuneResult: ...
