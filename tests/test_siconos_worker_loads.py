"""The Siconos worker's loads (gravity, moments, law loads) agree with the reference solver's
force evaluation (``ref_solver.forces.applied_forces``) at random states, and the adapter
declares what it does not know UNSUPPORTED.

The worker module runs under Debian's Python; it imports numpy, its siblings ``geometry`` and
``project_kernels`` (by bare name) and the project's kernels, so it is imported here from its
folder. Siconos itself is imported only when a model is built, which these tests never do: they
run without Siconos.
"""

from __future__ import annotations

import dataclasses
import importlib
import json
import sys
from pathlib import Path

import numpy as np
import pytest

from clearbench.adapters.base import RunSettings, Support
from clearbench.adapters.siconos import engine as siconos_engine
from clearbench.adapters.trajectory import RunStatus
from clearbench.kernels import quaternion, time_profiles
from clearbench.kernels.quaternion import quat_normalize, quat_to_matrix
from clearbench.ref_solver.forces import applied_forces, no_angle_memory, rotation_matrices
from clearbench.ref_solver.scene_system import build_system
from clearbench.scenarios.library import get_scene, scene_names
from clearbench.scenarios.loads import AngleLawLoad, DistanceLawLoad, LoadApplication
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.serialization import scene_to_json


@pytest.fixture(scope="module")
def worker():
    folder = str(Path(siconos_engine.__file__).parent / "worker")
    sys.path.insert(0, folder)
    try:
        yield importlib.import_module("engine")
    finally:
        sys.path.remove(folder)


class _FakeDS:
    """Stands for a Siconos NewtonEulerDS: q = (centre of mass, quaternion), twist."""

    def __init__(self, q, twist):
        self._q, self._twist = q, twist

    def q(self):
        return self._q

    def twist(self):
        return self._twist


def _extra_laws(scene: Scene) -> Scene:
    """c60-on plus the application kinds it lacks: a distance law turned into a body-frame
    moment (lever) on a third body's law pair, an angle law of two bodies applied as a world
    force (lever) and a body-frame moment."""
    handle, plate, contact = "handle", "plate", "moving_contact"
    extra = (
        DistanceLawLoad(name="extra_distance", body_a=handle, point_a=(1.0, 2.0, 0.5),
                        body_b=plate, point_b=(-0.5, 3.0, 1.0), stiffness=2.5,
                        rest_length=12.0, applications=(
                            LoadApplication(body=plate, action="moment",
                                            direction=(0.3, -0.2, 1.0), frame="body",
                                            coefficient=0.7, lever=4.0),
                            LoadApplication(body=handle, action="force",
                                            direction=(0.0, 1.0, 0.2), frame="world",
                                            point=(2.0, -1.0, 0.3), coefficient=-1.3))),
        AngleLawLoad(name="extra_angle", axis=(0.0, 0.6, 0.8), stiffness=7.0, offset=0.4,
                     angle_bodies=(contact, handle), angle_coefficients=(0.5, -2.0),
                     applications=(
                         LoadApplication(body=handle, action="force", direction=(1.0, 1.0, 0.0),
                                         frame="world", point=(0.5, 0.5, -0.5), coefficient=1.1,
                                         lever=3.0),
                         LoadApplication(body=contact, action="moment",
                                         direction=(0.0, 0.0, 1.0), frame="body",
                                         coefficient=-0.4))),
    )
    return dataclasses.replace(scene, loads=scene.loads + extra)


def test_worker_loads_match_the_reference_forces_at_random_states(worker):
    scene = _extra_laws(get_scene("c60-on")).expanded
    system = build_system(scene)
    data = json.loads(scene_to_json(scene, indent=None))
    bodies = [worker.Body(i, b) for i, b in enumerate(data["bodies"])]
    by_name = {b.name: b for b in bodies}
    loads = worker.Loads(data, by_name)
    assert {"angle_law", "distance_law", "moment"} <= {load["kind"] for load in data["loads"]}
    rng = np.random.default_rng(11)
    nb = len(bodies)
    for trial in range(50):
        x = rng.normal(scale=10.0, size=(nb, 3))  # [mm], the size of the C-60 mechanism
        p = np.array([quat_normalize(q) for q in rng.normal(size=(nb, 4))])
        v = rng.normal(scale=100.0, size=(nb, 3))
        omega = rng.normal(scale=10.0, size=(nb, 3))
        for b, body in enumerate(bodies):
            if not body.fixed:
                body.ds = _FakeDS(np.r_[x[b], p[b]], np.r_[v[b], omega[b]])
        # Fixed bodies stay at their scene pose on both sides.
        x[system.body_fixed] = [body.q0[:3] for body in bodies if body.fixed]
        p[system.body_fixed] = [body.q0[3:] for body in bodies if body.fixed]
        t = 0.5 if trial % 2 else 1.5  # the tripping-bar moment acts for t < 1 only
        reference = applied_forces(
            t, x, rotation_matrices(p), v, omega, system.mass, system.gravity,
            system.body_fixed, system.force_kind, system.force_body_a, system.force_body_b,
            system.force_parameters, no_angle_memory(system.force_kind.shape[0]))
        for b, body in enumerate(bodies):
            if body.fixed:
                continue
            force, moment = loads.on_body(body.name, t)
            # Forces up to ~1e3 (N-scale laws on mm levers, g = 9810 mm/ms^2 on grams): the
            # two sides sum the same terms in a different order, so agreement is round-off of
            # the largest term, 1e-12 relative.
            scale = 1.0 + np.max(np.abs(reference[b]))
            np.testing.assert_allclose(force, reference[b, :3], rtol=0, atol=1e-12 * scale)
            np.testing.assert_allclose(moment, reference[b, 3:], rtol=0, atol=1e-12 * scale)


