"""The C-60 model's documented alternatives: named variants and validated overrides
reach the scene's laws and friction, bad values are refused naming the field, the default is
the source's model, and a campaign takes a variant through its scene_parameters."""

from __future__ import annotations

import math

import pytest

from clearbench.harness.cli.main import main
from clearbench.harness.studies.campaign.definition import (
    CampaignError,
    load_campaign,
    with_overrides,
)
from clearbench.harness.studies.campaign.execution import plan_samples
from clearbench.scenarios.c60 import model, variants
from clearbench.scenarios.library import get_scene
from clearbench.scenarios.validation import SceneError

C60_SCENES = ["c60-on", "c60-trip", "c60-contact-force-test", "c60-trip-force-test"]


def contact_law(scene):
    return next(load for load in scene.loads if load.name == "contact_pressure_spring")


def friction_by_class(scene) -> dict[str, set[float]]:
    out: dict[str, set[float]] = {}
    for pair in scene.contacts:
        if pair.name.startswith("Probe_"):
            continue
        kind = variants.contact_class(model.sheet_contact_name(pair.name))
        out.setdefault(kind, set()).add(pair.friction)
    return out


def test_the_default_is_the_source_model():
    assert variants.model_parameters() == variants.ModelParameters()
    assert variants.model_parameters("source").changes() == {}
    scene = get_scene("c60-on")
    sheet = {c["name"]: c["friction"] for c in model.load_model()["contacts"]}
    for pair in scene.contacts:
        assert pair.friction == sheet[model.sheet_contact_name(pair.name)], pair.name
    law = contact_law(scene)
    # The source's law: offset (54.54 + 22) deg + 0.49 rad, forces M / 5.48 and M / 6.06.
    assert law.offset == math.radians(54.54 + 22.0) + 0.49
    assert [a.lever for a in law.applications] == [5.48, None, 6.06]
    assert scene.description.endswith("Model: the source's model.")


@pytest.mark.parametrize("name", list(variants.VARIANTS))
@pytest.mark.parametrize("scene_name", C60_SCENES)
def test_every_named_variant_builds_every_c60_scene_and_is_recorded(name, scene_name):
    scene = get_scene(scene_name, variant=name)
    defaults = {}
    if scene_name == "c60-contact-force-test":   # the bench test's own default arm
        defaults = {"handle_spring_arm": variants.VARIANTS[name].get("handle_spring_arm",
                                                                     "design")}
    parameters = variants.model_parameters(name, **defaults)
    assert scene.description.endswith(f"Model: {parameters.label()}.")
    if parameters != variants.model_parameters("source", **defaults):
        # The variant changes the scene's content, so its runs are cached apart.
        assert scene.content_hash != get_scene(scene_name).content_hash


def test_the_law_takes_preload_offset_and_levers():
    law = contact_law(get_scene("c60-on", variant="old-validated-levers"))
    assert [a.lever for a in law.applications] == [5.0, None, 4.84]
    law = contact_law(get_scene("c60-on", variant="offset-67", contact_spring_preload=0.9599))
    # offset -67 deg: D = theta_mc - theta_plate + 67 deg; exact arithmetic of the same terms.
    assert law.offset == math.radians(67.0) + 0.9599
    design = get_scene("c60-on", variant="design-arm").loads[0].applications[0]
    assert design.point == (0.0, -5.65, -0.9)


def test_paper_table_4_gives_each_pair_its_materials_value():
    frictions = friction_by_class(get_scene("c60-on", variant="paper-table-4"))
    plastic_pairs = {"J1", "C1", "J3", "J4", "C4", "C5", "C3", "C6", "FC_X"}
    metal_plastic = {"S3", "J2", "J5", "J6", "J7", "TRIP", "plunger_bearing"}
    assert plastic_pairs | metal_plastic | {"C7"} == set(variants.CONTACT_CLASSES)
    for kind in plastic_pairs:
        assert frictions[kind] == {0.3}, kind
    for kind in metal_plastic:
        assert frictions[kind] == {0.1}, kind
    # C7 is metal on metal (blade on the fixed contact): Table 4 has no value, the source's.
    assert frictions["C7"] == {0.1}
    assert variants.table_4_friction(frozenset({variants.METAL})) is None


def test_friction_overrides_merge_over_the_variant():
    frictions = friction_by_class(get_scene("c60-on", variant="latch-0.1"))
    assert frictions["C4"] == {0.1} and frictions["S3"] == {0.2}
    frictions = friction_by_class(get_scene("c60-on", variant="latch-0.1",
                                            friction={"C5": 0.25}))
    assert frictions["C4"] == {0.1} and frictions["C5"] == {0.25}


