"""Regression check: a quick suite compared with a committed baseline whose tolerances are
measured, not chosen.

- :mod:`.suite`: the suite's runs (a new baseline's: what each engine declares), their specs,
  running them;
- :mod:`.perturbations`: the perturbations that carry no physics (round-off of the initial
  state, numba and OpenBLAS code paths, an engine's own arithmetic settings);
- :mod:`.tolerance`: the tolerance model (exact, bounded, statistical figures; floors);
- :mod:`.measure`: measuring a baseline (``--update``): every run under every perturbation;
- :mod:`.baseline`: the baseline file; :mod:`.compare`: the check against it.
"""

from clearbench.harness.studies.regress.baseline import (
    DEFAULT_BASELINE,
    load_baseline,
    new_baseline,
    updated_baseline,
    write_baseline,
)
from clearbench.harness.studies.regress.compare import RegressOutcome, compare, version_note
from clearbench.harness.studies.regress.measure import measure_baseline
from clearbench.harness.studies.regress.suite import (
    default_suite,
    run_suite,
    suite_entries,
    suite_specs,
)
from clearbench.harness.studies.regress.tolerance import Check, classify

__all__ = ["DEFAULT_BASELINE", "Check", "RegressOutcome", "classify", "compare",
           "default_suite", "load_baseline", "measure_baseline", "new_baseline", "run_suite",
           "suite_entries", "suite_specs", "updated_baseline", "version_note",
           "write_baseline"]
