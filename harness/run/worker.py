"""The worker process: runs one scene in one engine, then measures the trajectory.

A worker is started by :mod:`.runner` with the ``spawn`` context, receives
:class:`~.messages.WorkerRequest` objects on a pipe and answers each with two messages: a
:class:`~.messages.RanMessage` (the engine's outcome and wall times, the trajectory written to
the given .npz path) and then a :class:`~.messages.MeasuredMessage` (figures, expectations and
the run's status after the harness's checks). The parent applies the wall-clock limit to the
first phase and a separate limit to the second, so that a metric that is slow or crashes never
hides the run's own outcome. A request that only measures (a stored trajectory whose measuring
code changed) gets the second message alone.

Nothing here trusts the engine: an exception is a crashed run with its message, and the
measuring phase decides the run's status (:func:`measure_phase`: a trajectory with non-finite
values is a diverged run whatever status the engine gave). The run phase only hands the spec
to the engine, so the trajectory depends on the physics sources alone
(:data:`clearbench.PHYSICS_SUBPACKAGES`); this module's measuring phase is a measuring source
(:data:`clearbench.MEASURING_SOURCES`).
"""

from __future__ import annotations

import ctypes
import dataclasses
import importlib
import logging
import os
import signal
import time
import traceback
from pathlib import Path

from clearbench.adapters.base import Capability, RunSettings, Support
from clearbench.adapters.trajectory import RunStatus, Trajectory
from clearbench.harness.measure.figures import first_non_finite, measure
from clearbench.harness.run.messages import MeasuredMessage, RanMessage, WorkerRequest
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.serialization import scene_from_dict

LOG = logging.getLogger(__name__)

_PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:
    """Ask Linux to SIGKILL this process when its parent dies (kill -9 of a sweep leaves no
    orphan workers); put it in its own process group so the parent can kill what it spawned."""
    try:
        os.setpgrp()
    except OSError:  # pragma: no cover - not permitted
        pass
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):  # pragma: no cover - not Linux
        pass


def worker_main(conn, parent_pid: int) -> None:
    """Serve requests from ``conn`` until ``None`` or the pipe closes."""
    _die_with_parent()
    if os.getppid() != parent_pid:  # the parent died before prctl took effect
        os._exit(1)
    try:  # engines that print must not garble the CLI's standard output
        os.dup2(2, 1)
    except OSError:  # pragma: no cover
        pass
    while True:
        try:
            request = conn.recv()
        except (EOFError, OSError):
            return
        if request is None:
            return
        if request.measure_only:
            conn.send(measure_stored(request))
            continue
        ran, scene, trajectory = run_phase(request)
        conn.send(ran)
        conn.send(measure_phase(request, scene, trajectory))


def _exception_message(error: BaseException) -> str:
    frames = traceback.extract_tb(error.__traceback__)
    where = f" (at {Path(frames[-1].filename).name}:{frames[-1].lineno})" if frames else ""
    return f"{type(error).__name__}: {error}{where}"


def run_phase(request: WorkerRequest) -> tuple[RanMessage, Scene | None, Trajectory | None]:
    """Build the scene and engine, run, save the trajectory.

    Returns
    -------
    ran : RanMessage
        The engine's outcome as it reported it (crashed, with the exception, when the engine
        or the adapter raised).
    scene, trajectory
        For the measuring phase (``trajectory`` None when the engine raised).
    """
    start = time.perf_counter()
    scene = None
    trajectory = None
    try:
        scene = scene_from_dict(request.scene)
        engine = importlib.import_module(request.module).create(request.preset)
        capabilities = {feature: Capability(Support(support), detail)
                        for feature, (support, detail) in request.capabilities.items()}
        settings = RunSettings(time_step=request.time_step, horizon=request.horizon,
                               record_every=request.record_every, options=dict(request.options))
        trajectory = engine.run(scene, settings, capabilities=capabilities)
        path = Path(request.trajectory_path)
        partial = path.with_name(path.name + ".partial.npz")
        trajectory.save(partial)
        os.replace(partial, path)
        ran = RanMessage(status=trajectory.status.value, message=trajectory.message,
                         engine_version=request.engine_version,
                         capabilities=request.capabilities,
                         build_seconds=float(trajectory.build_seconds),
                         stepping_seconds=float(trajectory.stepping_seconds),
                         steps=int(trajectory.steps), samples=int(len(trajectory.times)),
                         trajectory_saved=True)
    except Exception as error:  # an engine or adapter bug is a recorded outcome
        LOG.debug("run raised", exc_info=True)
        ran = RanMessage(status=RunStatus.CRASHED.value, message=_exception_message(error),
                         engine_version=request.engine_version,
                         capabilities=request.capabilities)
        trajectory = None
    return dataclasses.replace(ran, worker_seconds=time.perf_counter() - start), scene, \
        trajectory


def measure_phase(request: WorkerRequest, scene: Scene | None,
                  trajectory: Trajectory | None) -> MeasuredMessage:
    """The run's status, figures, expectations and verdict from its trajectory: the one place
    the run's status is decided (:mod:`.messages`). A trajectory the engine called ok with a
    non-finite value is diverged; then :func:`clearbench.harness.measure.figures.measure`
    (whose checks may find it diverged too)."""
    start = time.perf_counter()
    if trajectory is None or scene is None:
        return MeasuredMessage(seconds=time.perf_counter() - start)
    status, reason = trajectory.status, ""
    if status is RunStatus.OK:
        bad = first_non_finite(trajectory)
        if bad is not None:  # the engine said ok: the verdict says both
            status, reason = RunStatus.DIVERGED, f"engine status ok, harness: diverged ({bad})"
            trajectory.status, trajectory.message = status, reason
    out = MeasuredMessage(status=status.value, reason=reason)
    try:
        reference = None
        if request.reference_path:
            reference = Trajectory.load(request.reference_path)
        result = measure(scene, trajectory, reference,
                         request.reference_label or "reference trajectory")
        out = MeasuredMessage(status=result.verdict.value,
                              reason=result.verdict_reason or reason, figures=result.figures,
                              expectations=list(result.expectations),
                              error_source=result.error_source,
                              metrics_error=result.metrics_error)
    except Exception as error:
        LOG.debug("metrics raised", exc_info=True)
        out = dataclasses.replace(out, metrics_error=_exception_message(error))
    return dataclasses.replace(out, seconds=time.perf_counter() - start)


def measure_stored(request: WorkerRequest) -> MeasuredMessage:
    """:func:`measure_phase` of the trajectory stored at ``request.trajectory_path`` (an
    empty measurement when there is none)."""
    path = Path(request.trajectory_path)
    if not path.exists():
        return MeasuredMessage()
    return measure_phase(request, scene_from_dict(request.scene), Trajectory.load(path))
