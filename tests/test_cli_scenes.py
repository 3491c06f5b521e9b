"""The scene sub-commands of the CLI, run in-process through ``main``."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from clearbench.harness.cli.main import main
from clearbench.harness.cli.scenes import scene_features
from clearbench.scenarios.library import get_entry, scene_names
from clearbench.scenarios.registry import SceneEntry
from clearbench.scenarios.serialization import load_scene_file, scene_from_toml

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "ball_on_ramp.toml"


def test_list_shows_every_scene_with_tags_and_features(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    for name in scene_names():
        assert name in out
    assert "tags:" in out and "features:" in out
    assert "Engines:" in out and "reference" in out


def test_list_with_unknown_tag_fails_naming_the_tags(capsys):
    assert main(["list", "--tag", "nope"]) == 2
    assert "smoke" in capsys.readouterr().err


def test_show_prints_a_scene_file_that_reads_back(capsys):
    assert main(["show", "clearance-pendulum", "--units", "mm-g-ms"]) == 0
    scene = scene_from_toml(capsys.readouterr().out)
    assert scene.units.length == "mm"
    assert scene.clearance_joints[0].radial_clearance == pytest.approx(0.1, rel=1e-12)


def test_show_unknown_scene_exits_non_zero(capsys):
    assert main(["show", "no-such-scene"]) == 2
    assert "known scenes" in capsys.readouterr().err


def test_show_bad_units_names_the_accepted_units(capsys):
    assert main(["show", "pendulum", "--units", "ft-lb-s"]) == 2
    assert "mm" in capsys.readouterr().err


def test_validate_accepts_the_hand_written_example(capsys):
    assert main(["validate", str(EXAMPLE)]) == 0
    assert "valid scene 'ball-on-ramp'" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("replace", "by", "expected"),
    [
        ("mass = 4.11 ", "mass = -4.11 ", "mass = -4.11"),
        ('body_b = "ball"', 'body_b = "balll"', "body_b = 'balll'"),
        ("radius = 5.0", "radius = nan", "radius = nan"),
        ("restitution = 0.6", "restitution = 1.6", "restitution = 1.6"),
        ("friction = 0.2", "friction = -0.2", "friction = -0.2"),
        ("time_step = 0.1 ", "time_step = 0.0 ", "time_step = 0.0"),
        ('name = "ramp"', 'name = "ramp"\nmasse = 3.0', "masse"),
        ("horizon = 200.0", "horizon = [", "not valid TOML"),
    ],
)
def test_validate_broken_file_names_field_and_value(tmp_path, capsys, replace, by, expected):
    text = EXAMPLE.read_text()
    assert replace in text
    broken = tmp_path / "broken.toml"
    broken.write_text(text.replace(replace, by, 1))
    assert main(["validate", str(broken)]) == 2
    assert expected in capsys.readouterr().err


def test_validate_missing_file(capsys):
    assert main(["validate", "/nonexistent/scene.toml"]) == 2
    assert "no such file" in capsys.readouterr().err


def test_documented_scene_example_is_the_shipped_example_and_valid():
    reference = (ROOT / "docs" / "scene-format.md").read_text()
    blocks = re.findall(r"```toml\n(.*?)```", reference, flags=re.S)
    assert blocks, "docs/scene-format.md documents the scene format with a TOML example"
    assert blocks[0] == EXAMPLE.read_text()
    assert scene_from_toml(blocks[0]) == load_scene_file(EXAMPLE)


def test_every_command_has_help(capsys):
    for command in ("list", "show", "validate", "demo"):
        with pytest.raises(SystemExit) as caught:
            main([command, "--help"])
        assert caught.value.code == 0
        assert "usage" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", "is a binary file (NUL byte at offset 8)"),
        ('name = "caf\u00e9"\n'.encode("latin-1"), "is not UTF-8 text (byte 0xe9 at offset 11)"),
    ],
    ids=["binary", "latin-1"],
)
def test_a_file_that_is_not_utf8_text_exits_2_naming_file_and_problem(tmp_path, capsys,
                                                                      content, expected):
    path = tmp_path / "scene.toml"
    path.write_bytes(content)
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and expected in err and "Traceback" not in err
    # The run command reads scene files the same way, before any engine runs.
    assert main(["run", str(path), "-e", "reference", "--store", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and expected in err


@pytest.mark.parametrize("radius", ["1e308", "1e31", "-1e31"])
def test_a_magnitude_that_would_overflow_the_engines_is_refused_naming_the_field(
        tmp_path, capsys, radius):
    text = EXAMPLE.read_text()
    assert "radius = 5.0" in text
    path = tmp_path / "huge.toml"
    path.write_text(text.replace("radius = 5.0", f"radius = {radius}", 1))
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err
    assert "radius" in err and "magnitude exceeds 1e+30" in err


def test_the_magnitude_bound_lets_every_library_scene_through():
    # MAX_MAGNITUDE must refuse nothing a real mechanism needs: every registered scene, also
    # rescaled to the smallest units offered (um, mg, us: lengths x 1e6), validates.
    from clearbench.scenarios.library import get_entry
    from clearbench.scenarios.units import UnitSystem

    for name in scene_names():
        get_entry(name).build().rescaled(UnitSystem("um", "mg", "us"))


def test_list_features_come_from_the_cache_and_are_the_built_scenes_features(
        tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    names = ["pendulum", "clearance-pendulum"]
    first = scene_features(names)
    assert first == {name: sorted(get_entry(name).build().features) for name in names}

    def no_build(self, **parameters):
        raise AssertionError(f"{self.name} built although its features are cached")

    monkeypatch.setattr(SceneEntry, "build", no_build)
    assert scene_features(names) == first
