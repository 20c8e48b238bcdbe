"""Types of the native module `monolayer._native` (Rust, PyO3). Use it through `monolayer`."""

from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np

__version__: str

_Path = Union[str, PathLike[str]]

class Scene:
    """A scene: a scene file's text, the overrides set on it, validated."""

    @staticmethod
    def from_toml(path: _Path) -> Scene:
        """A scene read from a TOML file; relative paths in it are taken from its directory."""
    @staticmethod
    def read_run(path: _Path) -> Scene:
        """The resolved scene of a run directory, read to look at the run: an unregistered
        term is kept."""
        ...
    @staticmethod
    def from_text(text: str) -> Scene:
        """A scene from TOML text."""
    @staticmethod
    def from_dict(d: Dict[str, Any]) -> Scene:
        """A scene from a dict of tables, as the TOML file would have them."""
    def set(self, key: str, value: Any) -> Scene:
        """Sets `section.key` (as `--set`), validates again, returns the scene; a bad value
        raises ValueError with the command line's message and leaves the scene as it was."""
    def update(self, values: Dict[str, Any]) -> Scene:
        """Sets several keys, validating once after all of them; returns the scene."""
    def copy(self) -> Scene:
        """A copy, to change without changing this one."""
    def to_toml(self) -> str:
        """The resolved scene: every key with its value, as DIR/scene.toml holds it."""
    @property
    def end_time(self) -> float:
        """The model time at the end of the run, relax_time + time."""
    @property
    def overrides(self) -> List[str]:
        """The overrides set, as section.key=value."""

class Observation:
    """What a callback sees: the state after a step."""

    time: float
    iteration: int
    cells: Dict[str, np.ndarray]
    def stop(self) -> None:
        """Asks the run to stop after this step's callbacks."""

class Edit:
    """A change to the state between steps, applied when the function given it returns."""

    time: float
    iteration: int
    ids: List[int]
    def set_param(self, name: str, value: float) -> None:
        """Sets zeta, xi, gamma, mu, lambda, kappa or omega."""
    def state(self, name: str) -> List[float]:
        """A term's per-cell state (such as "polarity.theta"), one value per identity."""
    def set_state(self, name: str, values: List[float]) -> None:
        """Sets a term's per-cell state, one value per identity."""

class Simulation:
    """A scene simulated in memory (use `monolayer.Simulation`)."""

    def __init__(self, scene: Scene, threads: Optional[int] = None, backend: str = "cpu") -> None: ...
    @property
    def scene(self) -> Scene: ...
    @property
    def time(self) -> float: ...
    @property
    def iteration(self) -> int: ...
    @property
    def n_cells(self) -> int: ...
    def step(self, n: int) -> None: ...
    def run_until(self, until: Optional[float] = None, progress: Optional[Callable[[float], Any]] = None) -> None: ...
    def cells(self) -> Dict[str, np.ndarray]: ...
    def phi(self) -> Tuple[np.ndarray, np.ndarray, np.ndarray]: ...
    def fields(self) -> Dict[str, np.ndarray]: ...
    def observables(self) -> Dict[str, float]: ...
    def add_callback(self, func: Callable[[Observation], Any], every: Optional[float] = None, steps: Optional[int] = None) -> None: ...
    def add_force(self, func: Callable[[float, Dict[str, np.ndarray]], Any], name: Optional[str] = None) -> None: ...
    def add_fix(self, func: Callable[[Edit], Any], every: Optional[float] = None, steps: Optional[int] = None) -> None: ...
    def edit(self, func: Callable[[Edit], Any]) -> None: ...
    def render(self, colour: str = "none", **options: Any) -> bytes: ...

def run_dir(
    scene: Scene,
    out: _Path,
    overwrite: bool = False,
    threads: Optional[int] = None,
    progress: Optional[Callable[[float], Any]] = None,
) -> Tuple[Dict[str, Any], List[str]]:
    """Runs a scene into a run directory as `monolayer run`: (what it did, warnings)."""

def resume_dir(
    dir: _Path,
    time: Optional[float] = None,
    threads: Optional[int] = None,
    progress: Optional[Callable[[float], Any]] = None,
) -> Dict[str, Any]:
    """Continues a run directory from its latest checkpoint, as `monolayer run --resume`."""

def render_dir(dir: _Path, steps: Optional[List[int]] = None, colour: str = "none", **options: Any) -> List[Tuple[int, bytes]]:
    """Frames of a run directory drawn as `monolayer render` draws them."""

def sweep_points(
    scene: Scene,
    vary: Dict[str, List[Any]],
    seeds: Optional[Tuple[int, int]] = None,
    out: Optional[_Path] = None,
) -> List[Tuple[str, Scene, Optional[str]]]:
    """The points of a sweep, with the sweep's description written into `out`."""
