"""How many of the pair property test's configurations the gap kernel gets wrong.

Draws ``--draws`` configurations of one canonical pair, both orders, with the strategy of
``tests/test_kernel_against_instrument.py`` (hypothesis, derandomised: the same draws on every
run and revision), judges each with that test's own check against the independent instrument,
and prints the count of disagreements and the first few. The default suite draws 6 per pair
and ``-m slow`` 150; this counts over many more, to state how often a pair fails, not only
whether it does.

Run from the repository's root (it imports the test module from ``tests/``), for example on a
checkout of an older revision with its environment to measure the kernel before a change;
``--plain`` runs the kernels as plain Python (numba blocked), which needs no compile.

    python -m tools.pair_survey circle bore --draws 300
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kind_a", help="the pair's first shape kind, canonical order (circle)")
    parser.add_argument("kind_b", help="its second shape kind (bore)")
    parser.add_argument("--draws", type=int, default=300,
                        help="configurations drawn (each in a random order of the pair)")
    parser.add_argument("--plain", action="store_true",
                        help="block numba: the kernels run as plain Python")
    parser.add_argument("--show", type=int, default=5, help="disagreements printed")
    arguments = parser.parse_args(argv)
    if arguments.plain:
        sys.modules["numba"] = None
    warnings.filterwarnings("ignore")
    sys.path.insert(0, str(Path("tests").resolve()))
    import test_kernel_against_instrument as property_test
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    pair = (arguments.kind_a, arguments.kind_b)
    if pair not in property_test.PAIRS:
        parser.error(f"pair {pair!r} is not a canonical pair of the property test")
    drawn, failures = [], []

    @settings(max_examples=arguments.draws, deadline=None, database=None, derandomize=True,
              suppress_health_check=list(HealthCheck))
    @given(data=st.data(), swapped=st.booleans())
    def judge(data, swapped):
        configuration = data.draw(property_test.configurations(pair))
        drawn.append(swapped)
        try:
            property_test._check(pair, swapped, configuration)
        except AssertionError as failure:
            failures.append(str(failure))

    judge()
    print(f"{pair[0]}-{pair[1]} ({property_test.PAIRS[pair]}): {len(failures)} of {len(drawn)} "
          f"configurations disagree with the instrument")
    for failure in failures[:arguments.show]:
        print("  " + failure)
    return 0


if __name__ == "__main__":
    sys.exit(main())
