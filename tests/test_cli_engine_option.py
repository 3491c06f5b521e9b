"""``-e ENGINE[PRESET]``: one parser helper (harness/cli/common.py add_engine_option) for every
command; repeated flags accumulate where a command takes several engines, and a command that
runs one engine refuses a second instead of keeping the last."""

from __future__ import annotations

import argparse

import pytest

from clearbench.harness.cli.common import _AccumulateEngines, _OneEngine
from clearbench.harness.cli.main import build_parser


def _commands(parser: argparse.ArgumentParser, path: tuple = ()):
    """(command words, parser) of every command and sub-command."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _commands(sub, (*path, name))
    yield path, parser


def _engine_action(parser: argparse.ArgumentParser):
    return next((a for a in parser._actions if "-e" in a.option_strings), None)


COMMANDS = [(path, parser) for path, parser in _commands(build_parser())
            if _engine_action(parser) is not None]
#: Commands that take several engines, and what they need besides -e.
MANY = {("sweep",): ["pendulum"], ("compare",): [], ("demo",): [], ("stability",): [],
        ("c60", "compare"): [], ("bench", "physics-table"): [], ("bench", "contact-cost"): [],
        ("regress",): [], ("view",): ["c60-trip"]}
#: Commands that run one engine.
ONE = {("run",): ["pendulum"], ("campaign", "run"): ["c60-paper"],
       ("campaign", "report"): ["c60-paper"], ("campaign", "status"): ["c60-paper"]}


def test_every_engine_option_is_the_shared_helper():
    found = {path: type(_engine_action(parser)) for path, parser in COMMANDS}
    assert found == {**{p: _AccumulateEngines for p in MANY}, **{p: _OneEngine for p in ONE}}


@pytest.mark.parametrize("path", list(MANY), ids=" ".join)
def test_repeated_engines_accumulate(path):
    parser = build_parser()
    argv = [*path, *MANY[path]]
    args = parser.parse_args([*argv, "-e", "reference", "-e", "mujoco[tuned]", "pybullet"])
    assert args.engines == ["reference", "mujoco[tuned]", "pybullet"]
    default = parser.parse_args(argv).engines
    assert default == (["reference"] if path == ("sweep",) else None)
    # The default is replaced by the first -e, never extended, and never altered.
    assert parser.parse_args([*argv, "-e", "exudyn"]).engines == ["exudyn"]
    assert parser.parse_args(argv).engines == default


@pytest.mark.parametrize("path", list(ONE), ids=" ".join)
def test_a_second_engine_is_refused_where_a_command_runs_one(path, capsys):
    parser = build_parser()
    argv = [*path, *ONE[path]]
    assert parser.parse_args([*argv, "-e", "mujoco"]).engine == "mujoco"
    with pytest.raises(SystemExit) as caught:
        parser.parse_args([*argv, "-e", "mujoco", "-e", "pybullet"])
    assert caught.value.code == 2
    err = capsys.readouterr().err
    assert "given twice" in err and "'mujoco'" in err and "'pybullet'" in err
