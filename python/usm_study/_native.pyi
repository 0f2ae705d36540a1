# Type stubs of the compiled module usm_study._native (python/src/*.rs). The public API is
# usm_study/__init__.py, which wraps these and documents units; use that.
from typing import Any, Dict, List, Optional, Sequence, Tuple

class UsmStudyError(ValueError):
    """An error of usm-study; its message is located (file:line:col: key: ...) when the input has a place."""

class Run:
    @property
    def name(self) -> str: ...
    @property
    def mode(self) -> str: ...
    @property
    def design(self) -> str: ...
    @property
    def metrics(self) -> Dict[str, float]: ...
    @property
    def success(self) -> bool: ...
    @property
    def missed(self) -> Optional[str]: ...
    @property
    def failure(self) -> Optional[Tuple[float, str]]: ...
    def _columns(self) -> List[Tuple[str, bytes]]: ...

class Problem:
    def __init__(self, path: str) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def params(self) -> List[Dict[str, Any]]: ...
    @property
    def scenarios(self) -> List[str]: ...
    @property
    def metric_names(self) -> List[str]: ...
    @property
    def max_evals(self) -> int: ...
    def _evaluate(
        self, params: Dict[str, float]
    ) -> Tuple[List[List[Tuple[str, float]]], float, float, Optional[str]]: ...

def simulate(scenario: str, design: Optional[str] = None, overrides: Optional[Dict[str, Any]] = None) -> Run: ...
def simulate_many(
    scenario: str,
    params: List[Dict[str, Any]],
    design: Optional[str] = None,
    overrides: Optional[Dict[str, Any]] = None,
    jobs: int = 0,
) -> Tuple[List[str], List[bytes], List[bool], List[Optional[str]]]: ...
def design(name_or_path: str) -> Dict[str, Any]: ...
def scenario_info(
    name_or_path: str, design: Optional[str] = None, overrides: Optional[Dict[str, Any]] = None
) -> Dict[str, Any]: ...
def sweep(
    study: str,
    out: Optional[str] = None,
    jobs: int = 0,
    resume: bool = False,
    force: bool = False,
    case_timeout: float = 600.0,
) -> Dict[str, Any]: ...
def optimise(
    problem: str, out: Optional[str] = None, jobs: int = 0, resume: bool = False, plots: bool = True
) -> Dict[str, Any]: ...
def tcm(
    design: str,
    samples: Optional[int] = None,
    seed: int = 0,
    threshold: Optional[float] = None,
    sampling: str = "sobol",
    out: Optional[str] = None,
    char_length: Optional[float] = None,
    jobs: int = 0,
    mode: str = "transport",
    worst: Optional[int] = None,
) -> Tuple[str, str]: ...
