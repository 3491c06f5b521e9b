"""Filling numba's cache of this checkout before a suite of runs.

Runs from an empty cache compile the reference solver's and the measuring code's numba kernels
first (minutes of one core); runs started at once from an empty cache each compile the same
kernels. Short runs (two steps) made before a suite, with a long wall-clock limit, compile them
once into the cache (:func:`clearbench.numba_cache_dir`) that the suite's workers then load.
"""

from __future__ import annotations

import dataclasses
import tempfile
from collections.abc import Mapping, Sequence

from clearbench.harness.run.engine_choice import engine_defaults
from clearbench.harness.run.runner import RunJob, Runner, SweepOutcome
from clearbench.harness.run.spec import RunSpec, make_run_spec
from clearbench.harness.run.store import ResultsStore

#: Wall-clock limit of a warm-up run [s]: it may compile every numba kernel of the reference
#: solver and of the measuring code from an empty cache (minutes on a loaded 2-core machine).
WARM_UP_TIMEOUT = 3600.0

#: The reference engine's step loops (option ``step_loop``) whose kernels
#: :func:`reference_specs` compiles: ``auto`` (the compiled loop where the scene is supported,
#: else the Python step) and ``python`` (the Python step, the oracle of the compiled loop).
STEP_LOOPS = ("auto", "python")


def reference_specs(scenes: Sequence[str], step_loops: Sequence[str] = STEP_LOOPS
                    ) -> list[RunSpec]:
    """Two-step reference-engine runs of ``scenes`` (registered names) with each of
    ``step_loops``, interleaved by scene (scene 1 with each loop, then scene 2, ...) so that
    parallel workers compile different loops' kernels first."""
    return [warm_up_spec(make_run_spec(name, "reference", options={"step_loop": loop}))
            for name in scenes for loop in step_loops]


def warm_up_spec(spec: RunSpec) -> RunSpec:
    """``spec`` as a warm-up run: two steps (at most its horizon), a wall-clock limit long
    enough to compile every kernel from an empty cache, campaign ``numba-warm-up``."""
    return dataclasses.replace(spec, horizon=min(spec.horizon, 2 * spec.time_step),
                               record_every=1, timeout=WARM_UP_TIMEOUT,
                               campaign="numba-warm-up")


def fill_cache(specs: Sequence[RunSpec], jobs: int = 1,
               environment: Mapping[str, str] | None = None) -> SweepOutcome:
    """Run ``specs`` in ``jobs`` workers that each serve many runs, in a scratch store
    (results discarded: the kernels they compile stay in numba's cache). ``environment``:
    variables of the workers (the cache directory follows numba's code-generation settings).
    Returns the outcome, whose records say which runs failed."""
    if not specs:
        return SweepOutcome()
    with tempfile.TemporaryDirectory(prefix="clearbench-warm-") as scratch:
        runner = Runner(ResultsStore(scratch), jobs=jobs,
                        runs_per_worker=-(-len(specs) // max(1, jobs)),
                        environment=environment)
        return runner.run_all(list(specs), rerun=True)


def warm_up_jobs(specs: Sequence[RunSpec], engines: Sequence[str] | None = None,
                 extra_modules: Mapping[str, str] | None = None) -> list[RunJob]:
    """Warm-up jobs (:class:`~clearbench.harness.run.runner.RunJob`, ``warm_up``) for a batch
    of ``specs``: a two-step run (:func:`warm_up_spec`) of each distinct scene, preset and
    options that ``specs`` run with one of ``engines`` (default: the engines that declare numba
    kernels, ``HARNESS_DEFAULTS.numba``, plug-ins looked up in ``extra_modules``), the first
    scene of the batch first. Put before the batch, they make one worker compile those engines'
    kernels (or load them, seconds when the cache is full) while the other workers run the
    other engines' jobs."""
    if engines is None:
        engines = {name for name in {spec.engine.name for spec in specs}
                   if engine_defaults(name, extra_modules).numba}
    jobs, seen = [], set()
    for spec in specs:
        if spec.engine.name not in engines:
            continue
        identity = (spec.scene.content_hash, spec.engine.preset, spec.options)
        if identity in seen:
            continue
        seen.add(identity)
        jobs.append(RunJob(warm_up_spec(spec), warm_up=True))
    return jobs
