"""One colour and one marker per engine label, the same in every figure of the report.

The colour says the engine (the one it declares, ``HARNESS_DEFAULTS.colour``, else one of the
palette's; Okabe-Ito, readable by colour-blind readers), the marker and the line style say the
preset, so ``mujoco[default]`` and ``mujoco[tuned]`` are one family told apart in print too.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import dataclass

from clearbench.harness.run.engine_choice import engine_defaults, engine_names

#: Colours of the engines that declare none (Okabe-Ito's, and grey), less those an engine
#: declares: each such engine takes one, the same for the same name.
EXTRA_COLOURS = ("#D55E00", "#56B4E9", "#F0E442", "#999999", "#000000", "#0072B2", "#E69F00",
                 "#009E73", "#CC79A7")
#: Preset -> (marker, line style); a preset not listed takes the next of EXTRA_MARKERS.
PRESET_MARKERS = {"default": ("o", "-"), "tuned": ("s", "--"), "nsn-ac": ("^", "-."),
                  "projection": ("D", ":"), "no-projection": ("v", ":"), "nsgs": ("P", "--"),
                  "newton": ("X", "-."), "implicit": ("*", ":")}
EXTRA_MARKERS = ("h", "<", ">", "p")


@dataclass(frozen=True)
class EngineStyle:
    colour: str
    marker: str
    line_style: str

    def plot_kwargs(self) -> dict:
        """Keyword arguments of ``Axes.plot`` for this engine's line."""
        return {"color": self.colour, "marker": self.marker, "linestyle": self.line_style}


def split_label(label: str) -> tuple[str, str]:
    """``'mujoco[tuned] dt=0.001'`` -> ``('mujoco', 'tuned')`` (preset 'default' when absent)."""
    head = label.split(" ", 1)[0]
    name, _, rest = head.partition("[")
    return name, rest.rstrip("]") or "default"


def _pick(table: Mapping, extra: tuple, key: str):
    if key in table:
        return table[key]
    return extra[sum(map(ord, key)) % len(extra)]   # stable across runs (no hash seed)


@functools.cache
def _registered_colours() -> tuple[tuple[str, str], ...]:
    declared = ((name, engine_defaults(name).colour) for name in engine_names())
    return tuple((name, colour) for name, colour in declared if colour)


def engine_colours(extra_modules: Mapping[str, str] | None = None) -> dict[str, str]:
    """Engine name -> the colour it declares (``HARNESS_DEFAULTS.colour``), for the engines
    of the registry and of ``extra_modules`` that declare one."""
    colours = dict(_registered_colours())
    for name in extra_modules or {}:
        declared = engine_defaults(name, extra_modules).colour
        if declared:
            colours[name] = declared
    return colours


def engine_style(label: str, colours: Mapping[str, str] | None = None) -> EngineStyle:
    """The style of an engine label such as ``'siconos[nsn-ac]'`` (anything after a space,
    such as a step, is ignored). ``colours``: engine name -> declared colour (default: the
    registry's, :func:`engine_colours`); an engine without one takes a colour of
    :data:`EXTRA_COLOURS` that no engine declares."""
    name, preset = split_label(label)
    colours = dict(_registered_colours()) if colours is None else colours
    free = tuple(c for c in EXTRA_COLOURS if c not in colours.values()) or EXTRA_COLOURS
    colour = _pick(colours, free, name)
    marker = _pick(PRESET_MARKERS, tuple((m, "-") for m in EXTRA_MARKERS), preset)
    return EngineStyle(colour, *marker)
