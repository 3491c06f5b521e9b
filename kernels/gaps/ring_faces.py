"""Ring (circle or arc, B) against a face's solid (A: plane, rectangle or disc): every candidate a
ring needs, continuous while it crosses the face's bound.

The gap of a ring point is its signed distance to the face's solid
(:func:`~.face_solids.face_solid_distance`: the top face over the face, the edge beyond its
bound, the corner): continuous everywhere, and outside the solid so is its gradient (the
normal). A pair's contact offset d (taken by the caller) makes this the gap of the torus of
radius d about the ring, whose normal then stays continuous while the penetration is below d.
A bare ring's minimum at a face's edge (on it to round-off, or just inside) is the ring against
the edge line along their common normal (:mod:`.ring_edges`); deeper inside, a bare ring takes
the normal of the nearest face.

The candidates (slots, :data:`RING_FACE_SLOTS` = 8, all always kept):

- slots 0..5, support points: six points of the ring that hold it up when it lies on the face
  (as a box's corners do). A circle's are 60 degrees apart from the direction of the face's x
  axis in the ring's plane (its y axis where x is within 30 degrees of the ring's axis: the ring
  then stands, its support points far from the face), so they do not depend on the ring's own
  frame; an arc's are spread evenly over it, its ends included.
- slots 6..7, the deepest (closest) points: the two lowest local minima over the ring's angle of
  the gap, found on a grid of 24 samples per turn and refined by Brent's minimisation within
  one sample of each side. A minimum in the middle of the face is the ring's lowest point there;
  beyond the bound it is the ring's nearest point to the face's edge; for a ring lying across
  the edge the two minima are where it crosses it. A minimum at an arc's end is that end's
  support point, unless that support was moved to a crossing of the face's bound (then the
  minimum holds the end); a slot left without a minimum takes the ring's highest sample point
  that is not a support point (a true ring point far from the face, inactive unless the ring
  lies flat).
"""

from __future__ import annotations

import math

from clearbench.kernels.gaps.codes import DISC, PLANE, TWO_PI
from clearbench.kernels.gaps.face_solids import face_solid_distance
from clearbench.kernels.gaps.ring_edges import edge_continuation, ring_edge_contact, ring_point
from clearbench.kernels.gaps.staging import stage_contact
from clearbench.kernels.gaps.vectors import (
    column_of,
    rotate,
    rotate_back,
    scaled,
    sub,
    to_local,
    to_world,
)
from clearbench.kernels.jit import njit

#: Support points of a ring (slots 0..SUPPORT_POINTS - 1): 60 degrees apart on a circle.
SUPPORT_POINTS = 6
#: Local minima of the gap over the ring's angle (the slots after the support points).
MINIMA = 2
#: Candidate slots of a ring against a face's solid.
RING_FACE_SLOTS = SUPPORT_POINTS + MINIMA
#: Samples of a full turn for the search of the minima (15 degrees apart); a multiple of
#: SUPPORT_POINTS so that the support points are samples.
_SAMPLES_PER_TURN = 24
#: Absolute tolerance [rad] of the minimisation over the ring angle: the minimum's position to
#: 1e-9 of the radius; its gap, quadratic there, to round-off.
_ANGLE_TOLERANCE = 1e-9
#: A minimum within this of an arc's end [rad] is that end (its support point).
_AT_END = 1e-7
#: Golden-section ratio of Brent's minimisation, (3 - sqrt 5) / 2.
_GOLDEN = 0.3819660112501051
#: A projected face axis shorter than this picks the other axis for the support points' phase.
_PHASE_AXIS_MIN = 0.5
#: |ring axis . face normal| at or above this (the ring's plane within 45 degrees of the
#: face's), the ring lies on the face: its support points beyond the face's bound move to the
#: crossings (:func:`_stage_support`). A ring steeper than that rests on its lowest point or on
#: the edge it crosses (the minima), which the support points would only duplicate: a duplicate
#: of the edge contact of a hoop pivoting on an edge, swapping slots as the hoop turned, spun it.
_LYING = math.cos(0.25 * math.pi)
#: Bisections locating where the ring crosses the face's bound between two support points (at
#: most 120 degrees apart): the angle to 2^-40 of that, below 2e-12 rad.
_BOUND_BISECTIONS = 40


