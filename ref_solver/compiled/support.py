"""Which steppers the compiled loop runs: every feature of the Python step but the contact
solver's ``stall_window`` and the Python projection (``compiled_projection = False``)."""

from __future__ import annotations


def unsupported_feature(stepper) -> str | None:
    """The first feature of ``stepper`` (a ``MoreauJeanStepper``) the compiled loop lacks, in
    words, or None when it runs every step of it."""
    cfg = stepper.settings
    if cfg.solver.stall_window:
        return "the contact solver's stall_window"
    if not stepper.compiled_projection:
        return "the Python projection (compiled_projection = False)"
    return None
