"""What each scene feature becomes in the Siconos engine: native, approximated (how) or
unsupported (why), one function per feature kind (wired by
:class:`~clearbench.adapters.base.ModuleEngine`; the context is a
:class:`~clearbench.adapters.base.FeatureQuery` whose ``options`` are the resolved settings,
:func:`~.settings.resolve_settings`)."""

from __future__ import annotations

import numpy as np

from clearbench.adapters.base import Capability, Support
from clearbench.adapters.siconos.worker import geometry as worker_geometry
from clearbench.kernels.quaternion import quat_normalize, quat_to_matrix
from clearbench.scenarios.scene import Scene

_JOINT_CLASSES = {"revolute": "PivotJointR", "spherical": "KneeJointR",
                  "prismatic": "PrismaticJointR", "fixed": "FixedJointR"}


#: Features the worker handles exactly (within the nonsmooth time stepping), with how.
_NATIVE_FEATURES = {
    "gravity": "constant force in computeFExt",
    "contacts": "one NewtonImpactFrictionNSL interaction per candidate, exact (nonsmooth)",
    "friction": "Coulomb cone of NewtonImpactFrictionNSL, exact (nonsmooth)",
    "restitution": "Newton impact law of NewtonImpactFrictionNSL",
    "rings": "ring geometry of the shared kernels",
    "arcs": "arc geometry of the shared kernels",
    "clearance_joints": "expanded into their contact pairs (shared expansion)",
    "closed_loop": "GenericMechanical with Gauss-Seidel over all blocks (redundant joint rows)",
    "point_forces": "computeFExt / computeMExt at the step ends (theta-weighted)",
    "moments": "computeMExt at the step ends (theta-weighted)",
    "time_switched_loads": "switch tested at the times Moreau-Jean evaluates the loads (the "
                           "step ends): resolved to one step",
    "fixed_bodies": "no dynamical system (contacts with one dynamical system)",
}
#: Configuration-dependent forces applied explicitly, with what they are.
_EXPLICIT_FORCES = {
    "springs": "force",
    "torsional_springs": "moment",
    "angle_law_loads": "law scalar (scenarios.loads.AngleLawLoad) and its applications",
    "distance_law_loads": "law scalar (scenarios.loads.DistanceLawLoad) and its applications",
}


#: Why the combined projection cannot take pairs that drop candidates.
PROJECTION_DROPPED_SLOTS = (
    "TimeSteppingCombinedProjection projects the active contacts with a positive reaction "
    "(index set 2) as equalities (it iterates while |y| >= tolerance): a candidate dropped "
    "(outside a bore) while active is pulled back from its inactive gap; "
    "c60-trip diverged at 2.15 ms, the hook and the tripping bar thrown 1e10 mm apart")


def _pair_capability(kind_a: str, kind_b: str, projection: bool = False) -> Capability:
    reason = worker_geometry.unsupported_reason(kind_a, kind_b)
    if reason:
        return Capability(Support.UNSUPPORTED, reason)
    if projection and worker_geometry.drops_candidates(kind_a, kind_b):
        return Capability(Support.UNSUPPORTED, PROJECTION_DROPPED_SLOTS)
    detail = ("Python NewtonEuler3DR relation with the shared closed-form gap, points and "
              "contact frame")
    if worker_geometry.drops_candidates(kind_a, kind_b):
        detail += ("; one interaction per candidate slot, a slot the face or bore drops is "
                   f"handed the gap {worker_geometry.DROPPED_GAP:g} (inactive) until "
                   "the candidate returns")
    return Capability(Support.NATIVE, detail)


def plain_capability(context, name: str) -> Capability | None:
    if name in _EXPLICIT_FORCES:
        return Capability(
            Support.APPROXIMATED, _EXPLICIT_FORCES[name] + " from the current "
            "iterate in computeFExt / computeMExt, theta-weighted by Moreau-Jean "
            "without a stiffness Jacobian: stable only for h < 2 / omega of the "
            "stiffest spring")
    if name == "drivers":
        return driver_capability(context.scene)
    if name == "ideal_joints":
        return Capability(
            Support.NATIVE, "Siconos joint relations at velocity level; position drift "
            "corrected only by the projection preset")
    if name in _NATIVE_FEATURES:
        return Capability(Support.NATIVE, _NATIVE_FEATURES[name])
    return None


def shape_capability(context, kind: str) -> Capability | None:
    if kind in worker_geometry.SHAPE_KINDS:
        return Capability(Support.NATIVE, "shared closed-form geometry")
    return None


def joint_capability(context, kind: str) -> Capability | None:
    if kind in _JOINT_CLASSES:
        return Capability(Support.NATIVE, f"{_JOINT_CLASSES[kind]} + EqualityConditionNSL")
    return None


def pair_capability(context, kind_a: str, kind_b: str) -> Capability | None:
    known = worker_geometry.SHAPE_KINDS
    if kind_a not in known or kind_b not in known:
        return None
    # The preset's projection, or the run option's.
    return _pair_capability(kind_a, kind_b, bool(context.options["projection"]))


def driver_capability(scene: Scene) -> Capability:
    notes, problems = [], []
    for driver in scene.drivers:
        if driver.quantity == "position":
            notes.append(f"{driver.name}: position profile imposed through its rate")
        if driver.is_rotation:
            body = scene.body(driver.body)
            rotation = quat_to_matrix(quat_normalize(np.asarray(body.orientation, float)))
            alignment = rotation[driver.axis_index, :]
            if abs(np.max(np.abs(alignment)) - 1.0) > 1e-9:
                problems.append(f"{driver.name}: no axis of body {driver.body!r} is aligned "
                                f"with world {driver.component[-1]} at t = 0 (Siconos "
                                "prescribes body-axis angular velocities)")
            else:
                notes.append(f"{driver.name}: body-axis angular velocity aligned with "
                             f"world {driver.component[-1]} at t = 0 (exact while a joint "
                             "keeps that axis fixed)")
    if problems:
        return Capability(Support.UNSUPPORTED, "; ".join(problems))
    if notes:
        return Capability(Support.APPROXIMATED,
                          "BoundaryCondition on the twist; " + "; ".join(notes))
    return Capability(Support.NATIVE, "BoundaryCondition on the twist (prescribed velocity)")
