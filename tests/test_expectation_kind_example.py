"""Adding an expectation kind touches one module: ``free_fall``, declared whole in
tests/expectation_kind_example.py and registered for the test, is validated, measured, judged,
tabled and reported by the harness's own code with no other edit (as tests/fake_engine.py is
an engine plugged in without an edit of the harness)."""

from __future__ import annotations

import pytest

from clearbench.harness.measure.figures import measure
from clearbench.harness.measure.kinds import registered
from clearbench.harness.measure.units import figure_unit, unit_text
from clearbench.harness.measure.verdicts import criteria_table
from clearbench.harness.report.page import write_report
from clearbench.harness.run.messages import WorkerRequest
from clearbench.harness.run.spec import make_run_spec
from clearbench.harness.run.store import ResultsStore, RunRecord, machine_info, revision_info
from clearbench.harness.run.worker import measure_phase, run_phase
from clearbench.harness.studies.benchmarks.physics_table import run_cell, table_rows
from clearbench.scenarios.bodies import Body
from clearbench.scenarios.expectation_kinds import EXPECTATION_KINDS
from clearbench.scenarios.expectations import Expectation
from clearbench.scenarios.inertia import solid_sphere
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.shapes import Sphere
from clearbench.scenarios.validation import SceneError

from .expectation_kind_example import FREE_FALL
from .fake_engine import create as fake_engine
from .harness_helpers import FAKE


@pytest.fixture
def free_fall():
    with registered(FREE_FALL) as kind:
        yield kind
    assert "free_fall" not in EXPECTATION_KINDS  # withdrawn with the test


def _falling_ball(gravity: float = 9.81) -> Scene:
    """A ball released from rest with nothing to hit: 0.44 m of fall in 0.3 s."""
    return Scene(name="falling-ball", description="A ball in free flight.", horizon=0.3,
                 time_step=1e-3,
                 bodies=(Body("ball", mass=1.0, inertia=solid_sphere(1.0, 0.1),
                              shapes=(Sphere("s", radius=0.1),)),),
                 expectations=(Expectation("fall", kind="free_fall", body="ball",
                                           parameters={"gravity": gravity}),))


def test_the_kind_exists_only_while_registered(free_fall):
    assert EXPECTATION_KINDS["free_fall"] is FREE_FALL.declaration


def test_its_parameters_are_validated_by_its_declaration(free_fall):
    with pytest.raises(SceneError, match=r"parameters\.gravity = -9\.81: must be > 0"):
        _falling_ball(gravity=-9.81)
    # Its scene check: the closed form must be the scene's physics.
    with pytest.raises(SceneError, match=r"parameters\.gravity = 9\.7: must be the magnitude"):
        _falling_ball(gravity=9.7)


def test_it_is_measured_and_judged(free_fall):
    scene = _falling_ball()
    passing = measure(scene, fake_engine().run(scene, _settings()))
    result = next(r for r in passing.expectations if r["name"] == "fall")
    assert result["passed"] is True, result["detail"]
    assert result["criterion"] == "height within 1 % of the fall"
    assert passing.error_source == "analytic (fall)"
    # Symplectic Euler's g t h / 2: 1.5 mm after 0.3 s at h = 1 ms, 0.35 % of the 0.44 m fall.
    assert passing.figures["fall.height_max_error"] == pytest.approx(1.47e-3, rel=0.01)
    # A body whose recorded height drifts up by 0.1 m/s misses the parabola by 30 mm: fails.
    drifting = measure(scene, fake_engine().run(scene, _settings(bias=0.1)))
    result = next(r for r in drifting.expectations if r["name"] == "fall")
    assert result["passed"] is False
    assert result["detail"].startswith("height error ") and "% > 1 %" in result["detail"]


def test_its_figures_have_units(free_fall):
    scene = _falling_ball()
    assert unit_text("fall.height_max_error", scene) == "m"
    assert figure_unit("fall.height_relative_error", scene).of == "the fall height"
    # From a stored row, without the scene: by the expectation's kind.
    assert unit_text("fall.height_max_error", None, {"fall": "free_fall"}) == "m"


def test_it_is_tabled(free_fall):
    scene = _falling_ball()
    cell = run_cell(fake_engine(), scene, 1e-3)
    rows = dict(table_rows(scene, [cell]))
    assert rows["free-fall height error [mm]"] == ["1.47"]
    assert "| `free_fall` | height within 1 % of the fall height" in criteria_table()


@pytest.mark.parametrize("bias, passed, shown", [
    # The passing run: its verdict and its headline error, the kind's analytic error (1.5 mm
    # off a 0.44 m fall).
    (0.0, 1, ["data-verdict='pass'", "error 0.00333 rel."]),
    # The drifting run (0.1 m/s upward): the kind's criterion against its figure, 30 mm off.
    # A failed cell shows the failing expectation's value against its limit.
    (0.1, 0, ["data-verdict='physics failed'", "<span class='small'>height error 6.46 %",
              "fails fall: height error 6.46 % &gt; 1 %"]),
])
def test_it_is_stored_and_reported(free_fall, tmp_path, bias, passed, shown):
    # The run goes through the worker's two phases and into the store as `clearbench run`
    # sends it (here in this process, where the kind is registered), then into the report.
    store = ResultsStore(tmp_path / "store")
    spec = make_run_spec(_falling_ball(), "fake", options={"bias": bias},
                         extra_engine_modules=FAKE)
    request = WorkerRequest.of(spec, str(tmp_path / "run.npz"))
    ran, scene, trajectory = run_phase(request)
    measured = measure_phase(request, scene, trajectory)
    store.record(RunRecord.from_messages(spec, ran, measured, revision_info(), machine_info()),
                 tmp_path / "run.npz", scene=spec.scene)
    row = store.get(spec.key)
    assert "fall.height_relative_error" in row["metrics"]
    assert row["expectations_passed"] == passed
    page = write_report(store, tmp_path / "out")["html"].read_text()
    for text in shown:
        assert text in page, text


def _settings(**options):
    from clearbench.adapters.base import RunSettings
    return RunSettings(options=options)
