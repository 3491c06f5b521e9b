"""The glossary at the end of the report: every abbreviation and term of art the page uses,
each explained once (only those the page's text contains are listed)."""

from __future__ import annotations

import html
import re

from clearbench.harness.report.html_parts import esc, heading

#: Term -> what it means. Order of the page's glossary: alphabetical, case-insensitive.
TERMS: dict[str, str] = {
    "C1": "C-60 contact: the handle on its ON stops in the case and cover",
    "C3": "C-60 contact: the plate on its ON stops in the case",
    "C4": "C-60 latch contact: the hook's half rings on the tripping bar's wedge (side, top, "
          "hollow and fillet faces)",
    "C5": "C-60 latch contact: the tripping bar on the hook",
    "C6": "C-60 contact: the moving contact on the plate",
    "C7": "C-60 contact: the moving contact on the fixed contact; its normal force is FC-1",
    "J1": "C-60 revolute joint with clearance: the handle in the case and cover",
    "J2": "C-60 revolute joint with clearance: the plate on the needle",
    "J3": "C-60 revolute joint with clearance: the hook on the plate",
    "J4": "C-60 revolute joint with clearance: the tripping bar on the plate",
    "J5": "C-60 revolute joint with clearance: the rod on the handle",
    "J6": "C-60 revolute joint with clearance: the rod on the hook",
    "J7": "C-60 revolute joint with clearance: the moving contact on the needle",
    "S3": "C-60: the needle's bearing in the case and cover",
    "FC-1": "C-60 functional condition 1: the C7 contact force in the ON pose [N]",
    "FC-2": "C-60 functional condition 2: x of the tripping bar's pin axis [mm]",
    "FC-3": "C-60 functional condition 3: -y of the tripping bar's pin axis [mm]",
    "FC-4": "C-60 functional condition 4: x of the tripping bar's lamage axis [mm]",
    "FC-5": "C-60 functional condition 5: -y of the tripping bar's lamage axis [mm]",
    "FC-6": "C-60 functional condition 6: the tripping bar to plunger distance in x [mm]",
    "strike": "C-60 trip: the plunger first pushes the tripping bar",
    "release": "C-60 trip: the latch contacts C4 and C5 first carry no force",
    "opening": "C-60 trip: C7's gap first exceeds 0.1 mm (the contacts are open)",
    "ON pose": "the C-60 closed and latched, the moving contact pressed on the fixed one",
    "comfortable step": "a scene's own time step (its time_step field): the step its "
                        "expectations are set for, and the one the overview shows",
    "x reference": "wall time per simulated time over the reference engine's at its finest "
                   "step on the same scene and horizon",
    "Pareto front": "the runs no other run beats on both error and wall time (a run that "
                    "did not finish is never on it)",
    "error budget": "the largest relative error accepted on a figure (1 %, 5 %)",
    "rebuild's overlap": "how deep an engine's rebuilt shapes (a ring of spheres, a bore's "
                         "polygon lining) let the exact surfaces overlap while they only touch",
    "Q2": "predictivity coefficient of a metamodel: 1 - (cross-validated squared error) / "
          "(variance of the output); 1 is a perfect prediction",
    "FORM": "first-order reliability method: the probability of leaving a limit from the "
            "linearised limit state at its most probable point",
    "S1": "first-order Sobol' index: the share of an output's variance one input explains "
          "alone",
    "ST": "total Sobol' index: the share of an output's variance an input takes part in, "
          "interactions included",
    "SRC": "standardised regression coefficient of a linear fit of the output on the inputs",
    "R^2": "share of the output's variance a linear fit explains",
    "Cp": "process capability: (USL - LSL) / (6 sigma)",
    "Cpk": "process capability with centring: min(USL - mean, mean - LSL) / (3 sigma)",
    "Cc": "centring coefficient of the mean within the limits",
    "PPM": "parts per million outside the specification limits",
    "LSL": "lower specification limit",
    "USL": "upper specification limit",
    "CI": "confidence interval",
    "CV": "coefficient of variation: standard deviation over mean (of an estimate)",
    "RMS": "root mean square",
    "sigma": "standard deviation",
    "LARS": "least-angle regression: how a polynomial chaos keeps its terms",
    "chaos": "polynomial chaos expansion: a metamodel of orthogonal polynomials in the inputs",
    "kriging": "Gaussian-process metamodel",
    "Monte Carlo": "many runs of one scene with inputs drawn at random (here the joints' "
                   "clearances)",
    "dt": "the time step of a run",
}


def _visible_text(page: str) -> str:
    """The page's text without tags, scripts, styles and embedded data."""
    page = re.sub(r"<(script|style)\b.*?</\1>", " ", page, flags=re.S | re.I)
    page = re.sub(r"<[^>]+>", " ", page)
    return html.unescape(page)


def used_terms(page: str) -> list[str]:
    """The :data:`TERMS` the page's visible text contains, as whole words."""
    text = _visible_text(page)
    return [term for term in TERMS
            if re.search(rf"(?<![\w-]){re.escape(term)}(?![\w-])", text)]


def glossary_html(page: str) -> str:
    """The glossary section for ``page`` (the rest of the page's HTML)."""
    terms = sorted(used_terms(page), key=str.lower)
    if not terms:
        return ""
    rows = "".join(f"<dt id='term-{esc(re.sub(r'[^A-Za-z0-9]+', '-', t))}'>{esc(t)}</dt>"
                   f"<dd>{esc(TERMS[t])}</dd>" for t in terms)
    return heading(2, "Glossary", "glossary") + f"<dl class='glossary'>{rows}</dl>"
