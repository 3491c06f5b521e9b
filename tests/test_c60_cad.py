"""The C-60 primitives: the committed document, its loader, and its extraction from the STEP files.

The loader tests always run; the re-extraction tests need OpenCASCADE (extra ``cad``) and are
skipped only when ``OCP`` cannot be imported.
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import math
import sys
import tomllib

import pytest

from clearbench.scenarios.c60.primitives import (
    PRIMITIVES_PATH,
    Arc,
    Circle,
    Cylinder,
    Plane,
    Ring,
    compare_documents,
    load_primitives,
)
from tools.c60_cad.__main__ import main as extract_main
from tools.c60_cad.extract import CAD_DIR

DATA_DIR = PRIMITIVES_PATH.parent
HAS_OCP = importlib.util.find_spec("OCP") is not None
needs_ocp = pytest.mark.skipif(not HAS_OCP, reason="OpenCASCADE (extra 'cad') not installed")

# The document keeps 12 decimals (mm, rad): values read from exact OCC circles and lines agree
# with the README's round numbers to that rounding, so 1e-9 mm is a bound with ample margin.
EXACT = 1.0e-9


@pytest.fixture(scope="module")
def model():
    with (DATA_DIR / "model.toml").open("rb") as stream:
        return tomllib.load(stream)


@pytest.fixture(scope="module")
def primitives():
    return load_primitives()


def test_every_named_file_is_in_the_document_in_the_frame_of_its_body(model, primitives):
    frame_name = model["frame"]["name"]
    for group in ("contacts", "measurements"):
        for pair in model[group]:
            for side in ("1", "2"):
                body = pair[f"body{side}"]
                entry = primitives[pair[f"cad{side}"]]
                assert entry.frame == ("world" if body == frame_name else body)
    assert len(model["contacts"]) == 39 and len(model["measurements"]) == 7


def test_every_file_reduces_to_primitives_with_small_residuals(primitives):
    for entry in primitives:
        assert entry.primitives, entry.path
        assert entry.unreduced == (), entry.path
        for primitive in entry.primitives:
            # The extraction accepts a face only when its residual is at most
            # accept_residual_mm; the loader must see the same bound.
            assert primitive.residual_mm <= primitives.extraction["accept_residual_mm"]


def test_sha256_of_each_shipped_step_file_matches_the_document(primitives):
    for entry in primitives:
        digest = hashlib.sha256((CAD_DIR / entry.path).read_bytes()).hexdigest()
        assert digest == entry.sha256, entry.path


def test_readme_example_j1_journal_in_world(primitives):
    entry = primitives["C60/J1/Case_handle_J1_journal_surface.stp"]
    assert entry.frame == "world"
    (journal,) = entry.primitives
    assert isinstance(journal, Cylinder) and not isinstance(journal, Ring)
    assert journal.is_full
    assert journal.radius == pytest.approx(2.3, abs=EXACT)
    assert journal.axis == pytest.approx((0.0, 0.0, 1.0), abs=EXACT)
    assert journal.axis_point == pytest.approx((-16.1, 10.0, 0.5), abs=EXACT)  # z from 0.5 ...
    assert journal.axis_point[2] + journal.length == pytest.approx(7.3, abs=EXACT)  # ... to 7.3
    # The B-spline surface stays within 0.1 micrometre of that exact cylinder (measured 3.4e-5).
    assert journal.residual_mm < 1.0e-4


def test_readme_example_handle_bearing_ring_in_handle_frame(primitives):
    entry = primitives["REVISED_CAD2/J1/Handle_Case_J1_bottom_bearing2.stp"]
    assert entry.frame == "handle"
    (ring,) = entry.primitives
    assert isinstance(ring, Ring) and ring.is_full
    assert ring.radius == pytest.approx(2.8, abs=EXACT)
    assert ring.axis_point[2] == pytest.approx(0.5, abs=EXACT)  # the band spans z 0.5 .. 0.506
    assert ring.length == pytest.approx(0.006, abs=EXACT)
    assert ring.material == "outside"  # a bore: its axis is not in the handle's material


def test_revolute_joint_clearances_follow_from_ring_and_journal_radii(model, primitives):
    """J1 bottom, J2..J7: ring radius - journal radius - offset = 0.021 mm (data sheet)."""
    contacts = {pair["name"]: pair for pair in model["contacts"]}
    for name in ("Handle_case_J1_bot", "Needle_plate_J2_bot", "Plate_hook_J3_bot",
                 "Plate_Tbar_J4_top", "Rod_handle_J5_bot", "Rod_hook_J6_top",
                 "Mcontact_needle_J7_bot"):
        pair = contacts[name]
        (ring,) = primitives[pair["cad1"]].of_kind("ring")
        (journal,) = primitives[pair["cad2"]].of_kind("cylinder")
        # Radii are the exact boundary circles (12 decimals kept), offsets exact decimals.
        assert ring.radius - journal.radius - pair["offset"] == pytest.approx(0.021, abs=EXACT)


def test_loader_builds_the_right_dataclasses(primitives):
    (arc,) = primitives["REVISED_CAD3/C4/Hook_half_ring_C4_bottom.stp"].primitives
    assert type(arc) is Arc and not arc.is_full
    assert arc.end_angle - arc.start_angle == pytest.approx(math.pi, abs=EXACT)  # a half ring
    # point_at follows the documented convention: it lies on the circle, in its plane.
    point = arc.point_at(arc.start_angle)
    offset = [point[i] - arc.centre[i] for i in range(3)]
    assert math.hypot(*offset) == pytest.approx(arc.radius, abs=EXACT)
    assert sum(offset[i] * arc.normal[i] for i in range(3)) == pytest.approx(0.0, abs=EXACT)
    (plane,) = primitives["C60/C1/Handle_case_C1_ON_plane.stp"].primitives
    assert isinstance(plane, Plane) and plane.outward in (-1, 1)
    assert [edge.kind for edge in plane.boundary] == ["segment"] * 4
    ring = primitives["REVISED_CAD2/J1/Handle_Case_J1_top_bearing2.stp"].primitives[0]
    assert type(ring.mid_circle) is Circle


def test_compare_documents_reports_differences_beyond_tolerance():
    document = {"a": [1.0, {"b": "x"}], "ocp_version": "1"}
    assert compare_documents(document, {"a": [1.0 + 1e-9, {"b": "x"}], "ocp_version": "2"},
                             tolerance=1e-7) == []
    differences = compare_documents(document, {"a": [1.1, {"b": "y"}], "ocp_version": "1"},
                                    tolerance=1e-7)
    assert len(differences) == 2 and differences[0].startswith("$.a[0]")


@needs_ocp
def test_reextraction_matches_the_committed_document(capsys):
    # c60-extract --check extracts again from the STEP files and compares within the stated
    # tolerance (CHECK_TOLERANCE); exit status 0 means no difference.
    assert extract_main(["--check"]) == 0
    assert "matches" in capsys.readouterr().out


@needs_ocp
def test_check_fails_on_a_changed_document(tmp_path, capsys):
    document = json.loads(PRIMITIVES_PATH.read_text(encoding="utf-8"))
    document["files"][0]["primitives"][0]["residual_mm"] += 1.0e-3
    changed = tmp_path / "primitives.json"
    changed.write_text(json.dumps(document), encoding="utf-8")
    assert extract_main(["--check", "--output", str(changed)]) == 1
    assert "1 differences" in capsys.readouterr().err


def test_missing_opencascade_is_a_clear_user_error(monkeypatch, capsys):
    for name in [key for key in sys.modules if key == "OCP" or key.startswith("OCP.")]:
        monkeypatch.setitem(sys.modules, name, None)
    monkeypatch.setitem(sys.modules, "OCP", None)
    assert extract_main(["--check"]) == 2
    assert "pip install -e '.[cad]'" in capsys.readouterr().err
