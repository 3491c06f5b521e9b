"""Scene sub-commands: ``list``, ``show`` and ``validate``."""

from __future__ import annotations

import argparse
import json
import sys
import textwrap

import clearbench
from clearbench.adapters import all_availability
from clearbench.harness.cli.commands import command_help
from clearbench.harness.cli.errors import UserError
from clearbench.scenarios.library import SCENES, get_entry, scene_names
from clearbench.scenarios.scene import Scene
from clearbench.scenarios.serialization import (
    load_scene_file,
    scene_from_dict,
    scene_to_dict,
    scene_to_json,
    scene_to_toml,
)
from clearbench.scenarios.units import LENGTH_UNITS, MASS_UNITS, TIME_UNITS, UnitSystem
from clearbench.scenarios.validation import SceneError


def register(subparsers) -> None:
    """Add the scene sub-commands to ``subparsers``."""
    listing = subparsers.add_parser(
        "list", help=command_help("list"),
        description="List every registered scene with its tags and derived features, and every "
        "engine with its availability on this machine.",
    )
    listing.add_argument("--tag", help="only scenes with this tag")
    listing.set_defaults(handler=run_list)

    show = subparsers.add_parser(
        "show", help=command_help("show"),
        description="Print a registered scene as a TOML (default) or JSON scene file.",
    )
    show.add_argument("scene", help="registered scene name (see `clearbench list`)")
    show.add_argument("--format", choices=("toml", "json"), default="toml")
    show.add_argument("--units", metavar="L-M-T",
                      help="rescale to another unit system first, e.g. mm-g-ms")
    show.set_defaults(handler=run_show)

    validate = subparsers.add_parser(
        "validate", help=command_help("validate"),
        description="Read a scene file, validate every field and cross reference, and check "
        "that it round-trips losslessly. Exit status 0 when valid, 2 with the field and value "
        "at fault otherwise.",
    )
    validate.add_argument("file", help="scene file (.toml or .json)")
    validate.set_defaults(handler=run_validate)


def parse_units(text: str) -> UnitSystem:
    """``'mm-g-ms'`` -> UnitSystem; UserError naming the accepted units otherwise."""
    parts = text.split("-")
    if len(parts) != 3:
        raise UserError(f"--units {text!r}: expected LENGTH-MASS-TIME, e.g. mm-g-ms")
    try:
        return UnitSystem(*parts)
    except SceneError as error:
        raise UserError(
            f"--units {text!r}: {error} (length {sorted(LENGTH_UNITS)}, mass "
            f"{sorted(MASS_UNITS)}, time {sorted(TIME_UNITS)})"
        ) from None


def run_list(args: argparse.Namespace) -> int:
    names = scene_names(args.tag)
    if args.tag and not names:
        tags = sorted({t for e in SCENES.values() for t in e.tags})
        raise UserError(f"no scene has tag {args.tag!r}; tags: {', '.join(tags)}")
    print(f"Scenes ({len(names)}):")
    features_of = scene_features(names)
    for name in names:
        entry = get_entry(name)
        print(f"  {name:<22} {entry.summary}")
        print(f"  {'':<22} tags: {', '.join(entry.tags)}")
        features = ", ".join(features_of[name]) or "(none)"
        for line in textwrap.wrap(f"features: {features}", 74):
            print(f"  {'':<22} {line}")
    print()
    print_engines()
    return 0


#: File of the registered scenes' features in :func:`clearbench.checkout_cache_dir`.
FEATURES_FILE = "scene-features.json"


def scene_features(names: list[str]) -> dict[str, list[str]]:
    """Name -> sorted features of the registered scenes ``names``. Building a scene to derive
    them takes seconds for the C-60's (its CAD primitives), so they are kept in the cache
    directory of this checkout and source state, which a change of the scenes' sources
    replaces: only scenes not found there are built (and added)."""
    path = clearbench.checkout_cache_dir() / FEATURES_FILE
    try:
        cached = json.loads(path.read_text())
    except (OSError, ValueError):
        cached = {}
    missing = [name for name in names if name not in cached]
    for name in missing:
        cached[name] = sorted(get_entry(name).build().features)
    if missing:
        try:
            clearbench.write_json(path, cached, indent=1, sort_keys=True)
        except OSError:  # a read-only cache only costs the builds next time
            pass
    return {name: cached[name] for name in names}


def check_round_trip(scene: Scene, where: str) -> None:
    """UserError naming ``where`` when ``scene`` does not come back equal from its dict form."""
    if scene_from_dict(scene_to_dict(scene)) != scene:
        raise UserError(f"{where}: the scene does not round-trip losslessly (a bug)")


def print_engines() -> None:
    """Print every engine of the registry with its availability here."""
    print("Engines:")
    for availability in all_availability():
        state = "available" if availability.available else "unavailable"
        print(f"  {availability.engine:<10} {state:<12} {availability.detail}")


def run_show(args: argparse.Namespace) -> int:
    try:
        scene = get_entry(args.scene).build()
    except KeyError as error:
        raise UserError(str(error.args[0])) from None
    if args.units:
        scene = scene.rescaled(parse_units(args.units))
    sys.stdout.write(scene_to_toml(scene) if args.format == "toml" else scene_to_json(scene))
    if args.format == "json":
        sys.stdout.write("\n")
    return 0


def run_validate(args: argparse.Namespace) -> int:
    try:
        scene = load_scene_file(args.file)
    except FileNotFoundError:
        raise UserError(f"{args.file}: no such file") from None
    except SceneError as error:
        raise UserError(f"{args.file}: invalid scene: {error}") from None
    check_round_trip(scene, args.file)
    print(f"{args.file}: valid scene {scene.name!r} in {scene.units.describe()}: "
          f"{len(scene.bodies)} bodies, {len(scene.joints)} joints, "
          f"{len(scene.clearance_joints)} clearance joints, {len(scene.all_contacts)} contact "
          f"pairs, horizon {scene.horizon} {scene.units.time}")
    print(f"  features: {', '.join(sorted(scene.features)) or '(none)'}")
    return 0
