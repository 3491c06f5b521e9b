"""``clearbench view``: a stored run, or a scene's stored runs in several engines, played in
the browser side by side (the report's viewer, as a page of its own)."""

from __future__ import annotations

import argparse
from pathlib import Path

from clearbench.harness.cli.commands import command_help
from clearbench.harness.cli.common import UserError, add_engine_option, add_store_option, open_store
from clearbench.harness.report.viewer.payload import FRAMES, viewer_page, viewer_payload
from clearbench.harness.report.viewer.stored import ViewInputError, first_events, stored_runs


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "view", help=command_help("view"),
        description="Write a self-contained HTML page (no network needed) that plays stored "
        "runs side by side on one time slider: each body drawn from the scene's shapes, the "
        "contacts that carry force and their forces, the C-60 trip's strike, release and "
        "opening as buttons, and the scene's labelled parts, joints and contacts. RUN_OR_SCENE "
        "is a run key (or a unique prefix of 6 characters or more) or a scene name; for a "
        "scene, each engine's stored run at --dt (else its finest step).",
    )
    parser.add_argument("run_or_scene", metavar="RUN_OR_SCENE",
                        help="a run key of the store, or a scene name")
    add_engine_option(parser, many=True, help="engines to show, ENGINE (every preset) or "
                      "ENGINE[PRESET] (default: every engine with a stored run)")
    parser.add_argument("--dt", type=float, default=None, metavar="DT",
                        help="the step to show, in the scene's time unit (default: each "
                        "engine's finest)")
    parser.add_argument("--frames", type=int, default=FRAMES, metavar="N",
                        help=f"frames of the time slider (default {FRAMES})")
    parser.add_argument("--no-contacts", action="store_true",
                        help="leave out contact points and forces (a smaller page)")
    parser.add_argument("--out", default=None, metavar="FILE",
                        help="the page to write (default reports/out/view-RUN_OR_SCENE.html)")
    add_store_option(parser)
    parser.set_defaults(handler=run_view)


def run_view(args: argparse.Namespace) -> int:
    if args.dt is not None and not args.dt > 0:
        raise UserError(f"--dt {args.dt!r}: must be > 0")
    if args.frames < 2:
        raise UserError(f"--frames {args.frames!r}: must be at least 2")
    store = open_store(args, create=False)
    try:
        scene, runs = stored_runs(store, args.run_or_scene, args.engines or (), args.dt)
    except ViewInputError as error:
        raise UserError(str(error)) from None
    payload = viewer_payload(scene, runs, first_events(runs), args.frames,
                             contacts=not args.no_contacts)
    out = Path(args.out or f"reports/out/view-{args.run_or_scene}.html")
    out.parent.mkdir(parents=True, exist_ok=True)
    title = f"{scene.name}: " + ", ".join(run.label for run in runs)
    out.write_text(viewer_page(payload, title, scene.description), encoding="utf-8")
    print(f"view: {out} ({out.stat().st_size / 1e6:.2f} MB, {len(runs)} runs, "
          f"{len(payload['times'])} frames)")
    return 0
