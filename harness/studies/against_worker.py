"""Worker of :mod:`.against`: runs reference-engine cases for whatever clearbench it imports.

Run as a script (``python against_worker.py``) by the interpreter of one revision: it reads one
JSON request per line on stdin, ``{"scene": name, "parameters": {...}, "preset": name,
"horizon": float or null, "time_step": float or null}``, runs the case (after a 20-step warm-up
of the same scene that compiles the kernels, untimed) and writes one JSON line on stdout:
stepping wall time [s], steps, unconverged steps, mean solver iterations and active contacts
per step, solver seconds and contact sweeps. An empty line or end of input stops it.

It imports only what every revision since the package layout has (``create(preset).run``,
``get_scene``, ``RunSettings``), so the same script measures the baseline and this revision.
"""

from __future__ import annotations

import importlib
import json
import sys


def _first(*names):
    """The first module of ``names`` that imports."""
    for name in names:
        try:
            return importlib.import_module(name)
        except ImportError:
            continue
    raise ImportError(f"none of {names} imports")


def _case(request: dict) -> dict:
    import numpy as np

    engine_module = _first("clearbench.adapters.reference.engine", "clearbench.adapters.reference")
    library = _first("clearbench.scenarios.library", "clearbench.scenarios.registry")
    base = _first("clearbench.adapters.base")
    scene = library.get_scene(request["scene"], **request.get("parameters", {}))
    engine = engine_module.create(request.get("preset", "default"))
    step = request.get("time_step")
    engine.run(scene, base.RunSettings(time_step=step, horizon=20 * (step or scene.time_step)))
    trajectory = engine.run(scene, base.RunSettings(time_step=step,
                                                    horizon=request.get("horizon")))
    metadata = trajectory.metadata
    return {
        "status": trajectory.status.value,
        "stepping_seconds": float(trajectory.stepping_seconds),
        "steps": int(trajectory.steps),
        # Revisions before the typed statistics kept them in the metadata.
        "unconverged_steps": (len(metadata["unconverged_steps"]) if "unconverged_steps" in metadata
                              else int(trajectory.unconverged_count)),
        "unconverged_projections": len(metadata.get("unconverged_projections", [])),
        "mean_iterations": float(np.mean(trajectory.solver_iterations[1:])),
        "mean_active_contacts": float(np.mean(trajectory.active_contacts[1:])),
        "solver_seconds": float(metadata.get("solver_seconds",
                                             getattr(trajectory, "solver_seconds", float("nan")))),
        "contact_sweeps": int(metadata.get("contact_sweeps", 0)),
    }


def main() -> int:
    for line in sys.stdin:
        if not line.strip():
            break
        try:
            reply = _case(json.loads(line))
        except Exception as error:  # noqa: BLE001 - reported to the parent, which decides
            reply = {"error": f"{type(error).__name__}: {error}"}
        sys.stdout.write(json.dumps(reply) + "\n")
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
