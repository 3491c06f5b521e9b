"""The tolerance model: each figure of each run judged against what round-off moves it by.

``clearbench regress --update`` runs every suite entry as it is and under perturbations that
carry no physics (:mod:`.perturbations`), and records per run and figure a :class:`Check` of
one of three classes:

- **exact**: the perturbations moved the figure by at most round-off amplified by a solver's
  stopping tolerance (spread <= :data:`STATISTICAL_SPREAD` of its size). A new value passes
  within :data:`EXACT_WIDEN` times the measured spread plus a floor (below).
- **bounded**: a figure whose size, not its value, carries the physics: energy growth (energy
  may not grow; how much round-off or a contact model adds varies by machine, 9.66e-7 on one
  CPU and 8.99e-7 on another for the same code), quaternion norm errors and solver residuals
  (round-off of a normalisation or a stopping test), and the constraint violations of the rigid
  engines (those declaring ``rigid_contacts``, :mod:`clearbench.adapters.harness_defaults`:
  penetration, clearance excess, joint and driver errors, creep of a body that must stick:
  round-off or solver tolerance). A new value passes when
  its magnitude stays below :data:`BOUND_HEADROOM` times the largest magnitude measured, or
  below the floor.
- **statistical**: a figure the perturbations moved by more (impacts amplify round-off; the
  compliant engines' C-60 runs are chaotic): the runs form an ensemble, and a new value
  passes inside the ensemble's range widened by :data:`ENSEMBLE_WIDEN` times its width on
  each side, plus the floor.

The floor keeps a spread measured as exactly 0 on one machine from making a check bitwise:
:data:`FLOOR_RELATIVE` of the larger of the figure's magnitude and the scale of its dimension
in the scene (:func:`figure_scale`; e.g. the scene's size for a length, 1 for a relative
figure, the energy scale for an energy). Counts of iterations get a floor of their own
(:data:`COUNT_FLOOR_RELATIVE`, :data:`COUNT_FLOOR_ABSOLUTE`). A figure that was NaN in any
measured run may be NaN (e.g. a stop time when the box had not stopped).
"""

from __future__ import annotations

import math
import re
from dataclasses import asdict, dataclass

from clearbench.scenarios.scales import scene_size
from clearbench.scenarios.scene import Scene

#: An exact figure passes within this many times its measured spread (plus the floor). The
#: spread is the largest of a handful of samples of the round-off a machine adds; another
#: CPU's round-off is of the same kind but may sit in the tail of that distribution: for a
#: normal law the largest of 6 samples is about 1.3 standard deviations, 10 times it about
#: 13, so a legitimate move beyond it is practically excluded, while it stays orders of
#: magnitude below any physics change (a 1 % friction change moves a stop distance by 1 %).
EXACT_WIDEN = 10.0
#: Relative spread (of max(|value|, scale)) above which a figure is statistical, not exact:
#: round-off alone gives about N eps = 2e-13 after N = 1e3 steps; a solver that stops at a
#: relative tolerance of 1e-8..1e-10 moves its figures by about that much; 1e-6 is above
#: both and below the smallest physics change the suite must catch (1e-2 relative).
STATISTICAL_SPREAD = 1e-6
#: Floor of every check, relative to max(|value|, the scale of its dimension). A figure
#: computed over N = 1e3..1e4 steps accumulates round-off of about N eps = 2e-13..2e-12 of
#: its scale; a solver's relative stopping tolerance (1e-8 and below in the suite's engines)
#: can amplify that to its own size, hence 1e-8. It is 6 orders of magnitude below the
#: deliberate changes the suite must catch (1 % friction, 10 % restitution or clearance).
FLOOR_RELATIVE = 1e-8
#: A bounded figure passes below this many times the largest magnitude measured: only its
#: order of magnitude is a property of the code (measured: 7 % between two CPUs for the
#: clearance pendulum's contact-free energy growth, 15 % for a PyBullet C-60 penetration).
BOUND_HEADROOM = 10.0
#: An ensemble's range [min, max] is widened by this many times its width on each side:
#: for a normal law, the range of 8 draws spans about 2.8 standard deviations, so the widened
#: interval spans about +-4.2 around the mean (a new draw falls outside with probability
#: about 3e-5); heavy-tailed figures get the same room relative to their measured spread.
ENSEMBLE_WIDEN = 1.0
#: Floor of an iteration count (a mean over steps): a residual close to the stopping
#: tolerance needs one more iteration on another machine, in a few steps; 5 % of the mean
#: plus half an iteration covers that and still catches a solver that doubles its work.
COUNT_FLOOR_RELATIVE = 0.05
COUNT_FLOOR_ABSOLUTE = 0.5

