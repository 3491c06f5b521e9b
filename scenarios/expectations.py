"""Physics expectations: what a scene must do, when physics says so.

Each expectation has a ``kind`` from :data:`EXPECTATION_KINDS`
(:mod:`.expectation_kinds`), which fixes the parameters it takes, their physical dimensions
and domains, and what the harness checks (the analytic formulas live in :mod:`.analytic`).
``body`` names the body it is about, where one is.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

from clearbench.scenarios.element import Element
from clearbench.scenarios.expectation_kinds import (
    EXPECTATION_KINDS,
    OUTPUT_DIMENSION,
    ExpectationKind,
)
from clearbench.scenarios.validation import DIMENSIONLESS, SceneError

__all__ = ["EXPECTATION_KINDS", "OUTPUT_DIMENSION", "Expectation", "ExpectationKind"]


@dataclass(frozen=True)
class Expectation(Element):
    """An expectation of ``kind`` about ``body`` (or the named ``output``, for
    ``output_value``) with ``parameters`` (name -> value, in the scene's units; dimensions
    fixed by the kind)."""

    collection = "expectations"
    kind: str = ""
    body: str | None = None
    parameters: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))
    output: str | None = None

    def _validate(self) -> None:
        if self.kind not in EXPECTATION_KINDS:
            raise SceneError("kind", self.kind, f"must be one of {sorted(EXPECTATION_KINDS)}")
        spec = EXPECTATION_KINDS[self.kind]
        if spec.needs_body and not self.body:
            raise SceneError("body", self.body, f"expectation {self.kind!r} needs a body")
        if spec.needs_output and not self.output:
            raise SceneError("output", self.output,
                             f"expectation {self.kind!r} needs the name of an [[outputs]] entry")
        if self.output is not None and not spec.needs_output:
            raise SceneError("output", self.output, f"expectation {self.kind!r} takes no output")
        self._set("parameters", MappingProxyType(spec.check_parameters(dict(self.parameters))))

    @property
    def statement(self) -> str:
        return EXPECTATION_KINDS[self.kind].statement

    def field_dimension(self, name: str) -> dict | None:
        """Dimensions of the entries of ``parameters``."""
        if name == "parameters":
            # Parameters in the output's unit are converted by the scene (Scene.rescaled),
            # which knows the output: here they are left as they are.
            return {key: (DIMENSIONLESS if parameter.dimension == OUTPUT_DIMENSION
                          else parameter.dimension)
                    for key, parameter in EXPECTATION_KINDS[self.kind].parameters.items()
                    if key in self.parameters}
        return None

    def __hash__(self) -> int:
        return hash((self.name, self.kind, self.body, tuple(self.parameters.items()),
                     self.output))
