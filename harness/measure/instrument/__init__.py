"""The independent contact-geometry instrument: every gap and penetration measured a second way.

It shares no code with the gap kernel (:mod:`clearbench.kernels.gaps`) or with the pair
functions of :mod:`clearbench.scenarios.geometry` (nor with :mod:`clearbench.kernels.frames`
or :mod:`clearbench.kernels.quaternion`): it reads the scene's shape dataclasses and places
them itself with :mod:`scipy.spatial.transform`. Dependencies point down this list:

- :mod:`.placement`: world placement of a shape's frame from its body's pose (scipy);
- :mod:`.solids`: the exact signed distance function of each shape's solid, with a subgradient
  where the solid is convex, its bounding sphere and its sizes;
- :mod:`.surfaces`: each shape's boundary as parametrised patches, with, for any parameter
  cell, a bound of how far the cell's points lie from its centre (its covering radius) and of
  how far a linear function can drop over it;
- :mod:`.search`: certified minimisation of a partner's signed distance over a patched
  surface (branch and bound on those bounds), vectorised over many configurations;
- :mod:`.pair`: :func:`independent_gap`, the pair reading, and :func:`pair_gaps`, the same at
  many configurations of one pair;
- :mod:`.run_check`: the run-wide check: the instrument's penetration and clearance excess of a
  recorded run beside the kernel's, and the "unseen penetration" verdict.

What is measured (the guarantee) is in :mod:`.pair`'s docstring and docs/harness.md.
"""

from clearbench.harness.measure.instrument.pair import (
    IndependentGap,
    independent_gap,
    pair_gaps,
)

__all__ = ["IndependentGap", "independent_gap", "pair_gaps"]
