from typing import Any, Literal, Mapping

import numpy as np

from ..evaluation.settings import Setting
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

class Candidate:
    setting: Setting
    nstep: int
    error: dict[str, float]
    speedup: float
    measured: bool
    status: str
    held_out: dict[str, float] | None
    reasons: dict[str, str]
    def label(self, original: Setting) -> str: ...

class TuneResult:
    model: MjModel
    original: MjModel
    setting: Setting
    original_setting: Setting
    settings: dict[str, Change]
    speedup: float
    error: TuneError
    candidates: list[Candidate]
    objective: str
    control_period: float
    wall_time: float
    evaluations: int
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
