"""What the reference engine does with each scene feature: every feature it knows is exact
(nonsmooth) and native; a contact pair is native where the shared geometry has a closed-form gap
for it (:mod:`clearbench.scenarios.geometry`). A feature not listed here is unknown to it. The
functions take the context of :class:`~clearbench.adapters.base.ModuleEngine` first (unused:
the answers depend on neither the scene's values nor the options)."""

from __future__ import annotations

from clearbench.adapters.base import Capability, Support
from clearbench.ref_solver.system import JOINT_CODES
from clearbench.scenarios.geometry import SHAPE_CODES, supported_pair

EXACT = "exact (nonsmooth)"

#: Plain features the reference solver handles exactly.
NATIVE_FEATURES = (
    "gravity", "contacts", "friction", "restitution", "rings", "arcs", "ideal_joints",
    "closed_loop", "clearance_joints", "springs", "torsional_springs", "point_forces",
    "moments", "angle_law_loads", "distance_law_loads", "time_switched_loads", "drivers",
    "fixed_bodies",
)


def plain_capability(context, name: str) -> Capability | None:
    """Native for :data:`NATIVE_FEATURES`, else unknown (None)."""
    return Capability(Support.NATIVE, EXACT) if name in NATIVE_FEATURES else None


def shape_capability(context, kind: str) -> Capability | None:
    """Native for every shape kind of the shared geometry, else unknown (None)."""
    return Capability(Support.NATIVE, EXACT) if kind in SHAPE_CODES else None


def joint_capability(context, kind: str) -> Capability | None:
    """Native for every ideal joint kind of the solver, else unknown (None)."""
    return Capability(Support.NATIVE, EXACT) if kind in JOINT_CODES else None


def pair_capability(context, kind_a: str, kind_b: str) -> Capability | None:
    """Native where the shared geometry has a gap function for the pair, unsupported where it
    has none; unknown (None) for a shape kind it does not know."""
    if kind_a not in SHAPE_CODES or kind_b not in SHAPE_CODES:
        return None
    if supported_pair(kind_a, kind_b):
        return Capability(Support.NATIVE, "closed-form gap")
    return Capability(Support.UNSUPPORTED, f"no gap function for {kind_a} against {kind_b}")
