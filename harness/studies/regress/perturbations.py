"""Perturbations that carry no physics, under which the regression tolerances are measured.

Each perturbation reruns a suite entry with something changed that a correct program may not
depend on beyond round-off, and that differs between machines of our kind:

- ``roundoff``: the initial state of every moving body multiplied component by component by
  (1 + k eps), k a whole number drawn in [-ulps, ulps] (seeded; eps = 2.2e-16): position,
  orientation quaternion, velocity, angular velocity. A perturbation of the size of one
  rounding, applied before the engine builds the scene (:func:`perturb_initial_state`); without
  it nothing changes. Its seeds also make the ensembles of chaotic runs.
- ``environment``: variables of the worker processes that change the arithmetic, not the
  model: ``NUMBA_CPU_NAME=generic`` (numba compiles for a generic x86-64: no FMA, no AVX, other
  vector widths and so other summation orders), ``NUMBA_OPT=0`` (no LLVM optimisation: no
  reassociation or vectorisation), ``OPENBLAS_CORETYPE=Prescott`` (OpenBLAS's SSE3 kernels
  instead of the host's AVX ones: what another CPU picks at run time). numba caches each in a
  directory of its own (:func:`clearbench.numba_cache_dir`), so the code really is recompiled.
- ``options``: an engine's own setting that changes only its arithmetic, as the engine
  declares it (``HARNESS_DEFAULTS.perturbations``,
  :mod:`clearbench.adapters.harness_defaults`): Exudyn's sparse linear solver instead of the
  dense one (another factorisation order). MuJoCo, PyBullet and the Siconos worker expose no
  thread or SIMD setting (MuJoCo steps single-threaded; the Siconos worker runs with one
  OpenMP thread), so they are perturbed by the first two only.

A perturbation is a plain dict in the baseline (``perturbations``), so the set is stated where
the tolerances measured from it are.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence

import numpy as np

from clearbench.harness.run.engine_choice import engine_defaults, engine_names
from clearbench.scenarios.bodies import Motion
from clearbench.scenarios.scene import Scene

#: Machine epsilon of double precision.
EPS = float(np.finfo(float).eps)
#: Size of a round-off perturbation, in units of eps (relative): a few roundings.
ROUNDOFF_ULPS = 4
#: Round-off perturbations of an entry without an ``ensemble`` of its own.
ROUNDOFF_SEEDS = 2

#: The perturbations of every engine written into a new baseline (with the engines' own,
#: :func:`default_perturbations`).
GENERIC_PERTURBATIONS = [
    {"name": "roundoff", "kind": "roundoff", "ulps": ROUNDOFF_ULPS, "seeds": ROUNDOFF_SEEDS,
     "why": "initial state of every moving body times (1 + k eps), |k| <= ulps, seeded: one "
     "rounding of the input (an entry's 'ensemble' sets its number of seeds)"},
    {"name": "numba-generic", "kind": "environment",
     "environment": {"NUMBA_CPU_NAME": "generic"},
     "why": "numba compiles for a generic x86-64 (no FMA/AVX): other rounding and summation "
     "order in every compiled kernel, as on another CPU"},
    {"name": "numba-opt0", "kind": "environment", "environment": {"NUMBA_OPT": "0"},
     "why": "numba without LLVM optimisation: no reassociation, no vectorisation"},
    {"name": "openblas-prescott", "kind": "environment",
     "environment": {"OPENBLAS_CORETYPE": "Prescott"},
     "why": "OpenBLAS's SSE3 kernels instead of the host's: the BLAS another CPU picks"},
]


def default_perturbations(engines: Sequence[str] | None = None,
                          extra_modules: Mapping[str, str] | None = None) -> list[dict]:
    """The perturbations of a new baseline: :data:`GENERIC_PERTURBATIONS`, then the option
    perturbations each engine declares (``HARNESS_DEFAULTS.perturbations``) for ``engines``
    (names; default: every engine of the registry and of ``extra_modules``)."""
    names = engine_names(extra_modules) if engines is None else engines
    own = [{"name": p.name, "kind": "options", "engines": [name], "options": dict(p.options),
            "why": p.why}
           for name in names for p in engine_defaults(name, extra_modules).perturbations]
    return [dict(p) for p in GENERIC_PERTURBATIONS] + own


@dataclasses.dataclass(frozen=True)
class Variant:
    """One perturbed rerun of a suite entry.

    Attributes
    ----------
    name : str
        ``roundoff-3``, ``numba-generic``, ...
    seed : int
        Round-off seed (0: the initial state as given).
    ulps : int
        Size of the round-off perturbation [eps].
    environment, options : dict
        Worker environment variables; engine options over the entry's own.
    """

    name: str
    seed: int = 0
    ulps: int = ROUNDOFF_ULPS
    environment: dict = dataclasses.field(default_factory=dict)
    options: dict = dataclasses.field(default_factory=dict)

    @property
    def environment_key(self) -> tuple:
        """Hashable form of :attr:`environment` (runs sharing it share their workers)."""
        return tuple(sorted(self.environment.items()))


def check_perturbations(perturbations: list[dict]) -> None:
    """ValueError naming the entry and field of ``perturbations`` at fault."""
    for index, item in enumerate(perturbations):
        where = f"perturbations[{index}]"
        kind = item.get("kind")
        if kind not in ("roundoff", "environment", "options"):
            raise ValueError(f"{where}.kind: {kind!r} is not roundoff, environment or options")
        if not item.get("name"):
            raise ValueError(f"{where}.name: missing")
        if kind == "roundoff":
            for field in ("ulps", "seeds"):
                value = item.get(field)
                if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                    raise ValueError(f"{where}.{field}: {value!r} is not an integer >= 1")
        elif not isinstance(item.get(kind), dict) or not item[kind]:
            raise ValueError(f"{where}.{kind}: expected a non-empty table")


def variants_for(entry: dict, engine: str, perturbations: list[dict]) -> list[Variant]:
    """The perturbed reruns of a suite entry run in ``engine`` (its name): a round-off seed per
    ensemble member (the entry's ``ensemble``, else the perturbation's ``seeds``), then every
    environment and option perturbation that applies to the engine."""
    variants = []
    for item in perturbations:
        engines = item.get("engines")
        if engines and engine not in engines:
            continue
        if item["kind"] == "roundoff":
            seeds = int(entry.get("ensemble", item["seeds"]))
            variants += [Variant(f"{item['name']}-{seed}", seed=seed, ulps=int(item["ulps"]))
                         for seed in range(1, seeds + 1)]
        elif item["kind"] == "environment":
            variants.append(Variant(item["name"], environment=dict(item["environment"])))
        else:
            variants.append(Variant(item["name"], options=dict(item["options"])))
    return variants


def _perturbed(values: tuple, rng: np.random.Generator, ulps: int) -> tuple:
    factors = 1.0 + EPS * rng.integers(-ulps, ulps + 1, size=len(values))
    return tuple(float(v) * float(f) for v, f in zip(values, factors, strict=True))


def perturb_initial_state(scene: Scene, seed: int, ulps: int = ROUNDOFF_ULPS) -> Scene:
    """``scene`` with the initial state of every body that is not fixed multiplied, component
    by component, by (1 + k eps), k a whole number in [-ulps, ulps] drawn from ``seed``.

    Position [L], orientation quaternion [-] (left unnormalised: its norm moves by about
    ulps eps, as after one rounding; every engine normalises), velocity [L/T] and angular
    velocity [1/T]. A component that is exactly 0 stays 0 (a symmetric scene stays
    symmetric, as on any machine). Seed 0 returns ``scene`` itself.
    """
    if seed == 0:
        return scene
    rng = np.random.default_rng(seed)
    bodies = []
    for body in scene.bodies:
        if body.motion is Motion.FIXED:
            bodies.append(body)
            continue
        bodies.append(dataclasses.replace(
            body, position=_perturbed(body.position, rng, ulps),
            orientation=_perturbed(body.orientation, rng, ulps),
            velocity=_perturbed(body.velocity, rng, ulps),
            angular_velocity=_perturbed(body.angular_velocity, rng, ulps)))
    return dataclasses.replace(scene, bodies=tuple(bodies))
