"""clearbench: a cross-validation harness for rigid-body contact simulators.

The sub-packages live in top-level folders of the repository and are installed under this
namespace: ``clearbench.scenarios`` (engine-neutral scenes, geometry, analytic references),
``clearbench.ref_solver`` (our nonsmooth Moreau--Jean solver), ``clearbench.adapters`` (one
module per engine) and ``clearbench.harness`` (runner, metrics, store, report, CLI).
"""

__version__ = "0.1.0"