@njit(cache=True, inline="always")
def _distance(theta, centre, e1, e2, radius, kind, size_1, size_2, depth):
    """Signed distance [L] of the ring point at ``theta`` to the face's solid."""
    return face_solid_distance(kind, size_1, size_2, depth,
                               ring_point(centre, e1, e2, radius, theta))[0]


@njit(cache=True)
def _minimise(low, high, x, fx, centre, e1, e2, radius, kind, size_1, size_2, depth):
    """Brent's minimisation (golden section with parabolic steps; R. P. Brent, Algorithms for
    Minimization without Derivatives, 1973, ch. 5) of the centre line's distance to the solid
    over [low, high], from the point ``x`` of value ``fx`` inside it. Returns (angle, value)."""
    w = v = x
    fw = fv = fx
    step = 0.0
    previous_step = 0.0
    for _ in range(100):
        middle = 0.5 * (low + high)
        tolerance = _ANGLE_TOLERANCE + 4.4e-16 * abs(x)
        if abs(x - middle) <= 2.0 * tolerance - 0.5 * (high - low):
            break
        golden = True
        if abs(previous_step) > tolerance:
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            if (abs(p) < abs(0.5 * q * previous_step) and p > q * (low - x)
                    and p < q * (high - x)):
                previous_step = step
                step = p / q
                if (x + step) - low < 2.0 * tolerance or high - (x + step) < 2.0 * tolerance:
                    step = tolerance if x < middle else -tolerance
                golden = False
        if golden:
            previous_step = (high - x) if x < middle else (low - x)
            step = _GOLDEN * previous_step
        if abs(step) >= tolerance:
            u = x + step
        else:
            u = x + (tolerance if step > 0.0 else -tolerance)
        fu = _distance(u, centre, e1, e2, radius, kind, size_1, size_2, depth)
        if fu <= fx:
            if u < x:
                high = x
            else:
                low = x
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            if u < x:
                low = u
            else:
                high = u
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v == x or v == w:
                v, fv = u, fu
    return x, fx


@njit(cache=True)
def _stage_ring_point(index, theta, centre, e1, e2, radius, kind, size_1, size_2, depth,
                      face_position, face_rotation, stage):
    """Stage the contact of the ring point at ``theta``: gap = its distance to the solid, the
    normal the distance's gradient, the point on A the solid's surface point nearest it (all
    mapped from the face frame to world)."""
    point = ring_point(centre, e1, e2, radius, theta)
    distance, gradient = face_solid_distance(kind, size_1, size_2, depth, point)
    on_face = sub(point, scaled(gradient, distance))
    stage_contact(stage, index, distance,
                  to_world(face_position, face_rotation, on_face),
                  rotate(face_rotation, gradient))


@njit(cache=True, inline="always")
def _beyond_bound(kind, size_1, size_2, point):
    """How far [L] the face-frame ``point``'s projection on the face's plane lies beyond the
    face's bound (> 0 beyond it; a plane has none: -inf)."""
    if kind == PLANE:
        return -math.inf
    if kind == DISC:
        return math.hypot(point[0], point[1]) - size_1
    return max(abs(point[0]) - size_1, abs(point[1]) - size_2)


@njit(cache=True, inline="always")
def _point_beyond(theta, centre, e1, e2, radius, kind, size_1, size_2):
    """True if the ring point at ``theta`` lies beyond the face's bound (projected)."""
    return _beyond_bound(kind, size_1, size_2, ring_point(centre, e1, e2, radius, theta)) > 0.0


@njit(cache=True)
def _bound_crossing(outside, inside, centre, e1, e2, radius, kind, size_1, size_2):
    """Angle [rad] where the ring crosses the face's bound between its point at ``outside``
    (beyond the bound) and at ``inside`` (within it), by bisection; the angle returned is on
    the bound's inner side."""
    for _ in range(_BOUND_BISECTIONS):
        middle = 0.5 * (outside + inside)
        if _point_beyond(middle, centre, e1, e2, radius, kind, size_1, size_2):
            outside = middle
        else:
            inside = middle
    return inside


