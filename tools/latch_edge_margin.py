"""Where the tripping bar's arc of a C-60 latch pair lies against the hook's latch face, over a
reference run of `c60-on` (docs/c60.md, "The same blind spot in that variant's `c60-on`").

The arc (a half ring) is sampled densely in the face's frame at every recorded state. Printed per
state: the hook's angle from its start [deg]; the arc's lowest point (x, y in the face's frame
[mm]); its margin inside the face's edge across the face (half width - |x| [mm], negative:
past the edge); its height over the face's plane; and the lowest height of the part of the arc
still over the face [um] (negative: under the face's plane, which a gap kernel that takes only
the lowest point does not see once that point is past the edge).

    .venv/bin/python -m tools.latch_edge_margin [--variant preload-0.9599] [--clearance 0.07]
        [--horizon 1.5] [--every 20] [--pair Hook_Tbar_C4_3] [--option step_loop=python]

With branch `ring-face-edge`'s kernel in place (`git checkout ring-face-edge -- kernels/gaps.py`;
numba's cache follows the sources), the same command steps the reference with the edge kernel.
"""

from __future__ import annotations

import argparse

import numpy as np

from clearbench.adapters.base import RunSettings
from clearbench.adapters.reference import create
from clearbench.scenarios.geometry import shape_world_placements
from clearbench.scenarios.library import get_scene

#: Points the arc is sampled at.
ARC_SAMPLES = 4001
#: The C-60's joints (their clearances set together by --clearance).
JOINTS = tuple(f"J{i}" for i in range(1, 8))


def arc_against_face(face, face_placements, ring, ring_placements):
    """Per state (T,): the arc's lowest point (x, y, z) in the face's frame (T, 3) [L], and the
    lowest z of its part over the face (T,) [L] (NaN when no part is over it)."""
    angles = np.linspace(ring.start_angle, ring.end_angle, ARC_SAMPLES)
    (face_position, face_rotation), (ring_position, ring_rotation) = (face_placements,
                                                                      ring_placements)
    centre = np.einsum("tji,tj->ti", face_rotation, ring_position - face_position)
    u = np.einsum("tji,tj->ti", face_rotation, ring_rotation[:, :, 0])
    v = np.einsum("tji,tj->ti", face_rotation, ring_rotation[:, :, 1])
    points = (centre[:, None, :] + ring.radius * (np.cos(angles)[None, :, None] * u[:, None, :]
                                                   + np.sin(angles)[None, :, None]
                                                   * v[:, None, :]))
    lowest = points[np.arange(len(points)), np.argmin(points[:, :, 2], axis=1)]
    half_x, half_y = face.half_extents
    over = (np.abs(points[:, :, 0]) <= half_x) & (np.abs(points[:, :, 1]) <= half_y)
    over_height = np.where(over, points[:, :, 2], np.inf).min(axis=1)
    return lowest, np.where(np.isfinite(over_height), over_height, np.nan)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variant", default=None, help="a model variant (docs/c60.md)")
    parser.add_argument("--clearance", type=float, default=None,
                        help="every joint's radial clearance [mm] (default: the model's)")
    parser.add_argument("--horizon", type=float, default=1.5, help="[ms]")
    parser.add_argument("--every", type=int, default=20, help="record every N steps")
    parser.add_argument("--pair", default="Hook_Tbar_C4_3")
    parser.add_argument("--option", action="append", default=[], metavar="KEY=VALUE",
                        help="a reference engine option (strings)")
    args = parser.parse_args()
    parameters = {}
    if args.variant:
        parameters["variant"] = args.variant
    if args.clearance is not None:
        parameters["clearances"] = {joint: args.clearance for joint in JOINTS}
    scene = get_scene("c60-on", **parameters)
    options = dict(option.split("=", 1) for option in args.option)
    trajectory = create("default").run(scene, RunSettings(
        horizon=args.horizon, record_every=args.every, options=options))
    print(f"{trajectory.status.value}: {trajectory.message or 'no message'}")
    expanded = scene.expanded
    bodies = {body.name: body for body in expanded.bodies}
    contact = next(c for c in expanded.contacts if c.name == args.pair)
    shapes = [(bodies[contact.body_a].shape(contact.shape_a), contact.body_a),
              (bodies[contact.body_b].shape(contact.shape_b), contact.body_b)]
    (face, face_body), (ring, ring_body) = sorted(shapes, key=lambda s: s[0].kind != "rectangle")

    def placements(shape, body):
        index = trajectory.body_names.index(body)
        return shape_world_placements(shape, trajectory.positions[:, index],
                                      trajectory.orientations[:, index])

    lowest, over_height = arc_against_face(face, placements(face, face_body), ring,
                                           placements(ring, ring_body))
    hook = trajectory.orientations[:, trajectory.body_names.index("hook")]
    angle = 2.0 * np.degrees(np.arctan2(hook[:, 3], hook[:, 0]))
    angle -= angle[0]
    print(f"{args.pair}: face half width {face.half_extents[0]} mm, arc radius {ring.radius} "
          f"mm; contact offset {contact.offset * 1e3:g} um")
    print("t [ms]  hook [deg]  lowest x, y [mm]   margin [mm]  height [um]  "
          "over the face [um]")
    for k, t in enumerate(trajectory.times):
        print(f"{t:6.3f}  {angle[k]:10.2f}  {lowest[k, 0]:+.4f}, {lowest[k, 1]:+.4f}  "
              f"{face.half_extents[0] - abs(lowest[k, 0]):+11.4f}  {lowest[k, 2] * 1e3:+11.2f}  "
              f"{over_height[k] * 1e3:+18.2f}")


if __name__ == "__main__":
    main()
