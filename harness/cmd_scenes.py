"""Scene sub-commands: ``list``, ``show``, ``validate`` and ``demo``."""

from __future__ import annotations


def register(subparsers) -> None:
    """Add the scene sub-commands to ``subparsers``."""
    demo = subparsers.add_parser("demo", help="the main job of the README")
    demo.set_defaults(handler=lambda args: 0)