@njit(cache=True)
def _stage_support(k, phase, step, count, is_arc, centre, e1, e2, radius, kind, size_1, size_2,
                   depth, low_limit, high_limit, spacing, face_position, face_rotation, stage):
    """Stage support point ``k`` of ``count``, at ``phase + k * step`` [rad]; one beyond the
    face's bound next to a support within it is moved along the ring to where the ring crosses
    the bound (the nearer crossing when both neighbours are within), as a box's corners beyond
    a face give way to the clipped polygon's vertices on its bound: a ring lying across the
    bound is then held up at the crossings, whatever its own frame, not only by the supports
    on one side of its centre. There the contact is the ring against the edge line
    (:func:`~.ring_edges.ring_edge_contact`) where that holds, else the ring point's distance to
    the solid. Returns True if the support was moved (an arc's end then no longer holds its
    end point: :func:`ring_face` stages a minimum there)."""
    theta = phase + k * step
    if not _point_beyond(theta, centre, e1, e2, radius, kind, size_1, size_2):
        _stage_ring_point(k, theta, centre, e1, e2, radius, kind, size_1, size_2, depth,
                          face_position, face_rotation, stage)
        return False
    previous_within = (k > 0 or not is_arc) and not _point_beyond(
        theta - step, centre, e1, e2, radius, kind, size_1, size_2)
    next_within = (k < count - 1 or not is_arc) and not _point_beyond(
        theta + step, centre, e1, e2, radius, kind, size_1, size_2)
    if previous_within and next_within:
        before = _bound_crossing(theta, theta - step, centre, e1, e2, radius, kind, size_1,
                                 size_2)
        after = _bound_crossing(theta, theta + step, centre, e1, e2, radius, kind, size_1,
                                size_2)
        theta = before if theta - before < after - theta else after
    elif previous_within:
        theta = _bound_crossing(theta, theta - step, centre, e1, e2, radius, kind, size_1,
                                size_2)
    elif next_within:
        theta = _bound_crossing(theta, theta + step, centre, e1, e2, radius, kind, size_1,
                                size_2)
    else:
        _stage_ring_point(k, theta, centre, e1, e2, radius, kind, size_1, size_2, depth,
                          face_position, face_rotation, stage)
        return False
    is_edge, gap, on_edge, normal = ring_edge_contact(
        theta, centre, e1, e2, radius, kind, size_1, size_2, depth,
        max(theta - spacing, low_limit), min(theta + spacing, high_limit))
    if is_edge:
        stage_contact(stage, k, gap, to_world(face_position, face_rotation, on_edge),
                      rotate(face_rotation, normal))
    else:
        _stage_ring_point(k, theta, centre, e1, e2, radius, kind, size_1, size_2, depth,
                          face_position, face_rotation, stage)
    return True


@njit(cache=True, inline="always")
def _support_phase(e1, e2):
    """Angle, in the ring's frame, of the face's x axis projected on the ring's plane (its y
    axis when x is within 30 degrees of the ring's axis): the first support point of a circle,
    independent of the ring's own x axis. ``e1``, ``e2``: the ring's axes in the face frame."""
    a, b = e1[0], e2[0]
    if math.hypot(a, b) < _PHASE_AXIS_MIN:
        a, b = e1[1], e2[1]
    return math.atan2(b, a)


