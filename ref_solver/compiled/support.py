"""Which steppers the compiled loop runs: every feature of the Python step but impact
localisation (``StepperSettings.localise_impacts`` on a scene with a pair of restitution > 0,
where the Python step splits a step at the crossing time)."""

from __future__ import annotations

import numpy as np


def unsupported_feature(stepper) -> str | None:
    """The first feature of ``stepper`` (a ``MoreauJeanStepper``) the compiled loop lacks, in
    words, or None when it runs every step of it."""
    cfg = stepper.settings
    if cfg.localise_impacts and bool(np.any(stepper.system.pair_restitution > 0.0)):
        return "impact localisation (localise_impacts on a pair with restitution > 0)"
    if cfg.solver.stall_window:
        return "the contact solver's stall_window"
    if not stepper.compiled_projection:
        return "the Python projection (compiled_projection = False)"
    return None
