"""PyBullet's distance of every contact pair at t = 0 against the scene's gap: the check that
the collision geometry PyBullet resolves is the scene's (docs/engines/pybullet.md, "Units").

``getClosestPoints`` between each pair's collision objects, against
:func:`clearbench.scenarios.geometry.contacts_between` minus the pair's offset, both in the
scene's length unit.
"""

from __future__ import annotations

import math

from clearbench.adapters.pybullet.build import build_world, disconnect
from clearbench.adapters.pybullet.engine import internal_scene
from clearbench.adapters.pybullet.library import pb
from clearbench.adapters.pybullet.settings import resolve_settings
from clearbench.scenarios.geometry import UnsupportedPairError, contacts_between
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.validation import LENGTH

__all__ = ["pair_distances"]


def pair_distances(scene: Scene, preset: str, options: dict | None = None,
                   reach: float = 1.0) -> list[tuple[str, float, float]]:
    """(pair name, scene gap, PyBullet distance) per pair of ``scene.expanded``, in the scene's
    length unit [L]; the gap is NaN where the scene's kernel finds no candidate, the distance
    inf where PyBullet finds nothing within ``reach`` [L]."""
    settings = resolve_settings(preset, options)
    internal = internal_scene(scene, settings)
    to_scene = internal.units.factor_to(scene.units, LENGTH)
    built = build_world(internal, settings, internal.time_step)
    out = []
    try:
        expanded = scene.expanded
        for index, contact in enumerate(expanded.contacts):
            a, b = expanded.body(contact.body_a), expanded.body(contact.body_b)
            try:
                found = contacts_between(a.shape(contact.shape_a), (a.position, a.orientation),
                                         b.shape(contact.shape_b), (b.position, b.orientation))
                gap = float(found.gap.min()) - contact.offset if found.count else math.nan
            except UnsupportedPairError:
                gap = math.nan
            best = math.inf
            a_objects, b_objects = built.pair_objects[index]
            for oa in a_objects:
                for ob in b_objects:
                    for point in pb.getClosestPoints(oa.pb_body, ob.pb_body, reach / to_scene,
                                                     oa.link, ob.link,
                                                     physicsClientId=built.client):
                        best = min(best, point[8] * to_scene)
            out.append((contact.name, gap, best))
    finally:
        disconnect(built)
    return out
