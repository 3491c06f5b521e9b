"""One colour and one marker per engine label, the same in every figure of the report.

The colour says the engine (Okabe-Ito palette, readable by colour-blind readers), the marker
and the line style say the preset, so ``mujoco[default]`` and ``mujoco[tuned]`` are one family
told apart in print too.
"""

from __future__ import annotations

from dataclasses import dataclass

#: Engine name -> colour (Okabe-Ito); an engine not listed takes the next of EXTRA_COLOURS.
ENGINE_COLOURS = {"reference": "#000000", "mujoco": "#0072B2", "pybullet": "#E69F00",
                  "exudyn": "#009E73", "siconos": "#CC79A7"}
EXTRA_COLOURS = ("#D55E00", "#56B4E9", "#F0E442", "#999999")
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


def _pick(table: dict, extra: tuple, key: str):
    if key in table:
        return table[key]
    return extra[sum(map(ord, key)) % len(extra)]   # stable across runs (no hash seed)


def engine_style(label: str) -> EngineStyle:
    """The style of an engine label such as ``'siconos[nsn-ac]'`` (anything after a space,
    such as a step, is ignored)."""
    name, preset = split_label(label)
    colour = _pick(ENGINE_COLOURS, EXTRA_COLOURS, name)
    marker = _pick(PRESET_MARKERS, tuple((m, "-") for m in EXTRA_MARKERS), preset)
    return EngineStyle(colour, *marker)