def test_twist_angle_is_the_quaternion_twist(worker):
    rng = np.random.default_rng(3)
    for _ in range(200):
        q = quat_normalize(rng.normal(size=4))
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        expected = 2.0 * np.arctan2(np.sign(q[0]) * (q[1:] @ axis), abs(q[0]))
        # Dimensionless angles of order 1: round-off of a few ulp of the atan2 arguments.
        assert abs(worker.twist_angle(quat_to_matrix(q), axis) - expected) < 1e-12


def test_worker_refuses_an_unknown_load_kind(worker):
    with pytest.raises(ValueError, match="unknown load kind"):
        worker.Loads({"loads": [{"kind": "magnetic", "name": "m"}]}, {})


def test_capabilities_of_c60_state_law_loads_and_bounded_pairs():
    capabilities = siconos_engine.create().capabilities(get_scene("c60-on"))
    assert not [f for f, c in capabilities.items() if c.support is Support.UNSUPPORTED]
    for feature in ("angle_law_loads", "distance_law_loads"):
        assert capabilities[feature].support is Support.APPROXIMATED
        assert "stiffness Jacobian" in capabilities[feature].detail
    for pair in ("pair:arc-bore", "pair:bore-cylinder", "pair:cylinder-rectangle"):
        assert capabilities[pair].support is Support.NATIVE
    # A journal's bore drops its candidates without an axial overlap (inactive slots); a face's
    # solid (kernels/gaps/face_solids.py) and a ring's bore (kernels/gaps/round_solids.py) keep
    # every slot, past their bounds too.
    assert "inactive" in capabilities["pair:bore-cylinder"].detail
    for pair in ("pair:arc-bore", "pair:cylinder-rectangle"):
        assert "inactive" not in capabilities[pair].detail


def test_unknown_features_are_unsupported(monkeypatch):
    scene = get_scene("pendulum")
    features = scene.features | {"warp_drive", "shape:torus", "pair:plane-torus"}
    monkeypatch.setattr(Scene, "features", property(lambda self: features))
    capabilities = siconos_engine.create().capabilities(scene)
    for feature in ("warp_drive", "shape:torus", "pair:plane-torus"):
        assert capabilities[feature].support is Support.UNSUPPORTED
        assert capabilities[feature].detail
    # Every feature of every library scene is one the adapter knows (none falls through to
    # "does not know").
    monkeypatch.undo()
    for name in scene_names():
        for feature, capability in siconos_engine.create().capabilities(
                get_scene(name)).items():
            assert "does not know" not in capability.detail, (name, feature)


def test_projection_refuses_pairs_that_drop_candidates():
    """The combined projection pulls active contacts to y = 0 as equalities: a dropped slot
    (gap 1e12) would be pulled back, so a journal's bore is unsupported with it, by preset and
    by option; the default preset keeps it."""
    scene = get_scene("c60-on")
    capabilities = siconos_engine.create("projection").capabilities(scene)
    assert capabilities["pair:bore-cylinder"].support is Support.UNSUPPORTED
    assert "index set 2" in capabilities["pair:bore-cylinder"].detail
    # Pairs that never drop a candidate stay supported with projection: a face's solid and a
    # ring's bore keep every slot past their bounds.
    for pair in ("pair:circle-cylinder", "pair:cylinder-rectangle", "pair:arc-bore"):
        assert capabilities[pair].support is Support.NATIVE
    trajectory = siconos_engine.create("projection").run(scene)
    assert trajectory.status is RunStatus.UNSUPPORTED and "CombinedProjection" in trajectory.message
    # Switched on by an option: refused before any worker starts.
    trajectory = siconos_engine.create("nsn-ac").run(
        scene, RunSettings(options={"projection": True}))
    assert trajectory.status is RunStatus.UNSUPPORTED
    assert "pair:bore-cylinder" in trajectory.message


def test_the_worker_takes_quaternions_and_time_profiles_from_the_kernels(worker):
    """The worker's rotations and driver profiles are the floor's kernels (imported through
    ``project_kernels``, by path under Debian's Python), not copies of them."""
    assert worker.quaternion is quaternion
    assert worker.time_profiles is time_profiles
    assert not {"evaluate_profile", "profile_rate", "_conjugate"} & set(vars(worker))
