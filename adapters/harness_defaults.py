"""What an engine declares to the harness about itself: its runs in the quick regression suite,
whether its figures are exact (rigid contacts) or spread by compliance, whether it compiles
numba kernels, its C-60 ladders, its colour in the report, and the perturbations of its own
arithmetic.

Each engine subpackage declares one :class:`HarnessDefaults` as ``HARNESS_DEFAULTS`` in its
``__init__`` (plain data: reading it imports neither the adapter's modules nor the engine's
package); an engine plugged in with ``--engine-module NAME=MODULE`` declares it in that module.
The harness derives from them, for every engine of :data:`clearbench.adapters.ENGINES` and
every plugged-in one, the quick suite of a new baseline (``clearbench regress``), the tolerance
class of its figures, the numba warm-up, the C-60 plans (``clearbench c60 compare``) and the
report's colours. An engine that declares nothing gets :data:`UNDECLARED`: the shared quick
scenes in its ``default`` preset, compliant, no C-60 ladder, a colour from the palette.

Times are in the time unit of the scene they apply to (s for the library's quick scenes, ms
for the C-60, whose units are mm-g-ms).

The C-60 step costs the engines declare (``c60_step_cost``) were measured by one ``clearbench
demo`` on a 2-core machine (each engine's demo-plan c60-on runs, 4 ms of horizon, wall time per
step over the reference's 1.35 ms per step at 1 us): MuJoCo tuned 0.32, PyBullet tuned 4.3,
Drake tuned 9.6, Siconos 53 (at 10 us); Exudyn mechanism 5.8 (the "x ref" column of the C-60
table of a later ``clearbench demo``, its idle connectors switched off; 98 with every
connector on).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field

#: The C-60 scenes of the cross-engine plans (registered scene names).
C60_ON = "c60-on"
C60_TRIP = "c60-trip"


@dataclass(frozen=True)
class QuickRun:
    """One run of an engine in the quick regression suite (``clearbench regress``).

    Attributes
    ----------
    scene : str
        Registered scene name.
    horizon : float, optional
        Run horizon [scene time unit] (default: the scene's).
    preset : str, optional
        Preset of this run (default: :attr:`HarnessDefaults.regress_preset`).
    parameters : Mapping
        The scene factory's keyword parameters (as ``--set``), e.g. the C-60's ``horizon``.
    time_step : float, optional
        Step [scene time unit] (default: the scene's).
    record_every : int
        Steps between recorded samples.
    ensemble : int, optional
        Round-off perturbations its tolerances are measured from (default: the baseline's
        round-off seeds); chaotic runs need an ensemble of 8 (``harness/studies/regress``).
    ident : str, optional
        Its id in the baseline (default ``ENGINE[PRESET] SCENE``).
    """

    scene: str
    horizon: float | None = None
    preset: str | None = None
    parameters: Mapping[str, object] = field(default_factory=dict)
    time_step: float | None = None
    record_every: int = 1
    ensemble: int | None = None
    ident: str | None = None

    def __post_init__(self) -> None:
        for name in ("horizon", "time_step"):
            value = getattr(self, name)
            if value is not None and not value > 0:
                raise ValueError(f"QuickRun({self.scene!r}).{name} = {value!r}: must be > 0")
        if self.record_every < 1:
            raise ValueError(f"QuickRun({self.scene!r}).record_every = {self.record_every!r}: "
                             "must be >= 1")
        if self.ensemble is not None and self.ensemble < 1:
            raise ValueError(f"QuickRun({self.scene!r}).ensemble = {self.ensemble!r}: "
                             "must be >= 1")

    def entry(self, engine: str, default_preset: str) -> dict:
        """The suite entry of this run for ``engine`` (a plain dict, as in a baseline file:
        ``harness/studies/regress/suite.py``)."""
        label = f"{engine}[{self.preset or default_preset}]"
        entry: dict = {"id": self.ident or f"{label} {self.scene}", "scene": self.scene,
                       "engine": label}
        if self.parameters:
            entry["parameters"] = dict(self.parameters)
        if self.time_step is not None:
            entry["time_step"] = self.time_step
        if self.horizon is not None:
            entry["horizon"] = self.horizon
        if self.record_every != 1:
            entry["record_every"] = self.record_every
        if self.ensemble is not None:
            entry["ensemble"] = self.ensemble
        return entry


#: The quick scenes every engine runs unless it declares others: a bounce (restitution,
#: contact), stick on an incline (friction) and a pendulum (an ideal joint); horizons [s].
QUICK_SCENES = (QuickRun("bouncing-ball-e0.5", 1.0), QuickRun("incline-stick", 0.3),
                QuickRun("pendulum", 1.0))


def short_c60(horizon: float = 0.2, time_step: float = 1e-3, preset: str | None = None,
              ensemble: int | None = None) -> QuickRun:
    """The short ``c60-on`` of the quick suite: ``horizon`` and ``time_step`` in ms, a sample
    every 10 steps. 0.2 ms covers the first settling impacts of the joints."""
    return QuickRun(C60_ON, preset=preset, parameters={"horizon": horizon},
                    time_step=time_step, record_every=10, ensemble=ensemble)


@dataclass(frozen=True)
class OptionPerturbation:
    """A setting of the engine's own that changes only its arithmetic (another factorisation
    order, another summation), under which the regression tolerances of its runs are also
    measured (a baseline's ``perturbations``, kind ``options``)."""

    name: str
    options: Mapping[str, object]
    why: str


#: Plan name -> scene -> preset -> ladder of steps [ms] (the plans of ``clearbench c60
#: compare``: ``demo`` and ``full``).
C60Ladders = Mapping[str, Mapping[str, Mapping[str, tuple[float, ...]]]]


def both_c60_scenes(ladder: Mapping[str, tuple[float, ...]]) -> dict:
    """``{c60-on: ladder, c60-trip: ladder}``: the same ladder (preset -> steps [ms]) on both
    C-60 scenes."""
    return {C60_ON: dict(ladder), C60_TRIP: dict(ladder)}


_COLOUR = re.compile(r"^#[0-9A-Fa-f]{6}$")


@dataclass(frozen=True)
class HarnessDefaults:
    """An engine's declaration to the harness (see the module docstring).

    Attributes
    ----------
    regress_preset : str
        The preset its quick-suite runs use unless a run names its own.
    regress_runs : tuple of QuickRun
        Its runs in the quick suite of a new baseline (``clearbench regress``).
    rigid_contacts : bool
        Contacts without compliance (impulses, no contact spring): its penetration, joint
        errors and stick creep are round-off or a solver tolerance, checked as bounds, not as
        values; a compliant engine's are properties of its contact model, checked as values.
        Also recorded in each trajectory's metadata (``Engine.RIGID_CONTACTS``).
    numba : bool
        Its runs compile numba kernels: the suite first fills numba's cache with one short
        run per scene, so that parallel fresh workers do not all compile at once.
    perturbations : tuple of OptionPerturbation
        Settings of its own that change only its arithmetic, for a new baseline.
    c60_ladders : C60Ladders
        Plan -> C-60 scene -> preset -> steps [ms] of ``clearbench c60 compare`` (an engine
        that cannot build the C-60 may still declare a step: its run is recorded
        ``unsupported`` with the reason).
    c60_step_cost : float
        Its wall time per C-60 step relative to the reference engine's (both at their plan
        steps, measured side by side in one ``clearbench c60 compare``: wall [s] / steps). The
        plans start the runs of largest expected cost (steps x this) first, so that a plan's
        wall time is about its longest run's rather than that run's plus all before it.
    colour : str, optional
        ``#RRGGBB`` of its lines in every figure of the report (default: one of the
        palette's, the same for the same name).
    """

    regress_preset: str = "default"
    regress_runs: tuple[QuickRun, ...] = QUICK_SCENES
    rigid_contacts: bool = False
    numba: bool = False
    perturbations: tuple[OptionPerturbation, ...] = ()
    c60_ladders: C60Ladders = field(default_factory=dict)
    c60_step_cost: float = 1.0
    colour: str | None = None

    def __post_init__(self) -> None:
        if not self.c60_step_cost > 0:
            raise ValueError(f"HarnessDefaults.c60_step_cost = {self.c60_step_cost!r}: "
                             "must be > 0")
        if self.colour is not None and not _COLOUR.match(self.colour):
            raise ValueError(f"HarnessDefaults.colour = {self.colour!r}: expected #RRGGBB")
        for plan, scenes in self.c60_ladders.items():
            for scene, ladder in scenes.items():
                for preset, steps in ladder.items():
                    if not steps or not all(float(dt) > 0 for dt in steps):
                        raise ValueError(f"HarnessDefaults.c60_ladders[{plan!r}][{scene!r}]"
                                         f"[{preset!r}] = {steps!r}: expected steps > 0")

    def regress_entries(self, engine: str) -> list[dict]:
        """The suite entries of ``engine``'s :attr:`regress_runs`."""
        return [run.entry(engine, self.regress_preset) for run in self.regress_runs]


#: What an engine that declares nothing gets.
UNDECLARED = HarnessDefaults()


def declared_defaults(module) -> HarnessDefaults:
    """The ``HARNESS_DEFAULTS`` of an engine's module (:data:`UNDECLARED` when it has none).

    Raises
    ------
    TypeError
        ``HARNESS_DEFAULTS`` is not a :class:`HarnessDefaults`.
    """
    declared = getattr(module, "HARNESS_DEFAULTS", UNDECLARED)
    if not isinstance(declared, HarnessDefaults):
        raise TypeError(f"{module.__name__}.HARNESS_DEFAULTS is a {type(declared).__name__}, "
                        "not a HarnessDefaults")
    return declared