@njit(cache=True)
def ring_face(kind, size_1, size_2, depth, face_position, face_rotation, ring_position,
              ring_rotation, radius, start_angle, span, is_arc, stage):
    """Ring (B) against the solid of a face (A): :data:`RING_FACE_SLOTS` candidates, staged in
    slots 0..7 (module docstring). Returns the slot count.

    Parameters
    ----------
    kind, size_1, size_2, depth
        The face's code and :func:`~.face_solids.face_solid_parameters` [L].
    face_position, face_rotation
        The face frame's world placement (3-tuple [L], 3 rows of 3).
    ring_position, ring_rotation
        The ring frame's world placement (the ring in its xy-plane about the origin).
    radius, start_angle, span, is_arc
        The ring's radius [L] and an arc's first angle and extent [rad] (a circle: 0, 2 pi,
        False).
    """
    centre = to_local(face_position, face_rotation, ring_position)
    e1 = rotate_back(face_rotation, column_of(ring_rotation, 0))
    e2 = rotate_back(face_rotation, column_of(ring_rotation, 1))
    if is_arc:
        phase = start_angle
        per_gap = max(2, int(math.ceil(_SAMPLES_PER_TURN * span
                                       / (TWO_PI * (SUPPORT_POINTS - 1)))))
        samples = per_gap * (SUPPORT_POINTS - 1) + 1
        spacing = span / (samples - 1)
    else:
        phase = _support_phase(e1, e2)
        per_gap = _SAMPLES_PER_TURN // SUPPORT_POINTS
        samples = _SAMPLES_PER_TURN
        spacing = TWO_PI / samples
    low_limit, high_limit = (phase, phase + span) if is_arc else (-math.inf, math.inf)
    # The ring's axis against the face's normal (z): within _LYING of it, the ring lies on the
    # face and its support points beyond the bound move to where it crosses the bound.
    lying = abs(e1[0] * e2[1] - e1[1] * e2[0]) >= _LYING
    start_moved = False
    end_moved = False
    for k in range(SUPPORT_POINTS):
        if lying:
            moved = _stage_support(k, phase, per_gap * spacing, SUPPORT_POINTS, is_arc, centre,
                                   e1, e2, radius, kind, size_1, size_2, depth, low_limit,
                                   high_limit, spacing, face_position, face_rotation, stage)
            if k == 0:
                start_moved = moved
            elif k == SUPPORT_POINTS - 1:
                end_moved = moved
        else:
            _stage_ring_point(k, phase + k * per_gap * spacing, centre, e1, e2, radius, kind,
                              size_1, size_2, depth, face_position, face_rotation, stage)
    # The samples' discrete local minima (the two lowest), and the two highest samples that
    # are not support points (fills). The cyclic neighbours of a circle's first and last
    # samples are each other; an arc's ends compare with their one neighbour.
    first_value = _distance(phase, centre, e1, e2, radius, kind, size_1, size_2, depth)
    second_value = _distance(phase + spacing, centre, e1, e2, radius, kind, size_1, size_2,
                             depth)
    best_value, best_index = math.inf, -1
    next_value, next_index = math.inf, -1
    high_value, high_index = -math.inf, 1
    higher_value, higher_index = -math.inf, 1
    before = math.inf
    if not is_arc:
        before = _distance(phase - spacing, centre, e1, e2, radius, kind, size_1, size_2,
                           depth)
    here = first_value
    following = second_value
    for i in range(samples):
        if i + 1 < samples:
            if i >= 1:
                following = _distance(phase + (i + 1) * spacing, centre, e1, e2, radius, kind,
                                      size_1, size_2, depth)
        elif is_arc:
            following = math.inf
        else:
            following = first_value
        if here < before and here <= following:
            if here < best_value:
                next_value, next_index = best_value, best_index
                best_value, best_index = here, i
            elif here < next_value:
                next_value, next_index = here, i
        if i % per_gap != 0:
            if here > high_value:
                higher_value, higher_index = high_value, high_index
                high_value, high_index = here, i
            elif here > higher_value:
                higher_value, higher_index = here, i
        before, here = here, following
    # Refine the minima; one at an arc's end is that end's support point, unless that support
    # was moved to a crossing of the bound (the end itself then has no other candidate).
    found = 0
    found_angle = (0.0, 0.0)
    found_value = (0.0, 0.0)
    for index in (best_index, next_index):
        if index < 0:
            continue
        theta = phase + index * spacing
        low = theta - spacing
        high = theta + spacing
        if is_arc:
            low = max(low, phase)
            high = min(high, phase + span)
        value = _distance(theta, centre, e1, e2, radius, kind, size_1, size_2, depth)
        theta, value = _minimise(low, high, theta, value, centre, e1, e2, radius, kind, size_1,
                                 size_2, depth)
        if is_arc and ((theta - phase < _AT_END and not start_moved)
                       or (phase + span - theta < _AT_END and not end_moved)):
            continue
        if found == 0:
            found_angle = (theta, 0.0)
            found_value = (value, 0.0)
        else:
            found_angle = (found_angle[0], theta)
            found_value = (found_value[0], value)
        found += 1
    if found == 2 and found_value[1] < found_value[0]:
        found_angle = (found_angle[1], found_angle[0])
        found_value = (found_value[1], found_value[0])
    fills = (phase + high_index * spacing, phase + higher_index * spacing)
    for m in range(MINIMA):
        theta = found_angle[m] if m < found else fills[m - found]
        if m < found:
            is_edge, gap, on_edge, normal = edge_continuation(
                theta, found_value[m], centre, e1, e2, radius, kind, size_1, size_2, depth, spacing,
                low_limit, high_limit)
            if is_edge:
                stage_contact(stage, SUPPORT_POINTS + m, gap,
                              to_world(face_position, face_rotation, on_edge),
                              rotate(face_rotation, normal))
                continue
        _stage_ring_point(SUPPORT_POINTS + m, theta, centre, e1, e2, radius, kind, size_1,
                          size_2, depth, face_position, face_rotation, stage)
    return RING_FACE_SLOTS
