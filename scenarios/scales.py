"""How large a scene, a body, a shape or a contact feature is: the one module of length scales.

Tolerances, guards and verdicts are relative to a length of the scene; each different length
is a differently named function here (they are not interchangeable: each keeps the exact
definition its callers were built and measured with). All lengths are in the scene's length
unit [L] and are computed from the scene description (its initial configuration), with
clearance joints expanded into their shapes and pairs where they have them.

=============================  ===============================================================
function                       used for
=============================  ===============================================================
:func:`shape_dimensions`       the radius, half length and half extents a shape has
:func:`smallest_shape_size`    a shape's smallest size (inf for a half-space)
:func:`body_size`              a body's largest extent (energy and stiction scales)
:func:`scene_size`             spread of the bodies and their sizes (escape verdict)
:func:`contact_feature_sizes`  per contact pair, the smaller of its two shapes (tunnelling)
:func:`smallest_contact_feature`  ... and the radial clearances (penetration criterion)
:func:`feature_lengths`        clearances, shape sizes, offsets, joint lever arms (the
                               reference's and Siconos's tolerances)
:func:`smallest_feature_length`  what a collision tolerance must resolve (MuJoCo)
:func:`largest_length`         the scene's largest length (MuJoCo's plane boxes)
:func:`largest_shape_dimension`  the largest shape dimension (MuJoCo's energy guard)
=============================  ===============================================================
"""

from __future__ import annotations

import math

import numpy as np

from clearbench.kernels.poses import centre_of_mass_frames
from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Shape

#: Attributes that give a shape's size, in the order they are read.
_SIZE_ATTRIBUTES = ("radius", "half_length")


def shape_dimensions(shape: Shape) -> list[float]:
    """The radius, the half length and the half extents a shape has, in that order [L] (empty
    for a plane)."""
    dimensions = [getattr(shape, name) for name in _SIZE_ATTRIBUTES if hasattr(shape, name)]
    return dimensions + list(getattr(shape, "half_extents", ()))


def smallest_shape_size(shape: Shape) -> float:
    """Smallest characteristic size of a shape [L]: its smallest half extent, else its radius;
    inf for a half-space."""
    if hasattr(shape, "half_extents"):
        return float(min(shape.half_extents))
    if hasattr(shape, "radius"):
        return float(shape.radius)
    return math.inf


def body_size(body: Body) -> float:
    """Size of a body [L]: its largest shape extent (norm of the half extents, or radius plus
    half length), or its centre-of-mass offset if that is larger."""
    sizes = []
    for shape in body.shapes:
        if hasattr(shape, "half_extents"):
            sizes.append(float(np.linalg.norm(shape.half_extents)))
        elif hasattr(shape, "radius"):
            sizes.append(float(shape.radius) + float(getattr(shape, "half_length", 0.0)))
    return max(sizes + [float(np.linalg.norm(body.center_of_mass))])


def scene_size(scene: Scene) -> float:
    """Length scale of the scene's initial configuration [L] (> 0): the largest of the spread
    of the body-frame origins and the :func:`body_size` of every body; 1 when all are 0."""
    positions = np.array([b.position for b in scene.bodies], dtype=float)
    spread = float(np.max(np.ptp(positions, axis=0))) if len(positions) > 1 else 0.0
    size = max([spread] + [body_size(b) for b in scene.bodies])
    return size if size > 0 else 1.0


def contact_feature_sizes(scene: Scene) -> np.ndarray:
    """(npair,) per contact pair of ``scene.expanded`` (explicit pairs, then those of the
    clearance joints), the :func:`smallest_shape_size` of its smaller shape [L]."""
    expanded = scene.expanded
    shapes = {(b.name, s.name): s for b in expanded.bodies for s in b.shapes}
    return np.array([min(smallest_shape_size(shapes[(c.body_a, c.shape_a)]),
                         smallest_shape_size(shapes[(c.body_b, c.shape_b)]))
                     for c in expanded.contacts])


def smallest_contact_feature(scene: Scene) -> float:
    """Smallest of the :func:`contact_feature_sizes` and the radial clearances [L]; inf when
    the scene has neither (or only half-spaces)."""
    sizes = [float(size) for size in contact_feature_sizes(scene)]
    sizes += [j.radial_clearance for j in scene.clearance_joints]
    finite = [s for s in sizes if math.isfinite(s)]
    return min(finite) if finite else math.inf


def feature_lengths(scene: Scene) -> list[float]:
    """Characteristic lengths of the scene [L], each positive and finite: radial and axial
    clearances, shape dimensions (:func:`shape_dimensions`), positive contact offsets, and the
    lever arms of the joints (distance from each moving body's centre of mass to the anchor)."""
    lengths = []
    for joint in scene.clearance_joints:
        lengths += [joint.radial_clearance, joint.axial_clearance]
    for body in scene.expanded.bodies:
        for shape in body.shapes:
            lengths += shape_dimensions(shape)
    for contact in scene.all_contacts:
        if contact.offset > 0:
            lengths.append(contact.offset)
    x, _, _ = centre_of_mass_frames([b.position for b in scene.bodies],
                                    [b.orientation for b in scene.bodies],
                                    [b.center_of_mass for b in scene.bodies])
    for joint in scene.joints:
        for name in (joint.body_a, joint.body_b):
            if scene.body(name).motion is not Motion.FIXED:
                lengths.append(float(np.linalg.norm(np.asarray(joint.anchor)
                                                    - x[scene.body_index(name)])))
    return [length for length in lengths if length > 0 and math.isfinite(length)]


def largest_length(scene: Scene) -> float:
    """Largest characteristic length of the scene [L] (> 0): distances of the body origins,
    centres of mass and shape origins from their frames' origins, and the shape dimensions."""
    lengths = [1e-300]
    for body in scene.expanded.bodies:
        lengths.append(float(np.linalg.norm(body.position)))
        lengths.append(float(np.linalg.norm(body.center_of_mass)))
        for shape in body.shapes:
            lengths.append(float(np.linalg.norm(shape.position)))
            lengths += [float(x) for x in shape_dimensions(shape)]
    return max(lengths)


def smallest_feature_length(scene: Scene) -> float:
    """Smallest positive clearance, contact offset (either sign) or shape dimension [L]: the
    scale a collision tolerance must resolve; :func:`largest_length` when there is none."""
    lengths = []
    for joint in scene.clearance_joints:
        lengths += [joint.radial_clearance, joint.axial_clearance]
    for contact in scene.all_contacts:
        if contact.offset != 0:
            lengths.append(abs(contact.offset))
    for body in scene.expanded.bodies:
        for shape in body.shapes:
            lengths += shape_dimensions(shape)
    positive = [x for x in lengths if x > 0 and math.isfinite(x)]
    return min(positive) if positive else largest_length(scene)


def largest_shape_dimension(scene: Scene) -> float:
    """Largest :func:`shape_dimensions` of any shape of the scene [L] (0 without shapes)."""
    return max([0.0] + [float(x) for body in scene.expanded.bodies for shape in body.shapes
                        for x in shape_dimensions(shape)])