#: (regular expression on the figure name, whether it applies to rigid engines only, why the
#: figure is checked as a bound). In an engine without compliance (rigid contacts), penetration
#: and joint errors are round-off or the solver's stopping tolerance, not a property of the
#: model.
BOUNDED_FIGURES = (
    (r"energy_growth", False,
     "energy may not grow; its growth is round-off, a solver tolerance or a contact model's "
     "estimate, whose size only is a property of the code"),
    (r"quaternion_norm_error", False, "round-off of the engine's quaternion normalisation"),
    (r"solver_residual", False, "residual at convergence: round-off below the stopping test"),
    (r"penetration|clearance_excess|joint_distance|joint_angle|driver_offset|driver_angle",
     True, "a rigid engine's constraint violation: round-off or solver tolerance"),
    (r"stiction|stick\.|latched\.", True,
     "a rigid engine's creep where physics says stick: round-off"),
)

#: (regular expression on the last part of the figure name, dimension), first match wins;
#: a name that matches none is taken as relative (scale 1). A wrong guess changes the floor by
#: the ratio of two scales of the scene (at most about 100 in the library's units), far less
#: than the orders of magnitude between the floor and a physics change.
FIGURE_DIMENSIONS = (
    (r"relative|(^|_)ratio($|_)|^error$|^energy_drift$|^energy_growth|quaternion|residual",
     "relative"),
    (r"iterations|unconverged|steps|count", "count"),
    (r"angle", "angle"),
    (r"rate|speed|velocity", "velocity"),
    (r"time|period", "time"),
    (r"energy", "energy"),
    (r"penetration|eccentricity|excess|distance|displacement|offset|height|position",
     "length"),
)


def figure_dimension(name: str) -> str:
    """``length``, ``time``, ``velocity``, ``energy``, ``angle``, ``count`` or ``relative``
    for a figure name (its part after the last dot decides)."""
    last = name.rsplit(".", 1)[-1]
    for pattern, dimension in FIGURE_DIMENSIONS:
        if re.search(pattern, last):
            return dimension
    return "relative"


def figure_scale(name: str, scene: Scene, horizon: float, metrics: dict) -> float:
    """Scale of figure ``name``'s dimension in the scene's units: the scene's size [L]
    (:func:`~clearbench.scenarios.scales.scene_size`), the run's horizon [T], their ratio
    [L/T], the run's ``energy_scale`` figure [M L^2/T^2] (1 when absent), 1 otherwise."""
    dimension = figure_dimension(name)
    if dimension == "length":
        return scene_size(scene)
    if dimension == "time":
        return float(horizon)
    if dimension == "velocity":
        return scene_size(scene) / float(horizon)
    if dimension == "energy":
        energy = metrics.get("energy_scale")
        return float(energy) if energy is not None and math.isfinite(float(energy)) \
            and float(energy) > 0 else 1.0
    return 1.0


def bounded_reason(name: str, rigid: bool) -> str:
    """Why figure ``name`` of an engine with rigid contacts (``rigid``) or compliant ones is
    checked as a bound ('' when it is not)."""
    for pattern, rigid_only, why in BOUNDED_FIGURES:
        if re.search(pattern, name) and (rigid or not rigid_only):
            return why
    return ""


