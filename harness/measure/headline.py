"""Which figures summarise a scene: the headline metric of each scene and the metric columns
worth showing for it (shared by the CLI tables, the stability suite and the report)."""

from __future__ import annotations

import math

from clearbench.scenarios.expectation_kinds import body_stays, energy_may_not_grow
from clearbench.scenarios.scene import Scene

#: Metric name -> (short label, unit kind: "length", "relative", "rate", "angle", "count").
METRIC_LABELS: dict[str, tuple[str, str]] = {
    "error": ("error", "relative"),
    "penetration_max": ("penetration", "length"),
    "instrument_penetration_max": ("penetration (instrument)", "length"),
    "clearance_excess_max": ("clearance excess", "length"),
    "joint_distance_max": ("joint gap", "length"),
    "joint_angle_max": ("joint angle", "angle"),
    "quaternion_norm_error_max": ("|q|-1", "relative"),
    "stiction_displacement": ("stick slip", "length"),
    "stiction_creep_rate": ("creep rate", "rate"),
    "energy_drift": ("energy drift", "relative"),
    "energy_growth": ("energy growth", "relative"),
    "solver_unconverged_steps": ("unconverged", "count"),
}


def scene_metric_names(scene: Scene) -> list[str]:
    """The metrics that matter for ``scene``, most telling first."""
    names = ["error"]
    if any(body_stays(e.kind) for e in scene.expectations):
        names += ["stiction_displacement", "stiction_creep_rate"]
    if scene.clearance_joints:
        names.append("clearance_excess_max")
    if scene.contacts:
        names += ["penetration_max", "instrument_penetration_max"]
    if scene.joints:
        names += ["joint_distance_max", "joint_angle_max"]
    if any(energy_may_not_grow(e.kind) for e in scene.expectations):
        names += ["energy_growth", "energy_drift"]
    names.append("quaternion_norm_error_max")
    return list(dict.fromkeys(names))


def headline(scene: Scene, figures: dict) -> tuple[str, float]:
    """The first metric of :func:`scene_metric_names` the run has (name, value)."""
    for name in scene_metric_names(scene):
        value = figures.get(name)
        if value is not None and math.isfinite(value):
            return name, float(value)
    return "", math.nan


def format_value(value, unit: str = "") -> str:
    """Compact text for a figure (3 significant digits, '—' for missing)."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "—"
    if isinstance(value, int | float):
        if value == 0:
            text = "0"
        elif 1e-3 <= abs(value) < 1e4:
            text = f"{value:.3g}"
        else:
            text = f"{value:.2e}"
        return f"{text} {unit}".strip()
    return str(value)