@pytest.mark.parametrize("parameters, field", [
    ({"variant": "paper"}, "variant"),
    ({"contact_spring_preload": -0.1}, "contact_spring_preload"),
    ({"contact_spring_preload": math.nan}, "contact_spring_preload"),
    ({"contact_spring_angle_offset": 10.0}, "contact_spring_angle_offset"),
    ({"moving_contact_force_lever": 0.0}, "moving_contact_force_lever"),
    ({"plate_force_lever": "5"}, "plate_force_lever"),
    ({"handle_spring_arm": "left"}, "handle_spring_arm"),
    ({"friction_set": "table-4"}, "friction_set"),
    ({"friction": {"C9": 0.1}}, "friction.C9"),
    ({"friction": {"C4": 1.5}}, "friction.C4"),
    ({"friction": 0.1}, "friction"),
    ({"preload": 0.9}, "preload"),
])
def test_bad_values_are_refused_naming_the_field(parameters, field):
    with pytest.raises(SceneError) as error:
        get_scene("c60-on", **parameters)
    assert error.value.field == field


def test_a_bad_value_on_the_command_line_exits_2_before_any_run(tmp_path, capsys):
    code = main(["run", "c60-on", "--set", "contact_spring_preload=-1", "--store",
                 str(tmp_path)])
    assert code == 2
    assert "contact_spring_preload" in capsys.readouterr().err


def test_a_campaign_runs_any_named_variant_through_scene_parameters():
    study = load_campaign("c60-paper-mc")
    variant = with_overrides(study, samples=2, scene_parameters={"variant": "preload-0.9599"})
    samples = plan_samples(variant)
    scene = samples[0].spec.scene
    assert contact_law(scene).offset == math.radians(54.54 + 22.0) + 0.9599
    assert dict(samples[0].spec.source.parameters)["variant"] == "preload-0.9599"
    broken = with_overrides(study, samples=1, scene_parameters={"variant": "nope"})
    with pytest.raises(CampaignError, match="variant"):
        plan_samples(broken)


def _solids(path):
    """Volume [mm3] and centroid [mm] of each solid of a STEP file (OpenCASCADE)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.STEPControl import STEPControl_Reader
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    reader = STEPControl_Reader()
    reader.ReadFile(str(path))
    reader.TransferRoots()
    explorer = TopExp_Explorer(reader.OneShape(), TopAbs_SOLID)
    out = []
    while explorer.More():
        properties = GProp_GProps()
        BRepGProp.VolumeProperties_s(explorer.Current(), properties)
        centre = properties.CentreOfMass()
        out.append((properties.Mass(), (centre.X(), centre.Y(), centre.Z())))
        explorer.Next()
    return out


#: Densities [g/cm3] telling the materials apart: moulded plastics (filled ones included) are
#: below 2.2, steel and copper alloys above 7; nothing of the mechanism lies in between.
PLASTIC_BELOW, METAL_ABOVE = 2.2, 7.0


def test_part_materials_follow_from_the_sheet_masses_and_the_cad_volumes():
    pytest.importorskip("OCP")
    from tools.c60_cad.extract import CAD_DIR

    for body in model.load_model()["bodies"]:
        material = variants.PART_MATERIALS[body["name"]][0]
        if body["name"] in ("plunger", "moving_contact"):
            continue   # the plunger by its function; the moving contact below
        mass = body.get("paper_mass", body["mass"])   # g
        volume = sum(v for v, _ in _solids(CAD_DIR / body["cad"]))   # mm3
        density = 1e3 * mass / volume   # g/cm3
        if material == variants.PLASTIC:
            assert density < PLASTIC_BELOW, body["name"]
        else:
            assert density > METAL_ABOVE, body["name"]
    # The moving contact: two solids whose densities reproduce the sheet's mass and centre of
    # mass (x and z fix the two masses; y checks them) are a plastic carrier and a metal blade.
    entry = next(b for b in model.load_model()["bodies"] if b["name"] == "moving_contact")
    (v1, c1), (v2, c2) = sorted(_solids(CAD_DIR / entry["cad"]))[::-1]   # carrier first
    x = entry["center_of_mass"][0]
    blade_mass = entry["mass"] * (x - c1[0]) / (c2[0] - c1[0])
    carrier_mass = entry["mass"] - blade_mass
    assert 1e3 * carrier_mass / v1 < PLASTIC_BELOW < METAL_ABOVE < 1e3 * blade_mass / v2
    y = (carrier_mass * c1[1] + blade_mass * c2[1]) / entry["mass"]
    # The sheet's y of the centre of mass, to its 4th digit (printed to 7; 1e-3 mm allows
    # the CAD's B-spline volumes).
    assert y == pytest.approx(entry["center_of_mass"][1], abs=1e-3)