@dataclass(frozen=True)
class Check:
    """How one figure of one run is judged (stored in the baseline as a dict).

    Attributes
    ----------
    kind : {'exact', 'bounded', 'statistical'}
    base : float
        The unperturbed run's value (NaN allowed).
    spread : float
        Largest |perturbed - base| over the perturbed runs (0 when none was finite).
    low, high : float
        Smallest and largest value over the base and perturbed runs.
    floor : float
        The floor of the check [the figure's unit].
    limit : float
        exact: the tolerance on |new - base|; bounded: the bound on |new|; statistical: the
        margin added on each side of [low, high].
    samples : int
        Perturbed runs that gave a finite value.
    nan_allowed : bool
        Whether NaN was measured in some run.
    why : str
    """

    kind: str
    base: float
    spread: float
    low: float
    high: float
    floor: float
    limit: float
    samples: int
    nan_allowed: bool
    why: str

    def allows(self, new: float) -> bool:
        """Whether ``new`` passes."""
        if math.isnan(new):
            return self.nan_allowed or math.isnan(self.base)
        if not math.isfinite(new):
            return new == self.base
        if self.kind == "bounded":
            return abs(new) <= self.limit
        if self.kind == "statistical":
            return self.low - self.limit <= new <= self.high + self.limit
        if math.isnan(self.base):
            return False
        return abs(new - self.base) <= self.limit

    def describe(self) -> str:
        """The criterion, for a regression line."""
        if self.kind == "bounded":
            return f"bounded: |value| <= {self.limit:.3g}"
        if self.kind == "statistical":
            return (f"statistical: within [{self.low - self.limit:.6g}, "
                    f"{self.high + self.limit:.6g}], the range of {self.samples + 1} runs "
                    "widened")
        return f"exact: tolerance {self.limit:.3g}, measured spread {self.spread:.3g}"

    def to_dict(self) -> dict:
        return {key: _plain(value) for key, value in asdict(self).items()}

    @classmethod
    def from_dict(cls, data: dict) -> Check:
        return cls(**{key: (_number(value) if key in _FLOAT_FIELDS else value)
                      for key, value in data.items()})


_FLOAT_FIELDS = ("base", "spread", "low", "high", "floor", "limit")


def _plain(value):
    """JSON-safe: non-finite floats as the strings 'nan', 'inf', '-inf'."""
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return value


def _number(value) -> float:
    return float("nan") if value is None else float(value)


def floor_of(name: str, base: float, scale: float) -> float:
    """The floor of a check of figure ``name`` (see the module docstring)."""
    size = abs(base) if math.isfinite(base) else 0.0
    if figure_dimension(name) == "count":
        return COUNT_FLOOR_RELATIVE * size + COUNT_FLOOR_ABSOLUTE
    return FLOOR_RELATIVE * max(size, scale)


def classify(name: str, rigid: bool, base: float, perturbed: list[float],
             scale: float) -> Check:
    """The check of figure ``name`` of a run of an engine with rigid contacts (``rigid``) or
    compliant ones from its unperturbed value ``base`` and its values under the perturbations
    (``perturbed``; NaN where a run gave NaN, a run that did not measure it left out),
    ``scale`` the scale of its dimension (:func:`figure_scale`)."""
    values = [base, *perturbed]
    finite = [v for v in values if math.isfinite(v)]
    nan_allowed = any(math.isnan(v) for v in values)
    samples = sum(1 for v in perturbed if math.isfinite(v))
    low, high = (min(finite), max(finite)) if finite else (math.nan, math.nan)
    spread = max((abs(v - base) for v in perturbed if math.isfinite(v)), default=0.0) \
        if math.isfinite(base) else 0.0
    floor = floor_of(name, base, scale)
    reason = bounded_reason(name, rigid)
    if reason and finite:
        largest = max(abs(v) for v in finite)
        limit = max(BOUND_HEADROOM * largest, floor)
        return Check("bounded", base, spread, low, high, floor, limit, samples, nan_allowed,
                     f"{reason}; largest of {samples + 1} runs {largest:.3g}")
    finite_perturbed = [v for v in perturbed if math.isfinite(v)]
    mixed = math.isfinite(base) != all(math.isfinite(v) for v in perturbed)
    size = max(abs(base) if math.isfinite(base) else 0.0, scale)
    if finite and (mixed or spread > STATISTICAL_SPREAD * size) and finite_perturbed:
        limit = ENSEMBLE_WIDEN * (high - low) + floor
        return Check("statistical", base, spread, low, high, floor, limit, samples,
                     nan_allowed, f"the perturbations moved it by {spread:.3g} "
                     f"({spread / size:.2g} of its scale): an ensemble of {samples + 1} runs")
    limit = EXACT_WIDEN * spread + floor
    return Check("exact", base, spread, low, high, floor, limit, samples, nan_allowed,
                 f"round-off: {samples} perturbed runs moved it by at most {spread:.3g}")
