"""The worker process: runs one scene in one engine, then measures the trajectory.

A worker is started by :mod:`.runner` with the ``spawn`` context, receives JSON-able requests on
a pipe and answers each with two messages: ``ran`` (outcome, wall times, trajectory written to
the given .npz path) and then ``measured`` (metrics, expectations, verdict). The parent applies
the wall-clock limit to the first phase and a separate limit to the second, so that a metric
that is slow or crashes never hides the run's own outcome.

Nothing here trusts the engine: an exception is a crashed run with its message, and a
trajectory with non-finite values is a diverged run whatever status the engine gave.
"""

from __future__ import annotations

import ctypes
import importlib
import logging
import os
import signal
import time
import traceback
from pathlib import Path

from clearbench.adapters.base import RunSettings
from clearbench.adapters.trajectory import RunStatus, Trajectory
from clearbench.harness.measure.figures import first_non_finite, measure
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
        ran, scene, trajectory = run_phase(request)
        conn.send(ran)
        conn.send(measure_phase(request, scene, trajectory))


def _exception_message(error: BaseException) -> str:
    frames = traceback.extract_tb(error.__traceback__)
    where = f" (at {Path(frames[-1].filename).name}:{frames[-1].lineno})" if frames else ""
    return f"{type(error).__name__}: {error}{where}"


def run_phase(request: dict):
    """Build the scene and engine, run, guard, save the trajectory.

    Returns
    -------
    ran : dict
        ``phase``, ``status`` (RunStatus value), ``message``, ``engine_version``,
        ``capabilities`` (feature -> [support, detail]), ``worker_seconds`` (whole phase [s]),
        ``build_seconds``, ``stepping_seconds``, ``steps``, ``samples``, ``trajectory_saved``.
    scene, trajectory
        For the measuring phase (``trajectory`` None when the engine raised).
    """
    start = time.perf_counter()
    ran = {"phase": "ran", "status": RunStatus.CRASHED.value, "message": "",
           "engine_version": "", "capabilities": {}, "worker_seconds": 0.0,
           "build_seconds": float("nan"), "stepping_seconds": float("nan"), "steps": 0,
           "samples": 0, "trajectory_saved": False}
    scene = None
    trajectory = None
    try:
        scene = scene_from_dict(request["scene"])
        module = importlib.import_module(request["module"])
        ran["engine_version"] = str(module.availability()[1])
        engine = module.create(request["preset"])
        ran["capabilities"] = {
            feature: [capability.support.value, capability.detail]
            for feature, capability in sorted(engine.capabilities(scene).items())
        }
        settings = RunSettings(time_step=request["time_step"], horizon=request["horizon"],
                               record_every=request["record_every"],
                               options=dict(request["options"]))
        trajectory = engine.run(scene, settings)
        status, message = trajectory.status, trajectory.message
        ran["engine_status"], ran["engine_message"] = status.value, message
        if status is RunStatus.OK:
            bad = first_non_finite(trajectory)
            if bad is not None:  # the engine said ok: the verdict says both
                status, message = RunStatus.DIVERGED, f"engine status ok, harness: diverged ({bad})"
                trajectory.status, trajectory.message = status, message
        ran.update(status=status.value, message=message,
                   build_seconds=float(trajectory.build_seconds),
                   stepping_seconds=float(trajectory.stepping_seconds),
                   steps=int(trajectory.steps), samples=int(len(trajectory.times)))
        path = Path(request["trajectory_path"])
        partial = path.with_name(path.name + ".partial.npz")
        trajectory.save(partial)
        os.replace(partial, path)
        ran["trajectory_saved"] = True
    except Exception as error:  # an engine or adapter bug is a recorded outcome
        LOG.debug("run raised", exc_info=True)
        ran["status"] = RunStatus.CRASHED.value
        ran["message"] = _exception_message(error)
        trajectory = None
    ran["worker_seconds"] = time.perf_counter() - start
    return ran, scene, trajectory


def measure_phase(request: dict, scene, trajectory: Trajectory | None) -> dict:
    """Metrics, expectations and verdict of a finished run
    (:func:`clearbench.harness.measure.figures.measure`)."""
    start = time.perf_counter()
    out = {"phase": "measured", "figures": {}, "expectations": [], "verdict": None,
           "verdict_reason": "", "error_source": "", "metrics_error": ""}
    if trajectory is None or scene is None:
        out["seconds"] = time.perf_counter() - start
        return out
    try:
        reference = None
        if request.get("reference_path"):
            reference = Trajectory.load(request["reference_path"])
        result = measure(scene, trajectory, reference,
                         request.get("reference_label") or "reference trajectory")
        out.update(figures=result.figures, expectations=list(result.expectations),
                   verdict=result.verdict.value, verdict_reason=result.verdict_reason,
                   error_source=result.error_source, metrics_error=result.metrics_error)
    except Exception as error:
        LOG.debug("metrics raised", exc_info=True)
        out["metrics_error"] = _exception_message(error)
    out["seconds"] = time.perf_counter() - start
    return out
