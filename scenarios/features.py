"""The words of :attr:`Scene.features <clearbench.scenarios.scene.Scene.features>`: how a
feature is written (by the scene) and read (by the engines, once, in
:meth:`clearbench.adapters.base.Engine.capabilities`).

A feature is a plain name (:data:`PLAIN_FEATURES`: ``friction``, ``drivers``, ...) or a
qualified one: ``shape:<kind>``, ``joint:<kind>`` or ``pair:<kind>-<kind>`` (the two shape
kinds sorted). Text that is none of these (a feature of a newer vocabulary) reads as a plain
feature of that name, which an engine that does not know it reports unsupported.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

#: Plain features a scene can use (see Scene.features for when each is set).
PLAIN_FEATURES = (
    "gravity", "contacts", "friction", "restitution", "rings", "arcs", "ideal_joints",
    "closed_loop", "clearance_joints", "springs", "torsional_springs", "point_forces",
    "moments", "angle_law_loads", "distance_law_loads", "time_switched_loads", "drivers",
    "fixed_bodies",
)

#: The plain feature of each load kind (``Load.kind``).
LOAD_FEATURES = {
    "linear_spring": "springs", "torsional_spring": "torsional_springs",
    "point_force": "point_forces", "moment": "moments",
    "angle_law": "angle_law_loads", "distance_law": "distance_law_loads",
}

#: Features whose work no energy balance counts: a driver's prescribed motion, point forces
#: and moments (time-switched or not), and law loads (their forces are not the gradient of a
#: potential in general: a torsion law applied as a force on a body-fixed lever, a distance
#: law pushing along a body axis). Where none is present the scene conserves or dissipates
#: energy (gravity and springs store it, friction, dampers and restitution e <= 1 only take it),
#: so any gain is the engine's. The one list for the harness's energy figures and verdict and
#: the engines' energy guard.
WORK_FEATURES = ("drivers", "point_forces", "moments", "angle_law_loads", "distance_law_loads")


class FeatureKind(enum.Enum):
    """What a feature names: a plain capability, a shape kind, a joint kind, a shape pair."""

    PLAIN = "plain"
    SHAPE = "shape"
    JOINT = "joint"
    PAIR = "pair"


@dataclass(frozen=True)
class Feature:
    """A parsed feature.

    Attributes
    ----------
    text : str
        The feature as Scene.features writes it.
    kind : FeatureKind
    parts : tuple of str
        PLAIN: (name,); SHAPE and JOINT: (kind,); PAIR: (kind_a, kind_b), sorted.
    """

    text: str
    kind: FeatureKind
    parts: tuple[str, ...]


def shape_feature(kind: str) -> str:
    """``shape:<kind>``."""
    return f"shape:{kind}"


def joint_feature(kind: str) -> str:
    """``joint:<kind>``."""
    return f"joint:{kind}"


def pair_feature(kind_a: str, kind_b: str) -> str:
    """``pair:<kind>-<kind>``, the two kinds sorted (the feature of either order)."""
    first, second = sorted((kind_a, kind_b))
    return f"pair:{first}-{second}"


def parse_feature(text: str) -> Feature:
    """Read a feature written by Scene.features (see the module docstring)."""
    prefix, colon, rest = text.partition(":")
    if colon and rest:
        if prefix == "shape":
            return Feature(text, FeatureKind.SHAPE, (rest,))
        if prefix == "joint":
            return Feature(text, FeatureKind.JOINT, (rest,))
        kinds = rest.split("-")
        if prefix == "pair" and len(kinds) == 2 and all(kinds):
            return Feature(text, FeatureKind.PAIR, tuple(kinds))
    return Feature(text, FeatureKind.PLAIN, (text,))
