"""Which bounded faces of a C-60 run were touched at their edge (a partner past the face's bound).

Reads a stored trajectory (``clearbench run ... --out t.npz`` or the results store's
``trajectories/KEY.npz``) and the scene it was run with, and, for every contact pair with a
rectangle or disc, finds the recorded states where one of the pair's candidates is near
contact (gap minus offset below ``--near`` mm) with its point on the face's solid ON the face's
bound (the face's edge or rim, or its side or back: not inside the face): the partner is past
the face's edge. Printed per such pair: how many states, the first and last time [ms], the
smallest gap there [mm] and how far past the bound the partner's point lies [mm].

    .venv/bin/python -m tools.c60_face_edges t.npz --scene c60-trip [--variant source]
        [--clearance 0.07] [--near 0.005]
"""

from __future__ import annotations

import argparse

import numpy as np

from clearbench.adapters.trajectory import Trajectory
from clearbench.scenarios.geometry import contacts_between, shape_world_placement
from clearbench.scenarios.library import get_scene

JOINTS = tuple(f"J{i}" for i in range(1, 8))
#: A point within this of the face's bound [mm] counts as on it (round-off of the placements).
ON_BOUND = 1e-9


def past_bound(face, local) -> float:
    """How far the face-frame point ``local`` lies outside the face's outline [mm] (<= 0:
    inside it)."""
    if face.kind == "disc":
        return float(np.hypot(local[0], local[1]) - face.radius)
    return float(max(abs(local[0]) - face.half_extents[0], abs(local[1]) - face.half_extents[1]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trajectory")
    parser.add_argument("--scene", required=True)
    parser.add_argument("--variant", default="source")
    parser.add_argument("--clearance", type=float, default=None)
    parser.add_argument("--near", type=float, default=0.005, help="[mm]")
    args = parser.parse_args()
    parameters = {"variant": args.variant}
    if args.clearance is not None:
        parameters["clearances"] = {joint: args.clearance for joint in JOINTS}
    scene = get_scene(args.scene, **parameters).expanded
    trajectory = Trajectory.load(args.trajectory)
    bodies = {body.name: body for body in scene.bodies}
    index = {name: k for k, name in enumerate(trajectory.body_names)}
    found = False
    for contact in scene.contacts:
        shapes = [(bodies[contact.body_a].shape(contact.shape_a), contact.body_a),
                  (bodies[contact.body_b].shape(contact.shape_b), contact.body_b)]
        faces = [k for k, (shape, _) in enumerate(shapes) if shape.kind in ("rectangle",
                                                                              "disc")]
        if not faces:
            continue
        face, face_body = shapes[faces[0]]
        times, gaps, beyond = [], [], []
        for t in range(len(trajectory.times)):
            poses = [(trajectory.positions[t, index[body]],
                      trajectory.orientations[t, index[body]]) for _, body in shapes]
            pair = contacts_between(shapes[0][0], poses[0], shapes[1][0], poses[1])
            if pair.count == 0:
                continue
            face_points = pair.point_a if faces[0] == 0 else pair.point_b
            position, rotation = shape_world_placement(face, *poses[faces[0]])
            for k in np.nonzero(pair.gap - contact.offset < args.near)[0]:
                local = rotation.T @ (face_points[k] - position)
                if past_bound(face, local) >= -ON_BOUND or local[2] < -ON_BOUND:
                    partner = pair.point_b[k] if faces[0] == 0 else pair.point_a[k]
                    times.append(trajectory.times[t])
                    gaps.append(pair.gap[k] - contact.offset)
                    beyond.append(past_bound(face, rotation.T @ (partner - position)))
                    break
        if times:
            found = True
            print(f"{contact.name}: {len(times)} states, {times[0]:.3f}..{times[-1]:.3f} ms, "
                  f"smallest gap {min(gaps):+.3e} mm, partner past the bound by up to "
                  f"{max(beyond):.3e} mm")
    if not found:
        print(f"no face touched at its edge (gap below {args.near} mm)")


if __name__ == "__main__":
    main()
