"""The contract every engine adapter implements (brax-style: same shape in every module).

An adapter module exposes ``availability() -> (bool, str)`` and ``create(preset) -> Engine``.
An :class:`Engine` states per scene feature whether it supports it (natively, approximated with
how and how large, or not with why), and runs a scene into a :class:`~.trajectory.Trajectory`.
"""

from __future__ import annotations

import enum
from abc import ABC, abstractmethod
from dataclasses import dataclass, field

from clearbench.adapters.trajectory import RunStatus, Trajectory
from clearbench.scenarios.scene import Scene


class Support(enum.Enum):
    NATIVE = "native"
    APPROXIMATED = "approximated"
    UNSUPPORTED = "unsupported"


@dataclass(frozen=True)
class Capability:
    """How an engine handles one scene feature."""

    support: Support
    detail: str = ""


@dataclass(frozen=True)
class RunSettings:
    """What a run asks of an engine (times in the scene's time unit).

    ``time_step`` and ``horizon`` default to the scene's; ``record_every`` keeps one sample
    every that many steps (the last step is always kept); ``options`` are engine-specific
    overrides of the preset.
    """

    time_step: float | None = None
    horizon: float | None = None
    record_every: int = 1
    options: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.time_step is not None and not self.time_step > 0:
            raise ValueError(f"time_step must be > 0, got {self.time_step!r}")
        if self.horizon is not None and not self.horizon > 0:
            raise ValueError(f"horizon must be > 0, got {self.horizon!r}")
        if self.record_every < 1:
            raise ValueError(f"record_every must be >= 1, got {self.record_every!r}")


class Engine(ABC):
    """An engine (with a preset) able to run scenes."""

    name: str = ""
    preset: str = "default"

    @property
    def label(self) -> str:
        """``engine[preset]`` as used in results."""
        return f"{self.name}[{self.preset}]"

    @abstractmethod
    def capabilities(self, scene: Scene) -> dict[str, Capability]:
        """Support of each feature of ``scene.features``."""

    def unsupported_reasons(self, scene: Scene) -> list[str]:
        """Why the scene cannot run here (empty when it can)."""
        return [
            f"{feature}: {capability.detail}"
            for feature, capability in sorted(self.capabilities(scene).items())
            if capability.support is Support.UNSUPPORTED
        ]

    def run(self, scene: Scene, settings: RunSettings | None = None) -> Trajectory:
        """Run ``scene``; an unsupported scene gives an UNSUPPORTED trajectory, not an error."""
        settings = settings or RunSettings()
        reasons = self.unsupported_reasons(scene)
        if reasons:
            return Trajectory.empty(self.name, self.preset, scene, RunStatus.UNSUPPORTED,
                                    "; ".join(reasons))
        return self._run(scene, settings)

    @abstractmethod
    def _run(self, scene: Scene, settings: RunSettings) -> Trajectory:
        """Run a supported scene."""
