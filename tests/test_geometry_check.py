"""The run-wide geometry check: the "unseen penetration" verdict on synthetic trajectories.

A ring (radius 0.5 m, standing in the xz-plane) over a fixed face (half extents 1 x 1 m, depth
0.5 m) at a few recorded states. Where the ring's lowest point is past the face's edge but the
ring still dips into the face's solid (the case worked by hand in tests/test_instrument.py:
0.1 m deep), a kernel figure that reads 0 there is blind, and the run must fail with the named
verdict; where the kernel's figure and the instrument's agree, the run passes.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearbench.adapters.trajectory import Trajectory, scene_fields
from clearbench.harness.measure import figures, geometry_check, series
from clearbench.harness.measure.verdicts import VERDICTS, run_verdict
from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.inertia import solid_sphere
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Circle, Rectangle

STAND_UP = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0)
#: Ring centres [m]: above the face, dipping 0.01 over it, over the edge (0.1 deep in the
#: slab, lowest point 0.2 past the edge), and above again.
ABOVE, DIPPING, OVER_THE_EDGE = (0.0, 0.0, 0.6), (0.3, 0.0, 0.49), (1.2, 0.0, 0.3)


def ring_scene() -> Scene:
    table = Body("table", motion=Motion.FIXED,
                 shapes=(Rectangle("face", half_extents=(1.0, 1.0), depth=0.5),))
    ring = Body("ring", mass=1.0, inertia=solid_sphere(1.0, 0.5), position=ABOVE,
                shapes=(Circle("rim", radius=0.5, orientation=STAND_UP),))
    return Scene(name="ring-over-edge", description="A ring over a face's edge.",
                 horizon=1.0, time_step=0.01, bodies=(table, ring),
                 contacts=(ContactPair("table_ring", body_a="table", shape_a="face",
                                       body_b="ring", shape_b="rim", friction=0.3),))


def trajectory(scene: Scene, centres) -> Trajectory:
    """A recorded run with the ring's body at ``centres`` (T, 3), the table at rest."""
    count = len(centres)
    positions = np.zeros((count, 2, 3))
    positions[:, 1] = centres
    orientations = np.zeros((count, 2, 4))
    orientations[..., 0] = 1.0
    return Trajectory(
        engine="synthetic", preset="default", **scene_fields(scene), time_step=0.01,
        times=0.01 * np.arange(count), positions=positions, orientations=orientations,
        velocities=np.zeros((count, 2, 3)), angular_velocities=np.zeros((count, 2, 3)),
        contact_normal_force=np.zeros((count, 1)), contact_force=np.zeros((count, 1, 3)),
        solver_iterations=np.zeros(count, dtype=np.int64), solver_residual=np.zeros(count),
        solver_converged=np.ones(count, dtype=bool), active_contacts=np.zeros(count, np.int64))


@pytest.fixture
def blind_kernel(monkeypatch):
    """A kernel figure that sees nothing at the state over the edge (as the gap kernel of
    ddb0acf did): the figure of this revision everywhere else."""
    real = series.penetration

    def blind(scene, run):
        depth = np.array(real(scene, run), dtype=float)
        over = np.all(np.isclose(run.positions[:, 1], OVER_THE_EDGE), axis=1)
        depth[over] = 0.0
        return depth

    monkeypatch.setattr(series, "penetration", blind)


def test_unseen_penetration_fails_the_run_by_name(blind_kernel):
    scene = ring_scene()
    run = trajectory(scene, [ABOVE, DIPPING, OVER_THE_EDGE, ABOVE])
    measured = figures.measure(scene, run)
    unseen = measured.figures[geometry_check.UNSEEN_FIGURE]
    # 0.1 m deep by the hand computation, less the allowance (resolution 5e-7 m, round-off
    # 1e-9 of the scene's size): at least 0.0999.
    assert unseen == pytest.approx(0.1, abs=1e-4)
    assert measured.figures["unseen_penetration_time"] == pytest.approx(0.02)
    assert measured.figures["instrument_penetration_max"] == pytest.approx(0.1, abs=1e-5)
    verdict = run_verdict(measured.verdict.value, None, measured.figures)
    assert verdict == geometry_check.UNSEEN_PENETRATION and verdict in VERDICTS
    reason = measured.verdict_reason
    assert "table_ring" in reason and "t = 0.02 s" in reason
    assert "instrument witnesses 0.1 m" in reason and "kernel's figure is 0 m" in reason


def test_agreeing_figures_pass():
    """The ring dipping 0.01 over the face: the kernel sees it, both figures agree."""
    scene = ring_scene()
    run = trajectory(scene, [ABOVE, DIPPING, ABOVE])
    measured = figures.measure(scene, run)
    assert measured.figures[geometry_check.UNSEEN_FIGURE] == 0.0
    # Both within the pair's resolution, 1e-6 of its smallest length (the ring's 0.5 m).
    assert measured.figures["instrument_penetration_max"] == pytest.approx(0.01, abs=5e-7)
    assert measured.figures["instrument_difference_max"] <= 5e-7
    assert run_verdict(measured.verdict.value, 1, measured.figures) == "pass"
    result = geometry_check.check(scene, run)
    assert result.agrees and result.unseen_intervals() == {}


def test_a_stride_finds_the_interval_ends(blind_kernel):
    """Read at a stride of 4, the flagged interval's first and last states are still found
    (the states within a stride of a flagged one are read too)."""
    scene = ring_scene()
    centres = [ABOVE] * 5 + [OVER_THE_EDGE] * 6 + [ABOVE] * 9
    result = geometry_check.check(scene, trajectory(scene, centres), stride=4)
    first, last, count = result.unseen_intervals()["table_ring"]
    assert (first, last, count) == (pytest.approx(0.05), pytest.approx(0.10), 6)
    assert not result.instrument.read[1:4, 0].any()  # far from it, the stride is kept


def test_kernel_figure_of_another_shape_is_refused():
    scene = ring_scene()
    with pytest.raises(ValueError, match="kernel penetration has shape"):
        geometry_check.check(scene, trajectory(scene, [ABOVE]), kernel_penetration=np.zeros(3))
